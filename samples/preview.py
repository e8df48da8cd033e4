# SPDX-License-Identifier: GPL-3.0-or-later
"""Previews a FAP stream on a head in Blender, as a user would with the add-on: File >
Import > FAP Stream with the live preview (the core evaluates the face's tables on every
frame), then renders every frame, a contact sheet and a video with the sound.

    blender -b samples/build/makehuman_head.blend --python-exit-code 1 \\
        --python samples/preview.py -- STREAM.fap|.fba OUT_DIR [--audio WAV] [--title TEXT]

Writes OUT_DIR/frames/frame_0001.png..., OUT_DIR/contact_sheet.png and OUT_DIR/preview.mp4
(each through a .part name, renamed when complete). Progress on stdout.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import blender_session  # noqa: E402

ARGS = blender_session.start()

import bpy  # noqa: E402
import numpy as np  # noqa: E402

SHEET_COLUMNS, SHEET_ROWS = 4, 3


def import_stream(head: bpy.types.Object, stream: Path) -> tuple[int, int]:
    """The add-on's import, live; returns the scene's frame range it set."""
    bpy.context.view_layer.objects.active = head
    head.select_set(True)
    try:
        result = bpy.ops.mpeg4face.import_fap_stream(filepath=str(stream), preview="LIVE")
    except RuntimeError as error:  # the operator's error report (an unreadable stream)
        raise SystemExit(f"preview: {error}") from None
    if result != {"FINISHED"}:
        raise SystemExit(f"preview: the add-on could not import {stream}")
    scene = bpy.context.scene
    return scene.frame_start, scene.frame_end


def render_frames(frames: range, folder: Path, title: str) -> list[Path]:
    scene = bpy.context.scene
    scene.render.image_settings.file_format = "PNG"
    scene.render.use_stamp = True  # the frame number burnt in, for the contact sheet
    scene.render.use_stamp_date = scene.render.use_stamp_time = False
    scene.render.use_stamp_render_time = scene.render.use_stamp_camera = False
    scene.render.use_stamp_lens = scene.render.use_stamp_scene = False
    scene.render.use_stamp_filename = scene.render.use_stamp_memory = False
    scene.render.use_stamp_frame = scene.render.use_stamp_note = True
    scene.render.stamp_note_text = title
    scene.render.stamp_font_size = 14
    folder.mkdir(parents=True, exist_ok=True)
    paths, started = [], time.monotonic()
    for n, frame in enumerate(frames, 1):
        scene.frame_set(frame)
        path = folder / f"frame_{frame:04d}.png"
        scene.render.filepath = str(folder / f"frame_{frame:04d}.part.png")
        bpy.ops.render.render(write_still=True)
        Path(scene.render.filepath).replace(path)
        paths.append(path)
        if n % 50 == 0 or n == len(frames):
            print(f"preview: rendered {n}/{len(frames)} frames "
                  f"({time.monotonic() - started:.0f} s)", flush=True)
    return paths


def contact_sheet(paths: list[Path], out: Path) -> list[int]:
    """SHEET_ROWS x SHEET_COLUMNS frames spread over the stream; returns their frames."""
    count = min(len(paths), SHEET_COLUMNS * SHEET_ROWS)
    chosen = [paths[i] for i in np.linspace(0, len(paths) - 1, count).round().astype(int)]
    blender_session.save_sheet(chosen, out, SHEET_COLUMNS)
    return [int(p.stem.split("_")[1]) for p in chosen]


def video(paths: list[Path], audio: Path | None, out: Path) -> None:
    """The frames (and the sound) through the sequencer as H.264 + AAC in MPEG-4."""
    source = bpy.context.scene
    scene = bpy.data.scenes.new("preview video")
    scene.render.fps, scene.render.fps_base = source.render.fps, source.render.fps_base
    scene.render.resolution_x = source.render.resolution_x
    scene.render.resolution_y = source.render.resolution_y
    scene.render.resolution_percentage = 100
    edit = scene.sequence_editor_create()
    strip = edit.sequences.new_image("frames", str(paths[0]), channel=1, frame_start=1)
    for path in paths[1:]:
        strip.elements.append(path.name)
    if audio is not None:
        edit.sequences.new_sound("sound", str(audio), channel=2, frame_start=1)
    scene.frame_start, scene.frame_end = 1, len(paths)
    settings = scene.render
    settings.image_settings.file_format = "FFMPEG"
    settings.ffmpeg.format = "MPEG4"
    settings.ffmpeg.codec = "H264"
    settings.ffmpeg.constant_rate_factor = "MEDIUM"
    settings.ffmpeg.audio_codec = "AAC" if audio is not None else "NONE"
    settings.use_file_extension = False
    part = out.with_name(out.stem + ".part.mp4")
    settings.filepath = str(part)
    bpy.ops.render.render(animation=True, scene=scene.name)
    part.replace(out)


def main() -> None:
    parser = argparse.ArgumentParser(prog="preview.py")
    parser.add_argument("stream", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--audio", type=Path)
    parser.add_argument("--title", default="")
    args = parser.parse_args(ARGS)
    for path in (args.stream, args.audio):
        if path is not None and not path.is_file():
            raise SystemExit(f"preview: {path}: no such file")
    head = blender_session.head_object()
    first, last = import_stream(head, args.stream.resolve())
    frames = args.out / "frames"
    shutil.rmtree(frames, ignore_errors=True)  # a second run starts clean
    paths = render_frames(range(first, last + 1), frames, args.title or args.stream.name)
    shown = contact_sheet(paths, args.out / "contact_sheet.png")
    video(paths, args.audio, args.out / "preview.mp4")
    print(f"preview: {len(paths)} frames in {frames}/, contact sheet of frames "
          f"{', '.join(map(str, shown))}, video {args.out / 'preview.mp4'}")


main()
