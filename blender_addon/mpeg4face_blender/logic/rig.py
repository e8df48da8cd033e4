# SPDX-License-Identifier: GPL-3.0-or-later
"""Rigged heads without bpy, testable with plain pytest: which shape keys belong to the rig,
the messages refusing a rig the tables cannot take (a modifier changing the vertex count, a
pose that moves the skin but not its FAP's feature point), and the FAP poses of bone rigs
(the FAP -> bone mapping and the iterative correction of a bone's motion until the feature
point lands at the FAP's amplitude).

A deformed copy is the evaluated mesh at a grammar marker minus the evaluated mesh at the
`neutral` marker (poses.read_posed_face_model); the displacements handed in here are in any axes as
long as they agree."""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

import mpeg4face

from . import shape_keys

Array = npt.NDArray[np.float64]

# Modifiers that move vertices and keep them (Blender's "deform only" modifiers and the
# ones editing data beside the positions): anything else may change the vertex count.
DEFORM_MODIFIERS = frozenset({
    "ARMATURE", "CAST", "CURVE", "DISPLACE", "HOOK", "LAPLACIANDEFORM", "LATTICE",
    "MESH_DEFORM", "SHRINKWRAP", "SIMPLE_DEFORM", "SMOOTH", "CORRECTIVE_SMOOTH",
    "LAPLACIANSMOOTH", "SURFACE_DEFORM", "WARP", "WAVE", "MESH_CACHE", "DATA_TRANSFER",
    "NORMAL_EDIT", "WEIGHTED_NORMAL", "UV_PROJECT", "UV_WARP", "VERTEX_WEIGHT_EDIT",
    "VERTEX_WEIGHT_MIX", "VERTEX_WEIGHT_PROXIMITY",
})
# A copy whose largest displacement is below this fraction of the face's size is the
# neutral (float32 noise of a rig at rest).
STILL = 1e-6
# A pose's feature point moving less than this fraction of the pose's largest displacement
# does not move.
UNMOVED = 1e-3

_KEY_PATH = re.compile(r'^key_blocks\["((?:[^"\\]|\\.)*)"\]\.value$')


def animated_key_names(data_paths: Iterable[str]) -> set[str]:
    """The shape keys whose value a driver or an action sets, from the Key's animation
    data paths (key_blocks["jaw_corrective"].value)."""
    out = set()
    for path in data_paths:
        match = _KEY_PATH.match(path)
        if match:
            out.add(match.group(1).replace('\\"', '"').replace("\\\\", "\\"))
    return out


def topology_message(obj: str, vertices: int, evaluated: int,
                     modifiers: Iterable[tuple[str, str]]) -> str:
    """Why an object whose modifiers change its vertex count cannot be exported; modifiers
    are (name, type) of those enabled in the viewport."""
    changing = [f"{kind.replace('_', ' ').title()} '{name}'" for name, kind in modifiers
                if kind not in DEFORM_MODIFIERS]
    which = ", ".join(changing) if changing else "one of its modifiers"
    return (f"{obj}: {which} changes its vertex count ({vertices} -> {evaluated}); the "
            "FaceDefTables move the mesh's own vertices: apply it or turn it off in the "
            "viewport (deform modifiers such as Armature are fine)")


def missing_armature_message(obj: str, modifier: str) -> str:
    return (f"{obj}: its Armature modifier '{modifier}' has no armature object: pick the "
            "rig in the modifier or remove the modifier")


def moves(displacement: npt.ArrayLike, size: float) -> bool:
    """Whether a deformed copy moves anything (beyond float noise) on a face `size` big."""
    d = np.asarray(displacement, dtype=np.float64)
    return d.size > 0 and float(np.abs(d).max()) > STILL * size


def unmoved_feature_point_message(marker: str, displacements: Mapping[str, Array],
                                  feature_point: tuple[str, str, int] | None) -> str | None:
    """The error for a pose marker whose rig moves the skin but not its FAP's feature point
    (the bones' weights miss it), else None. displacements: object name -> its copy;
    feature_point: (id, object name, vertex) of the FAP's point, None when the FAP has none
    or the face does not set it."""
    parsed = shape_keys.parse(marker)
    if parsed is None or parsed["fap"] < 3 or feature_point is None:
        return None
    fp, obj, vertex = feature_point
    largest = max((float(np.linalg.norm(d, axis=1).max()) for d in displacements.values()
                   if len(d)), default=0.0)
    if largest == 0.0:
        return None
    d = displacements.get(obj)
    if d is not None and float(np.linalg.norm(d[vertex])) >= UNMOVED * largest:
        return None
    fap = mpeg4face.fap(parsed["fap"])
    return (f"pose marker {marker}: the rig moves the skin but not feature point {fp} "
            f"(FAP {fap.number} {fap.name}'s, vertex {vertex} of {obj}): weight that vertex "
            "to the bone that poses it, or move it with a shape key of the same name")


