# SPDX-License-Identifier: GPL-3.0-or-later
"""FAP streams on a head mesh: baking a stream into shape-key animation, the live preview
(the tables of the whole face, head, parts and poses, evaluated by the core on each frame
change), encoding the imported stream, and speaking text onto the face. The import
operator (import_stream.py) and the speech operator bake through bake_stream(). Every
operator checks its input and reports problems in the UI instead of raising."""

import functools
import hashlib
import math
import tempfile
from dataclasses import dataclass
from pathlib import Path

import bpy
import numpy as np
from bpy.app.handlers import persistent
from bpy.props import EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty
from bpy_extras.io_utils import ExportHelper

import mpeg4face

from . import (bake_poses, compat, live_draw, live_logic, mesh_data, operators, poses,
               shape_keys, stream_logic, ui_text)

LIVE_KEY = "MPEG-4 live"  # the shape key the live preview writes; not in the grammar
# The reference key the preview adds to a part without shape keys (LIVE_KEY needs one);
# named so that stopping knows it can go, in a saved file or after Undo too.
LIVE_BASIS = "MPEG-4 live basis"
ACTION_GROUP = "MPEG-4 FAP stream"
SPEECH_STRIP = "MPEG-4 speech"
# What the core may raise for a bad file or face, shown as a report instead of a traceback.
INPUT_ERRORS = (mpeg4face.Error, OSError, ValueError, RuntimeError)
RESAMPLE_ITEMS = (
    ("HOLD", "Sample and hold", "Each scene frame shows the last stream frame at or before "
     "its time, as a decoder holds a FAP until it is sent again"),
    ("LINEAR", "Linear", "FAP values interpolated linearly between the stream frames around "
     "each scene frame's time (viseme and expression weights cross-fade)"),
)


class MPEG4FACE_PG_stream(bpy.types.PropertyGroup):
    """The stream last imported or spoken onto an object (saved with the .blend) and the
    last encoding of it."""

    filepath: StringProperty(name="Stream", subtype="FILE_PATH")
    fit_path: StringProperty(name="FIT", subtype="FILE_PATH")
    start_frame: IntProperty(name="Start frame", default=1)
    frames: IntProperty(name="Frames")
    encoded_path: StringProperty(name="Encoded", subtype="FILE_PATH")
    encoded_mode: StringProperty(name="Mode")
    bits: IntProperty(name="Bits")
    bits_per_second: FloatProperty(name="Bit rate")
    psnr: FloatProperty(name="PSNR", default=math.nan)  # inf: lossless, nan: none


def stream_mesh(op: bpy.types.Operator, context: bpy.types.Context, poses_enough: bool = False
                ) -> tuple[bpy.types.Object, stream_logic.FaceKeys] | None:
    """The active mesh and its shape keys named by the grammar; None (reported) when there
    is no such mesh or it has no such key (with poses_enough, pose markers will do: a
    rigged head's poses play in the live preview)."""
    obj = operators.active_mesh(op, context)
    if obj is None:
        return None
    if obj.mode != "OBJECT":
        op.report({"ERROR"}, "Switch to Object Mode (shape keys are read from the mesh)")
        return None
    keys = grammar_keys(obj)
    for problem in keys.malformed:
        op.report({"WARNING"}, f"Shape key {problem}")
    if not keys.keys and not (poses_enough and poses.pose_markers(context.scene, obj)):
        op.report({"ERROR"}, f"{obj.name} has no shape keys named fap<N>[_<label>]@<value>, "
                  "viseme<N> or expression<N>[@<intensity>] (see docs/fat.md)")
        return None
    return obj, keys


def grammar_keys(obj: bpy.types.Object) -> stream_logic.FaceKeys:
    """The object's shape keys named in the grammar (and the malformed ones)."""
    blocks = obj.data.shape_keys.key_blocks if obj.data.shape_keys else ()
    return stream_logic.face_keys(b.name for b in blocks)


def read_stream(op: bpy.types.Operator, path: str, fit_path: str = ""
                ) -> mpeg4face.FapStream | None:
    """The stream of a .fap / .fba file, through the FIT when one is given; None (reported)
    when a file is unreadable."""
    try:
        stream = mpeg4face.read_fap_stream(bpy.path.abspath(path))
        if fit_path:
            stream = mpeg4face.read_fit_json(bpy.path.abspath(fit_path)).interpolate(stream)
    except INPUT_ERRORS as error:
        op.report({"ERROR"}, f"Cannot read the stream: {error}")
        return None
    if len(stream) == 0:
        op.report({"ERROR"}, f"{path} holds no frames")
        return None
    return stream


