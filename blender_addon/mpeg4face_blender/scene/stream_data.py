# SPDX-License-Identifier: GPL-3.0-or-later
"""A FAP stream on Blender data: the shape keys of an object named in the grammar, the
curves a bake writes into them, the stream remembered on the head, the scene's frame rate
and the folder the add-on writes files to. bpy, no operators: the bake, live preview,
speech and import operators (ui/operators/) share it, and so does the live preview
(live_preview.py)."""

import tempfile
from pathlib import Path

import bpy
import numpy as np

from ..logic import stream as stream_logic
from . import compat

ACTION_GROUP = "MPEG-4 FAP stream"


def grammar_keys(obj: bpy.types.Object) -> stream_logic.FaceKeys:
    """The object's shape keys named in the grammar (and the malformed ones)."""
    blocks = obj.data.shape_keys.key_blocks if obj.data.shape_keys else ()
    return stream_logic.face_keys(b.name for b in blocks)


def scene_rate(scene: bpy.types.Scene) -> float:
    return scene.render.fps / scene.render.fps_base


def set_scene_rate(scene: bpy.types.Scene, frame_rate: float) -> None:
    scene.render.fps, scene.render.fps_base = stream_logic.scene_fps(frame_rate)


_LINEAR = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["LINEAR"].value


def key_shape_keys(obj: bpy.types.Object, result: stream_logic.Bake, start: int) -> list[str]:
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


def output_folder(folder: str, temporary: str) -> Path:
    """A folder for files the add-on writes (speech, converted captures): relative to the
    .blend ("//"), or <temp>/`temporary` while the file has never been saved."""
    if folder.startswith("//") and not bpy.data.filepath:
        return Path(tempfile.gettempdir()) / temporary
    return Path(bpy.path.abspath(folder))
