# SPDX-License-Identifier: GPL-3.0-or-later
"""The sidebar tab "MPEG-4" of the 3D Viewport: feature point list, FAPU read-out and the
Table 6 location warnings of the active mesh."""

from __future__ import annotations

import bpy
from bpy.app.handlers import persistent

from ...logic import feature_points
from ...scene import mesh_data
from .. import preferences
from .. import text as ui_text

# The face state of one object, kept until a depsgraph update changes the geometry or
# place of its head or parts (not a selection, a frame or another object's change): the
# panels and the list's rows share one reading of the mesh, not one per redraw.
_cache: dict[tuple[int, str, float], tuple[feature_points.FaceState, frozenset[int]]] = {}


@persistent
def _forget(_scene: object = None, depsgraph: bpy.types.Depsgraph | None = None) -> None:
    if depsgraph is None:  # a file was loaded
        _cache.clear()
        return
    changed = {u.id.original.as_pointer() for u in depsgraph.updates
               if u.is_updated_geometry or u.is_updated_transform}
    for key in [k for k, (_, ids) in _cache.items() if ids & changed]:
        del _cache[key]


def _face_ids(obj: bpy.types.Object) -> frozenset[int]:
    """The objects and meshes whose change changes the face state of `obj`."""
    objects = [obj, *mesh_data.face_parts(obj)]
    return frozenset(p for o in objects for p in (o.as_pointer(), o.data.as_pointer()))


def cached_face_state(context: bpy.types.Context) -> feature_points.FaceState | None:
    """The active mesh's state, or None when the active object is not a mesh."""
    obj = context.active_object
    if obj is None or obj.type != "MESH":
        return None
    tolerance = preferences.preferences(context).constraint_tolerance
    key = (obj.as_pointer(), obj.mode, tolerance)
    if key not in _cache:
        _cache[key] = mesh_data.read_face_state(obj, tolerance), _face_ids(obj)
    return _cache[key][0]


class MPEG4FACE_UL_feature_points(bpy.types.UIList):
    """Every feature point with its status: set (vertex, or the part holding it) or
    missing; F = needed for the FAPU, C = needed for cloning. The description is in the
    box below the list, for the selected point (a row of 229 px has no room for it)."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_propname,
                  index=0):
        state = cached_face_state(context)
        row = state.rows[index] if state and index < len(state.rows) else None
        is_set = row is not None and row.is_set
        split = layout.split(factor=0.42)
        split.label(text=item.fp_id, icon="CHECKMARK" if is_set else "X")
        flags = split.split(factor=0.72)
        part = state.part_points.get(item.fp_id) if state else None
        found = context.active_object.get("mpeg4face_fp_confidence", {}) if is_set else {}
        confidence = f" {round(100 * found[item.fp_id])}%" if item.fp_id in found else ""
        flags.label(text=((part or f"v {row.vertex}") + confidence) if is_set else "missing")
        flags.label(text=("F" if item.needed_for_fapu else "")
                    + ("C" if item.needed_for_cloning else ""))

    def filter_items(self, context, data, propname):
        # The filter matches the description too (the name holds it), though rows show the id.
        items = getattr(data, propname)
        flags = [self.bitflag_filter_item] * len(items)
        if self.filter_name:
            wanted = self.filter_name.lower()
            flags = [self.bitflag_filter_item if wanted in i.name.lower() else 0 for i in items]
        return flags, []


class _Sidebar:
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "MPEG-4"


class MPEG4FACE_PT_feature_points(_Sidebar, bpy.types.Panel):
    bl_label = "Feature Points"

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        state = cached_face_state(context)
        if state is None:
            ui_text.label(layout, context, "Make the head mesh the active object", "INFO")
            return
        wm = context.window_manager
        layout.template_list(
            "MPEG4FACE_UL_feature_points", "", wm, "mpeg4face_feature_points",
            wm, "mpeg4face_feature_point_index", rows=8,
        )
        items = wm.mpeg4face_feature_points
        index = wm.mpeg4face_feature_point_index
        if 0 <= index < len(items):
            item, row = items[index], state.rows[index] if index < len(state.rows) else None
            box = layout.box()
            ui_text.label(box, context, f"{item.fp_id} {item.description}", boxes=1)
            if row is not None and row.is_set:
                part = state.part_points.get(item.fp_id)
                where = f"on {part}" if part else f"vertex {row.vertex}"
                ui_text.label(box, context, f"Set: {where}", "CHECKMARK", boxes=1)
            else:
                ui_text.label(box, context, "Not set", "X", boxes=1)
            needed = [t for t, n in (("the FAPU", item.needed_for_fapu),
                                     ("cloning", item.needed_for_cloning)) if n]
            if needed:
                ui_text.label(box, context, f"Needed for {' and '.join(needed)}", boxes=1)
            box.operator_context = "EXEC_DEFAULT"  # the list already chose the point
            op = box.operator("mpeg4face.assign_feature_point",
                              text=f"Assign {item.fp_id} to Selected Vertex")
            op.feature_point = item.fp_id
        ui_text.label(layout, context, "F: needed for FAPU, C: for cloning")
        for title, needed in (("FAPU", feature_points.fapu_points()),
                              ("cloning", feature_points.cloning_points())):
            absent = feature_points.missing(state.rows, needed)
            text = f"missing for {title}: {', '.join(absent)}" if absent else f"complete for {title}"
            ui_text.label(layout, context, text, "ERROR" if absent else "CHECKMARK")
        for warning in state.group_warnings:
            ui_text.label(layout, context, warning, "ERROR")

        col = layout.column(align=True)
        col.operator("mpeg4face.assign_feature_point", text="Assign (Search)...", icon="VIEWZOOM")
        col.operator("mpeg4face.mirror_feature_points", icon="MOD_MIRROR")
        col.operator("mpeg4face.find_feature_points", icon="SHADERFX")
        col.operator("mpeg4face.make_animatable", icon="SHAPEKEY_DATA")


class MPEG4FACE_PT_fapu(_Sidebar, bpy.types.Panel):
    """FAPU measured from the feature points in object space (Blender's Z up read as the
    standard's Y up), the parts' points (the pupils on the eyeballs) included."""

    bl_label = "FAPU"
    bl_parent_id = "MPEG4FACE_PT_feature_points"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context: bpy.types.Context) -> None:
        state = cached_face_state(context)
        if state is None:
            return
        col = self.layout.column(align=True)
        for reading in state.fapu:
            if not reading.measured:
                ui_text.label(col, context, reading.lines()[0], "ERROR")
                continue
            ui_text.label(col, context, f"{reading.name} = {reading.value:.5g}")
            ui_text.label(col, context, f"    FAPU = {reading.unit:.5g}")
            ui_text.label(col, context, f"    from {', '.join(reading.points_used)}: "
                          f"{reading.method}")


class MPEG4FACE_PT_location_warnings(_Sidebar, bpy.types.Panel):
    bl_label = "Location Warnings (Table 6)"
    bl_parent_id = "MPEG4FACE_PT_feature_points"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context: bpy.types.Context) -> None:
        state = cached_face_state(context)
        if state is None:
            return
        col = self.layout.column(align=True)
        if not state.location_warnings:
            col.label(text="No warnings", icon="CHECKMARK")
        for warning in state.location_warnings:
            ui_text.label(col, context, warning.message,
                          "INFO" if warning.advisory else "ERROR")


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
