# SPDX-License-Identifier: GPL-3.0-or-later
"""Pose FAPs with Bones: for a head skinned to an armature (a Rigify face rig, or any rig
with named face bones through a FAP -> bone mapping table), each mapped FAP gets a grammar
marker at which its bone is posed so that the FAP's feature point moves the FAP's amplitude
(in the head's FAPU) along the FAP's direction, measured on the evaluated mesh and
corrected until within the tolerance (rig_logic.fit_pose). "Generate FaceDefTables" and the
export then read the rig's deformed copies there (poses.read_posed_face_model). A panel in the
sidebar's MPEG-4 tab runs it."""

# No postponed annotations: bpy reads the property annotations.
from collections.abc import Callable

import bpy
import mpeg4face
import numpy as np
from bpy.props import FloatProperty, IntProperty, StringProperty
from mathutils import Vector

from ...logic import feature_points, shape_keys
from ...logic import rig as rig_logic
from ...scene import mesh_data, poses
from ..panels.feature_points import _Sidebar
from . import faces as operators_faces
from .feature_points import active_mesh

# The last report per head object name, for the panel; forgotten with the other reports.
pose_reports: dict[str, rig_logic.PoseReport] = {}


def rig_of(head: bpy.types.Object) -> bpy.types.Object | None:
    """The armature of the head's first Armature modifier enabled in the viewport."""
    for modifier in head.modifiers:
        if modifier.type == "ARMATURE" and modifier.show_viewport:
            return modifier.object
    return None


def _set(bone: bpy.types.PoseBone, channel: rig_logic.BoneChannel, direction: Vector,
         value: float) -> None:
    """Puts the bone at `value` of its channel: a distance along `direction` (the bone's
    local axes) or an angle about its axis; every other channel at rest."""
    bone.location = direction * value if channel.channel == "location" else (0.0, 0.0, 0.0)
    bone.rotation_mode = "XYZ"
    rotation = [0.0, 0.0, 0.0]
    if channel.channel == "rotation":
        rotation["XYZ".index(channel.axis)] = value
    bone.rotation_euler = rotation


def _local_direction(head: bpy.types.Object, rig: bpy.types.Object, bone: bpy.types.PoseBone,
                     standard: np.ndarray) -> Vector:
    """A direction of the head's standard axes in the bone's rest axes (pose locations)."""
    obj = Vector(feature_points.to_blender_axes(standard)[0])
    world = head.matrix_world.to_3x3() @ obj
    local = bone.bone.matrix_local.to_3x3().inverted() @ (rig.matrix_world.to_3x3().inverted()
                                                          @ world)
    return local.normalized()


def key_fap_poses(head: bpy.types.Object, rig: bpy.types.Object,
              mapping: dict[int, rig_logic.BoneChannel], amplitude: int,
              scene: bpy.types.Scene, tolerance: float = 0.05,
              progress: Callable[[float], None] | None = None) -> rig_logic.PoseReport:
    """Poses each mapped FAP (see the module's doc) and keys the bones at a new marker per
    FAP posed within the tolerance, after the scene's last marker (the neutral marker at the
    start frame when there is none); markers of the same name are replaced. The report
    names the FAPs posed and why the others are not."""
    poses.check_armatures([head])
    report = rig_logic.PoseReport()
    bones = rig.pose.bones
    channels = {}
    for fap, channel in sorted(mapping.items()):
        missing = [name for name in channel.bones if name not in bones]
        if missing:
            report.missed.append((fap, f"{rig.name} has no bone {', '.join(missing)}"))
        else:
            channels[fap] = channel
    used = {name for c in channels.values() for name in c.bones}
    animation = rig.animation_data
    action = animation.action if animation is not None else None
    if animation is not None:
        animation.action = None  # the fit sets the bones by hand; keyed afterwards
    was = scene.frame_current
    try:
        for name in used:
            _set(bones[name], rig_logic.BoneChannel(name), Vector(), 0.0)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        _, faces, fp_vertices, _ = mesh_data.mesh_and_points(head)
        with poses.rig_only([head], operators_faces.key_names):
            bpy.context.view_layer.update()
            neutral = feature_points.to_standard_axes(poses.evaluated_coords(head, depsgraph))
            fapu = mpeg4face.measure_fapu(
                feature_points.face_model_from_arrays(neutral, faces, fp_vertices))
            fits = []
            for done, (fap, channel) in enumerate(channels.items(), 1):
                fit = _fit(head, rig, fap, channel, amplitude, fapu, fp_vertices, neutral,
                           depsgraph, tolerance)
                for name in channel.bones:
                    _set(bones[name], channel, Vector(), 0.0)
                if isinstance(fit, str):
                    report.missed.append((fap, fit))
                elif not fit.ok:
                    report.missed.append((fap, fit.reason))
                else:
                    fits.append((fit, channel))
                if progress is not None:
                    progress(done / max(1, len(channels)))
    finally:
        if animation is not None:
            animation.action = action
    _key_poses(head, rig, fits, used, amplitude, scene)
    scene.frame_set(was)
    report.posed = [fit for fit, _ in fits]
    return report


