# SPDX-License-Identifier: GPL-3.0-or-later
"""FAP shape keys without bpy, testable with plain pytest: key names in the grammar of
docs/fat.md, slider ranges, suggestions for keys named otherwise, left/right partner FAPs,
mirroring displacements across X = 0, and the report of "Generate
FaceDefTables" and cloning.

Displacements handed in for models are in the standard's axes (feature_points.to_standard_axes);
feature_points.to_blender_axes turns the core's answers back into Blender's.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache

import numpy as np
import numpy.typing as npt

import mpeg4face

from . import feature_points

Array = npt.NDArray[np.float64]
# A key's motion from the Basis: every vertex's (N, 3), or (vertices, (len(vertices), 3)) for
# a sparse shape (the core's FaceShape: only the vertices that move).
Displacement = Array | tuple[npt.NDArray[np.int32], Array]

KINDS = ("FAP", "VISEME", "EXPRESSION")
# One FAPU distance (1024 units): the jaw drops by MNS0 at open_jaw 1024. Big enough to
# sculpt, and the generator interpolates between the amplitudes it is given.
DEFAULT_AMPLITUDE = 1024
FULL_INTENSITY = 63  # the largest expression intensity; a viseme is always this amount
FIRST_LOW_LEVEL_FAP = 3  # FAP 1 and 2 are the viseme and the expression


# --- names ----------------------------------------------------------------------------------


def _label(text: str) -> str:
    """Text as a grammar label: letters, digits, '_' and '-' ("p, b, m" -> "p_b_m")."""
    return re.sub(r"[^A-Za-z0-9_-]+", "_", text).strip("_")


def low_level_faps() -> list[mpeg4face.FapInfo]:
    return [f for f in mpeg4face.faps() if f.number >= FIRST_LOW_LEVEL_FAP]


def fap_enum_items() -> list[tuple[str, str, str]]:
    """EnumProperty items: ("3", "3 open_jaw", "MNS units, positive down")."""
    items = []
    for f in low_level_faps():
        both = ", bidirectional" if f.bidirectional else ""
        items.append((str(f.number), f"{f.number} {f.name}",
                      f"{f.fapu} units, positive {f.positive_motion}{both}"))
    return items


def viseme_enum_items() -> list[tuple[str, str, str]]:
    return [(str(v.number), f"{v.number} {v.phonemes}", f"as in {v.example}")
            for v in mpeg4face.visemes() if v.number > 0]


def expression_enum_items() -> list[tuple[str, str, str]]:
    return [(str(e.number), f"{e.number} {e.name}", e.description)
            for e in mpeg4face.expressions() if e.number > 0]


def key_name(kind: str, number: int, amplitude: int = DEFAULT_AMPLITUDE,
             intensity: int = FULL_INTENSITY) -> str:
    """The grammar name of a FAP (amplitude in FAPU units), viseme or expression key, with
    the standard's name as label: fap3_open_jaw@1024, viseme1_p_b_m, expression1_joy@40."""
    if kind == "FAP":
        return mpeg4face.format_shape_key_name(number, amplitude,
                                               label=mpeg4face.fap(number).name)
    if kind == "VISEME":
        label = _label(mpeg4face.visemes()[number].phonemes)
        return mpeg4face.format_shape_key_name(1, FULL_INTENSITY, select=number, label=label)
    if kind == "EXPRESSION":
        label = mpeg4face.expressions()[number].name
        return mpeg4face.format_shape_key_name(2, intensity, select=number, label=label)
    raise ValueError(f"kind must be one of {', '.join(KINDS)}")


def parse(name: str) -> mpeg4face.ShapeKeyName | None:
    """The parsed grammar name, or None for names that are not ours or are malformed."""
    try:
        return mpeg4face.parse_shape_key_name(name)
    except mpeg4face.Error:
        return None


def is_grammar_name(name: str) -> bool:
    return parse(name) is not None


def slider_range(name: str) -> tuple[float, float]:
    """Slider min / max for a grammar key. A key is the full shape at its amplitude, so 0..1
    covers 0..amplitude; a bidirectional FAP also gets -1 to preview the opposite motion
    (Blender extrapolates linearly, as the tables do with a single amplitude)."""
    parsed = parse(name)
    if parsed is not None and parsed["fap"] >= FIRST_LOW_LEVEL_FAP \
            and mpeg4face.fap(parsed["fap"]).bidirectional:
        return -1.0, 1.0
    return 0.0, 1.0


