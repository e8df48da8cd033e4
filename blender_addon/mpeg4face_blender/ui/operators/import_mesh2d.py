# SPDX-License-Identifier: GPL-3.0-or-later
"""File > Import > 2D mesh sequence (.json, .m2d; docs/mesh2d.md): a textured plane whose
vertices follow the sequence's frames, baked as one shape key per frame keyed on its frame.
The plane lies in Blender's XZ plane (facing -Y, the front view), 1 unit per `scale` pixels,
the image's top-left at the origin; the texture is the image the intra plane lies on."""

from pathlib import Path

import bpy
import numpy as np
from bpy.props import FloatProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

import mpeg4face

from ...scene import compat


def plane_coords(frame: np.ndarray, scale: float) -> np.ndarray:
    """Pixel (x, y down) -> Blender (x, 0, -y) / scale."""
    out = np.zeros((len(frame), 3))
    out[:, 0] = frame[:, 0] / scale
    out[:, 2] = -frame[:, 1] / scale
    return out


def build_plane(name: str, sequence: dict, image_path: str, scale: float,
                start_frame: int) -> bpy.types.Object:
    frames = np.asarray(sequence["frames"], float)
    triangles = np.asarray(sequence["triangles"], int)
    if len(triangles) == 0:
        triangles = np.asarray(mpeg4face.mesh2d_triangles(sequence), int)
    # Ours are clockwise on the screen, and so seen from the front view (-Y) once y is -Z:
    # reversed, so that the faces are counterclockwise and their normals face the front.
    triangles = triangles[:, ::-1]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(plane_coords(frames[0], scale).tolist(), [], triangles.tolist())
    width, height = sequence["width"], sequence["height"]
    uv = mesh.uv_layers.new(name="texture")
    corners = triangles.reshape(-1)
    u = (frames[0][corners, 0] + 0.5) / width  # pixel centres at integer coordinates
    v = 1 - (frames[0][corners, 1] + 0.5) / height
    uv.data.foreach_set("uv", np.stack([u, v], axis=1).reshape(-1))
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.collection.objects.link(obj)
    if image_path:
        material = bpy.data.materials.new(name)
        tree = compat.material_node_tree(material)
        texture = tree.nodes.new("ShaderNodeTexImage")
        texture.image = bpy.data.images.load(image_path, check_existing=True)
        texture.interpolation = "Linear"
        tree.links.new(texture.outputs["Color"],
                       tree.nodes["Principled BSDF"].inputs["Base Color"])
        mesh.materials.append(material)
    obj.shape_key_add(name="Basis", from_mix=False)
    for f in range(1, len(frames)):
        key = obj.shape_key_add(name=f"frame_{f:05d}", from_mix=False)
        key.data.foreach_set("co", plane_coords(frames[f], scale).reshape(-1))
        for frame, value in ((f - 1, 0.0), (f, 1.0), (f + 1, 0.0)):
            key.value = value
            key.keyframe_insert("value", frame=start_frame + frame)
    return obj


class MPEG4FACE_OT_import_mesh2d(bpy.types.Operator, ImportHelper):
    """Import a 2D mesh sequence (JSON or .m2d) as a textured plane animated by shape keys"""

    bl_idname = "mpeg4face.import_mesh2d"
    bl_label = "Import 2D Mesh Sequence"
    bl_options = {"REGISTER", "UNDO"}

    filter_glob: StringProperty(default="*.json;*.m2d", options={"HIDDEN"})
    image: StringProperty(name="Image", subtype="FILE_PATH",
                          description="The image the sequence's intra plane lies on")
    scale: FloatProperty(name="Pixels per unit", default=100.0, min=1e-3)
    start_frame: IntProperty(name="Start frame", default=1)

    def execute(self, context: bpy.types.Context) -> set[str]:
        path = Path(self.filepath)
        try:
            if path.suffix.lower() == ".m2d":
                sequence = mpeg4face.decode_mesh2d(path.read_bytes())
            else:
                sequence = mpeg4face.read_mesh2d(path)
        except (mpeg4face.Error, OSError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        image = bpy.path.abspath(self.image) if self.image else ""
        if image and not Path(image).is_file():
            self.report({"ERROR"}, f"{image}: no such image")
            return {"CANCELLED"}
        obj = build_plane(path.stem, sequence, image, self.scale, self.start_frame)
        context.view_layer.objects.active = obj
        frames = len(sequence["frames"])
        context.scene.frame_start = self.start_frame
        context.scene.frame_end = self.start_frame + frames - 1
        self.report({"INFO"}, f"{frames} frames, {len(obj.data.vertices)} nodes from {path}")
        return {"FINISHED"}


def mesh2d_import_menu(menu: bpy.types.Menu, context: bpy.types.Context) -> None:
    menu.layout.operator(MPEG4FACE_OT_import_mesh2d.bl_idname,
                         text="2D mesh sequence (.json, .m2d)")


def register() -> None:
    bpy.utils.register_class(MPEG4FACE_OT_import_mesh2d)
    bpy.types.TOPBAR_MT_file_import.append(mesh2d_import_menu)


def unregister() -> None:
    bpy.types.TOPBAR_MT_file_import.remove(mesh2d_import_menu)
    bpy.utils.unregister_class(MPEG4FACE_OT_import_mesh2d)
