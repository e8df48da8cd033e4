# SPDX-License-Identifier: GPL-3.0-or-later
"""File > Import > FAP stream (.fap, .fba; or one dropped on the 3D viewport,
ui/file_handlers.py) and Live Link Face capture (.csv): a stream, or a capture converted to
one by the core, onto the active head mesh, baked into shape-key animation or played live
through the face's tables."""

import bpy
from bpy.props import EnumProperty, FloatProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

import mpeg4face

from ...logic import arkit as arkit_logic
from ...logic import shape_keys
from ...logic import stream as stream_logic
from ...scene import live_preview, mesh_data, stream_data
from . import faces as operators_faces
from . import live as operators_live
from . import stream as operators_stream
from .bake import bake_stream


class _StreamImport(ImportHelper):
    """What the imports share: the options saying how a stream shows on the active head
    (frame rate, resampling, start frame, bake or live) and the showing."""

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

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        # A file dropped on the viewport (ui/file_handlers.py) comes with its path set by
        # the caller (a path remembered from the last import does not count): the options
        # in a dialog instead of the file browser, as Blender's own importers do.
        if self.properties.is_property_set("filepath", ghost=False):
            return context.window_manager.invoke_props_dialog(self)
        return super().invoke(context, event)

    def draw_frames(self, layout: bpy.types.UILayout, resampled: bool = True) -> None:
        # Each label above its widget: beside it, the file browser's narrow side panel
        # cuts the label ("Frame r...").
        layout.label(text="Frame rate")
        layout.prop(self, "frame_rate", text="")
        if resampled:
            col = layout.column()
            col.enabled = self.frame_rate == "SCENE"
            col.label(text="Resample")
            col.prop(self, "resample", text="")
        layout.prop(self, "start_frame")

    def draw_preview(self, layout: bpy.types.UILayout) -> None:
        layout.label(text="Preview")
        layout.row().prop(self, "preview", expand=True)

    def show(self, context: bpy.types.Context, obj: bpy.types.Object,
             keys: stream_logic.FaceKeys, stream: mpeg4face.FapStream, path: str,
             fit_path: str = "") -> set[str]:
        """Bakes the stream onto the head or plays it live, from the start frame, at the
        stream's or the scene's rate; the object remembers `path` (a .fap or .fba) for the
        live preview and the encoder. On failure the scene's frame rate is as it was."""
        scene = context.scene
        if self.preview != "LIVE" and not keys.keys:
            self.report({"ERROR"}, f"{obj.name} has no shape keys named in the grammar to "
                        "bake onto, only pose markers (a rig's): choose Live preview")
            return {"CANCELLED"}
        rate = scene.render.fps, scene.render.fps_base
        if self.frame_rate == "STREAM":
            stream_data.set_scene_rate(scene, stream.frame_rate)
        live_preview.stop_live(obj)
        if self.preview == "LIVE":
            result = operators_live.run_live(self, context, obj, keys, stream, self.start_frame)
        else:
            bake_stream(self, context, obj, keys, stream, self.start_frame, self.resample)
            result = {"FINISHED"}
        if result != {"FINISHED"}:
            scene.render.fps, scene.render.fps_base = rate
            return result
        frames = stream_logic.scene_frame_count(stream.duration, stream_data.scene_rate(scene))
        stream_data.remember_stream(obj, path, fit_path, self.start_frame, frames)
        return result


class MPEG4FACE_OT_import_fap_stream(_StreamImport, bpy.types.Operator):
    """Import an MPEG-4 FAP stream (.fap text or .fba bitstream) onto the active mesh, whose
    shape keys are named fap<N>[_<label>]@<value>, viseme<N>, expression<N>[@<intensity>]"""

    bl_idname = "mpeg4face.import_fap_stream"
    bl_label = "Import FAP Stream"
    bl_options = {"REGISTER", "UNDO", "PRESET"}

    filter_glob: StringProperty(default="*.fap;*.fba", options={"HIDDEN"})
    fit_path: StringProperty(
        name="FIT", subtype="FILE_PATH",
        description="A FAP Interpolation Table (.json) that fills in unsent FAPs before "
        "baking; empty for none")

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        self.draw_frames(layout)
        layout.prop(self, "fit_path")
        self.draw_preview(layout)

    def execute(self, context: bpy.types.Context) -> set[str]:
        found = operators_stream.stream_mesh(self, context, poses_enough=True)
        if found is None:
            return {"CANCELLED"}
        obj, keys = found
        stream = operators_stream.read_stream(self, self.filepath, self.fit_path)
        if stream is None:
            return {"CANCELLED"}
        return self.show(context, obj, keys, stream, self.filepath, self.fit_path)


