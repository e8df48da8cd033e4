# SPDX-License-Identifier: GPL-3.0-or-later
"""The live preview drawn with Blender's gpu module: a triangle batch per mesh of the face,
its vertex buffer (positions and normals) refilled from the core's evaluation on a frame
change, drawn in a SpaceView3D handler with the material colours and a studio-like light,
while the original objects show nothing in the viewport (an empty geometry-nodes
modifier, off for rendering: they stay active and selectable). No mesh is written or tagged, so
Blender re-evaluates nothing: the cost of a frame is the core's evaluation, its vertex
normals (the core's vertex_normals), both placed in the object's frame by the core
(FatEvaluator.object_coordinates), and the normals' turn (logic/live.py).

Blender has no GPU context in background mode (-b): there the buffers are filled (the
per-frame work is measurable and testable) and nothing is uploaded or drawn. Where the
shader cannot be made (cannot_draw), the live preview writes the live keys instead."""

from __future__ import annotations

from dataclasses import dataclass, field

import bpy
import mpeg4face
import numpy as np

from ..logic import live as live_logic
from . import compat

# The modifier that hides a drawn object in the viewport, and its node group.
HIDE_MODIFIER = HIDE_GROUP = "MPEG-4 live (drawn)"

# The shader in create-info style (gpu.shader.create_from_info; 3.4 has it too): the
# uniforms are push constants (at most 128 bytes everywhere: 116 here), the vertex shader
# hands the fragment shader the object-space position, the view-space normal and the
# colour. The mat3 normal_to_view is the model-view matrix's inverse transpose.
_PUSH_CONSTANTS = (("MAT4", "mvp"), ("MAT3", "normal_to_view"), ("FLOAT", "flat_shading"))
_ATTRIBUTES = (("VEC3", "pos"), ("VEC3", "nor"), ("VEC4", "col"))
_VARYINGS = (("VEC3", "v_pos"), ("VEC3", "v_nor"), ("VEC4", "v_col"))

_VERTEX = """
void main()
{
  gl_Position = mvp * vec4(pos, 1.0);
  v_pos = pos;
  v_nor = normal_to_view * nor;
  v_col = col;
}
"""

# A key light from the upper left and a fill from the right, in view space, like the Solid
# mode's studio light; the material colour is linear, as the viewport's colour management
# expects (it turns the result into the display's). A mesh of flat faces (use_smooth off)
# is shaded flat, from the face's own slope, as Blender shows it: the cross product of the
# object-space position's screen derivatives, turned into view space as a normal is.
_FRAGMENT = """
void main()
{
  vec3 n = flat_shading > 0.5 ? normal_to_view * cross(dFdx(v_pos), dFdy(v_pos)) : v_nor;
  n = normalize(n);
  if (n.z < 0.0) n = -n;
  float key = max(dot(n, normalize(vec3(-0.45, 0.55, 0.7))), 0.0);
  float fill = max(dot(n, normalize(vec3(0.7, -0.1, 0.7))), 0.0);
  vec3 lit = v_col.rgb * (0.12 + 0.68 * key + 0.25 * fill) + vec3(0.06) * pow(key, 20.0);
  fragColor = vec4(clamp(lit, 0.0, 1.0), 1.0);
}
"""


@dataclass
class DrawMesh:
    """One object of a live face: its triangles, per-vertex colours and the latest
    positions and normals (object space, Blender's axes)."""

    name: str
    triangles: np.ndarray  # (T, 3) int32
    colours: np.ndarray  # (N, 4) float32
    positions: np.ndarray | None = None
    vertex_normals: np.ndarray | None = None
    batch: object | None = None  # gpu.types.GPUBatch of the latest buffers
    index_buffer: object | None = None
    dirty: bool = True
    neutral_normals: np.ndarray | None = None  # of the undeformed mesh, for rigid motion
    shown: tuple[np.ndarray, np.ndarray] | None = None  # the update's coords and placement
    flat: bool = False  # no smooth faces: shaded flat, as Blender shows it

    def update(self, coords: np.ndarray, placed: np.ndarray, placement: np.ndarray,
               rigid: bool) -> None:
        """The evaluation's coordinates (N, 3, standard axes), `placed` by `placement`
        (4, 4) into the object's frame in Blender's axes (float32, the core's
        object_coordinates); `rigid` when they are the neutral ones (a part without
        deformation): its normals are the neutral ones turned. Nothing changes (and
        nothing is uploaded) when coords and placement are those of the last update."""
        if self.shown is not None and np.array_equal(self.shown[1], placement) and (
                np.array_equal(self.shown[0], coords)):
            return
        self.shown = coords, placement
        self.positions = placed
        if not rigid:
            normals = mpeg4face.vertex_normals(coords, self.triangles)
        else:
            if self.neutral_normals is None:
                self.neutral_normals = mpeg4face.vertex_normals(coords, self.triangles)
            normals = self.neutral_normals
        self.vertex_normals = live_logic.placed_normals(normals, placement)
        self.dirty = True