def scene_rate(scene: bpy.types.Scene) -> float:
    return scene.render.fps / scene.render.fps_base


def set_scene_rate(scene: bpy.types.Scene, frame_rate: float) -> None:
    scene.render.fps, scene.render.fps_base = stream_logic.scene_fps(frame_rate)


_LINEAR = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["LINEAR"].value


def bake_stream(op: bpy.types.Operator, context: bpy.types.Context, obj: bpy.types.Object,
                keys: stream_logic.FaceKeys, stream: mpeg4face.FapStream, start: int,
                method: str) -> stream_logic.Bake:
    """Keys the shape keys of the head and its parts from `start` at the scene's frame
    rate (LINEAR keyframes, in an action on each mesh's Key datablock, replacing earlier
    curves of those keys), widens their sliders, keys the poses the stream drives
    (bake_poses: eyes, head, the jaw's parts as object keyframes), sets the scene's frame
    range and reports what was baked, and in a popup what could not be."""
    scene = context.scene
    fps = scene_rate(scene)
    result = stream_logic.bake(stream, keys, fps, method)
    clamped = _key_shape_keys(obj, result, start)
    missing = set(result.missing)
    baked = set(result.baked_faps)
    for part in poses.parts(obj):
        part_keys = grammar_keys(part)
        if part_keys.keys:
            part_result = stream_logic.bake(stream, part_keys, fps, method)
            clamped += _key_shape_keys(part, part_result, start)
            missing &= set(part_result.missing)
            baked |= set(part_result.baked_faps)

    def key_names(o: bpy.types.Object) -> list[str]:
        return [k.name for k in (keys if o == obj else grammar_keys(o)).keys]

    posed = bake_poses.bake(obj, scene, key_names, stream, start, result.frames, fps)
    baked |= set(posed.faps)
    missing -= {f"FAP {f} ({mpeg4face.fap(f).name})" for f in posed.faps}
    scene.frame_start = start
    scene.frame_end = start + result.frames - 1
    scene.frame_set(start)

    problems = list(posed.problems)
    if clamped:
        problems.append(f"Values beyond ±{stream_logic.SLIDER_LIMIT:g} are clamped on: "
                        + ", ".join(clamped))
    if missing:
        problems.append("In the stream without a shape key or pose marker (shown neither "
                        "baked nor live): " + ", ".join(sorted(missing, key=_fap_order)))
    if {stream_logic.VISEME_FAP, stream_logic.EXPRESSION_FAP} & baked and any(
            f >= 3 for f in baked):
        problems.append("The bake adds the keys of low-level FAPs to those of visemes and "
                        "expressions, where the standard lets the low-level FAPs override "
                        "them: Live shows the exact result")
    for problem in problems:
        op.report({"WARNING"}, problem)
    poses_text = f"; poses of {', '.join(posed.keyed)} keyed" if posed.keyed else ""
    summary = (f"Baked {len(baked)} FAPs ({', '.join(map(str, sorted(baked))) or 'none'}) "
               f"onto {obj.name}: {result.frames} frames from frame {start}{poses_text}")
    op.report({"INFO"}, summary)
    if problems:
        ui_text.popup(context, "Bake", [summary, *problems])
    result.baked_faps = sorted(baked)
    result.missing = sorted(missing, key=_fap_order)
    return result


def _fap_order(text: str) -> tuple[str, int]:
    kind, _, rest = text.partition(" ")
    number = rest.split(" ")[0]
    return kind, int(number) if number.isdigit() else 0


