# SPDX-License-Identifier: GPL-3.0-or-later
"""Sidebar panels of the "MPEG-4" tab for FAP shape keys: adding, mapping and mirroring
keys, the last "Generate FaceDefTables" report, and cloning."""

import bpy
from bpy.props import EnumProperty

from ...logic import shape_keys
from .. import text as ui_text
from ..operators import arkit as operators_arkit
from ..operators import faces as operators_faces
from .feature_points import _Sidebar

REPORTS = (("TABLES", "FaceDefTables", "The last Generate FaceDefTables report"),
           ("ARKIT", "FAP Keys from ARKit", "The last FAP Keys from ARKit Keys report"))


class MPEG4FACE_OT_show_report(bpy.types.Operator):
    """Show the whole report of the active mesh's last run in a popup"""

    bl_idname = "mpeg4face.show_report"
    bl_label = "Show Report"
    bl_options = {"REGISTER", "UNDO"}  # as every operator of the add-on (test_addon_undo)

    kind: EnumProperty(items=REPORTS, default="TABLES")

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = context.active_object
        source = (operators_faces.table_reports if self.kind == "TABLES"
                  else operators_arkit.arkit_reports)
        report = source.get(obj.name) if obj is not None else None
        if report is None:
            self.report({"ERROR"}, "No report yet: run it first")
            return {"CANCELLED"}
        lines = report.lines()
        ui_text.popup(context, dict((k, t) for k, t, _ in REPORTS)[self.kind], lines)
        print("\n".join(lines))  # the whole report in the console too
        return {"FINISHED"}


def _grammar_keys(obj: bpy.types.Object) -> list[str]:
    keys = obj.data.shape_keys
    return [k.name for k in keys.key_blocks if shape_keys.is_grammar_name(k.name)] if keys else []


class MPEG4FACE_PT_shape_keys(_Sidebar, bpy.types.Panel):
    bl_label = "FAP Shape Keys"

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        return context.active_object is not None and context.active_object.type == "MESH"

    def draw(self, context: bpy.types.Context) -> None:
        obj = context.active_object
        layout = self.layout
        named = _grammar_keys(obj)
        ui_text.label(layout, context, f"{len(named)} shape keys named for MPEG-4")
        col = layout.column(align=True)
        col.operator("mpeg4face.add_fap_shape_key", text="Add FAP Key...", icon="VIEWZOOM")
        for kind, text in (("VISEME", "Add Viseme Key..."), ("EXPRESSION", "Add Expression Key...")):
            col.operator("mpeg4face.add_fap_shape_key", text=text).kind = kind
        col.operator("mpeg4face.map_shape_keys", icon="SHAPEKEY_DATA")
        col.operator("mpeg4face.mirror_shape_key", icon="MOD_MIRROR")
        col.operator("mpeg4face.arkit_fap_keys", icon="SHAPEKEY_DATA")
        report = operators_arkit.arkit_reports.get(obj.name)
        if report is not None:
            ui_text.label(layout, context, report.summary(), "INFO")
            layout.operator("mpeg4face.show_report", text="Show ARKit Report",
                            icon="TEXT").kind = "ARKIT"


class MPEG4FACE_PT_face_tables(_Sidebar, bpy.types.Panel):
    """The FaceDefTables the shape keys give: the last report of Generate FaceDefTables."""

    bl_label = "FaceDefTables"
    bl_parent_id = "MPEG4FACE_PT_shape_keys"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        layout.operator("mpeg4face.generate_tables", icon="FILE_REFRESH")
        report = operators_faces.table_reports.get(context.active_object.name)
        if report is None:
            layout.label(text="Not generated yet")
            return
        # The summary and the count of warnings here; the whole report (one line per table,
        # ~75 on a full head) in a popup, so it does not push the other panels away.
        lines = report.lines()
        ui_text.label(layout, context, lines[0], "CHECKMARK")
        warnings = sum(line.startswith(("warning", "ignored")) for line in lines)
        if warnings:
            ui_text.label(layout, context, f"{warnings} warnings", "ERROR")
        layout.operator("mpeg4face.show_report", icon="TEXT").kind = "TABLES"


class MPEG4FACE_PT_cloning(_Sidebar, bpy.types.Panel):
    bl_label = "Cloning"
    bl_parent_id = "MPEG4FACE_PT_shape_keys"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context: bpy.types.Context) -> None:
        targets = [o.name for o in context.selected_objects
                   if o != context.active_object and o.type == "MESH"]
        layout = self.layout
        ui_text.label(layout, context, f"Source: {context.active_object.name} (active)")
        ui_text.label(layout, context,
                      f"Targets: {', '.join(targets) if targets else 'select other meshes'}")
        layout.operator("mpeg4face.clone_motion", icon="DUPLICATE")


_classes = (MPEG4FACE_OT_show_report, MPEG4FACE_PT_shape_keys, MPEG4FACE_PT_face_tables,
            MPEG4FACE_PT_cloning)
register, unregister = bpy.utils.register_classes_factory(_classes)
