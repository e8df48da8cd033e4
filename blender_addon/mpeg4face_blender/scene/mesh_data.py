# SPDX-License-Identifier: GPL-3.0-or-later
"""Reading and writing a mesh object's vertices and FP_ vertex groups through bmesh, the
same way in Object and Edit Mode (in Edit Mode the mesh datablock is stale)."""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from contextlib import contextmanager

import bmesh
import bpy
import mpeg4face
import numpy as np

from ..logic import feature_points


@contextmanager
def face_bmesh(obj: bpy.types.Object, write: bool = False) -> Iterator[bmesh.types.BMesh]:
    """The object's bmesh: the edit-mode one, or a copy of the mesh written back on exit
    when write is set."""
    mesh = obj.data
    if obj.mode == "EDIT":
        bm = bmesh.from_edit_mesh(mesh)
        _index(bm)
        yield bm
        if write:
            bmesh.update_edit_mesh(mesh)
        return
    bm = bmesh.new()
    try:
        bm.from_mesh(mesh)
        _index(bm)
        yield bm
        if write:
            bm.to_mesh(mesh)
            mesh.update()
    finally:
        bm.free()


def _index(bm: bmesh.types.BMesh) -> None:
    # Edits in Edit Mode can leave vertex indices stale; vertex groups use the mesh's order.
    bm.verts.index_update()
    bm.verts.ensure_lookup_table()


def standard_coords(bm: bmesh.types.BMesh) -> np.ndarray:
    """Vertex positions in the standard's axes (object space, Y up)."""
    return feature_points.to_standard_axes([v.co[:] for v in bm.verts])


def coord_index(bm: bmesh.types.BMesh) -> list[int]:
    """Faces as an IndexedFaceSet coordIndex: vertex numbers, -1 after each face."""
    out: list[int] = []
    for face in bm.faces:
        out.extend(v.index for v in face.verts)
        out.append(-1)
    return out


def fp_groups(obj: bpy.types.Object, bm: bmesh.types.BMesh | None = None
              ) -> dict[str, list[tuple[int, float]]]:
    """FP_ vertex group name -> its (vertex, weight) members: from `bm`, or without it from
    the mesh datablock (Object Mode; far quicker than making a bmesh of a dense mesh)."""
    by_index = {g.index: g.name for g in obj.vertex_groups
                if feature_points.feature_point_of_group(g.name)}
    groups: dict[str, list[tuple[int, float]]] = {name: [] for name in by_index.values()}
    if not by_index:
        return groups
    if bm is None:
        members = ((v.index, g.group, g.weight) for v in obj.data.vertices for g in v.groups)
    else:
        layer = bm.verts.layers.deform.active
        if layer is None:
            return groups
        members = ((v.index, i, w) for v in bm.verts for i, w in v[layer].items())
    for vertex, index, weight in members:
        name = by_index.get(index)
        if name is not None:
            groups[name].append((vertex, weight))
    return groups


def selected_vertices(bm: bmesh.types.BMesh) -> list[int]:
    return [v.index for v in bm.verts if v.select]


def set_feature_points(obj: bpy.types.Object, bm: bmesh.types.BMesh,
                       vertices: dict[str, int]) -> None:
    """Makes each FP_<fp> hold exactly its vertex, with weight 1, in one pass over the mesh
    (Find Feature Points sets 80 at once on heads of 50,000 vertices)."""
    groups = {}
    for fp, vertex in vertices.items():
        name = feature_points.group_name(fp)
        groups[(obj.vertex_groups.get(name) or obj.vertex_groups.new(name=name)).index] = vertex
    layer = bm.verts.layers.deform.verify()
    for v in bm.verts:
        weights = v[layer]
        for index in groups:
            if index in weights:
                del weights[index]
    for index, vertex in groups.items():
        bm.verts[vertex][layer][index] = 1.0


def set_feature_point(obj: bpy.types.Object, bm: bmesh.types.BMesh, fp: str, vertex: int) -> None:
    """Makes FP_<fp> hold exactly `vertex`, with weight 1 (moving it if it was elsewhere)."""
    name = feature_points.group_name(fp)
    group = obj.vertex_groups.get(name) or obj.vertex_groups.new(name=name)
    layer = bm.verts.layers.deform.verify()
    for v in bm.verts:
        weights = v[layer]
        if group.index in weights:
            del weights[group.index]
    bm.verts[vertex][layer][group.index] = 1.0


def shape_key_coords(block: bpy.types.ShapeKey) -> np.ndarray:
    """A shape key's vertex positions (N, 3), Blender's axes."""
    co = np.empty(len(block.data) * 3, dtype=np.float32)
    block.data.foreach_get("co", co)
    return co.reshape(-1, 3).astype(np.float64)


def set_shape_key_coords(block: bpy.types.ShapeKey, coords: np.ndarray) -> None:
    block.data.foreach_set("co", np.asarray(coords, dtype=np.float32).ravel())


def read_face_model(obj: bpy.types.Object, shape_keys: Iterable[str] = ()
               ) -> tuple[mpeg4face.FaceModel, list[str]]:
    """The mesh as a FaceModel (standard axes) with its feature points and the named shape
    keys as morph targets (displacements from the reference key: the whole shape, whatever
    key it is relative to), for generate_face and clone_face; and the FP_ group warnings.
    Shape keys are read from the mesh datablock, so the object should be in Object Mode."""
    coords, faces, fp_vertices, warnings = mesh_and_points(obj)
    targets = shape_key_displacements(obj, shape_keys)
    return feature_points.face_model_from_arrays(coords, faces, fp_vertices, targets), warnings