def _key_shape_keys(obj: bpy.types.Object, result: stream_logic.Bake, start: int) -> list[str]:
    """Writes a bake's curves into the object's shape keys; the keys whose values are
    clamped."""
    shape_keys = obj.data.shape_keys
    animation = shape_keys.animation_data or shape_keys.animation_data_create()
    if animation.action is None:
        animation.action = bpy.data.actions.new(f"{obj.name} {ACTION_GROUP}")
    frames = np.arange(result.frames, dtype=np.float64) + start
    clamped = []
    for name, values in result.curves.items():
        path = f'key_blocks["{bpy.utils.escape_identifier(name)}"].value'
        curve = compat.new_fcurve(animation, path, ACTION_GROUP)
        curve.keyframe_points.add(result.frames)
        curve.keyframe_points.foreach_set("co", np.column_stack((frames, values)).ravel())
        curve.keyframe_points.foreach_set("interpolation", [_LINEAR] * result.frames)
        curve.update()
        # Animated values clamp to the slider range too, so it must hold the baked values.
        block = shape_keys.key_blocks[name]
        low, high, beyond = stream_logic.widened_slider(
            (block.slider_min, block.slider_max), (float(values.min()), float(values.max())))
        block.slider_max, block.slider_min = high, low
        if beyond:
            clamped.append(f"{obj.name}: {name}" if obj.parent else name)
    return clamped


def remember_stream(obj: bpy.types.Object, path: str, fit_path: str, start: int, frames: int
                    ) -> None:
    state = obj.mpeg4face_stream
    state.filepath, state.fit_path = path, fit_path
    state.start_frame, state.frames = start, frames


# --- Live preview ------------------------------------------------------------------------


@dataclass
class LiveObject:
    """An object of a live face (object i of [head, *parts], mesh i of its model)."""

    name: str
    chain: tuple[int, ...]  # the Transforms from the head's down to the one holding its mesh
    unposed: np.ndarray  # (4, 4): the inverse of the chain's neutral matrix
    restore: tuple[bool, int]  # show_only_shape_key, active_shape_key_index
    pointer: int = 0  # as_pointer(): finds the object again after a rename
    drawn: live_draw.DrawMesh | None = None  # drawn with the gpu module (LiveState.draw)


@dataclass
class LiveState:
    """The live preview of one head: its face's tables and the stream, played from the
    scene frame `start` at the scene's frame rate (sample and hold), on its objects."""

    evaluator: mpeg4face.FatEvaluator
    stream: mpeg4face.FapStream
    start: int
    centers: list[np.ndarray]  # per Transform: the center the evaluation leaves as it is
    objects: list[LiveObject]
    neutral: list[np.ndarray]  # per object: the evaluator's neutral coordinates
    # Drawn with the gpu module (live_draw) instead of written into the live keys; the keys
    # are written for rendering only.
    draw: bool = False


_live: dict[str, LiveState] = {}  # head object name -> state


def is_live(obj: bpy.types.Object) -> bool:
    return obj.name in _live or (obj.data.shape_keys is not None
                                 and LIVE_KEY in obj.data.shape_keys.key_blocks)


def start_live(obj: bpy.types.Object, scene: bpy.types.Scene, keys: stream_logic.FaceKeys,
               stream: mpeg4face.FapStream, start: int, draw: bool | None = None) -> list[str]:
    """Builds the tables of the whole face for the FAPs the stream animates
    (generate_face on poses.face_model: the head's grammar keys `keys`, its parts' grammar
    keys and the pose markers, of those FAPs), then shows the stream through the core's
    evaluator: the exact MPEG-4 result, visemes and expressions
    with the standard's priorities included, eyes, jaw and head moved by their Transforms.

    Each object of the face gets a shape key LIVE_KEY shown alone (show_only_shape_key),
    so the Basis, the other keys and the objects' matrices (which the pose keyframes
    drive) are never changed. `draw` (default: unless Blender runs in the background) draws
    the face with the gpu module (live_draw), the objects hidden in the viewport, and
    writes the live keys only for rendering; else every frame is written into the live
    keys. Returns generate_face's warnings; raises mpeg4face.Error for a face it refuses,
    ValueError for objects sharing a mesh."""
    stop_live(obj)
    objects = [obj, *poses.parts(obj)]
    _refuse_shared_meshes(objects)

    def key_names(o: bpy.types.Object) -> list[str]:
        return [k.name for k in (keys if o == obj else grammar_keys(o)).keys]

    # Only the tables of the FAPs the stream animates: the others cannot move the face
    # while it plays, and reading their shape keys is most of the start's cost.
    faps = stream_logic.animated_faps(stream)

    def wanted(name: str) -> bool:
        parsed = shape_keys.parse(name)
        return parsed is None or parsed["fap"] in faps  # a malformed name: the core says why

    model, _ = poses.face_model(obj, key_names, scene, wanted=wanted)
    generated = mpeg4face.generate_face(model)
    neutral = [t.local_matrix() for t in model.transforms]
    draw = not bpy.app.background if draw is None else draw
    drawn = live_draw.add_face(obj.name, objects) if draw else [None] * len(objects)
    live_objects = []
    for index, o in enumerate(objects):
        # poses.face_model makes each part (Transform i, holding mesh i) a child of the
        # head's Transform 0.
        chain = (0,) if index == 0 else (0, index)
        live_objects.append(LiveObject(o.name, chain, np.linalg.inv(_product(neutral, chain)),
                                       (o.show_only_shape_key, o.active_shape_key_index),
                                       o.as_pointer(), drawn[index]))
        _add_live_key(o)
    evaluator = mpeg4face.FatEvaluator(generated["face"])
    state = LiveState(evaluator, stream, start, [t.center for t in model.transforms],
                      live_objects, list(evaluator.neutral()["coord"]), draw)
    _live[obj.name] = state
    for handlers, handler in _HANDLERS:
        if handler not in handlers():
            handlers().append(handler)
    _show(state, scene)
    return list(generated["warnings"])