def _fit(head, rig, fap, channel, amplitude, fapu, fp_vertices, neutral, depsgraph,
         tolerance) -> rig_logic.PoseFit | str:
    """The fit of one FAP, or why it cannot be tried."""
    info = mpeg4face.fap(fap)
    vertex = fp_vertices.get(info.feature_point)
    if vertex is None:
        return f"feature point {info.feature_point} is not set on {head.name}"
    try:
        direction = rig_logic.fap_direction(fap)
        unit = fapu.unit(info.fapu)  # the FAPU: the distance / 1024
    except (ValueError, mpeg4face.Error) as error:
        return str(error)
    if unit == 0.0:
        return f"the head's {info.fapu}0 is not measured: {', '.join(fapu.missing())} missing"
    wanted = amplitude * unit
    bones = [rig.pose.bones[name] for name in channel.bones]
    for bone in bones:
        if channel.channel == "location" and bone.bone.use_connect:
            return (f"bone {bone.name} is connected to its parent, so it cannot move: map "
                    "a free bone (a control) or a rotation")
    local = [_local_direction(head, rig, bone, direction) for bone in bones]
    bone = bones[0]

    def measure(value: float) -> np.ndarray:
        for each, direction_there in zip(bones, local):
            _set(each, channel, direction_there, value)
        bpy.context.view_layer.update()
        coords = poses.evaluated_coords(head, depsgraph)
        return feature_points.to_standard_axes(coords[vertex])[0] - neutral[vertex]

    if channel.channel == "rotation":  # an arc of `wanted` at the point's distance
        pivot = rig.matrix_world @ bone.bone.head_local
        point = head.matrix_world @ Vector(feature_points.to_blender_axes(neutral[vertex])[0])
        first = channel.sign * wanted / max((point - pivot).length, 1e-9)
    else:
        first = channel.sign * wanted
    return rig_logic.fit_pose(fap, measure, direction, wanted, first, tolerance)


def _key_poses(head, rig, fits, used, amplitude, scene) -> None:
    """Keys the rest pose at the neutral marker and each fit at its own new marker."""
    markers = scene.timeline_markers
    names = [shape_keys.key_name("FAP", fit.fap, amplitude) for fit, _ in fits]
    for marker in [m for m in markers if m.name in names]:
        markers.remove(marker)
    neutral = next((m for m in markers if m.name.lower() == poses.NEUTRAL_MARKER), None)
    if neutral is None:
        neutral = markers.new(poses.NEUTRAL_MARKER, frame=scene.frame_start)
    frame = max(m.frame for m in markers) + 1
    bones = rig.pose.bones
    plan = [(neutral.frame, None)] + [(frame + i, f) for i, f in enumerate(fits)]
    for at, fitted in plan:
        for name in used:
            _set(bones[name], rig_logic.BoneChannel(name), Vector(), 0.0)
        if fitted is not None:
            fit, channel = fitted
            for name in channel.bones:
                direction = _local_direction(head, rig, bones[name],
                                             rig_logic.fap_direction(fit.fap)) \
                    if channel.channel == "location" else Vector()
                _set(bones[name], channel, direction, fit.value)
            markers.new(shape_keys.key_name("FAP", fit.fap, amplitude), frame=at)
        for name in used:
            bones[name].keyframe_insert("location", frame=at)
            bones[name].keyframe_insert("rotation_euler", frame=at)


