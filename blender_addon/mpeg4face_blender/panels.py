# SPDX-License-Identifier: GPL-3.0-or-later
"""The sidebar tab "MPEG-4" of the 3D Viewport: feature point list, FAPU read-out and the
Table 6 location warnings of the active mesh."""

from __future__ import annotations

import bpy
from bpy.app.handlers import persistent

from . import fp_logic, mesh_data, preferences

# The face state of one object, kept until the next depsgraph update: the three panels and
# the list's rows share one reading of the mesh per redraw.
_cache: dict[tuple[int, str, float], fp_logic.FaceState] = {}


@persistent
def _forget(*_args: object) -> None:
    _cache.clear()


def face_state(context: bpy.types.Context) -> fp_logic.FaceState | None:
    """The active mesh's state, or None when the active object is not a mesh."""
    obj = context.active_object
    if obj is None or obj.type != "MESH":
        return None
    tolerance = preferences.preferences(context).constraint_tolerance
    key = (obj.as_pointer(), obj.mode, tolerance)
    if key not in _cache:
        _cache[key] = mesh_data.face_state(obj, tolerance)
    return _cache[key]


class MPEG4FACE_UL_feature_points(bpy.types.UIList):
    """Every feature point with its status: set (vertex) or missing; F = needed for the
    FAPU, C = needed for cloning."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_propname,
                  index=0):
        state = face_state(context)
        row = state.rows[index] if state and index < len(state.rows) else None
        is_set = row is not None and row.is_set
        split = layout.split(factor=0.55)
        split.label(text=item.name, icon="CHECKMARK" if is_set else "X")
        flags = split.row(align=True)
        flags.label(text=f"vertex {row.vertex}" if is_set else "missing")
        flags.label(text="F" if item.needed_for_fapu else "")
        flags.label(text="C" if item.needed_for_cloning else "")


class _Sidebar:
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "MPEG-4"


class MPEG4FACE_PT_feature_points(_Sidebar, bpy.types.Panel):
    bl_label = "Feature Points"

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        state = face_state(context)
        if state is None:
            layout.label(text="Make the head mesh the active object", icon="INFO")
            return
        wm = context.window_manager
        layout.template_list(
            "MPEG4FACE_UL_feature_points", "", wm, "mpeg4face_feature_points",
            wm, "mpeg4face_feature_point_index", rows=8,
        )
        layout.label(text="F: needed for FAPU, C: needed for cloning")
        for title, needed in (("FAPU", fp_logic.fapu_points()),
                              ("cloning", fp_logic.cloning_points())):
            absent = fp_logic.missing(state.rows, needed)
            text = f"missing for {title}: {', '.join(absent)}" if absent else f"complete for {title}"
            layout.label(text=text, icon="ERROR" if absent else "CHECKMARK")
        for warning in state.group_warnings:
            layout.label(text=warning, icon="ERROR")

        col = layout.column(align=True)
        items = wm.mpeg4face_feature_points
        index = wm.mpeg4face_feature_point_index
        if 0 <= index < len(items):
            row = col.row()
            row.operator_context = "EXEC_DEFAULT"  # the list already chose the point
            op = row.operator("mpeg4face.assign_feature_point",
                              text=f"Assign {items[index].fp_id} to Selected Vertex")
            op.feature_point = items[index].fp_id
        col.operator("mpeg4face.assign_feature_point", text="Assign (Search)...", icon="VIEWZOOM")
        col.operator("mpeg4face.mirror_feature_points", icon="MOD_MIRROR")


class MPEG4FACE_PT_fapu(_Sidebar, bpy.types.Panel):
    """FAPU measured from the feature points in object space (Blender's Z up read as the
    standard's Y up)."""

    bl_label = "FAPU"
    bl_parent_id = "MPEG4FACE_PT_feature_points"

    def draw(self, context: bpy.types.Context) -> None:
        state = face_state(context)
        if state is None:
            return
        col = self.layout.column(align=True)
        for reading in state.fapu:
            for i, line in enumerate(reading.lines()):
                col.label(text=line, icon="ERROR" if i == 0 and not reading.measured else "NONE")


class MPEG4FACE_PT_location_warnings(_Sidebar, bpy.types.Panel):
    bl_label = "Location Warnings (Table 6)"
    bl_parent_id = "MPEG4FACE_PT_feature_points"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context: bpy.types.Context) -> None:
        state = face_state(context)
        if state is None:
            return
        col = self.layout.column(align=True)
        if not state.location_warnings:
            col.label(text="No warnings", icon="CHECKMARK")
        for warning in state.location_warnings:
            col.label(text=warning.message, icon="INFO" if warning.advisory else "ERROR")


_classes = (
    MPEG4FACE_UL_feature_points,
    MPEG4FACE_PT_feature_points,
    MPEG4FACE_PT_fapu,
    MPEG4FACE_PT_location_warnings,
)


def register() -> None:
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.app.handlers.depsgraph_update_post.append(_forget)
    bpy.app.handlers.load_post.append(_forget)


def unregister() -> None:
    for handlers in (bpy.app.handlers.depsgraph_update_post, bpy.app.handlers.load_post):
        if _forget in handlers:
            handlers.remove(_forget)
    _cache.clear()
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
