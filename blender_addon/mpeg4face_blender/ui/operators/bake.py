# SPDX-License-Identifier: GPL-3.0-or-later
"""Baking a FAP stream into shape-key animation (and pose keyframes) on the head and its
parts, reporting what was baked and what could not be; the import and speech operators
bake through bake_stream()."""

import bpy
import numpy as np

import mpeg4face

from ...logic import stream as stream_logic
from ...scene import bake_poses, live_preview, poses, stream_data
from ...scene.stream_data import grammar_keys
from .. import text as ui_text


def bake_stream(op: bpy.types.Operator, context: bpy.types.Context, obj: bpy.types.Object,
                keys: stream_logic.FaceKeys, stream: mpeg4face.FapStream, start: int,
                method: str) -> stream_logic.Bake:
    """Keys the shape keys of the head and its parts from `start` at the scene's frame
    rate (LINEAR keyframes, in an action on each mesh's Key datablock, replacing earlier
    curves of those keys), widens their sliders, keys the poses the stream drives
    (bake_poses: eyes, head, the jaw's parts as object keyframes), sets the scene's frame
    range and reports what was baked, and in a popup what could not be."""
    scene = context.scene
    fps = stream_data.scene_rate(scene)
    result = stream_logic.bake(stream, keys, fps, method)
    clamped = stream_data.key_shape_keys(obj, result, start)
    missing = set(result.missing)
    baked = set(result.baked_faps)
    for part in poses.parts(obj):
        part_keys = grammar_keys(part)
        if part_keys.keys:
            part_result = stream_logic.bake(stream, part_keys, fps, method)
            clamped += stream_data.key_shape_keys(part, part_result, start)
            missing &= set(part_result.missing)
            baked |= set(part_result.baked_faps)

    def key_names(o: bpy.types.Object) -> list[str]:
        return [k.name for k in (keys if o == obj else grammar_keys(o)).keys]

    posed = bake_poses.key_poses(obj, scene, key_names, stream, start, result.frames, fps)
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
        overridden = _priority_problem(obj, scene, keys, stream, start, result.frames, fps)
        if overridden:
            problems.append(overridden)
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


def _priority_problem(obj: bpy.types.Object, scene: bpy.types.Scene,
                      keys: stream_logic.FaceKeys, stream: mpeg4face.FapStream, start: int,
                      frames: int, fps: float) -> str | None:
    """Where the bake is not what a decoder shows: the scene frames at which a low-level FAP
    present overrides a viseme or expression on vertices both move (the core's
    priority_frames on the face's tables, each stream frame held until the next); shape
    keys add there. None when there is no such frame."""
    cannot = ("shape keys add, where the standard lets a low-level FAP override a viseme "
              "or expression on the vertices both move: Live shows the exact result")
    try:
        _, generated = live_preview.stream_face(obj, scene, keys, stream)
        evaluator = mpeg4face.FatEvaluator(generated["face"])
    except mpeg4face.Error as error:
        return f"The bake may differ from a decoder: {cannot} (no tables to say where: {error})"
    overridden = evaluator.priority_frames(stream).astype(np.float64)
    times = stream_logic.sample_times(stream.frame_numbers, stream.frame_rate)
    at = stream_logic.resample(times, overridden, np.arange(frames) / fps, "HOLD")[:, 0]
    scene_frames = start + np.flatnonzero(at > 0.5)
    if not len(scene_frames):
        return None
    return (f"The bake differs from a decoder at {len(scene_frames)} frames "
            f"({stream_logic.frame_ranges(scene_frames)}): {cannot}")


def _fap_order(text: str) -> tuple[str, int]:
    kind, _, rest = text.partition(" ")
    number = rest.split(" ")[0]
    return kind, int(number) if number.isdigit() else 0