# --- FAP poses of bone rigs -----------------------------------------------------------------


@dataclass(frozen=True)
class BoneChannel:
    """How a FAP poses a bone: `channel` is "location" (the bone moves its feature point
    along the FAP's direction) or "rotation" (about the bone's local `axis`, X, Y or Z:
    jaw and eyelid bones); sign flips the first guess for rigs whose bone points the other
    way; `also` are bones moved the same way with it (the two halves of a mid-lip)."""

    bone: str
    channel: str = "location"
    axis: str = "X"
    sign: float = 1.0
    also: tuple[str, ...] = ()

    @property
    def bones(self) -> tuple[str, ...]:
        return (self.bone, *self.also)


# FAP -> bone of Rigify's human meta-rig (Blender 3.4, Add > Armature > Human (Meta-Rig)),
# whose face bones deform when the head is bound to the meta-rig itself. The jaw turns
# about its pivot for FAP 3 and slides for 14 and 15; the mid-lips move both halves of the
# lip (lip.T.L and lip.T.R start at its middle), the corners cheek.B.* (which starts
# there), the brows the bottom brow chain (inner .003 to outer .001), the eyelids the
# middle of each lid chain.
RIGIFY_MAPPING: dict[int, BoneChannel] = {
    3: BoneChannel("jaw", "rotation", "X"), 14: BoneChannel("jaw"), 15: BoneChannel("jaw"),
    4: BoneChannel("lip.T.L", also=("lip.T.R",)),
    5: BoneChannel("lip.B.L", also=("lip.B.R",)),
    51: BoneChannel("lip.T.L", also=("lip.T.R",)),
    52: BoneChannel("lip.B.L", also=("lip.B.R",)),
    6: BoneChannel("cheek.B.L"), 7: BoneChannel("cheek.B.R"),
    12: BoneChannel("cheek.B.L"), 13: BoneChannel("cheek.B.R"),
    53: BoneChannel("cheek.B.L"), 54: BoneChannel("cheek.B.R"),
    59: BoneChannel("cheek.B.L"), 60: BoneChannel("cheek.B.R"),
    19: BoneChannel("lid.T.L.002"), 20: BoneChannel("lid.T.R.002"),
    21: BoneChannel("lid.B.L.002"), 22: BoneChannel("lid.B.R.002"),
    31: BoneChannel("brow.B.L.003"), 32: BoneChannel("brow.B.R.003"),
    33: BoneChannel("brow.B.L.002"), 34: BoneChannel("brow.B.R.002"),
    35: BoneChannel("brow.B.L.001"), 36: BoneChannel("brow.B.R.001"),
}


def mapping_from_json(text: str, source: str = "mapping") -> dict[int, BoneChannel]:
    """A user's mapping table: {"3": {"bone": "jaw", "channel": "rotation", "axis": "X"},
    "31": "brow_in.L", "4": {"bone": ["lip_up.L", "lip_up.R"]}, ...} (several bones move
    together); ValueError names the entry at fault."""
    try:
        raw = json.loads(text)
    except json.JSONDecodeError as error:
        raise ValueError(f"{source}: line {error.lineno}, column {error.colno}: {error.msg}") \
            from None
    if not isinstance(raw, dict):
        raise ValueError(f"{source}: expected an object of FAP number -> bone")
    out = {}
    for key, entry in raw.items():
        where = f"{source}: FAP {key}"
        if not key.isdigit() or not 3 <= int(key) <= mpeg4face.FAP_COUNT:
            raise ValueError(f"{where}: not a low-level FAP number (3..68)")
        if isinstance(entry, (str, list)):
            entry = {"bone": entry}
        names = entry.get("bone") if isinstance(entry, dict) else None
        names = [names] if isinstance(names, str) else names
        if not names or not all(isinstance(n, str) and n for n in names):
            raise ValueError(f"{where}: expected a bone name, a list of them or "
                             "{\"bone\": ...}")
        unknown = set(entry) - {"bone", "channel", "axis", "sign"}
        if unknown:
            raise ValueError(f"{where}: unknown field {sorted(unknown)[0]}")
        channel = entry.get("channel", "location")
        if channel not in ("location", "rotation"):
            raise ValueError(f"{where}: channel must be location or rotation, not {channel}")
        axis = entry.get("axis", "X")
        if axis not in ("X", "Y", "Z"):
            raise ValueError(f"{where}: axis must be X, Y or Z, not {axis}")
        sign = entry.get("sign", 1.0)
        if not isinstance(sign, (int, float)) or sign == 0:
            raise ValueError(f"{where}: sign must be a non-zero number")
        out[int(key)] = BoneChannel(names[0], channel, axis, float(sign), tuple(names[1:]))
    return out


