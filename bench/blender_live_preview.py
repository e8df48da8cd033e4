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
and the time to start the drawn preview (read the face, build the tables of the stream's
FAPs, the evaluator and the draw buffers): first the cold start, the first one of the
Blender session (run the bench several times for a median of cold starts), then the median
of `--passes` more starts (the add-on keeps nothing between starts, so each reads the
face anew; only Python's and the allocator's state are warm). Headless Blender has no GPU
context, so the upload of the buffers (two attr_fill of the positions and normals) is not
in the figure; the viewport test draws them under Xvfb.
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
from mpeg4face_blender.logic import stream as stream_logic  # noqa: E402
from mpeg4face_blender.scene import live_preview, stream_data  # noqa: E402
from mpeg4face_blender.ui.operators import stream as operators_stream  # noqa: E402


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


def start(head: bpy.types.Object, scene: bpy.types.Scene, keys, stream, draw: bool
          ) -> tuple[float, float]:
    """Seconds (wall, CPU) to start the live preview."""
    live_preview.stop_live(head)
    begin, begin_cpu = time.perf_counter(), time.process_time()
    live_preview.start_live(head, scene, keys, stream, scene.frame_start, draw=draw)
    return time.perf_counter() - begin, time.process_time() - begin_cpu


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
    keys = stream_data.grammar_keys(head)
    stream = operators_stream.read_stream(None, str(args.stream))
    print(f"bench: {head.name}: {vertices} vertices in {len(parts)} objects, "
          f"{len(keys.keys)} FAP shape keys of {len({k.fap for k in keys.keys})} FAPs; stream "
          f"{args.stream.name} animating {len(stream_logic.animated_faps(stream))} FAPs")
    cold = start(head, scene, keys, stream, draw=True)
    warm = [start(head, scene, keys, stream, draw=True) for _ in range(args.passes)]
    live_preview.stop_live(head)
    print(f"start     cold {cold[0]:5.2f} s ({cold[1]:5.2f} cpu)   then median of "
          f"{args.passes}: {statistics.median(w for w, _ in warm):5.2f} s "
          f"({statistics.median(c for _, c in warm):5.2f} cpu)")
    assert bpy.ops.mpeg4face.import_fap_stream(filepath=str(args.stream),
                                               preview="BAKE") == {"FINISHED"}
    frames = range(scene.frame_start, scene.frame_end + 1)
    print(f"bench: {len(frames)} frames, medians of {args.passes} passes, ms a frame")
    baked = per_frame(scene, frames, args.passes)
    print(f"baked     frame_set {figure(baked)}")
    head.data.shape_keys.animation_data_clear()
    for mode, draw in (("keys", False), ("drawn", True)):
        start(head, scene, keys, stream, draw)
        cost = per_frame(scene, frames, args.passes)
        handler = per_frame(scene, frames, args.passes,
                            lambda: live_preview._show_all(scene))  # noqa: SLF001
        print(f"{mode:9} frame_set {figure(cost)}   handler {figure(handler)}")
        live_preview.stop_live(head)


main()
