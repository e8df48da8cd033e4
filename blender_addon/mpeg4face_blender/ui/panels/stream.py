# SPDX-License-Identifier: GPL-3.0-or-later
"""The "FAP Stream" panel of the sidebar tab "MPEG-4": the stream on the active mesh, the
import, live preview, encoding and speech buttons, and the last encoding's numbers."""

from pathlib import Path

import bpy

from ...logic import stream as stream_logic
from ...scene import live_preview, stream_data
from .. import text as ui_text
from .feature_points import _Sidebar


class MPEG4FACE_PT_fap_stream(_Sidebar, bpy.types.Panel):
    bl_label = "FAP Stream"

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        obj = context.active_object
        if obj is None or obj.type != "MESH":
            ui_text.label(layout, context, "Make the head mesh the active object", "INFO")
            return
        count = len(stream_data.grammar_keys(obj).keys)
        ui_text.label(layout, context, f"{count} shape keys named for FAPs",
                      "CHECKMARK" if count else "ERROR")
        col = layout.column(align=True)
        col.operator("mpeg4face.import_fap_stream", text="Import FAP Stream...", icon="IMPORT")
        col.operator("mpeg4face.import_livelink_capture", text="Import Capture (.csv)...",
                     icon="IMPORT")
        col.operator("mpeg4face.speak_text", icon="SPEAKER")

        state = obj.mpeg4face_stream
        if not state.filepath:
            return
        box = layout.box()
        ui_text.label(box, context, Path(bpy.path.abspath(state.filepath)).name, "FILE", boxes=1)
        ui_text.label(box, context, f"{state.frames} frames from frame {state.start_frame}",
                      boxes=1)
        if state.fit_path:
            ui_text.label(box, context, f"FIT: {Path(bpy.path.abspath(state.fit_path)).name}",
                          boxes=1)
        if live_preview.is_live(obj):
            op = box.operator("mpeg4face.live_preview", text="Stop Live Preview", icon="PAUSE")
            op.action = "STOP"
        else:
            op = box.operator("mpeg4face.live_preview", text="Start Live Preview", icon="PLAY")
            op.action = "START"
        box.operator("mpeg4face.encode_fap_stream", text="Encode FAP Stream...", icon="EXPORT")
        if state.encoded_path:
            ui_text.label(box, context, f"{state.encoded_mode}: {Path(state.encoded_path).name}",
                          boxes=1)
            ui_text.label(box, context, stream_logic.encoding_summary(
                state.bits, state.bits_per_second, state.psnr), boxes=1)


def register() -> None:
    bpy.utils.register_class(MPEG4FACE_PT_fap_stream)


def unregister() -> None:
    bpy.utils.unregister_class(MPEG4FACE_PT_fap_stream)