@dataclass
class _Registry:
    faces: dict[str, list[DrawMesh]] = field(default_factory=dict)
    handler: object | None = None
    shader: object | None = None
    cannot_draw: str | None = None  # why the shader could not be made, once tried


_registry = _Registry()


def _material_colours(mesh: bpy.types.Mesh) -> np.ndarray:
    """A colour per vertex: the diffuse colour of the material of a polygon using it (the
    iris of an eyeball keeps its colour), grey without materials."""
    colours = np.full((len(mesh.vertices), 4), (0.6, 0.6, 0.6, 1.0), dtype=np.float32)
    slots = [np.array(m.diffuse_color if m else (0.6, 0.6, 0.6, 1.0), dtype=np.float32)
             for m in mesh.materials]
    if not slots:
        return colours
    loop_vertices = np.empty(len(mesh.loops), dtype=np.int64)
    mesh.loops.foreach_get("vertex_index", loop_vertices)
    material = np.empty(len(mesh.polygons), dtype=np.int64)
    mesh.polygons.foreach_get("material_index", material)
    sizes = np.empty(len(mesh.polygons), dtype=np.int64)
    mesh.polygons.foreach_get("loop_total", sizes)
    table = np.stack(slots)
    colours[loop_vertices] = table[np.clip(np.repeat(material, sizes), 0, len(table) - 1)]
    return colours


def draw_mesh(obj: bpy.types.Object) -> DrawMesh:
    """The object's mesh as a DrawMesh (its Basis positions until the first update)."""
    mesh = obj.data
    mesh.calc_loop_triangles()
    triangles = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    triangles = triangles.reshape(-1, 3)
    smooth = np.zeros(len(mesh.polygons), dtype=bool)
    mesh.polygons.foreach_get("use_smooth", smooth)
    return DrawMesh(obj.name, triangles, _material_colours(mesh), flat=not smooth.any())


def _empty_group() -> bpy.types.GeometryNodeTree:
    group = bpy.data.node_groups.get(HIDE_GROUP)
    if group is None:
        group = compat.new_modifier_node_group(HIDE_GROUP)
        group.nodes.new("NodeGroupInput")
        group.nodes.new("NodeGroupOutput")  # left unlinked: no geometry
    return group


def hide(obj: bpy.types.Object) -> None:
    """Hides the object in the viewport only, while it stays the active, selectable object
    the panels work on: a geometry-nodes modifier giving no geometry, off for rendering."""
    if obj.modifiers.get(HIDE_MODIFIER) is None:
        modifier = obj.modifiers.new(HIDE_MODIFIER, "NODES")
        modifier.node_group = _empty_group()
        modifier.show_render = False
        modifier.show_in_editmode = False  # Edit Mode shows the mesh being edited


def unhide(obj: bpy.types.Object) -> None:
    """Undoes hide() (also for a modifier left in a saved file)."""
    modifier = obj.modifiers.get(HIDE_MODIFIER)
    if modifier is not None:
        obj.modifiers.remove(modifier)
    group = bpy.data.node_groups.get(HIDE_GROUP)
    if group is not None and group.users == 0:
        bpy.data.node_groups.remove(group)


def add_face(head: str, objects: list[bpy.types.Object]) -> list[DrawMesh]:
    """Draws the face of `head` (its objects hidden in the viewport) from now on."""
    remove_face(head)
    meshes = [draw_mesh(o) for o in objects]
    _registry.faces[head] = meshes
    for o in objects:
        hide(o)
    if _registry.handler is None and not bpy.app.background:
        _registry.handler = bpy.types.SpaceView3D.draw_handler_add(
            _draw, (), "WINDOW", "POST_VIEW")
    return meshes


