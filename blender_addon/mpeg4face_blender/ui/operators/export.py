# SPDX-License-Identifier: GPL-3.0-or-later
"""File > Export > MPEG-4 Face (.wrl) and MPEG-4 Face glTF (.glb): the FaceDefTables
generated from a mesh's FAP shape keys, written by the core (which writes atomically, so a
failed export leaves no half-written file). The options are in sub-panels of the file
browser's operator panel, as Blender's own glTF exporter lays them out."""

# No postponed annotations: bpy reads the property annotations.
import bpy
from bpy.props import FloatProperty, StringProperty
from bpy_extras.io_utils import ExportHelper

import mpeg4face

from ...logic import shape_keys
from . import faces as operators_faces


class _ExportFace(ExportHelper):
    writer = None  # mpeg4face's write function for the format

    bl_options = {"REGISTER", "UNDO", "PRESET"}

    threshold: FloatProperty(
        name="Threshold", description="FAPU a vertex must move to be in a table",
        default=0.01, min=0.0, soft_max=1.0)
    object_name: StringProperty(
        name="Object", description="The head mesh to export (empty: the active object)")

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        if not self.object_name and context.active_object is not None:
            self.object_name = context.active_object.name
        return super().invoke(context, event)

    def draw(self, context: bpy.types.Context) -> None:
        pass  # the sub-panels below draw the options

    def head(self, context: bpy.types.Context) -> bpy.types.Object | None:
        obj = bpy.data.objects.get(self.object_name) if self.object_name \
            else context.active_object
        if obj is None:
            self.report({"ERROR"}, f"No object {self.object_name}" if self.object_name
                        else "No active object: make the head mesh active")
            return None
        if obj.type != "MESH":
            self.report({"ERROR"}, f"{obj.name} is a {obj.type.lower()} object, not a mesh")
            return None
        if not operators_faces.has_keys(self, obj, context.scene) \
                or not operators_faces.has_feature_points(self, obj):
            return None
        return obj

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = self.head(context)
        if obj is None:
            return {"CANCELLED"}
        if obj.mode == "EDIT":
            obj.update_from_editmode()

        def work(update) -> shape_keys.TablesReport:
            face, report = operators_faces.generate(obj, self.threshold, context.scene,
                                                    update)  # 0..1 over the pose markers
            update(1)
            self.writer(face, self.filepath)
            update(2)
            return report

        try:
            report = operators_faces.with_progress(context, 2, work)
        except (mpeg4face.Error, OSError) as error:
            self.report({"ERROR"}, f"Nothing written: {error}")
            return {"CANCELLED"}
        operators_faces.table_reports[obj.name] = report
        for warning in report.warnings:
            self.report({"WARNING"}, warning)
        self.report({"INFO"}, f"Wrote {self.filepath}: {report.lines()[0]}")
        return {"FINISHED"}


class MPEG4FACE_OT_export_vrml(_ExportFace, bpy.types.Operator):
    """Export the active mesh with the FaceDefTables of its FAP shape keys as VRML"""

    bl_idname = "mpeg4face.export_vrml"
    bl_label = "Export MPEG-4 Face (.wrl)"
    filename_ext = ".wrl"
    filter_glob: StringProperty(default="*.wrl", options={"HIDDEN"})
    writer = staticmethod(mpeg4face.write_vrml)


class MPEG4FACE_OT_export_gltf(_ExportFace, bpy.types.Operator):
    """Export the active mesh with the FaceDefTables of its FAP shape keys as glTF"""

    bl_idname = "mpeg4face.export_gltf"
    bl_label = "Export MPEG-4 Face glTF (.glb)"
    filename_ext = ".glb"
    filter_glob: StringProperty(default="*.glb", options={"HIDDEN"})
    writer = staticmethod(mpeg4face.write_face_gltf)


class _ExportOptions:
    """A sub-panel of the file browser's operator panel, shown for our two exporters."""

    bl_space_type = "FILE_BROWSER"
    bl_region_type = "TOOL_PROPS"
    bl_parent_id = "FILE_PT_operator"

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        operator = getattr(context.space_data, "active_operator", None)
        return operator is not None and operator.bl_idname in EXPORTERS


def _options(panel: bpy.types.Panel, context: bpy.types.Context):
    """The panel's layout set up as the file browser's options are, and the operator."""
    panel.layout.use_property_split = True
    panel.layout.use_property_decorate = False
    return panel.layout, context.space_data.active_operator


class MPEG4FACE_PT_export_head(_ExportOptions, bpy.types.Panel):
    bl_label = "Head"

    def draw(self, context: bpy.types.Context) -> None:
        layout, operator = _options(self, context)
        layout.prop_search(operator, "object_name", bpy.data, "objects")


class MPEG4FACE_PT_export_tables(_ExportOptions, bpy.types.Panel):
    bl_label = "FaceDefTables"

    def draw(self, context: bpy.types.Context) -> None:
        layout, operator = _options(self, context)
        layout.prop(operator, "threshold")


# The operators' idnames as the file browser's active_operator gives them: the class names.
EXPORTERS = {cls.__name__ for cls in (MPEG4FACE_OT_export_vrml, MPEG4FACE_OT_export_gltf)}


def _menu(self, context: bpy.types.Context) -> None:
    self.layout.operator(MPEG4FACE_OT_export_vrml.bl_idname, text="MPEG-4 Face (.wrl)")
    self.layout.operator(MPEG4FACE_OT_export_gltf.bl_idname, text="MPEG-4 Face glTF (.glb)")


_classes = (MPEG4FACE_OT_export_vrml, MPEG4FACE_OT_export_gltf, MPEG4FACE_PT_export_head,
            MPEG4FACE_PT_export_tables)


def register() -> None:
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.TOPBAR_MT_file_export.append(_menu)


def unregister() -> None:
    bpy.types.TOPBAR_MT_file_export.remove(_menu)
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
