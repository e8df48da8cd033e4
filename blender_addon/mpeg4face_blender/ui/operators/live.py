# SPDX-License-Identifier: GPL-3.0-or-later
"""The Live Preview operator: starts or stops the live preview (scene/live_preview.py) of
the stream imported on the active head."""

import bpy
from bpy.props import EnumProperty

import mpeg4face

from ...logic import stream as stream_logic
from ...scene import live_preview
from ...scene.stream_data import scene_rate
from . import stream as operators_stream
from .feature_points import active_mesh


class MPEG4FACE_OT_live_preview(bpy.types.Operator):
    """Start or stop the live preview of the object's stream: on every frame change the core
    evaluates the face's tables (built from the shape keys, the parts and the poses) for the
    stream, exactly"""

    bl_idname = "mpeg4face.live_preview"
    bl_label = "Live Preview"
    bl_options = {"REGISTER", "UNDO"}

    action: EnumProperty(items=(("START", "Start", ""), ("STOP", "Stop", "")), default="START")

    def execute(self, context: bpy.types.Context) -> set[str]:
        if self.action == "STOP":
            obj = active_mesh(self, context)
            if obj is None:
                return {"CANCELLED"}
            live_preview.stop_live(obj)
            self.report({"INFO"}, f"Live preview of {obj.name} stopped")
            return {"FINISHED"}
        found = operators_stream.stream_mesh(self, context, poses_enough=True)
        if found is None:
            return {"CANCELLED"}
        obj, keys = found
        state = obj.mpeg4face_stream
        if not state.filepath:
            self.report({"ERROR"}, f"No stream on {obj.name}: import one first")
            return {"CANCELLED"}
        stream = operators_stream.read_stream(self, state.filepath, state.fit_path)
        if stream is None:
            return {"CANCELLED"}
        return run_live(self, context, obj, keys, stream, state.start_frame)


def run_live(op: bpy.types.Operator, context: bpy.types.Context, obj: bpy.types.Object,
             keys: stream_logic.FaceKeys, stream: mpeg4face.FapStream, start: int) -> set[str]:
    """Starts the live preview and sets the scene's frame range; reports."""
    try:
        warnings = live_preview.start_live(obj, context.scene, keys, stream, start)
    except operators_stream.INPUT_ERRORS as error:
        op.report({"ERROR"}, f"Cannot build the face's tables from the shape keys: {error}")
        return {"CANCELLED"}
    for warning in warnings:
        op.report({"WARNING"}, warning)
    scene = context.scene
    frames = stream_logic.scene_frame_count(stream.duration, scene_rate(scene))
    scene.frame_start, scene.frame_end = start, start + frames - 1
    op.report({"INFO"}, f"Live preview of {obj.name}: {frames} frames from frame {start}")
    return {"FINISHED"}


register, unregister = bpy.utils.register_classes_factory((MPEG4FACE_OT_live_preview,))