def _refuse_shared_meshes(objects: list[bpy.types.Object]) -> None:
    # Shape keys belong to the mesh: two objects of one mesh would show one live key.
    owners: dict[int, str] = {}
    for o in objects:
        first = owners.setdefault(o.data.as_pointer(), o.name)
        if first != o.name:
            raise ValueError(f"{first} and {o.name} share the mesh {o.data.name}: the live "
                             "preview needs a mesh for each (Object > Relations > Make "
                             "Single User)")


def _product(matrices: list[np.ndarray], chain: tuple[int, ...]) -> np.ndarray:
    return functools.reduce(np.matmul, (matrices[i] for i in chain))


def _add_live_key(obj: bpy.types.Object) -> None:
    poses.suspend_rig(obj)  # the live key holds the rig's motion already
    if obj.data.shape_keys is None:  # a part without shape keys
        obj.shape_key_add(name=LIVE_BASIS, from_mix=False)
    obj.shape_key_add(name=LIVE_KEY, from_mix=False)
    obj.show_only_shape_key = True
    obj.active_shape_key_index = obj.data.shape_keys.key_blocks.find(LIVE_KEY)


def stop_live(obj: bpy.types.Object) -> None:
    """Ends the live preview of the head `obj`: the live keys of the face go (and the
    LIVE_BASIS when nothing else is left beside it), the Basis (and the baked keys, if any)
    show again, the objects show in the viewport again. Also cleans up live keys left in a
    saved file."""
    state = _live.pop(obj.name, None)
    live_draw.remove_face(obj.name)
    if state is None:
        objects = [(o, None) for o in (obj, *poses.parts(obj))]
    else:
        objects = [(bpy.data.objects.get(o.name), o.restore) for o in state.objects]
    for o, restore in objects:
        if o is not None and o.type == "MESH":
            live_draw.unhide(o)
            _remove_live_key(o, restore)
    _remove_handler_when_idle()


def _remove_live_key(obj: bpy.types.Object, restore: tuple[bool, int] | None) -> None:
    """Removes the object's live key (and the LIVE_BASIS when nothing else is left beside
    it) and shows its shape keys as `restore` says (as they were), or, without it, the
    Basis."""
    poses.resume_rig(obj)
    key = obj.data.shape_keys
    live = key.key_blocks.get(LIVE_KEY) if key else None
    if live is not None:
        obj.shape_key_remove(live)
        if len(key.key_blocks) == 1 and key.reference_key.name == LIVE_BASIS:
            obj.shape_key_clear()
    if restore is not None:
        obj.show_only_shape_key, obj.active_shape_key_index = restore
    elif live is not None:
        obj.show_only_shape_key, obj.active_shape_key_index = False, 0
    obj.data.update()


def _find(live: LiveObject, head: str, state: LiveState) -> bpy.types.Object | None:
    """The object of `live`, also after a rename (found by its pointer, which a rename
    keeps and Undo does not): the state follows the new name."""
    obj = bpy.data.objects.get(live.name)
    if obj is not None and obj.as_pointer() == live.pointer:
        return obj
    obj = next((o for o in bpy.data.objects if o.as_pointer() == live.pointer), None)
    if obj is None:
        return None
    live_draw.rename(live.name, obj.name)
    if live.name == head:
        _live[obj.name] = _live.pop(head)
    live.name = obj.name
    return obj


