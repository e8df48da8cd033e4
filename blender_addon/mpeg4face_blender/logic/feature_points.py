# SPDX-License-Identifier: GPL-3.0-or-later
"""Feature points, FAPU and mirroring without bpy, testable with plain pytest.

The bpy layer reads a mesh into numpy arrays and a dict of vertex groups; everything here
works on those. Coordinates passed in are the standard's: Y up, gaze along +Z, the face's
left at +X (to_standard_axes converts Blender's Z-up object coordinates).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache

import numpy as np
import numpy.typing as npt

import mpeg4face

GROUP_PREFIX = "FP_"
FAPU_DISTANCES = ("ES0", "IRISD0", "ENS0", "MNS0", "MW0")

Array = npt.NDArray[np.float64]


def group_name(feature_point: str) -> str:
    """The vertex group holding a feature point's vertex: FP_2.1."""
    return GROUP_PREFIX + feature_point


def feature_point_of_group(name: str) -> str | None:
    """The feature point a vertex group names, or None for other groups."""
    return name[len(GROUP_PREFIX):] if name.startswith(GROUP_PREFIX) else None


def to_standard_axes(coords: npt.ArrayLike) -> Array:
    """Blender's Z-up object coordinates to the standard's Y-up ones, as glTF export does:
    (x, y, z) -> (x, z, -y), so a face looking along Blender's -Y gazes along +Z."""
    c = np.asarray(coords, dtype=np.float64).reshape(-1, 3)
    return np.column_stack((c[:, 0], c[:, 2], -c[:, 1]))


def to_blender_axes(coords: npt.ArrayLike) -> Array:
    """The inverse of to_standard_axes: (x, y, z) -> (x, -z, y)."""
    c = np.asarray(coords, dtype=np.float64).reshape(-1, 3)
    return np.column_stack((c[:, 0], -c[:, 2], c[:, 1]))


@cache
def cloning_points() -> frozenset[str]:
    """The feature points cloning needs (the core's list, docs/clone.md)."""
    return frozenset(mpeg4face.clone_feature_points())


@cache
def fapu_feature_points() -> dict[str, tuple[str, ...]]:
    """FAPU distance -> the feature points measure_fapu uses on a complete face.

    Asks the core: a face with every feature point bound (all at one spot; the distances
    are then zero and unmeasured, but points_used is filled all the same)."""
    everywhere = {
        p.id: mpeg4face.FeaturePointBinding(-1, -1, (0.0, 0.0, 0.0))
        for p in mpeg4face.feature_points()
    }
    measurement = mpeg4face.measure_fapu(mpeg4face.FaceModel(feature_points=everywhere))
    return {name: getattr(measurement, name.lower()).points_used for name in FAPU_DISTANCES}


@cache
def fapu_points() -> frozenset[str]:
    """Every feature point the FAPU of a complete face are measured from."""
    return frozenset(p for points in fapu_feature_points().values() for p in points)


_SIDE = re.compile(r"\b(left|right|Left|Right)\b")
_SWAP = {"left": "right", "right": "left", "Left": "Right", "Right": "Left"}
_REFERENCE = re.compile(r"\b\d+\.\d+\b")


@cache
def mirror_partners() -> dict[str, str]:
    """Feature point -> its left/right partner (3.5 <-> 3.6, 2.6 <-> 2.7, ...).

    Rule: the partner is the point of the same group whose description is this one's with
    "left" and "right" swapped and every feature point it names replaced by that point's
    partner ("Midpoint between f.p. 2.2 and 2.4" <-> "... 2.2 and 2.5"). Points named
    in descriptions are paired first, so the loop repeats until nothing changes."""
    points = mpeg4face.feature_points()
    by_text = {(p.group, p.description): p.id for p in points}
    partners: dict[str, str] = {}
    while True:
        found = 0
        for p in points:
            if p.id in partners:
                continue
            text = _SIDE.sub(lambda m: _SWAP[m.group(0)], p.description)
            text = _REFERENCE.sub(lambda m: partners.get(m.group(0), m.group(0)), text)
            other = by_text.get((p.group, text))
            if other is not None and other != p.id:
                partners[p.id], partners[other] = other, p.id
                found += 1
        if not found:
            return partners


