# SPDX-License-Identifier: GPL-3.0-or-later
"""The "FAP Stream" panel of the sidebar tab "MPEG-4": the stream on the active mesh, the
import, live preview, encoding and speech buttons, and the last encoding's numbers."""

from pathlib import Path

import bpy

from . import operators_stream, panels, stream_logic


class MPEG4FACE_PT_fap_stream(panels._Sidebar, bpy.types.Panel):
    bl_label = "FAP Stream"

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        obj = context.active_object
        if obj is None or obj.type != "MESH":
            layout.label(text="Make the head mesh the active object", icon="INFO")
            return
        count = len(operators_stream.grammar_keys(obj).keys)
        layout.label(text=f"{count} shape keys named for FAPs",
                     icon="CHECKMARK" if count else "ERROR")
        col = layout.column(align=True)
        col.operator("mpeg4face.import_fap_stream", text="Import FAP Stream...", icon="IMPORT")
        col.operator("mpeg4face.import_livelink_capture", text="Import Capture (.csv)...",
                     icon="IMPORT")
        col.operator("mpeg4face.speak_text", icon="SPEAKER")

        state = obj.mpeg4face_stream
        if not state.filepath:
            return
        box = layout.box()
        box.label(text=Path(bpy.path.abspath(state.filepath)).name, icon="FILE")
        box.label(text=f"{state.frames} frames from frame {state.start_frame}")
        if state.fit_path:
            box.label(text=f"FIT: {Path(bpy.path.abspath(state.fit_path)).name}")
        if operators_stream.is_live(obj):
            op = box.operator("mpeg4face.live_preview", text="Stop Live Preview", icon="PAUSE")
            op.action = "STOP"
        else:
            op = box.operator("mpeg4face.live_preview", text="Start Live Preview", icon="PLAY")
            op.action = "START"
        box.operator("mpeg4face.encode_fap_stream", text="Encode FAP Stream...", icon="EXPORT")
        if state.encoded_path:
            box.label(text=f"{state.encoded_mode}: {Path(state.encoded_path).name}")
            box.label(text=stream_logic.encoding_summary(state.bits, state.bits_per_second,
                                                         state.psnr))


def register() -> None:
    bpy.utils.register_class(MPEG4FACE_PT_fap_stream)


def unregister() -> None:
    bpy.utils.unregister_class(MPEG4FACE_PT_fap_stream)
