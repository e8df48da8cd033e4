# SPDX-License-Identifier: GPL-3.0-or-later
"""Renders a Live Link Face capture and the FAP stream made from it side by side, a few
frames down the sheet, three heads across:

1. the capture on the ICT head through its own ARKit shapes (the weights set as the shape
   keys' values);
2. the FAP stream on the ICT head through its tables (the add-on's live preview);
3. the FAP stream on the MakeHuman head through its tables.

    blender -b samples/build/ict_head.blend --python-exit-code 1 \\
        --python samples/capture_sheet.py -- CAPTURE.csv STREAM.fap \\
        samples/build/makehuman_head.blend OUT.png [--rows 6] [--resolution 600]

The stream is `mpeg4face arkit to-fap CAPTURE.csv` (possibly coded and decoded): its frame
k is the capture at its first time + k / fps. Workbench, as the .blends are staged
(samples/make_blend.py); each tile is the face (hairline to chin). Writes OUT.png through a
.part name.
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import blender_session  # noqa: E402

ARGS = blender_session.start()

import bpy  # noqa: E402
import mpeg4face  # noqa: E402
import numpy as np  # noqa: E402
from mpeg4face_blender.scene import poses  # noqa: E402


def arkit_name(name: str) -> str:
    """A shape-key or Live Link Face channel name reduced to compare them: EyeBlinkLeft,
    eyeBlink_L -> eyeblinkleft (as arkit/capture.cpp matches them)."""
    lower = name.lower()
    lower = re.sub(r"_l$", "left", re.sub(r"_r$", "right", lower))
    return re.sub(r"[-_ ]", "", lower)


def channel_of(key: str, channels: dict[str, int]) -> int | None:
    """The capture column a shape key shows; ICT's halves (browInnerUp_L, cheekPuff_R) each
    take the whole shape's weight."""
    name = arkit_name(key)
    if name in channels:
        return channels[name]
    return channels.get(re.sub(r"(left|right)$", "", name))


def render(path: Path, note: str) -> Path:
    scene = bpy.context.scene
    scene.render.stamp_note_text = note
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    return path


def stage(resolution: int) -> bpy.types.Object:
    head = blender_session.head_object()
    blender_session.crop_to(head, blender_session.REGIONS["face"], resolution)
    blender_session.stamp_note(13)
    return head


def neutral_frame() -> int:
    return next(m.frame for m in bpy.context.scene.timeline_markers
                if m.name == poses.NEUTRAL_MARKER)


def live_stream(head: bpy.types.Object, stream: Path) -> int:
    """The add-on's import with the live preview; the scene's first frame."""
    bpy.context.view_layer.objects.active = head
    head.select_set(True)
    if bpy.ops.mpeg4face.import_fap_stream(filepath=str(stream), preview="LIVE") != {"FINISHED"}:
        raise SystemExit(f"capture_sheet: the add-on could not import {stream}")
    return bpy.context.scene.frame_start


def main() -> None:
    parser = argparse.ArgumentParser(prog="capture_sheet.py")
    parser.add_argument("capture", type=Path, help="a Live Link Face CSV")
    parser.add_argument("stream", type=Path, help="the FAP stream made from it (.fap, .fba)")
    parser.add_argument("makehuman", type=Path, help="the MakeHuman head's .blend")
    parser.add_argument("out", type=Path)
    parser.add_argument("--rows", type=int, default=6, help="frames shown")
    parser.add_argument("--resolution", type=int, default=600,
                        help="of the whole camera frame, of which the face is a part")
    args = parser.parse_args(ARGS)
    for path in (args.capture, args.stream, args.makehuman):
        if not path.is_file():
            raise SystemExit(f"capture_sheet: {path}: no such file")
    capture = mpeg4face.read_livelink_csv(args.capture)
    stream = mpeg4face.read_fap_stream(args.stream)
    # Frames spread over the stream, the first and last left out (the actor still settling).
    count = len(stream)
    shown = np.linspace(0, count - 1, args.rows + 2).round().astype(int)[1:-1]
    seconds = shown / stream.frame_rate
    rows = [int(np.abs(capture.times - capture.times[0] - t).argmin()) for t in seconds]
    channels = {arkit_name(c): i for i, c in enumerate(capture.channels)}
    tiles: dict[tuple[int, int], Path] = {}
    with tempfile.TemporaryDirectory() as folder:
        tile = Path(folder)
        # 1. The capture's weights on the ICT head's ARKit shape keys, at the neutral pose.
        head = stage(args.resolution)
        bpy.context.scene.frame_set(neutral_frame())
        keyed = [(block, channel_of(block.name, channels))
                 for obj in bpy.context.scene.objects
                 if obj.type == "MESH" and obj.data.shape_keys
                 for block in obj.data.shape_keys.key_blocks[1:]]
        keyed = [(block, c) for block, c in keyed if c is not None]
        if not keyed:
            raise SystemExit("capture_sheet: the ICT head has no shape key of the capture")
        for r, (row, t) in enumerate(zip(rows, seconds)):
            for block, c in keyed:
                block.value = float(capture.values[row, c])
            tiles[r, 0] = render(tile / f"{r}_0.png", f"capture on ICT (ARKit) {t:.2f} s")
        for block, _ in keyed:
            block.value = 0.0
        # 2. and 3. The stream on each head through its tables.
        for column, label in ((1, "FAPs on ICT"), (2, "FAPs on MakeHuman")):
            if column == 2:
                bpy.ops.wm.open_mainfile(filepath=str(args.makehuman))
                head = stage(args.resolution)
            first = live_stream(head, args.stream.resolve())
            for r, (k, t) in enumerate(zip(shown, seconds)):
                bpy.context.scene.frame_set(first + int(k))
                tiles[r, column] = render(tile / f"{r}_{column}.png", f"{label} {t:.2f} s")
        blender_session.save_sheet([tiles[r, c] for r in range(len(rows)) for c in range(3)],
                                   args.out, 3)
    print(f"capture_sheet: {len(rows)} frames of {args.stream.name} "
          f"({', '.join(f'{t:.2f}' for t in seconds)} s) -> {args.out}")


main()