# --- suggestions for keys named otherwise ---------------------------------------------------

_SIDES = {"l": "l", "left": "l", "r": "r", "right": "r"}
# Words of common names (ARKit, hand-made rigs) as the words of the FAP names.
_SYNONYMS: dict[str, tuple[str, ...]] = {
    "mouth": ("jaw", "lip", "cornerlip", "midlip"),
    "smile": ("raise", "cornerlip"),
    "blink": ("close", "t", "eyelid"),
    "closed": ("close",), "shut": ("close",),
    "eye": ("eyelid", "eyeball"), "lid": ("eyelid",), "upper": ("t",), "top": ("t",),
    "bottom": ("b",), "brow": ("eyebrow",), "inner": ("i",), "outer": ("o",),
    "middle": ("m",), "mid": ("m",), "up": ("raise",), "squint": ("lift",),
    "forward": ("thrust",), "out": ("thrust",), "nod": ("head", "pitch"),
    "turn": ("head", "yaw"), "tilt": ("head", "roll"), "lips": ("lip",),
}
_EXPRESSION_WORDS = {
    "joy": 1, "happy": 1, "happiness": 1, "sad": 2, "sadness": 2, "anger": 3, "angry": 3,
    "mad": 3, "fear": 4, "afraid": 4, "scared": 4, "disgust": 5, "disgusted": 5,
    "surprise": 6, "surprised": 6,
}
# Oculus / ARKit-style viseme names follow the standard's 14 visemes in order.
_VISEME_CODES = {"pp": 1, "ff": 2, "th": 3, "dd": 4, "kk": 5, "ch": 6, "ss": 7, "nn": 8,
                 "rr": 9, "aa": 10, "e": 11, "i": 12, "ih": 12, "o": 13, "oh": 13, "u": 14,
                 "ou": 14}


@dataclass(frozen=True)
class Suggestion:
    """What a shape key named otherwise probably is."""

    kind: str  # one of KINDS
    number: int  # FAP 3..68, viseme 1..14 or expression 1..6


def words(name: str) -> list[str]:
    """A key name's words in lower case: "eyeBlink_L" -> ["eye", "blink", "l"]."""
    return [w.lower() for w in re.findall(r"[A-Z]+(?![a-z])|[A-Z]?[a-z]+|\d+", name)]


def _fap_words(name: str) -> tuple[frozenset[str], str | None]:
    """A FAP name's words and side: "lower_t_lip_lm" -> ({lower, t, lip, m}, "l")."""
    found: set[str] = set()
    side = None
    for token in name.split("_"):
        match = re.fullmatch(r"([lr])(m?)", token)
        if match:
            side = match.group(1)
            if match.group(2):
                found.add("m")
        else:
            found.add(token)
    return frozenset(found), side


def suggest(name: str) -> Suggestion | None:
    """A viseme, expression or FAP for a key name, or None when nothing fits.

    Visemes by their usual codes after "viseme" ("viseme_PP", "V_aa") or alone ("PP");
    expressions by emotion words ("happy", "Surprise"); FAPs by the share of a FAP name's
    words the key's words (with _SYNONYMS) cover, at least half, the key's side (l / left,
    r / right) agreeing with the FAP's. Ties go to the lower FAP number."""
    parsed = parse(name)
    if parsed is not None:
        kind = {1: "VISEME", 2: "EXPRESSION"}.get(parsed["fap"], "FAP")
        return Suggestion(kind, parsed["select"] if kind != "FAP" else parsed["fap"])
    key_words = words(name)
    rest = [w for w in key_words if w not in ("viseme", "vis", "v")]
    if len(rest) == 1 and rest[0] in _VISEME_CODES and (len(rest) < len(key_words)
                                                          or len(rest[0]) == 2):
        return Suggestion("VISEME", _VISEME_CODES[rest[0]])
    for w in key_words:
        if w in _EXPRESSION_WORDS:
            return Suggestion("EXPRESSION", _EXPRESSION_WORDS[w])
    side = next((_SIDES[w] for w in key_words if w in _SIDES), None)
    vocabulary = {w for w in key_words if w not in _SIDES}
    for w in list(vocabulary):
        vocabulary.update(_SYNONYMS.get(w, ()))
    best: tuple[float, int] | None = None
    for f in low_level_faps():
        fap_words, fap_side = _fap_words(f.name)
        if side is not None and fap_side is not None and side != fap_side:
            continue
        score = len(fap_words & vocabulary) / len(fap_words)
        if score >= 0.5 and (best is None or score > best[0]):
            best = (score, f.number)
    return Suggestion("FAP", best[1]) if best else None


