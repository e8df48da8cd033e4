# SPDX-License-Identifier: GPL-3.0-or-later
"""File > Import > FAP stream (.fap, .fba): a stream onto the active head mesh, baked into
shape-key animation or played live through the face's tables."""

import bpy
from bpy.props import EnumProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

from . import operators_stream, stream_logic


class MPEG4FACE_OT_import_fap_stream(bpy.types.Operator, ImportHelper):
    """Import an MPEG-4 FAP stream (.fap text or .fba bitstream) onto the active mesh, whose
    shape keys are named fap<N>[_<label>]@<value>, viseme<N>, expression<N>[@<intensity>]"""

    bl_idname = "mpeg4face.import_fap_stream"
    bl_label = "Import FAP Stream"
    bl_options = {"REGISTER", "UNDO"}

    filter_glob: StringProperty(default="*.fap;*.fba", options={"HIDDEN"})
    frame_rate: EnumProperty(
        name="Frame rate",
        items=(
            ("STREAM", "Stream's", "Set the scene's frame rate to the stream's"),
            ("SCENE", "Scene's", "Keep the scene's frame rate and resample the stream"),
        ),
        default="STREAM",
    )
    resample: EnumProperty(name="Resample", items=operators_stream.RESAMPLE_ITEMS,
                           default="HOLD")
    start_frame: IntProperty(name="Start frame", default=1)
    fit_path: StringProperty(
        name="FIT", subtype="FILE_PATH",
        description="A FAP Interpolation Table (.json) that fills in unsent FAPs before "
        "baking; empty for none")
    preview: EnumProperty(
        name="Preview",
        items=(
            ("BAKE", "Bake", "Shape-key animation: each key's value from its FAP (approximate "
             "where low-level FAPs override visemes / expressions)"),
            ("LIVE", "Live", "The core evaluates the face's tables on every frame change: the "
             "exact MPEG-4 result, while the add-on runs"),
        ),
        default="BAKE",
    )

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        layout.prop(self, "frame_rate")
        row = layout.row()
        row.enabled = self.frame_rate == "SCENE"
        row.prop(self, "resample")
        layout.prop(self, "start_frame")
        layout.prop(self, "fit_path")
        layout.prop(self, "preview", expand=True)

    def execute(self, context: bpy.types.Context) -> set[str]:
        found = operators_stream.stream_mesh(self, context)
        if found is None:
            return {"CANCELLED"}
        obj, keys = found
        stream = operators_stream.read_stream(self, self.filepath, self.fit_path)
        if stream is None:
            return {"CANCELLED"}
        scene = context.scene
        if self.frame_rate == "STREAM":
            operators_stream.set_scene_rate(scene, stream.frame_rate)
        operators_stream.stop_live(obj)
        if self.preview == "LIVE":
            result = operators_stream.run_live(self, context, obj, keys, stream, self.start_frame)
        else:
            operators_stream.bake_stream(self, context, obj, keys, stream, self.start_frame,
                                         self.resample)
            result = {"FINISHED"}
        if result == {"FINISHED"}:
            frames = stream_logic.scene_frame_count(stream.duration,
                                                    operators_stream.scene_rate(scene))
            operators_stream.remember_stream(obj, self.filepath, self.fit_path,
                                             self.start_frame, frames)
        return result


def menu_entry(menu: bpy.types.Menu, context: bpy.types.Context) -> None:
    menu.layout.operator(MPEG4FACE_OT_import_fap_stream.bl_idname, text="FAP stream (.fap, .fba)")


def register() -> None:
    bpy.utils.register_class(MPEG4FACE_OT_import_fap_stream)
    bpy.types.TOPBAR_MT_file_import.append(menu_entry)


def unregister() -> None:
    bpy.types.TOPBAR_MT_file_import.remove(menu_entry)
    bpy.utils.unregister_class(MPEG4FACE_OT_import_fap_stream)
