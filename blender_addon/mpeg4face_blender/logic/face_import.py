# SPDX-License-Identifier: GPL-3.0-or-later
"""An MPEG-4 face (mpeg4face.MpegFace, read from VRML) as the add-on keeps a head, without
bpy: one mesh per IndexedFaceSet in Blender's axes, placed by its Transform chain, the head
(the mesh holding most feature points) first and the others its parts; the feature points
as the vertices of FP_ groups; the FaceDefTables as shape keys named in the grammar.

A table's keys are its FaceDefMeshes evaluated at each non-zero interval border (the
grammar takes several amplitudes of one FAP): the motion is piecewise linear between the
borders and continues the outermost interval beyond them, so the FaceDefTables the add-on
generates from these keys (borders: the amplitudes and 0) give the same motion at every
FAP value. What keys cannot hold is listed in `not_imported`, one line per kind."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

import mpeg4face

from . import feature_points, live, shape_keys

Array = npt.NDArray[np.float64]

VISEME_AMOUNT = shape_keys.FULL_INTENSITY  # the grammar's viseme keys are at 63


@dataclass
class ImportedMesh:
    """One object to make: vertices in Blender's axes (object space), faces, UVs per face
    corner (or None), its placement (4 x 4, Blender's axes), feature point -> vertex, and
    shape-key name -> displacements from the neutral (Blender's axes)."""

    name: str
    coords: Array
    faces: list[list[int]]
    uvs: Array | None
    matrix: Array
    feature_points: dict[str, int] = field(default_factory=dict)
    keys: dict[str, Array] = field(default_factory=dict)


@dataclass
class ImportedFace:
    meshes: list[ImportedMesh]  # the head first, then its parts
    not_imported: list[str]  # one line per kind of what the objects do not hold


def _blender_matrix(standard: npt.ArrayLike) -> Array:
    """A 4 x 4 transform of the standard's Y-up axes as the same transform in Blender's."""
    axes = np.eye(4)
    axes[:3, :3] = live.TO_BLENDER
    return axes @ np.asarray(standard, dtype=np.float64) @ axes.T


def _faces(mesh: mpeg4face.IndexedFaceSet) -> tuple[list[list[int]], Array | None, int]:
    """The coordIndex's faces (those of fewer than 3 distinct vertices left out: Blender
    takes none), their texture coordinates per corner, and how many were left out."""
    index = np.asarray(mesh.coord_index)
    tex = np.asarray(mesh.tex_coord)
    tex_index = np.asarray(mesh.tex_coord_index)
    if not len(tex_index) and len(tex) == mesh.vertex_count:
        tex_index = index  # VRML: without texCoordIndex the coordIndex indexes texCoord
    with_uvs = len(tex) > 0 and len(tex_index) == len(index)
    faces, uvs, dropped = [], [], 0
    start = 0
    ends = np.flatnonzero(index < 0).tolist()
    if not ends or ends[-1] != len(index) - 1:
        ends.append(len(index))
    for end in ends:
        face = index[start:end].tolist()
        corners = tex_index[start:end] if with_uvs else None
        start = end + 1
        if not face:
            continue
        if len(face) < 3 or len(set(face)) != len(face):
            dropped += 1
            continue
        faces.append(face)
        if with_uvs:
            uvs.append(tex[corners])
    return faces, (np.concatenate(uvs) if with_uvs and uvs else None), dropped


def _head_mesh(model: mpeg4face.FaceModel) -> int:
    """The mesh holding most feature points (the most vertices among equals)."""
    held = [0] * len(model.meshes)
    for binding in model.feature_points.values():
        if 0 <= binding.mesh < len(held) and binding.vertex >= 0:
            held[binding.mesh] += 1
    return max(range(len(held)), key=lambda m: (held[m], model.meshes[m].vertex_count))


def _key_amplitudes(table: dict) -> tuple[list[int], str | None]:
    """The amplitudes (FAP 3..68) or amounts (viseme, expression) at which the table's
    keys are made, and what the keys lose, if anything."""
    borders = sorted({b for m in table["meshes"] for b in m["interval_borders"]})
    if table["fap"] >= shape_keys.FIRST_LOW_LEVEL_FAP:
        return [b for b in borders if b != 0], None
    inside = [b for b in borders if 0 < b < VISEME_AMOUNT]
    if table["fap"] == 1:
        lost = f"viseme {table['select']} (borders {', '.join(map(str, inside))})" \
            if inside else None
        return [VISEME_AMOUNT], lost
    return sorted(set(inside) | {VISEME_AMOUNT}), None


def _key_name(fap: int, select: int, amplitude: int) -> str:
    if fap == 1:
        return shape_keys.key_name("VISEME", select)
    if fap == 2:
        return shape_keys.key_name("EXPRESSION", select, intensity=amplitude)
    return shape_keys.key_name("FAP", fap, amplitude)


def _frame(fap: int, select: int, amplitude: int) -> mpeg4face.FapStream:
    """A one-frame stream of that FAP (viseme, expression) alone. One stream per shape: in
    a stream of several frames, a FAP not sent in a frame holds its earlier value. Every
    other low-level FAP is sent at 0 with a low-level one, since a decoder gives a FAP not
    sent its left / right partner's value (not with a viseme or expression: a low-level
    FAP present takes a share of their motion)."""
    mask = np.zeros((1, mpeg4face.FAP_COUNT), dtype=bool)
    values = np.zeros((1, mpeg4face.FAP_COUNT), dtype=np.int32)
    visemes = np.zeros((1, 4), dtype=np.int32)
    expressions = np.zeros((1, 6), dtype=np.int32)
    mask[0, fap - 1] = True
    if fap == 1:
        visemes[0] = (select, 0, amplitude, 0)  # select1 at blend 63: the whole viseme
    elif fap == 2:
        expressions[0, :2] = (select, amplitude)
    else:
        mask[0, shape_keys.FIRST_LOW_LEVEL_FAP - 1:] = True
        values[0, fap - 1] = amplitude
    return mpeg4face.FapStream.from_arrays([0], mask, values, visemes, expressions)


def _table_label(table: dict) -> str:
    if table["fap"] == 1:
        return f"viseme {table['select']}"
    if table["fap"] == 2:
        return f"expression {table['select']}"
    return f"FAP {table['fap']} {mpeg4face.fap(table['fap']).name}"


def imported_face(face: mpeg4face.MpegFace, name: str) -> ImportedFace:
    """The objects to make for `face` (`name` for meshes without one) and what they leave
    out. Raises mpeg4face.Error when the tables cannot be evaluated (a FAPU the feature
    points do not measure), naming the table and the points."""
    model = face.scene_graph
    if not model.meshes:
        raise mpeg4face.Error("the face has no IndexedFaceSet")
    head = _head_mesh(model)
    order = [head] + [m for m in range(len(model.meshes)) if m != head]
    matrices = model.mesh_world_matrices()
    not_imported: list[str] = []
    meshes: dict[int, ImportedMesh] = {}
    dropped = 0
    for m in order:
        mesh = model.meshes[m]
        faces, uvs, left_out = _faces(mesh)
        dropped += left_out
        meshes[m] = ImportedMesh(mesh.name or (name if m == head else f"{name}.{m}"),
                                 feature_points.to_blender_axes(mesh.coord), faces, uvs,
                                 _blender_matrix(matrices[m]))
    if dropped:
        not_imported.append(f"{dropped} faces of fewer than 3 distinct vertices")
    unbound = []
    for fp, binding in sorted(model.feature_points.items()):
        if 0 <= binding.mesh < len(model.meshes) and binding.vertex >= 0:
            meshes[binding.mesh].feature_points[fp] = binding.vertex
        else:
            unbound.append(fp)
    if unbound:
        not_imported.append(f"feature points on no vertex (a position only): "
                            f"{', '.join(unbound)}")

    tables = face.tables
    shapes, owners, lost = [], [], []
    for table in tables:
        if not table["meshes"]:
            continue
        amplitudes, loses = _key_amplitudes(table)
        if loses:
            lost.append(loses)
        for amplitude in amplitudes:
            shapes.append((table["fap"], table["select"], amplitude))
            owners.append([m["mesh"] for m in table["meshes"]])
    if shapes:
        evaluator = mpeg4face.FatEvaluator(face)
        neutral = evaluator.neutral()["coord"]
        for (fap, select, amplitude), moved in zip(shapes, owners):
            coord = evaluator.evaluate(_frame(fap, select, amplitude), 0)["coord"]
            for m in moved:
                meshes[m].keys[_key_name(fap, select, amplitude)] = \
                    feature_points.to_blender_axes(coord[m] - neutral[m])
    if lost:
        not_imported.append("the shapes between 0 and 63 of " + "; ".join(lost)
                            + ": a viseme key holds the whole viseme only")
    turned = [_table_label(t) for t in tables if t["transforms"]]
    if turned:
        names = sorted({model.transforms[x].name or f"#{x}" for t in tables
                        for x in t["transforms"]})
        not_imported.append(f"the FaceDefTransforms (Transforms {', '.join(names)} turned, "
                            f"moved or scaled) of {', '.join(turned)}: shape keys move "
                            "vertices only")
    if face.fit is not None:
        not_imported.append("the FIT (FAP Interpolation Table): give it as a .json when "
                            "importing a FAP stream")
    return ImportedFace([meshes[m] for m in order], not_imported)