# --- mirroring ------------------------------------------------------------------------------


@cache
def fap_partners() -> dict[int, int]:
    """FAP -> its left/right partner: the FAP whose name differs only in l <-> r
    (stretch_l_cornerlip 6 <-> stretch_r_cornerlip 7, lower_t_lip_lm 8 <-> ..._rm 9)."""
    by_name = {f.name: f.number for f in low_level_faps()}
    partners = {}
    for name, number in by_name.items():
        swapped = "_".join(re.sub(r"^([lr])(m?)$", lambda m: ("r" if m.group(1) == "l" else "l")
                                  + m.group(2), t) for t in name.split("_"))
        if swapped != name and swapped in by_name:
            partners[number] = by_name[swapped]
    return partners


_MIRRORED_MOTION = {"left": "right", "right": "left"}


def mirrored_amplitude(fap: int, partner: int, amplitude: int) -> int:
    """The partner's amplitude for the mirror image of `fap` at `amplitude`: the same, unless
    both FAPs move the same sideways direction for positive values (yaw_l_eyeball and
    yaw_r_eyeball both turn left), where the mirror image is the opposite value."""
    motion = mpeg4face.fap(fap).positive_motion
    if motion in _MIRRORED_MOTION and mpeg4face.fap(partner).positive_motion == motion:
        return -amplitude
    return amplitude


@dataclass(frozen=True)
class MirroredKey:
    name: str
    partner: int
    amplitude: int


def mirrored_key(name: str) -> MirroredKey:
    """The grammar name of the partner key of a FAP key; ValueError says why there is none."""
    parsed = parse(name)
    if parsed is None or parsed["fap"] < FIRST_LOW_LEVEL_FAP:
        raise ValueError(f"'{name}' is not a FAP key (fap<N>[_<label>]@<amplitude>)")
    partner = fap_partners().get(parsed["fap"])
    if partner is None:
        raise ValueError(f"FAP {parsed['fap']} {mpeg4face.fap(parsed['fap']).name} has no "
                         "left/right partner")
    amplitude = mirrored_amplitude(parsed["fap"], partner, parsed["amplitude"])
    return MirroredKey(key_name("FAP", partner, amplitude), partner, amplitude)


@dataclass(frozen=True)
class MirrorPlane:
    """A face's plane of symmetry: a point on it and its unit normal (the object's axes)."""

    point: Array
    normal: Array
    pairs: int  # left/right feature point pairs it was fitted to; 0: the plane X = 0

    def reflect_points(self, points: npt.ArrayLike) -> Array:
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        return p - 2.0 * ((p - self.point) @ self.normal)[:, None] * self.normal

    def reflect_vectors(self, vectors: npt.ArrayLike) -> Array:
        v = np.asarray(vectors, dtype=np.float64).reshape(-1, 3)
        return v - 2.0 * (v @ self.normal)[:, None] * self.normal


X_PLANE = MirrorPlane(np.zeros(3), np.array([1.0, 0.0, 0.0]), 0)


def symmetry_plane(coords: npt.ArrayLike, fp_vertices: Mapping[str, int]) -> MirrorPlane:
    """The plane the set left/right feature point pairs (feature_points.mirror_partners) are
    mirror images across: through the mean of their midpoints, normal along the mean of their
    left-to-right directions (each turned towards the widest pair's). X = 0 when no pair with
    two distinct points is set, so a head modelled about X = 0 mirrors as before."""
    c = np.asarray(coords, dtype=np.float64).reshape(-1, 3)
    pairs = [(c[fp_vertices[a]], c[fp_vertices[b]])
             for a, b in feature_points.mirror_partners().items()
             if a < b and a in fp_vertices and b in fp_vertices]
    pairs = [(p, q) for p, q in pairs if np.linalg.norm(p - q) > 1e-9]
    if not pairs:
        return X_PLANE
    directions = np.array([(p - q) / np.linalg.norm(p - q) for p, q in pairs])
    widest = directions[int(np.argmax([np.linalg.norm(p - q) for p, q in pairs]))]
    directions *= np.sign(directions @ widest)[:, None]
    normal = directions.mean(axis=0)
    normal *= 1.0 if normal[0] >= 0 else -1.0  # towards +X, as X = 0's: only its plane matters
    midpoints = np.array([(p + q) / 2 for p, q in pairs])
    return MirrorPlane(midpoints.mean(axis=0), normal / np.linalg.norm(normal), len(pairs))


