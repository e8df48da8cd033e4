# SPDX-License-Identifier: GPL-3.0-or-later
"""The motion check on the active face (docs/motion-check.md): an operator that checks its
shape keys named in the grammar (and optionally the stream imported onto it) with
mpeg4face.check_motion, one that selects a pose's offending vertices in Edit Mode, and the
"Motion Check" panel listing the worst keys and frames. The last result of each object is
kept for the session (not saved with the .blend)."""

from pathlib import Path
from typing import Any

import bpy
from bpy.props import BoolProperty, EnumProperty, IntProperty

import mpeg4face

from ...logic import check as check_logic
from ...scene import mesh_data
from .. import text as ui_text
from ..panels.feature_points import _Sidebar
from . import stream as operators_stream

results: dict[str, dict[str, Any]] = {}  # object name -> check_motion's result


class MPEG4FACE_OT_check_motion(bpy.types.Operator):
    """Check every shape key named for MPEG-4 (and the imported stream) for stretched edges,
    flipped triangles, spikes, new self-intersections and lip corners"""

    bl_idname = "mpeg4face.check_motion"
    bl_label = "Check Motion"
    bl_options = {"REGISTER", "UNDO"}

    with_stream: BoolProperty(name="With the stream", default=False,
                              description="Also every frame of the stream imported onto the face")

    def execute(self, context: bpy.types.Context) -> set[str]:
        found = operators_stream.stream_mesh(self, context)
        if found is None:
            return {"CANCELLED"}
        obj, keys = found
        streams = []
        state = obj.mpeg4face_stream
        if self.with_stream:
            if not state.filepath:
                self.report({"ERROR"}, "No stream imported onto this face")
                return {"CANCELLED"}
            stream = operators_stream.read_stream(self, state.filepath, state.fit_path)
            if stream is None:
                return {"CANCELLED"}
            stream.name = Path(bpy.path.abspath(state.filepath)).name
            streams.append(stream)
        model, warnings = mesh_data.read_face_model(obj, [k.name for k in keys.keys])
        for warning in warnings:
            self.report({"WARNING"}, warning)
        wm = context.window_manager
        wm.progress_begin(0, 1)
        try:
            result = mpeg4face.check_motion(
                model, streams, progress=lambda done, total: wm.progress_update(done / total))
        except operators_stream.INPUT_ERRORS as error:
            self.report({"ERROR"}, f"Cannot check {obj.name}: {error}")
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        results[obj.name] = result
        text = check_logic.headline(result)
        spikes = check_logic.spikes(result)
        if spikes:
            text += f". {spikes}"
        self.report({"INFO"} if result["passed"] else {"WARNING"}, text)
        return {"FINISHED"}


class MPEG4FACE_OT_select_offending(bpy.types.Operator):
    """Select in Edit Mode the vertices this key or frame stretches, flips, makes intersect or
    moves as spikes"""

    bl_idname = "mpeg4face.select_offending"
    bl_label = "Select Offending Vertices"
    bl_options = {"REGISTER", "UNDO"}

    kind: EnumProperty(items=(("keys", "Key", ""), ("frames", "Frame", "")))
    index: IntProperty(min=0)

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = context.active_object
        result = results.get(obj.name) if obj is not None else None
        if result is None:
            self.report({"ERROR"}, "Run Check Motion on the active face first")
            return {"CANCELLED"}
        vertices = check_logic.offending_vertices(result, self.kind, self.index)
        if not vertices:
            self.report({"WARNING"}, "No offending vertices for this pose")
            return {"CANCELLED"}
        if obj.mode != "EDIT":
            bpy.ops.object.mode_set(mode="EDIT")
        context.tool_settings.mesh_select_mode = (True, False, False)
        with mesh_data.face_bmesh(obj, write=True) as bm:
            for v in bm.verts:
                v.select_set(False)
            for i in vertices:
                if i < len(bm.verts):
                    bm.verts[i].select_set(True)
            bm.select_flush_mode()
        pose = result[self.kind][self.index]["name"]
        spikes = len(check_logic.spike_vertices(result, self.kind, self.index))
        also = f" ({spikes} {'spike' if spikes == 1 else 'spikes'})" if spikes else ""
        self.report({"INFO"}, f"{len(vertices)} vertices selected{also}: {pose}")
        return {"FINISHED"}


class MPEG4FACE_PT_motion_check(_Sidebar, bpy.types.Panel):
    bl_label = "Motion Check"
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        return context.active_object is not None and context.active_object.type == "MESH"

    def draw(self, context: bpy.types.Context) -> None:
        obj = context.active_object
        layout = self.layout
        row = layout.row(align=True)
        row.operator("mpeg4face.check_motion", text="Check Keys", icon="VIEWZOOM")
        if obj.mpeg4face_stream.filepath:
            row.operator("mpeg4face.check_motion", text="Keys + Stream").with_stream = True
        result = results.get(obj.name)
        if result is None:
            return
        ui_text.label(layout, context, check_logic.headline(result),
                      "CHECKMARK" if result["passed"] else "ERROR")
        for failure in result["failures"]:
            ui_text.label(layout, context, failure, "ERROR")
        spikes = check_logic.spikes(result)
        if spikes:
            ui_text.label(layout, context, spikes, "ERROR")
        for kind, title in (("keys", "Worst keys"), ("frames", "Worst frames")):
            rows = check_logic.worst(result, kind)
            if not rows:
                continue
            box = layout.box()
            box.label(text=title)
            for r in rows:  # name and figures wrapped to the width, then the button
                line = box.split(factor=0.85)
                ui_text.label(line, context, r.name, boxes=1, factor=0.85)
                op = line.operator("mpeg4face.select_offending", text="",
                                   icon="RESTRICT_SELECT_OFF")
                op.kind, op.index = r.kind, r.index
                ui_text.label(box, context, f"    {r.text}", boxes=1)


CLASSES = (MPEG4FACE_OT_check_motion, MPEG4FACE_OT_select_offending, MPEG4FACE_PT_motion_check)


def register() -> None:
    for cls in CLASSES:
        bpy.utils.register_class(cls)


def unregister() -> None:
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
    results.clear()