@dataclass(frozen=True)
class FeaturePointRow:
    """One feature point in the panel's list."""

    id: str
    description: str
    vertex: int | None
    needed_for_fapu: bool
    needed_for_cloning: bool

    @property
    def is_set(self) -> bool:
        return self.vertex is not None


def feature_point_rows(fp_vertices: Mapping[str, int]) -> list[FeaturePointRow]:
    """Every feature point of the standard's table with its status on this face."""
    return [
        FeaturePointRow(
            p.id,
            p.description,
            fp_vertices.get(p.id),
            p.id in fapu_points(),
            p.id in cloning_points(),
        )
        for p in mpeg4face.feature_points()
    ]


def missing(rows: Iterable[FeaturePointRow], needed: frozenset[str]) -> list[str]:
    """The ids among `needed` that are not set, in table order."""
    return [r.id for r in rows if r.id in needed and not r.is_set]


def fp_vertices_from_groups(
    groups: Mapping[str, Sequence[tuple[int, float]]],
) -> tuple[dict[str, int], list[str]]:
    """Feature point -> vertex from FP_ vertex groups (group name -> (vertex, weight)).

    A group should hold one vertex; with several, the heaviest wins and a warning says so.
    Empty groups leave the point unset; FP_ groups naming no feature point are reported."""
    vertices: dict[str, int] = {}
    warnings: list[str] = []
    for name, members in groups.items():
        fp = feature_point_of_group(name)
        if fp is None:
            continue
        if mpeg4face.feature_point(fp) is None:
            warnings.append(f"vertex group {name}: {fp} is not a feature point")
            continue
        if not members:
            continue
        vertex = max(members, key=lambda m: m[1])[0]
        if len(members) > 1:
            warnings.append(
                f"vertex group {name} holds {len(members)} vertices; vertex {vertex} is used"
            )
        vertices[fp] = vertex
    return vertices, warnings


def face_model_from_arrays(
    coords: npt.ArrayLike,
    coord_index: npt.ArrayLike,
    fp_vertices: Mapping[str, int],
    morph_targets: Mapping[str, npt.ArrayLike] | None = None,
) -> mpeg4face.FaceModel:
    """A one-mesh FaceModel (standard axes) with the feature points bound to its vertices
    and the given morph targets (name -> (N, 3) displacements), e.g. shape keys for
    generate_face."""
    mesh = mpeg4face.IndexedFaceSet("mesh", coords, coord_index)
    if morph_targets:
        mesh.morph_targets = [mpeg4face.MorphTarget(n, d) for n, d in morph_targets.items()]
    bindings = {fp: mpeg4face.FeaturePointBinding(0, v) for fp, v in fp_vertices.items()}
    return mpeg4face.FaceModel(meshes=[mesh], feature_points=bindings)


@dataclass(frozen=True)
class FapuReading:
    """One FAPU distance as the panel shows it."""

    name: str  # ES0, ...
    measured: bool
    value: float  # model units
    unit: float  # value / 1024, the FAPU
    points_used: tuple[str, ...]
    method: str  # how it was measured, or what it needs

    def lines(self) -> list[str]:
        """The read-out: value and unit, then the points it came from; or what it needs."""
        if not self.measured:
            return [f"{self.name} unmeasured: {self.method}"]
        return [
            f"{self.name} = {self.value:.5g}   FAPU = {self.unit:.5g}",
            f"    from {', '.join(self.points_used)}: {self.method}",
        ]


def fapu_readings(measurement: mpeg4face.FapuMeasurement) -> list[FapuReading]:
    readings = []
    for name in FAPU_DISTANCES:
        d = getattr(measurement, name.lower())
        readings.append(
            FapuReading(name, d.measured, d.value, measurement.unit(name), d.points_used, d.method)
        )
    return readings


@dataclass(frozen=True)
class FaceState:
    """What the panel shows about one face."""

    rows: list[FeaturePointRow]
    group_warnings: list[str]
    fapu: list[FapuReading]
    location_warnings: list[mpeg4face.ConstraintWarning]
    # Feature points found on the head's parts (the pupils on the eyeballs): point -> part
    part_points: Mapping[str, str] = field(default_factory=dict)