def remove_face(head: str) -> None:
    """Stops drawing the face of `head`; its objects show again as they were."""
    for mesh in _registry.faces.pop(head, None) or []:
        obj = bpy.data.objects.get(mesh.name)
        if obj is not None:
            unhide(obj)
    if not _registry.faces and _registry.handler is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_registry.handler, "WINDOW")
        _registry.handler = None
    tag_redraw()


def rename(old: str, new: str) -> None:
    """An object of a drawn face was renamed."""
    if old in _registry.faces:
        _registry.faces[new] = _registry.faces.pop(old)
    for meshes in _registry.faces.values():
        for mesh in meshes:
            if mesh.name == old:
                mesh.name = new


def tag_redraw() -> None:
    for window in getattr(bpy.context.window_manager, "windows", ()):
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


def cannot_draw() -> str | None:
    """Why this Blender cannot draw the live preview (its shader cannot be made: no GPU
    context, a backend refusing it), the reason given by the first try; None when it can
    (the shader is made) and in background mode, where nothing is drawn (the buffers are
    filled all the same) and nothing is tried: create_from_info crashes 3.4 there."""
    if bpy.app.background:
        return None
    if _registry.shader is None and _registry.cannot_draw is None:
        try:
            _registry.shader = _new_shader()
        except Exception as error:  # noqa: BLE001 - any failure means: write shape keys
            _registry.cannot_draw = f"{type(error).__name__}: {error}"
    return _registry.cannot_draw


def _new_shader():
    import gpu

    varyings = gpu.types.GPUStageInterfaceInfo("mpeg4face_live")
    for kind, name in _VARYINGS:
        varyings.smooth(kind, name)
    info = gpu.types.GPUShaderCreateInfo()
    for kind, name in _PUSH_CONSTANTS:
        info.push_constant(kind, name)
    for slot, (kind, name) in enumerate(_ATTRIBUTES):
        info.vertex_in(slot, kind, name)
    info.vertex_out(varyings)
    info.fragment_out(0, "VEC4", "fragColor")
    info.vertex_source(_VERTEX)
    info.fragment_source(_FRAGMENT)
    return gpu.shader.create_from_info(info)


def _shader():
    if _registry.shader is None:
        _registry.shader = _new_shader()
    return _registry.shader


def _batch(mesh: DrawMesh):
    import gpu

    if mesh.batch is not None and not mesh.dirty:
        return mesh.batch
    shader = _shader()
    fmt = gpu.types.GPUVertFormat()
    fmt.attr_add(id="pos", comp_type="F32", len=3, fetch_mode="FLOAT")
    fmt.attr_add(id="nor", comp_type="F32", len=3, fetch_mode="FLOAT")
    fmt.attr_add(id="col", comp_type="F32", len=4, fetch_mode="FLOAT")
    vbo = gpu.types.GPUVertBuf(fmt, len(mesh.colours))
    vbo.attr_fill("pos", mesh.positions)
    vbo.attr_fill("nor", mesh.vertex_normals)
    vbo.attr_fill("col", mesh.colours)
    if mesh.index_buffer is None:
        mesh.index_buffer = gpu.types.GPUIndexBuf(type="TRIS", seq=mesh.triangles)
    mesh.batch = gpu.types.GPUBatch(type="TRIS", buf=vbo, elem=mesh.index_buffer)
    mesh.batch.program_set(shader)
    mesh.dirty = False
    return mesh.batch


def _draw() -> None:
    import gpu

    region = bpy.context.region_data
    if region is None or not _registry.faces:
        return
    shader = _shader()
    gpu.state.depth_test_set("LESS_EQUAL")
    gpu.state.depth_mask_set(True)
    gpu.state.face_culling_set("NONE")
    for meshes in _registry.faces.values():
        for mesh in meshes:
            obj = bpy.data.objects.get(mesh.name)
            if obj is None or mesh.positions is None:
                continue
            model_view = region.view_matrix @ obj.matrix_world
            shader.bind()
            shader.uniform_float("mvp", region.window_matrix @ model_view)
            shader.uniform_float("flat_shading", 1.0 if mesh.flat else 0.0)
            shader.uniform_float("normal_to_view",
                                 model_view.to_3x3().inverted_safe().transposed())
            _batch(mesh).draw(shader)
    gpu.state.depth_test_set("NONE")
    gpu.state.depth_mask_set(False)


def clear() -> None:
    for head in list(_registry.faces):
        remove_face(head)
    _registry.shader = None
    _registry.cannot_draw = None
