# SPDX-License-Identifier: GPL-3.0-or-later
"""The live preview of a FAP stream on a head: the tables of the whole face (head, parts
and poses) evaluated by the core on each frame change and render, drawn with the gpu
module (live_draw) or written into a live shape key. bpy data and handlers, no operators:
the Live Preview operator (ui/operators/live.py), the import and the panels use it.
register() adds the load handler that shows the objects a saved drawn preview hid;
unregister() ends every preview."""

from dataclasses import dataclass

import bpy
import numpy as np
from bpy.app.handlers import persistent

import mpeg4face

from ..logic import live as live_logic
from ..logic import shape_keys
from ..logic import stream as stream_logic
from . import live_draw, mesh_data, poses
from .stream_data import grammar_keys, scene_rate

LIVE_KEY = "MPEG-4 live"  # the shape key the live preview writes; not in the grammar
# The reference key the preview adds to a part without shape keys (LIVE_KEY needs one);
# named so that stopping knows it can go, in a saved file or after Undo too.
LIVE_BASIS = "MPEG-4 live basis"


@dataclass
class LiveObject:
    """An object of a live face (object i of [head, *parts], mesh i of its model)."""

    name: str
    chain: tuple[int, ...]  # the Transforms from the head's down to the one holding its mesh
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
    objects: list[LiveObject]
    neutral: list[np.ndarray]  # per object: the evaluator's neutral coordinates
    # Drawn with the gpu module (live_draw) instead of written into the live keys; the keys
    # are written for rendering only.
    draw: bool = False


_live: dict[str, LiveState] = {}  # head object name -> state
_cannot_draw_said = False  # the reason live_draw cannot draw is said once a session


def is_live(obj: bpy.types.Object) -> bool:
    return obj.name in _live or (obj.data.shape_keys is not None
                                 and LIVE_KEY in obj.data.shape_keys.key_blocks)


def stream_face(obj: bpy.types.Object, scene: bpy.types.Scene, keys: stream_logic.FaceKeys,
                stream: mpeg4face.FapStream) -> tuple[mpeg4face.FaceModel, dict]:
    """The posed face model of the head `obj` (its grammar keys `keys`, its parts' and the
    pose markers) and generate_face's result for it, for the FAPs the stream animates only:
    the others cannot move the face while it plays, and reading their shape keys is most of
    the cost. Raises mpeg4face.Error for a face the core refuses."""

    def key_names(o: bpy.types.Object) -> list[str]:
        return [k.name for k in (keys if o == obj else grammar_keys(o)).keys]

    faps = stream_logic.animated_faps(stream)

    def wanted(name: str) -> bool:
        parsed = shape_keys.parse(name)
        return parsed is None or parsed["fap"] in faps  # a malformed name: the core says why

    model, _ = poses.read_posed_face_model(obj, key_names, scene, wanted=wanted)
    return model, mpeg4face.generate_face(model)