def face_state_from_arrays(
    coords: npt.ArrayLike,
    coord_index: npt.ArrayLike,
    groups: Mapping[str, Sequence[tuple[int, float]]],
    constraint_tolerance: float = 0.02,
    part_points: Mapping[str, str] | None = None,
) -> FaceState:
    """Feature point statuses, FAPU and Table 6 warnings of a mesh (standard axes);
    `part_points` names the points whose vertices were added from the head's parts."""
    fp_vertices, group_warnings = fp_vertices_from_groups(groups)
    model = face_model_from_arrays(coords, coord_index, fp_vertices)
    measurement = mpeg4face.measure_fapu(model)
    return FaceState(
        feature_point_rows(fp_vertices),
        group_warnings,
        fapu_readings(measurement),
        mpeg4face.check_location_constraints(model, measurement, constraint_tolerance),
        dict(part_points or {}),
    )


@dataclass(frozen=True)
class MirrorMatch:
    """A partner placed (or refused) by the mirror helper."""

    source: str
    partner: str
    vertex: int  # the vertex nearest to the source's mirror image
    distance: float  # from the mirror image to that vertex
    accepted: bool  # distance <= tolerance
    # Vertices as near as `vertex` (itself included): more than one where vertices coincide,
    # as the lips of a face modelled with the mouth closed do; the lowest index is taken.
    ties: int = 1

    def message(self, tolerance: float) -> str:
        if self.accepted:
            text = (f"{self.partner} = vertex {self.vertex}, {self.distance:.4g} from the "
                    f"mirror image of {self.source}")
            if self.ties > 1:
                text += f" ({self.ties} vertices are that near: check which one is meant)"
            return text
        return (f"{self.partner} skipped: the vertex nearest to the mirror image of "
                f"{self.source} is {self.distance:.4g} away (tolerance {tolerance:.4g})")


MIRROR_SOURCES = ("MISSING", "LEFT", "RIGHT")
_SAME_PLACE = 1e-9  # model units: vertices closer than this count as one place


def mirror_tolerance(coords: npt.ArrayLike, relative: float) -> float:
    """An absolute tolerance: `relative` times the diagonal of the mesh's bounding box."""
    c = np.asarray(coords, dtype=np.float64).reshape(-1, 3)
    return float(relative * np.linalg.norm(np.ptp(c, axis=0))) if len(c) else 0.0


def mirror_matches(
    coords: npt.ArrayLike, fp_vertices: Mapping[str, int], source: str, tolerance: float
) -> list[MirrorMatch]:
    """For each set point with a partner, the vertex nearest its mirror image across X = 0.

    source: "MISSING" places partners that are not set yet; "LEFT" / "RIGHT" copy the points
    on the face's left (+X) / right (-X) onto their partners, replacing what is there."""
    if source not in MIRROR_SOURCES:
        raise ValueError(f"mirror source must be one of {', '.join(MIRROR_SOURCES)}")
    c = np.asarray(coords, dtype=np.float64).reshape(-1, 3)
    partners = mirror_partners()
    matches = []
    for fp in sorted(fp_vertices, key=_table_order):
        partner = partners.get(fp)
        if partner is None:
            continue
        x = c[fp_vertices[fp], 0]
        if source == "MISSING" and partner in fp_vertices:
            continue
        if (source == "LEFT" and x <= 0.0) or (source == "RIGHT" and x >= 0.0):
            continue
        image = c[fp_vertices[fp]] * (-1.0, 1.0, 1.0)
        distances = np.linalg.norm(c - image, axis=1)
        vertex = int(np.argmin(distances))
        nearest = float(distances[vertex])
        ties = int(np.count_nonzero(distances <= nearest + _SAME_PLACE))
        matches.append(MirrorMatch(fp, partner, vertex, nearest, nearest <= tolerance, ties))
    return matches


def _table_order(fp: str) -> tuple[int, int]:
    group, index = fp.split(".")
    return int(group), int(index)
