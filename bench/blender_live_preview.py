# SPDX-License-Identifier: GPL-3.0-or-later
"""The live preview's cost per frame on a dense head, beside Blender's own baked playback,
in one headless Blender (docs/blender.md, "Live preview"):

    blender -b samples/build/ict_head.blend --python-exit-code 1 \\
        --python bench/blender_live_preview.py -- [STREAM] [--passes 5]

STREAM defaults to samples/build/streams/test.fap. Each pass plays every frame of the
stream with scene.frame_set and prints the median of the passes' mean cost of a frame:
  baked     the stream baked into shape-key animation (Blender evaluates the keys);
  keys      the live preview writing its shape keys (the path rendering uses);
  drawn     the live preview for the viewport (gpu buffers filled, nothing tagged): the
            frame_set, and the add-on's own work in it (handler);
and the time to start the drawn preview. Headless Blender has no GPU context, so the
upload of the buffers (two attr_fill of the positions and normals) is not in the figure;
the viewport test draws them under Xvfb.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "samples"))
import blender_session  # noqa: E402

ARGS = blender_session.start()

import bpy  # noqa: E402
from mpeg4face_blender import operators_stream  # noqa: E402


def per_frame(scene: bpy.types.Scene, frames: range, passes: int, work=None
              ) -> tuple[float, float]:
    """Medians over passes of the mean milliseconds of a frame_set (or of `work`): wall
    time and the process's CPU time (all of Blender's threads; on a busy machine the
    steadier figure)."""
    walls, cpus = [], []
    for _ in range(passes):
        wall = cpu = 0.0
        for frame in frames:
            if work is not None:
                scene.frame_current = frame
            begin, begin_cpu = time.perf_counter(), time.process_time()
            if work is None:
                scene.frame_set(frame)
            else:
                work()
            wall += time.perf_counter() - begin
            cpu += time.process_time() - begin_cpu
        walls.append(1000.0 * wall / len(frames))
        cpus.append(1000.0 * cpu / len(frames))
    return statistics.median(walls), statistics.median(cpus)


def figure(ms: tuple[float, float]) -> str:
    return f"{ms[0]:6.2f} ({ms[1]:6.2f} cpu)"


def main() -> None:
    parser = argparse.ArgumentParser(prog="blender_live_preview.py")
    parser.add_argument("stream", nargs="?", type=Path,
                        default=ROOT / "samples/build/streams/test.fap")
    parser.add_argument("--passes", type=int, default=5)
    args = parser.parse_args(ARGS)
    scene = bpy.context.scene
    head = blender_session.head_object()
    for o in scene.objects:
        o.select_set(o == head)
    bpy.context.view_layer.objects.active = head
    parts = [head, *head.children_recursive]
    vertices = sum(len(o.data.vertices) for o in parts if o.type == "MESH")
    keys = operators_stream.grammar_keys(head)
    print(f"bench: {head.name}: {vertices} vertices in {len(parts)} objects, "
          f"{len(keys.keys)} FAP shape keys; stream {args.stream.name}")
    assert bpy.ops.mpeg4face.import_fap_stream(filepath=str(args.stream),
                                               preview="BAKE") == {"FINISHED"}
    frames = range(scene.frame_start, scene.frame_end + 1)
    print(f"bench: {len(frames)} frames, medians of {args.passes} passes, ms a frame")
    baked = per_frame(scene, frames, args.passes)
    print(f"baked     frame_set {figure(baked)}")
    stream = operators_stream.read_stream(None, str(args.stream))
    head.data.shape_keys.animation_data_clear()
    for mode, draw in (("keys", False), ("drawn", True)):
        begin, begin_cpu = time.perf_counter(), time.process_time()
        operators_stream.start_live(head, scene, keys, stream, scene.frame_start, draw=draw)
        started = time.perf_counter() - begin, time.process_time() - begin_cpu
        cost = per_frame(scene, frames, args.passes)
        handler = per_frame(scene, frames, args.passes,
                            lambda: operators_stream._show_all(scene))  # noqa: SLF001
        print(f"{mode:9} frame_set {figure(cost)}   handler {figure(handler)}   "
              f"start {started[0]:5.2f} s ({started[1]:5.2f} cpu)")
        operators_stream.stop_live(head)


main()