def _live_objects(head: str, state: LiveState) -> list[bpy.types.Object] | None:
    """The face's objects; None when one is gone or has lost its live key (by Undo, say)."""
    objects = [_find(o, head, state) for o in state.objects]
    for o in objects:
        key = o.data.shape_keys if o is not None and o.type == "MESH" else None
        if key is None or LIVE_KEY not in key.key_blocks:
            return None
    return objects


def _evaluated(state: LiveState, scene: bpy.types.Scene
               ) -> list[tuple[np.ndarray, np.ndarray]]:
    """The evaluation at the scene's frame: each object's coordinates (N, 3, standard
    axes) and the matrix (4, 4) that shows them in the object's own frame.

    An object's vertices are shown where the evaluated Transforms put them (L0 @ Li @
    coord), taken back through its neutral Transforms (inverse(N0 @ Ni)) into its own
    frame: the object stays where it is and the key carries the turn of an eye, the drop of
    the teeth with the jaw or a nod of the head."""
    seconds = (scene.frame_current - state.start) / scene_rate(scene)
    index = stream_logic.live_index(state.stream.frame_numbers, state.stream.frame_rate, seconds)
    result = state.evaluator.evaluate(state.stream, index)
    local = [mpeg4face.Transform(translation=t, rotation=r, scale=s, center=c).local_matrix()
             for t, r, s, c in zip(result["translation"], result["rotation"], result["scale"],
                                   state.centers)]
    return [(coords, live.unposed @ _product(local, live.chain))
            for live, coords in zip(state.objects, result["coord"])]


def _show(state: LiveState, scene: bpy.types.Scene, keys: bool = False) -> bool:
    """Shows the evaluation at the scene's frame: drawn (state.draw), or written into the
    live keys (without drawing, or when `keys`, for a render); False (and nothing shown)
    when _live_objects finds the face incomplete."""
    head = next(name for name, s in _live.items() if s is state)
    objects = _live_objects(head, state)
    if objects is None:
        return False
    for obj, live, (coords, matrix), neutral in zip(objects, state.objects,
                                                    _evaluated(state, scene), state.neutral):
        if live.drawn is not None:
            live.drawn.update(coords, matrix, rigid=np.array_equal(coords, neutral))
        if keys or not state.draw:
            mesh_data.set_shape_key_coords(obj.data.shape_keys.key_blocks[LIVE_KEY],
                                           live_logic.placed(coords, matrix))
            obj.data.update()
    if state.draw and not keys:
        live_draw.tag_redraw()  # the draw handler shows the new buffers
    return True


_rendering = False


def _show_all(scene: bpy.types.Scene) -> None:
    # A handler must never raise (it would on every frame): a face with an object that is
    # gone, or whose live key was removed (by Undo, say), leaves the preview, saying so.
    for name, state in list(_live.items()):
        try:
            if not _show(state, scene, keys=_rendering):
                stop_live_state(name, "an object of the face is gone or lost its live key")
        except Exception as error:  # noqa: BLE001
            stop_live_state(name, f"{type(error).__name__}: {error}")
    _remove_handler_when_idle()


def stop_live_state(name: str, reason: str) -> None:
    """Ends a preview that cannot go on, with a message in the status bar and the console."""
    _live.pop(name, None)
    live_draw.remove_face(name)
    message = f"MPEG-4: live preview of {name} stopped: {reason}"
    print(message)
    _stopped.append(message)
    if not bpy.app.background:
        bpy.app.timers.register(_report_stopped, first_interval=0.0)


_stopped: list[str] = []  # messages of previews that stopped themselves, for the UI


def _report_stopped() -> None:
    """Shows the messages of stopped previews in the status bar (handlers cannot report)."""
    if _stopped:
        text = _stopped[-1]

        def draw(menu: bpy.types.UIPopupMenu, _context: bpy.types.Context) -> None:
            menu.layout.label(text=text)

        bpy.context.window_manager.popup_menu(draw, title="Live preview", icon="ERROR")
        _stopped.clear()


@persistent
def _on_frame_change(scene: bpy.types.Scene, *_args: object) -> None:
    _show_all(scene)


@persistent
def _on_render_init(scene: bpy.types.Scene, *_args: object) -> None:
    global _rendering
    _rendering = True
    _show_all(scene)


@persistent
def _on_render_pre(scene: bpy.types.Scene, *_args: object) -> None:
    # Rendering (F12, animations, scripts) shows the exact shape-key path: the live keys
    # hold the frame being rendered.
    if _rendering:
        _show_all(scene)


