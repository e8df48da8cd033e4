# SPDX-License-Identifier: GPL-3.0-or-later
"""Speaking text onto the face with flite: the visemes (and the bookmarks' FAPs) baked as
shape-key animation, the audio a sound strip in sync."""

import hashlib
from pathlib import Path

import bpy
from bpy.props import EnumProperty, IntProperty, StringProperty

import mpeg4face

from ...scene import compat, live_preview, stream_data
from . import stream as operators_stream
from .bake import bake_stream

SPEECH_STRIP = "MPEG-4 speech"
VOICES = tuple((v, v, f"flite's voice {v}") for v in ("kal", "slt", "awb", "rms", "kal16"))
DEFAULT_SPEECH_FOLDER = "//speech"


def add_sound_strip(scene: bpy.types.Scene, obj: bpy.types.Object, wav: Path, start: int
                    ) -> compat.Strip:
    """The speech as a sound strip from `start` (replacing the object's earlier one), in
    its own channel above the others."""
    editor = scene.sequence_editor or scene.sequence_editor_create()
    strips = compat.strips(editor)
    name = f"{SPEECH_STRIP} {obj.name}"
    for strip in [s for s in strips if s.name.startswith(name)]:
        strips.remove(strip)
    channel = max((s.channel for s in strips), default=0) + 1
    return strips.new_sound(name, str(wav), channel, start)


class MPEG4FACE_OT_speak_text(bpy.types.Operator):
    """Speak a text with flite onto the face: the visemes (and the bookmarks' FAPs) become
    shape-key animation, the audio a sound strip in sync"""

    bl_idname = "mpeg4face.speak_text"
    bl_label = "Speak Text onto Face"
    bl_options = {"REGISTER", "UNDO"}

    text: StringProperty(
        name="Text", default="Hello world",
        description="What to say; bookmarks add expressions and FAPs, e.g. "
        "\"Hello <FAP 2 1 40 0 0 800 3> world\" smiles (joy at 40) from \"world\" "
        "(docs/speech.md)")
    voice: EnumProperty(name="Voice", items=VOICES, default="kal")
    folder: StringProperty(
        name="Audio folder", subtype="DIR_PATH", default=DEFAULT_SPEECH_FOLDER,
        description="Where the .wav and .fap go (// is the .blend's folder; a temporary "
        "folder while the file is unsaved)")
    start_frame: IntProperty(name="Start frame", default=1)

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        return context.window_manager.invoke_props_dialog(self, width=480)

    def execute(self, context: bpy.types.Context) -> set[str]:
        found = operators_stream.stream_mesh(self, context)
        if found is None:
            return {"CANCELLED"}
        obj, keys = found
        if not self.text.strip():
            self.report({"ERROR"}, "Nothing to say: the text is empty")
            return {"CANCELLED"}
        scene = context.scene
        fps = stream_data.scene_rate(scene)
        folder = stream_data.output_folder(self.folder, "mpeg4face-speech")
        # Named by what is said, so the same text, voice and rate reuse one file name.
        digest = hashlib.sha1(f"{self.text}|{self.voice}|{fps}".encode()).hexdigest()[:10]
        base = folder / f"{bpy.path.clean_name(obj.name)}-{digest}"
        wav, fap = base.with_suffix(".wav"), base.with_suffix(".fap")
        try:
            folder.mkdir(parents=True, exist_ok=True)
            stream = mpeg4face.speak(self.text, str(wav), fps, self.voice)
            mpeg4face.write_fap(stream, str(fap))
        except operators_stream.INPUT_ERRORS as error:  # flite missing or failing, a bad bookmark
            self.report({"ERROR"}, f"Cannot speak: {error}")
            return {"CANCELLED"}
        live_preview.stop_live(obj)
        result = bake_stream(self, context, obj, keys, stream, self.start_frame, "HOLD")
        stream_data.remember_stream(obj, str(fap), "", self.start_frame, result.frames)
        strip = add_sound_strip(scene, obj, wav, self.start_frame)
        scene.frame_end = max(scene.frame_end, strip.frame_final_end - 1)
        scene.sync_mode = "AUDIO_SYNC"  # drop frames rather than drift from the audio
        self.report({"INFO"}, f"Spoke into {wav}")
        return {"FINISHED"}


register, unregister = bpy.utils.register_classes_factory((MPEG4FACE_OT_speak_text,))
