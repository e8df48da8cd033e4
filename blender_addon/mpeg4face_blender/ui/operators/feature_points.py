# SPDX-License-Identifier: GPL-3.0-or-later
"""Operators: assign a feature point to the selected vertex, mirror feature points across
X = 0. Each one checks its input and reports problems in the UI instead of raising."""

import bpy
from bpy.props import EnumProperty, FloatProperty

from ...logic import feature_points
from ...scene import mesh_data
from .. import properties


def active_mesh(op: bpy.types.Operator, context: bpy.types.Context) -> bpy.types.Object | None:
    """The active object when it is a mesh; otherwise reports why not and returns None."""
    obj = context.active_object
    if obj is None:
        op.report({"ERROR"}, "No active object: make the head mesh active")
        return None
    if obj.type != "MESH":
        op.report({"ERROR"}, f"{obj.name} is a {obj.type.lower()} object, not a mesh")
        return None
    return obj


class MPEG4FACE_OT_assign_feature_point(bpy.types.Operator):
    """Make the selected vertex an MPEG-4 feature point (vertex group FP_<id>, weight 1)"""

    bl_idname = "mpeg4face.assign_feature_point"
    bl_label = "Assign Feature Point"
    bl_options = {"REGISTER", "UNDO"}
    bl_property = "feature_point"  # what invoke_search_popup searches

    feature_point: EnumProperty(
        name="Feature point", items=properties.feature_point_enum_items()
    )

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        context.window_manager.invoke_search_popup(self)
        return {"RUNNING_MODAL"}

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = active_mesh(self, context)
        if obj is None:
            return {"CANCELLED"}
        if obj.mode != "EDIT":
            self.report({"ERROR"}, "Switch to Edit Mode and select one vertex")
            return {"CANCELLED"}
        with mesh_data.face_bmesh(obj, write=True) as bm:
            selected = mesh_data.selected_vertices(bm)
            if len(selected) != 1:
                self.report(
                    {"ERROR"}, f"Select exactly one vertex ({len(selected)} are selected)"
                )
                return {"CANCELLED"}
            mesh_data.set_feature_point(obj, bm, self.feature_point, selected[0])
        self.report(
            {"INFO"}, f"Feature point {self.feature_point} is vertex {selected[0]}"
        )
        return {"FINISHED"}


class MPEG4FACE_OT_mirror_feature_points(bpy.types.Operator):
    """Place the left/right partners of set feature points (3.5 <-> 3.6, ...) at the
    vertices nearest to their mirror images across the X = 0 plane (object space)"""

    bl_idname = "mpeg4face.mirror_feature_points"
    bl_label = "Mirror Feature Points"
    bl_options = {"REGISTER", "UNDO"}

    source: EnumProperty(
        name="From",
        items=(
            ("MISSING", "Missing partners", "Place only partners that are not set yet"),
            ("LEFT", "Face's left (+X)", "Copy the points at +X onto their partners"),
            ("RIGHT", "Face's right (-X)", "Copy the points at -X onto their partners"),
        ),
        default="MISSING",
    )
    tolerance: FloatProperty(
        name="Tolerance",
        description="Skip a partner when the nearest vertex is farther from the mirror image "
        "than this fraction of the mesh's bounding-box diagonal",
        default=0.01,
        min=0.0,
        max=1.0,
        subtype="FACTOR",
    )

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = active_mesh(self, context)
        if obj is None:
            return {"CANCELLED"}
        with mesh_data.face_bmesh(obj, write=True) as bm:
            coords = mesh_data.standard_coords(bm)
            fp_vertices, _ = feature_points.fp_vertices_from_groups(mesh_data.fp_groups(obj, bm))
            if not fp_vertices:
                self.report({"ERROR"}, f"{obj.name} has no feature points (FP_ vertex groups)")
                return {"CANCELLED"}
            tolerance = feature_points.mirror_tolerance(coords, self.tolerance)
            matches = feature_points.mirror_matches(coords, fp_vertices, self.source, tolerance)
            for match in matches:
                if match.accepted:
                    mesh_data.set_feature_point(obj, bm, match.partner, match.vertex)
        for match in matches:
            self.report({"INFO"} if match.accepted else {"WARNING"}, match.message(tolerance))
        placed = sum(m.accepted for m in matches)
        self.report(
            {"INFO"} if placed == len(matches) else {"WARNING"},
            f"Mirrored {placed} feature points, skipped {len(matches) - placed}",
        )
        return {"FINISHED"}


register, unregister = bpy.utils.register_classes_factory(
    (MPEG4FACE_OT_assign_feature_point, MPEG4FACE_OT_mirror_feature_points)
)
