# SPDX-License-Identifier: GPL-3.0-or-later
"""File > Import > MPEG-4 face (.wrl; or one dropped on the 3D viewport,
ui/file_handlers.py): the face's meshes as objects (the head active, the other meshes its
parts), its feature points as FP_ groups and its FaceDefTables as grammar shape keys
(logic/face_import.py), ready for the add-on's panels, streams and export. Everything that
can fail comes before the first object is made, and a failure while making them removes
what was made."""

from pathlib import Path

import bpy
from bpy.props import StringProperty
from bpy_extras.io_utils import ImportHelper
from mathutils import Matrix

import mpeg4face

from ...logic import face_import
from . import faces as operators_faces
from .stream import INPUT_ERRORS


def _make_object(part: face_import.ImportedMesh, collection: bpy.types.Collection
                 ) -> bpy.types.Object:
    mesh = bpy.data.meshes.new(part.name)
    obj = None
    try:
        mesh.from_pydata(part.coords.tolist(), [], part.faces)
        if part.uvs is not None:
            mesh.uv_layers.new(name="UVMap").data.foreach_set("uv", part.uvs.ravel())
        mesh.update()
        obj = bpy.data.objects.new(part.name, mesh)
        collection.objects.link(obj)
        obj.matrix_world = Matrix(part.matrix.tolist())
        for fp, vertex in part.feature_points.items():
            obj.vertex_groups.new(name=f"FP_{fp}").add([vertex], 1.0, "REPLACE")
        for name, displacement in part.keys.items():
            operators_faces.add_key(obj, name, part.coords + displacement)
    except Exception:
        if obj is not None:
            bpy.data.objects.remove(obj)
        bpy.data.meshes.remove(mesh)
        raise
    return obj


def make_face(face: face_import.ImportedFace, collection: bpy.types.Collection
              ) -> list[bpy.types.Object]:
    """The face's objects, the head first with the others parented to it where they are;
    on failure none."""
    made: list[bpy.types.Object] = []
    try:
        for part in face.meshes:
            made.append(_make_object(part, collection))
        head = made[0]
        for obj in made[1:]:
            world = obj.matrix_world.copy()
            obj.parent = head
            obj.matrix_basis = head.matrix_world.inverted() @ world
    except Exception:
        for obj in made:
            mesh = obj.data
            bpy.data.objects.remove(obj)
            bpy.data.meshes.remove(mesh)
        raise
    return made


class MPEG4FACE_OT_import_mpeg4_face(ImportHelper, bpy.types.Operator):
    """Import an MPEG-4 face (VRML97 with its FaceDefTables and feature points): its meshes,
    FP_ groups and the tables as shape keys fap<N>@<value>, viseme<N>, expression<N>"""

    bl_idname = "mpeg4face.import_mpeg4_face"
    bl_label = "Import MPEG-4 Face"
    bl_options = {"REGISTER", "UNDO"}

    filter_glob: StringProperty(default="*.wrl", options={"HIDDEN"})

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        # A file dropped on the viewport (ui/file_handlers.py) comes with its path set by
        # the caller: imported at once, there being no options to ask for.
        if self.properties.is_property_set("filepath", ghost=False):
            return self.execute(context)
        return super().invoke(context, event)

    def execute(self, context: bpy.types.Context) -> set[str]:
        path = bpy.path.abspath(self.filepath)
        try:
            face = face_import.imported_face(mpeg4face.read_vrml(path), Path(path).stem)
        except INPUT_ERRORS as error:
            message = str(error)
            if path not in message:
                message = f"{path}: {message}"
            self.report({"ERROR"}, f"Nothing imported: {message}")
            return {"CANCELLED"}
        if context.mode != "OBJECT":
            bpy.ops.object.mode_set(mode="OBJECT")
        objects = make_face(face, context.collection)
        for obj in context.view_layer.objects:
            obj.select_set(obj in objects)
        head = objects[0]
        context.view_layer.objects.active = head
        keys = len({name for part in face.meshes for name in part.keys})
        points = sum(len(part.feature_points) for part in face.meshes)
        for line in face.not_imported:
            self.report({"WARNING"}, f"Not imported: {line}")
        self.report({"INFO"}, f"{head.name} from {path}: {len(objects)} meshes, {points} "
                    f"feature points, {keys} shape keys")
        return {"FINISHED"}


def face_import_menu(menu: bpy.types.Menu, context: bpy.types.Context) -> None:
    menu.layout.operator(MPEG4FACE_OT_import_mpeg4_face.bl_idname, text="MPEG-4 face (.wrl)")


def register() -> None:
    bpy.utils.register_class(MPEG4FACE_OT_import_mpeg4_face)
    bpy.types.TOPBAR_MT_file_import.append(face_import_menu)


def unregister() -> None:
    bpy.types.TOPBAR_MT_file_import.remove(face_import_menu)
    bpy.utils.unregister_class(MPEG4FACE_OT_import_mpeg4_face)