class MPEG4FACE_OT_import_livelink_capture(_StreamImport, bpy.types.Operator):
    """Import a Live Link Face capture (.csv of ARKit weights) onto the active mesh as a FAP
    stream: the weights converted to FAPs through an ARKit face (the head itself when it has
    ARKit shape keys, else the ARKit face file), then baked or played like a .fap"""

    bl_idname = "mpeg4face.import_livelink_capture"
    bl_label = "Import Live Link Face Capture"
    bl_options = {"REGISTER", "UNDO", "PRESET"}

    filter_glob: StringProperty(default="*.csv", options={"HIDDEN"})
    face_path: StringProperty(
        name="ARKit face", subtype="FILE_PATH",
        description="A head with ARKit blendshapes as morph targets and MPEG-4 feature points "
        "(.glb, e.g. samples/build/ict_head.glb) that converts the weights when the active "
        "head has no ARKit shape keys")
    fps: FloatProperty(
        name="FAP rate", default=25.0, min=1.0, max=240.0,
        description="The FAP stream's frame rate when the scene takes the stream's (with "
        "Scene's the capture is converted at the scene's rate)")
    folder: StringProperty(
        name="Stream folder", subtype="DIR_PATH", default="//captures",
        description="Where the converted stream (.fap) goes, for the live preview and the "
        "encoder (// is the .blend's folder; a temporary folder while the file is unsaved)")

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        layout.prop(self, "face_path")
        self.draw_frames(layout, resampled=False)  # converted at the rate shown
        row = layout.row()
        row.enabled = self.frame_rate == "STREAM"
        row.prop(self, "fps")
        self.draw_preview(layout)
        layout.prop(self, "folder")

    def arkit_face(self, obj: bpy.types.Object) -> mpeg4face.FaceModel:
        """The face whose ARKit shapes convert the weights: the head itself (its ARKit and
        grammar keys, which give the best fit) when it has ARKit shape keys, else the face
        file; ValueError when neither."""
        names = operators_faces.key_names(obj)
        arkit = arkit_logic.arkit_key_names(names)
        if arkit:
            grammar = [n for n in names if shape_keys.is_grammar_name(n)]
            return mesh_data.read_face_model(obj, arkit + grammar)[0]
        if not self.face_path:
            raise ValueError(
                f"{obj.name} has no ARKit shape keys (eyeBlinkLeft, jawOpen, ...): give an "
                "ARKit face (.glb with ARKit morph targets and feature points, e.g. "
                "samples/build/ict_head.glb) to convert the capture's weights")
        return mpeg4face.read_gltf(bpy.path.abspath(self.face_path))

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = context.active_object
        if obj is not None and obj.type == "MESH" and not stream_data.grammar_keys(
                obj).keys and arkit_logic.arkit_key_names(operators_faces.key_names(obj)):
            self.report({"ERROR"}, f"{obj.name} has ARKit shape keys but no FAP keys to show "
                        "the stream with: run FAP Keys from ARKit Keys first")
            return {"CANCELLED"}
        found = operators_stream.stream_mesh(self, context)
        if found is None:
            return {"CANCELLED"}
        obj, keys = found
        scene = context.scene
        fps = self.fps if self.frame_rate == "STREAM" else stream_data.scene_rate(scene)
        # Everything that can fail comes before any change of the scene.
        try:
            capture = mpeg4face.read_livelink_csv(bpy.path.abspath(self.filepath))
            stream = mpeg4face.arkit_capture_to_faps(capture, self.arkit_face(obj), fps)
            folder = stream_data.output_folder(self.folder, "mpeg4face-captures")
            folder.mkdir(parents=True, exist_ok=True)
            path = arkit_logic.capture_stream_path(folder, obj.name, self.filepath)
            mpeg4face.write_fap(stream, str(path))
        except operators_stream.INPUT_ERRORS as error:
            self.report({"ERROR"}, f"Cannot convert the capture: {error}")
            return {"CANCELLED"}
        for warning in capture.warnings:
            self.report({"WARNING"}, warning)
        self.report({"INFO"}, f"{len(capture)} capture frames at {capture.frame_rate:g} fps "
                    f"-> {len(stream)} FAP frames at {fps:g} fps in {path}")
        return self.show(context, obj, keys, stream, str(path))


def stream_import_menu(menu: bpy.types.Menu, context: bpy.types.Context) -> None:
    menu.layout.operator(MPEG4FACE_OT_import_fap_stream.bl_idname, text="FAP stream (.fap, .fba)")
    menu.layout.operator(MPEG4FACE_OT_import_livelink_capture.bl_idname,
                         text="Live Link Face capture (.csv)")


_classes = (MPEG4FACE_OT_import_fap_stream, MPEG4FACE_OT_import_livelink_capture)


def register() -> None:
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.TOPBAR_MT_file_import.append(stream_import_menu)


def unregister() -> None:
    bpy.types.TOPBAR_MT_file_import.remove(stream_import_menu)
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