def start_live(obj: bpy.types.Object, scene: bpy.types.Scene, keys: stream_logic.FaceKeys,
               stream: mpeg4face.FapStream, start: int, draw: bool | None = None) -> list[str]:
    """Builds the tables of the whole face for the FAPs the stream animates
    (generate_face on poses.read_posed_face_model: the head's grammar keys `keys`, its
    parts' grammar keys and the pose markers, of those FAPs), then shows the stream
    through the core's evaluator: the exact MPEG-4 result, visemes and expressions with
    the standard's priorities included, eyes, jaw and head moved by their Transforms.

    Each object of the face gets a shape key LIVE_KEY shown alone (show_only_shape_key),
    so the Basis, the other keys and the objects' matrices (which the pose keyframes
    drive) are never changed. `draw` (default: unless Blender runs in the background) draws
    the face with the gpu module (live_draw), the objects hidden in the viewport, and
    writes the live keys only for rendering; else, and where live_draw cannot draw, every
    frame is written into the live keys. Returns generate_face's warnings, after (the
    first time only) why the face cannot be drawn; raises mpeg4face.Error for a face it
    refuses, ValueError for objects sharing a mesh."""
    global _cannot_draw_said
    stop_live(obj)
    objects = [obj, *poses.parts(obj)]
    _refuse_shared_meshes(objects)
    _, generated = stream_face(obj, scene, keys, stream)
    draw = not bpy.app.background if draw is None else draw
    warnings = []
    reason = live_draw.cannot_draw() if draw else None
    if reason is not None:
        draw = False
        if not _cannot_draw_said:
            _cannot_draw_said = True
            warnings.append("MPEG-4: the live preview writes shape keys, as it cannot draw "
                            f"the face here ({reason})")
            print(warnings[-1])
    drawn = live_draw.add_face(obj.name, objects) if draw else [None] * len(objects)
    live_objects = []
    for index, o in enumerate(objects):
        # poses.read_posed_face_model makes each part (Transform i, holding mesh i) a child of the
        # head's Transform 0.
        chain = (0,) if index == 0 else (0, index)
        live_objects.append(LiveObject(o.name, chain,
                                       (o.show_only_shape_key, o.active_shape_key_index),
                                       o.as_pointer(), drawn[index]))
        _add_live_key(o)
    evaluator = mpeg4face.FatEvaluator(generated["face"])
    state = LiveState(evaluator, stream, start, live_objects,
                      list(evaluator.neutral()["coord"]), draw)
    _live[obj.name] = state
    for handlers, handler in _HANDLERS:
        if handler not in handlers():
            handlers().append(handler)
    _show(state, scene)
    return warnings + list(generated["warnings"])


def _refuse_shared_meshes(objects: list[bpy.types.Object]) -> None:
    # Shape keys belong to the mesh: two objects of one mesh would show one live key.
    owners: dict[int, str] = {}
    for o in objects:
        first = owners.setdefault(o.data.as_pointer(), o.name)
        if first != o.name:
            raise ValueError(f"{first} and {o.name} share the mesh {o.data.name}: the live "
                             "preview needs a mesh for each (Object > Relations > Make "
                             "Single User)")


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
               ) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The evaluation at the scene's frame, per object: its mesh's coordinates (N, 3,
    standard axes), the same shown in the object's own frame in Blender's axes (float32),
    and the placement (4, 4) between the two (the core's object_coordinates).

    An object's vertices are shown where the evaluated Transforms put them (L0 @ Li @
    coord), taken back through its neutral Transforms (inverse(N0 @ Ni)) into its own
    frame: the object stays where it is and the key carries the turn of an eye, the drop of
    the teeth with the jaw or a nod of the head."""
    seconds = (scene.frame_current - state.start) / scene_rate(scene)
    index = stream_logic.live_index(state.stream.frame_numbers, state.stream.frame_rate, seconds)
    result = state.evaluator.object_coordinates(
        state.stream, index, [live.chain for live in state.objects], live_logic.TO_BLENDER)
    return list(zip(result["coord"], result["placed"], result["placement"]))


def _show(state: LiveState, scene: bpy.types.Scene, keys: bool = False) -> bool:
    """Shows the evaluation at the scene's frame: drawn (state.draw), or written into the
    live keys (without drawing, or when `keys`, for a render); False (and nothing shown)
    when _live_objects finds the face incomplete."""
    head = next(name for name, s in _live.items() if s is state)
    objects = _live_objects(head, state)
    if objects is None:
        return False
    for obj, live, (coords, placed, placement), neutral in zip(
            objects, state.objects, _evaluated(state, scene), state.neutral):
        if live.drawn is not None:
            live.drawn.update(coords, placed, placement, rigid=np.array_equal(coords, neutral))
        if keys or not state.draw:
            mesh_data.set_shape_key_coords(obj.data.shape_keys.key_blocks[LIVE_KEY], placed)
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


@persistent
def _clean_after_load(*_args: object) -> None:
    """A file saved during a drawn preview keeps the modifier that empties its objects in
    the viewport; nothing draws them after loading, so they show again (the live keys stay
    for Stop Live Preview to remove, as documented)."""
    for obj in bpy.data.objects:
        if obj.type == "MESH" and obj.modifiers.get(live_draw.HIDE_MODIFIER) is not None:
            live_draw.unhide(obj)


def register() -> None:
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