@persistent
def _on_render_end(*_args: object) -> None:
    global _rendering
    _rendering = False


_HANDLERS = (
    (lambda: bpy.app.handlers.frame_change_pre, _on_frame_change),
    (lambda: bpy.app.handlers.render_init, _on_render_init),
    (lambda: bpy.app.handlers.render_pre, _on_render_pre),
    (lambda: bpy.app.handlers.render_complete, _on_render_end),
    (lambda: bpy.app.handlers.render_cancel, _on_render_end),
)


def _remove_handler_when_idle() -> None:
    global _rendering
    if _live:
        return
    _rendering = False
    for handlers, handler in _HANDLERS:
        if handler in handlers():
            handlers().remove(handler)


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
            obj = operators.active_mesh(self, context)
            if obj is None:
                return {"CANCELLED"}
            stop_live(obj)
            self.report({"INFO"}, f"Live preview of {obj.name} stopped")
            return {"FINISHED"}
        found = stream_mesh(self, context, poses_enough=True)
        if found is None:
            return {"CANCELLED"}
        obj, keys = found
        state = obj.mpeg4face_stream
        if not state.filepath:
            self.report({"ERROR"}, f"No stream on {obj.name}: import one first")
            return {"CANCELLED"}
        stream = read_stream(self, state.filepath, state.fit_path)
        if stream is None:
            return {"CANCELLED"}
        return run_live(self, context, obj, keys, stream, state.start_frame)


def run_live(op: bpy.types.Operator, context: bpy.types.Context, obj: bpy.types.Object,
             keys: stream_logic.FaceKeys, stream: mpeg4face.FapStream, start: int) -> set[str]:
    """Starts the live preview and sets the scene's frame range; reports."""
    try:
        warnings = start_live(obj, context.scene, keys, stream, start)
    except INPUT_ERRORS as error:
        op.report({"ERROR"}, f"Cannot build the face's tables from the shape keys: {error}")
        return {"CANCELLED"}
    for warning in warnings:
        op.report({"WARNING"}, warning)
    scene = context.scene
    frames = stream_logic.scene_frame_count(stream.duration, scene_rate(scene))
    scene.frame_start, scene.frame_end = start, start + frames - 1
    op.report({"INFO"}, f"Live preview of {obj.name}: {frames} frames from frame {start}")
    return {"FINISHED"}


# --- Encoding ----------------------------------------------------------------------------

ENCODING_MODES = (
    ("predictive", "Predictive", "The standard's predictive coding: arithmetic-coded "
     "differences from the previous frame"),
    ("dct", "DCT", "A DCT of 16 consecutive values of each FAP (docs/dct-mode.md)"),
    ("pca", "PCA", "A KLT per FAP group (docs/pca-mode.md)"),
)


class MPEG4FACE_OT_encode_fap_stream(bpy.types.Operator, ExportHelper):
    """Encode the stream imported on the active object as an FBA bitstream (.fba) and show
    its bit rate and PSNR"""

    bl_idname = "mpeg4face.encode_fap_stream"
    bl_label = "Encode FAP Stream"
    bl_options = {"REGISTER", "UNDO"}

    filename_ext = ".fba"
    filter_glob: StringProperty(default="*.fba", options={"HIDDEN"})
    mode: EnumProperty(name="Mode", items=ENCODING_MODES, default="predictive")
    fap_quant: IntProperty(
        name="Quantiser scale",
        description="fap_quant, the quantiser scale: larger is coarser (0: none)",
        default=1, min=0, max=31)

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        obj = context.active_object
        if obj is not None and obj.type == "MESH" and obj.mpeg4face_stream.filepath:
            source = Path(bpy.path.abspath(obj.mpeg4face_stream.filepath))
            self.filepath = str(source.with_name(source.stem + "_coded.fba"))
        return ExportHelper.invoke(self, context, event)

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = operators.active_mesh(self, context)
        if obj is None:
            return {"CANCELLED"}
        state = obj.mpeg4face_stream
        if not state.filepath:
            self.report({"ERROR"}, f"No stream on {obj.name}: import or speak one first")
            return {"CANCELLED"}
        # The stream as sent (no FIT: that is the decoder's side).
        stream = read_stream(self, state.filepath)
        if stream is None:
            return {"CANCELLED"}
        try:
            encoding = mpeg4face.encode_fba(stream, self.mode, self.fap_quant)
            mpeg4face.write_file_atomically(self.filepath, encoding.data)
        except INPUT_ERRORS as error:
            self.report({"ERROR"}, f"Cannot encode: {error}")
            return {"CANCELLED"}
        state.encoded_path, state.encoded_mode = self.filepath, self.mode
        state.bits, state.bits_per_second = encoding.bits, encoding.bits_per_second
        state.psnr = math.nan if encoding.psnr is None else encoding.psnr
        self.report({"INFO"}, f"Wrote {self.filepath}: "
                    + stream_logic.encoding_summary(encoding.bits, encoding.bits_per_second,
                                                    encoding.psnr))
        return {"FINISHED"}


