# SPDX-License-Identifier: GPL-3.0-or-later
"""Operators: assign a feature point to the selected vertex, mirror feature points across
X = 0, find them all from a template head. Each one checks its input and reports problems
in the UI instead of raising."""

from typing import Callable

import bpy
import mpeg4face
from bpy.props import EnumProperty, FloatProperty, StringProperty

from ...logic import feature_points
from ...scene import mesh_data
from .. import preferences, properties

# The object property holding Find Feature Points' confidence per point (id -> 0..1).
CONFIDENCE = "mpeg4face_fp_confidence"


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
        found = obj.get(CONFIDENCE)
        if found is not None and self.feature_point in found:
            del found[self.feature_point]  # yours now: Find Feature Points' guess is gone
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


def read_template(op: bpy.types.Operator, context: bpy.types.Context,
                  path: str) -> mpeg4face.FaceModel | None:
    """The template head: `path`, else the add-on preferences' Template head; None (reported)
    if neither is set or it does not read."""
    path = path or preferences.preferences(context).template_head
    if not path:
        op.report({"ERROR"}, "No template head: set one (a .glb with feature points, such as "
                  "samples/build/ict_head.glb) in the add-on preferences or the operator")
        return None
    try:
        return mpeg4face.read_model(bpy.path.abspath(path))
    except (mpeg4face.Error, OSError) as error:
        op.report({"ERROR"}, f"Template head: {error}")
        return None


def find_feature_points(op: bpy.types.Operator, obj: bpy.types.Object,
                        template: mpeg4face.FaceModel,
                        progress: Callable[[float], None]) -> bool:
    """Places obj's feature points from `template` (its FP_ groups kept as pins) as FP_
    groups, with each point's confidence in obj[CONFIDENCE]; reports what it placed and what
    it could not. False (reported) if it found no face."""
    model, warnings = mesh_data.read_face_model(obj)
    for warning in warnings:
        op.report({"WARNING"}, warning)
    try:
        points, info = mpeg4face.find_feature_points(
            model, template, pins=dict(model.feature_points),
            progress=lambda fraction, _step: progress(fraction))
    except mpeg4face.Error as error:
        op.report({"ERROR"}, f"{obj.name}: {error}")
        return False
    on_head = {fp: b.vertex for fp, (b, _, rule) in points.items() if b.mesh == 0}
    with mesh_data.face_bmesh(obj, write=True) as bm:
        mesh_data.set_feature_points(obj, bm, on_head)
    obj[CONFIDENCE] = {fp: round(c, 3) for fp, (b, c, _) in points.items() if b.mesh == 0}
    elsewhere = sorted(set(points) - set(on_head), key=lambda fp: tuple(map(int, fp.split("."))))
    for why in info["not_placed"]:
        op.report({"WARNING"}, f"not placed: {why}")
    if elsewhere:
        op.report({"WARNING"}, "not on this mesh (inside the head or on eyes, teeth or tongue "
                  f"it does not have): {', '.join(elsewhere)}")
    low = [fp for fp, c in obj[CONFIDENCE].items() if c < 0.5]
    if low:
        op.report({"WARNING"}, f"low confidence, check them: {', '.join(sorted(low))}")
    op.report({"INFO"}, f"{obj.name}: {len(on_head)} feature points placed "
              f"({len(model.feature_points)} of them yours, kept); fit residual "
              f"{100 * info['fit_residual']:.1f}% of ES0")
    return True


class TemplateHead:
    """The template head of the operators that use one."""

    template: StringProperty(
        name="Template head",
        description="A head with feature points (and, for Make Animatable, FAP, viseme and "
        "expression shape keys); default: the add-on preferences' Template head",
        subtype="FILE_PATH",
    )


class MPEG4FACE_OT_find_feature_points(TemplateHead, bpy.types.Operator):
    """Place every MPEG-4 feature point on the active head by fitting a template head that
    has them; the points you set are kept and pull the fit"""

    bl_idname = "mpeg4face.find_feature_points"
    bl_label = "Find Feature Points"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = active_mesh(self, context)
        if obj is None:
            return {"CANCELLED"}
        if obj.mode != "OBJECT":
            self.report({"ERROR"}, "Switch to Object Mode to find feature points")
            return {"CANCELLED"}
        template = read_template(self, context, self.template)
        if template is None:
            return {"CANCELLED"}
        wm = context.window_manager
        wm.progress_begin(0, 1)
        try:
            found = find_feature_points(self, obj, template, wm.progress_update)
        finally:
            wm.progress_end()
        return {"FINISHED"} if found else {"CANCELLED"}


register, unregister = bpy.utils.register_classes_factory(
    (MPEG4FACE_OT_assign_feature_point, MPEG4FACE_OT_mirror_feature_points,
     MPEG4FACE_OT_find_feature_points)
)