def mesh_and_points(obj: bpy.types.Object
                    ) -> tuple[np.ndarray, np.ndarray | list[int], dict[str, int], list[str]]:
    """The mesh's vertices (standard axes, object space), its coordIndex, its feature
    points (from the FP_ groups) and the warnings about those groups. In Object Mode read
    from the mesh datablock with foreach_get (a bmesh of a dense head costs a tenth of a
    second), in Edit Mode from the edit bmesh."""
    if obj.mode == "EDIT":
        with face_bmesh(obj) as bm:
            fp_vertices, warnings = feature_points.fp_vertices_from_groups(fp_groups(obj, bm))
            return standard_coords(bm), coord_index(bm), fp_vertices, warnings
    mesh = obj.data
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    fp_vertices, warnings = feature_points.fp_vertices_from_groups(fp_groups(obj))
    return feature_points.to_standard_axes(co), polygon_coord_index(mesh), fp_vertices, warnings


def polygon_coord_index(mesh: bpy.types.Mesh) -> np.ndarray:
    """The mesh's polygons as a coordIndex (int32, -1 after each face), in the order
    coord_index gives them from a bmesh of the mesh."""
    corners = np.empty(len(mesh.loops), dtype=np.int32)
    mesh.loops.foreach_get("vertex_index", corners)
    starts = np.empty(len(mesh.polygons), dtype=np.int64)
    mesh.polygons.foreach_get("loop_start", starts)
    sizes = np.empty(len(mesh.polygons), dtype=np.int64)
    mesh.polygons.foreach_get("loop_total", sizes)
    # Corner k of polygon i goes to its slot in the output, after i earlier -1s.
    local = np.arange(int(sizes.sum())) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    out = np.full(int(sizes.sum()) + len(sizes), -1, dtype=np.int32)
    out[np.repeat(np.cumsum(sizes + 1) - (sizes + 1), sizes) + local] = \
        corners[np.repeat(starts, sizes) + local]
    return out


def shape_key_displacements(obj: bpy.types.Object, names: Iterable[str]
                            ) -> dict[str, np.ndarray]:
    """Each named shape key as displacements (standard axes) from the reference key: the
    whole shape, whatever key it is relative to. The keys are read into one buffer (a
    foreach_get each) and turned in one product: a head has hundreds."""
    key = obj.data.shape_keys
    names = list(names)
    if key is None or not names:
        return {}
    count = len(obj.data.vertices)
    buffer = np.empty((len(names) + 1, count * 3), dtype=np.float32)
    key.reference_key.data.foreach_get("co", buffer[0])
    for row, name in zip(buffer[1:], names):
        key.key_blocks[name].data.foreach_get("co", row)
    # Minus the reference in float64 (exact) straight into the standard's axes, (x, y, z)
    # -> (x, z, -y) as feature_points.to_standard_axes, without temporaries of the whole buffer.
    rows = buffer.reshape(len(names) + 1, count, 3)
    moved = np.empty((len(names), count, 3))
    np.subtract(rows[1:, :, 0], rows[0, :, 0], out=moved[:, :, 0], dtype=np.float64)
    np.subtract(rows[1:, :, 2], rows[0, :, 2], out=moved[:, :, 1], dtype=np.float64)
    np.subtract(rows[0, :, 1], rows[1:, :, 1], out=moved[:, :, 2], dtype=np.float64)
    return dict(zip(names, moved))


def face_parts(obj: bpy.types.Object) -> list[bpy.types.Object]:
    """The mesh objects below the head (as poses.parts, which imports this module)."""
    return sorted((o for o in obj.children_recursive if o.type == "MESH"), key=lambda o: o.name)


def read_face_state(obj: bpy.types.Object, constraint_tolerance: float) -> feature_points.FaceState:
    """The head's feature point state, FAPU and Table 6 warnings, with the feature points
    its parts hold (the pupils on the eyeball objects) where the head has none: their
    vertices placed in the head's object space as they are now."""
    with face_bmesh(obj) as bm:
        coords, faces, groups = standard_coords(bm), coord_index(bm), fp_groups(obj, bm)
    taken = {name for name, members in groups.items() if members}
    extra: list[np.ndarray] = []
    part_points: dict[str, str] = {}
    to_head = obj.matrix_world.inverted()
    for part in face_parts(obj):
        if part.mode == "EDIT":
            continue  # read when it leaves Edit Mode
        matrix = np.array(to_head @ part.matrix_world)
        with face_bmesh(part) as bm:
            part_groups = fp_groups(part, bm)
            for name, members in sorted(part_groups.items()):
                if not members or name in taken:
                    continue
                vertex = max(members, key=lambda m: m[1])[0]
                point = matrix[:3, :3] @ np.array(bm.verts[vertex].co) + matrix[:3, 3]
                groups[name] = [(len(coords) + len(extra), 1.0)]
                extra.append(feature_points.to_standard_axes([point])[0])
                taken.add(name)
                fp = feature_points.feature_point_of_group(name)
                if fp is not None:
                    part_points[fp] = part.name
    if extra:
        coords = np.vstack([coords, np.array(extra)])
    return feature_points.face_state_from_arrays(coords, faces, groups, constraint_tolerance,
                                                 part_points)