# --- Speech ------------------------------------------------------------------------------

VOICES = tuple((v, v, f"flite's voice {v}") for v in ("kal", "slt", "awb", "rms", "kal16"))
DEFAULT_SPEECH_FOLDER = "//speech"


def output_folder(folder: str, temporary: str) -> Path:
    """A folder for files the add-on writes (speech, converted captures): relative to the
    .blend ("//"), or <temp>/`temporary` while the file has never been saved."""
    if folder.startswith("//") and not bpy.data.filepath:
        return Path(tempfile.gettempdir()) / temporary
    return Path(bpy.path.abspath(folder))


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
        found = stream_mesh(self, context)
        if found is None:
            return {"CANCELLED"}
        obj, keys = found
        if not self.text.strip():
            self.report({"ERROR"}, "Nothing to say: the text is empty")
            return {"CANCELLED"}
        scene = context.scene
        fps = scene_rate(scene)
        folder = output_folder(self.folder, "mpeg4face-speech")
        # Named by what is said, so the same text, voice and rate reuse one file name.
        digest = hashlib.sha1(f"{self.text}|{self.voice}|{fps}".encode()).hexdigest()[:10]
        base = folder / f"{bpy.path.clean_name(obj.name)}-{digest}"
        wav, fap = base.with_suffix(".wav"), base.with_suffix(".fap")
        try:
            folder.mkdir(parents=True, exist_ok=True)
            stream = mpeg4face.speak(self.text, str(wav), fps, self.voice)
            mpeg4face.write_fap(stream, str(fap))
        except INPUT_ERRORS as error:  # flite missing or failing, a bad bookmark
            self.report({"ERROR"}, f"Cannot speak: {error}")
            return {"CANCELLED"}
        stop_live(obj)
        result = bake_stream(self, context, obj, keys, stream, self.start_frame, "HOLD")
        remember_stream(obj, str(fap), "", self.start_frame, result.frames)
        strip = add_sound_strip(scene, obj, wav, self.start_frame)
        scene.frame_end = max(scene.frame_end, strip.frame_final_end - 1)
        scene.sync_mode = "AUDIO_SYNC"  # drop frames rather than drift from the audio
        self.report({"INFO"}, f"Spoke into {wav}")
        return {"FINISHED"}


_classes = (
    MPEG4FACE_PG_stream,
    MPEG4FACE_OT_live_preview,
    MPEG4FACE_OT_encode_fap_stream,
    MPEG4FACE_OT_speak_text,
)


@persistent
def _clean_after_load(*_args: object) -> None:
    """A file saved during a drawn preview keeps the modifier that empties its objects in
    the viewport; nothing draws them after loading, so they show again (the live keys stay
    for Stop Live Preview to remove, as documented)."""
    for obj in bpy.data.objects:
        if obj.type == "MESH" and obj.modifiers.get(live_draw.HIDE_MODIFIER) is not None:
            live_draw.unhide(obj)


def register() -> None:
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.Object.mpeg4face_stream = PointerProperty(type=MPEG4FACE_PG_stream)
    bpy.app.handlers.load_post.append(_clean_after_load)


def unregister() -> None:
    for name in list(_live):
        obj = bpy.data.objects.get(name)
        # Best effort: a mesh left showing its live key is cleaned by the next Stop.
        try:
            if obj is not None:
                stop_live(obj)
        except Exception:  # noqa: BLE001 - unregister must not fail
            pass
    _live.clear()
    live_draw.clear()
    _remove_handler_when_idle()
    if _clean_after_load in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_clean_after_load)
    del bpy.types.Object.mpeg4face_stream
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