class MPEG4FACE_OT_pose_faps_bones(bpy.types.Operator):
    """Pose the head's armature for each FAP of a FAP -> bone mapping (Rigify's face rig by
    default) at markers named in the grammar, each feature point within the tolerance of its
    amplitude; the report names the FAPs not posed"""

    bl_idname = "mpeg4face.pose_faps_bones"
    bl_label = "Pose FAPs with Bones"
    bl_options = {"REGISTER", "UNDO"}

    mapping_file: StringProperty(
        name="Mapping", subtype="FILE_PATH",
        description="A JSON table of FAP -> bone, channel, axis (docs/blender.md, \"Rigged "
        "heads\"); empty: Rigify's face rig")
    amplitude: IntProperty(
        name="Amplitude", description="The FAP value each pose shows, in FAPU units "
        "(1024 = one FAPU distance)", default=256, min=1, max=4096)
    tolerance: FloatProperty(
        name="Tolerance", description="How near the amplitude a feature point must land",
        default=0.05, min=0.001, max=0.5, subtype="FACTOR")

    def execute(self, context: bpy.types.Context) -> set[str]:
        head = active_mesh(self, context)
        if head is None or not operators_faces.has_feature_points(self, head):
            return {"CANCELLED"}
        if head.mode != "OBJECT":
            self.report({"ERROR"}, "Switch to Object Mode to pose the rig")
            return {"CANCELLED"}
        rig = rig_of(head)
        if rig is None:
            self.report({"ERROR"}, f"{head.name} has no Armature modifier with an armature: "
                        "bind the head to its rig first")
            return {"CANCELLED"}
        try:
            mapping = rig_logic.RIGIFY_MAPPING
            if self.mapping_file:
                path = bpy.path.abspath(self.mapping_file)
                with open(path, encoding="utf-8") as f:
                    mapping = rig_logic.mapping_from_json(f.read(), path)
            report = operators_faces.with_progress(context, 1, lambda update: key_fap_poses(
                head, rig, mapping, self.amplitude, context.scene, self.tolerance, update))
        except (OSError, ValueError) as error:  # mpeg4face.Error is a ValueError
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        pose_reports[head.name] = report
        if not report.posed:
            self.report({"ERROR"}, "; ".join(report.lines()))
            return {"CANCELLED"}
        for line in report.lines()[1:]:
            self.report({"WARNING"} if line.startswith("not posed") else {"INFO"}, line)
        self.report({"INFO"}, report.lines()[0])
        return {"FINISHED"}


class MPEG4FACE_PT_rig(_Sidebar, bpy.types.Panel):
    bl_label = "Rigged Head"
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        return context.active_object is not None and context.active_object.type == "MESH"

    def draw(self, context: bpy.types.Context) -> None:
        head = context.active_object
        rig = rig_of(head)
        layout = self.layout
        layout.label(text=f"Rig: {rig.name}" if rig else "No armature bound",
                     icon="ARMATURE_DATA")
        layout.operator(MPEG4FACE_OT_pose_faps_bones.bl_idname, icon="POSE_HLT")
        report = pose_reports.get(head.name)
        if report is not None:
            for line in report.lines()[:1] + [l for l in report.lines() if
                                              l.startswith("not posed")]:
                layout.label(text=line)


register, unregister = bpy.utils.register_classes_factory(
    (MPEG4FACE_OT_pose_faps_bones, MPEG4FACE_PT_rig))