def mapping_to_json(mapping: Mapping[int, BoneChannel]) -> str:
    return json.dumps({str(f): {"bone": list(c.bones) if c.also else c.bone,
                                "channel": c.channel, "axis": c.axis,
                                "sign": c.sign} for f, c in sorted(mapping.items())}, indent=1)


# The standard's directions (Y up, +X the face's left, +Z forward) of positive FAP motion.
_DIRECTIONS = {"up": (0, 1, 0), "down": (0, -1, 0), "left": (1, 0, 0), "right": (-1, 0, 0),
               "forward": (0, 0, 1), "backward": (0, 0, -1)}


def fap_direction(fap: int) -> Array:
    """The unit direction (standard axes) a feature point moves for a positive value."""
    motion = mpeg4face.fap(fap).positive_motion
    if motion not in _DIRECTIONS:
        raise ValueError(f"FAP {fap} {mpeg4face.fap(fap).name} turns ({motion}), it does "
                         "not translate a feature point")
    return np.asarray(_DIRECTIONS[motion], dtype=np.float64)


@dataclass
class PoseFit:
    """The outcome of posing one FAP: the control value found and where its feature point
    landed, as a fraction of the wanted motion along the FAP's direction."""

    fap: int
    value: float
    reached: float  # along the direction / wanted: 1.0 is exact
    sideways: float  # across the direction / wanted
    iterations: int
    reason: str = ""

    @property
    def ok(self) -> bool:
        return not self.reason


def fit_pose(fap: int, measure: Callable[[float], Array], direction: Array, wanted: float,
             first: float, tolerance: float = 0.05, iterations: int = 12) -> PoseFit:
    """Finds the control value (a bone's translation along a direction or a rotation angle)
    that moves the FAP's feature point `wanted` along `direction`: the secant method on
    measure(value) -> the point's displacement, from `first`. Within tolerance (5%) it
    stops; a control that does not move the point gives the reason."""
    def along(value: float) -> tuple[float, float]:
        d = measure(value)
        a = float(d @ direction)
        return a, float(np.linalg.norm(d - a * direction))

    x0, (a0, _) = 0.0, (0.0, 0.0)
    x1 = first
    a1, side = along(x1)
    for i in range(1, iterations + 1):
        if abs(a1 - wanted) <= tolerance * abs(wanted):
            return PoseFit(fap, x1, a1 / wanted, side / abs(wanted), i)
        if abs(a1 - a0) < 1e-12 * max(1.0, abs(wanted)):
            return PoseFit(fap, x1, a1 / wanted, side / abs(wanted), i,
                           "the bone does not move the feature point along the FAP")
        x0, a0, x1 = x1, a1, x1 + (wanted - a1) * (x1 - x0) / (a1 - a0)
        a1, side = along(x1)
    reached = a1 / wanted
    ok = abs(reached - 1.0) <= tolerance
    return PoseFit(fap, x1, reached, side / abs(wanted), iterations,
                   "" if ok else f"reached {reached:.0%} of the amplitude after "
                   f"{iterations} corrections")


@dataclass
class PoseReport:
    """What "Pose FAPs" did: the FAPs posed within the tolerance, and the others with why."""

    posed: list[PoseFit] = field(default_factory=list)
    missed: list[tuple[int, str]] = field(default_factory=list)

    def lines(self) -> list[str]:
        out = [f"{len(self.posed)} FAPs posed, {len(self.missed)} not"]
        out += [f"fap{p.fap} {mpeg4face.fap(p.fap).name}: {p.reached:.1%} of the amplitude "
                f"in {p.iterations} steps" for p in self.posed]
        out += [f"not posed: fap{f} {mpeg4face.fap(f).name}: {why}" for f, why in self.missed]
        return out