def mirror_vertices(coords: npt.ArrayLike, tolerance: float, plane: MirrorPlane = X_PLANE,
                    chunk: int = 1024) -> np.ndarray:
    """For each vertex, the vertex nearest its mirror image across `plane` when within
    `tolerance`, else -1. Brute force in chunks: memory stays chunk x N."""
    c = np.asarray(coords, dtype=np.float64).reshape(-1, 3)
    images = plane.reflect_points(c)
    out = np.full(len(c), -1, dtype=np.int64)
    for start in range(0, len(c), chunk):
        block = images[start:start + chunk]
        distances = np.linalg.norm(block[:, None, :] - c[None, :, :], axis=2)
        nearest = np.argmin(distances, axis=1)
        ok = distances[np.arange(len(block)), nearest] <= tolerance
        out[start:start + chunk] = np.where(ok, nearest, -1)
    return out


def mirror_displacements(displacements: npt.ArrayLike, partners: np.ndarray,
                         plane: MirrorPlane = X_PLANE) -> Array:
    """Each vertex takes its mirror vertex's displacement reflected across `plane`; vertices
    without a mirror vertex (partners -1) do not move."""
    d = np.asarray(displacements, dtype=np.float64).reshape(-1, 3)
    out = plane.reflect_vectors(d[np.maximum(partners, 0)])
    out[partners < 0] = 0.0
    return out


# --- FaceDefTables --------------------------------------------------------------------------


def table_title(fap: int, select: int) -> str:
    """fap3 open_jaw, viseme 1 (p, b, m), expression 1 (joy)."""
    if fap == 1:
        return f"viseme {select} ({mpeg4face.visemes()[select].phonemes})"
    if fap == 2:
        return f"expression {select} ({mpeg4face.expressions()[select].name})"
    return f"fap{fap} {mpeg4face.fap(fap).name}"


@dataclass(frozen=True)
class TablesReport:
    """What "Generate FaceDefTables" tells about a generated face."""

    covered: list[str]  # table titles, table order
    moved: list[int]  # vertices moved per table
    transforms: list[int]  # FaceDefTransforms per table (poses of eyes, jaw, head)
    copies: int  # shape keys and poses, one for a key and a pose of the same name
    warnings: list[str]
    ignored: list[str]

    def lines(self) -> list[str]:
        out = [f"{len(self.covered)} FaceDefTables from {self.copies} shape keys"]
        for title, n, t in zip(self.covered, self.moved, self.transforms):
            out.append(f"{title}: {n} vertices" + (f", {t} transforms" if t else ""))
        out += [f"warning: {w}" for w in self.warnings]
        if self.ignored:
            out.append(f"ignored (not in the grammar): {', '.join(self.ignored)}")
        return out


def tables_report(generated: Mapping[str, object], group_warnings: Sequence[str] = ()
                  ) -> TablesReport:
    """The report of generate_face's answer, after the warnings about FP_ groups."""
    tables = generated["face"].tables
    return TablesReport(
        [table_title(t["fap"], t["select"]) for t in tables],
        [sum(m["vertices"] for m in t["meshes"]) for t in tables],
        [len(t["transforms"]) for t in tables],
        int(generated["copies"]),
        [*group_warnings, *generated["warnings"]],
        list(generated["ignored"]),
    )


def cloned_shapes(copies: Sequence[Mapping[str, object]]
                  ) -> dict[str, tuple[npt.NDArray[np.int32], Array]]:
    """clone_face's copies (FaceShapes) as key name -> (vertices, displacement in Blender's
    axes) of the one mesh (0) the target is."""
    out = {}
    for c in copies:
        moved = [m for m in c["meshes"] if m["mesh"] == 0]
        out[c["name"]] = ((moved[0]["vertices"], feature_points.to_blender_axes(
            moved[0]["displacement"])) if moved
            else (np.zeros(0, np.int32), np.zeros((0, 3))))
    return out


def moved_coords(basis: Array, displacement: Displacement) -> Array:
    """The Basis coordinates (N, 3) moved by a key's displacement, whole or sparse."""
    if isinstance(displacement, tuple):
        vertices, rows = displacement
        out = basis.copy()
        out[vertices] += rows
        return out
    return basis + displacement
