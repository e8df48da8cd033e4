#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Checks what the README's demo command made, as a demanding new user would.

    PYTHONPATH=build/release/python /usr/bin/python3 tests/new_user/check_demo_output.py \\
        OUT_DIR [--samples samples/build] [--validator "node tests/tools/validate_gltf.mjs"]

- every file the demo's summary names is there and not empty;
- the glTF files (the exported face, the animated head, the sample heads) pass the Khronos
  glTF validator with no error and no warning;
- the VRML face reads back with our reader (tables, feature points, meshes as the report
  says) and with tovrmlx3d, a third-party VRML97 reader, without a warning;
- each decoded stream's PSNR against the original, computed here, is the one the demo
  printed, and decoding the bitstream again gives the decoded file;
- the preview has one rendered frame per scene frame of the stream, a contact sheet of 4 x 3
  frames and an MPEG-4 video;
- the talking portrait: its .m2d decodes to the JSON the demo wrote, one plane per frame of
  the sentence, no triangle folded in any plane; the feature points' nodes follow the tracks
  Blender projected (within the coding step) and the mouth opens; a video with sound as long
  as the sentence, and a contact sheet of 4 x 3 frames;
- the real capture's FAP stream (made on the ICT head) is as long as the capture, its coded
  and decoded copies check out as the sentence's, and its side-by-side sheet has 3 x 6 tiles.
Prints one line per check; exits 1 on the first failure.
"""

from __future__ import annotations

import argparse
import math
import re
import shlex
import struct
import subprocess
import sys
from pathlib import Path

import mpeg4face
import numpy as np

ROOT = Path(__file__).resolve().parents[2]


def fail(message: str) -> None:
    print(f"FAIL: {message}")
    raise SystemExit(1)


def ok(message: str) -> None:
    print(f"ok: {message}")


def check_files(out: Path) -> None:
    names = ["info.txt", "makehuman_head.wrl", "makehuman_head.glb", "makehuman_head_fat.txt",
             "hello.fap", "hello.wav", "hello_animated.glb", "summary.txt",
             "preview/contact_sheet.png", "preview/preview.mp4", "capture.fap",
             "capture_to_fap.txt", "capture_dct.fba", "capture_dct_decoded.fap",
             "coding_capture.txt", "capture_animated.glb", "capture_sheet.png"]
    names += [f"portrait/{name}" for name in (
        "portrait.png", "feature_points.csv", "tracks.csv", "portrait.m2d", "portrait.json",
        "portrait.mp4", "contact_sheet.png")]
    for mode in ("predictive", "dct"):
        names += [f"hello_{mode}.fba", f"hello_{mode}_decoded.fap", f"coding_{mode}.txt"]
    for name in names:
        path = out / name
        if not path.is_file() or path.stat().st_size == 0:
            fail(f"{path} is missing or empty")
    leftovers = [p for p in out.rglob("*") if ".part" in p.name]
    if leftovers:
        fail(f"half-written files left: {', '.join(map(str, leftovers))}")
    ok(f"{len(names)} files in {out}, no .part file left")


def check_gltf(files: list[Path], validator: str) -> None:
    command = [*shlex.split(validator), "--strict", *map(str, files)]
    result = subprocess.run(command, capture_output=True, text=True, cwd=ROOT)
    if result.returncode != 0:
        fail(f"gltf-validator on {len(files)} files:\n{result.stdout}{result.stderr}")
    for f in files:
        mpeg4face.read_gltf(f).validate()
    ok(f"gltf-validator: no error, no warning in {', '.join(f.name for f in files)}")


def check_vrml(out: Path) -> None:
    face = mpeg4face.read_vrml(out / "makehuman_head.wrl")
    face.validate()
    report = (out / "makehuman_head_fat.txt").read_text().splitlines()[0]
    tables = int(re.search(r"-> (\d+) tables", report).group(1))
    if len(face.tables) != tables:
        fail(f"makehuman_head.wrl holds {len(face.tables)} tables, the report says {tables}")
    graph = face.scene_graph
    if len(graph.meshes) != 7 or len(graph.feature_points) < 80:
        fail(f"makehuman_head.wrl: {len(graph.meshes)} meshes, {len(graph.feature_points)} "
             "feature points (expected 7 and the head's 84)")
    result = subprocess.run(["tovrmlx3d", "makehuman_head.wrl"], cwd=out, capture_output=True,
                            text=True)
    if result.returncode != 0 or result.stderr.strip():
        fail(f"tovrmlx3d makehuman_head.wrl: status {result.returncode}\n{result.stderr}")
    ok(f"makehuman_head.wrl: {tables} tables, {len(graph.meshes)} meshes, "
       f"{len(graph.feature_points)} feature points read back; tovrmlx3d reads it without a "
       "warning")


def printed_psnr(path: Path) -> float:
    match = re.search(r"^PSNR (\S+) dB", path.read_text(), re.MULTILINE)
    if match is None:
        fail(f"{path} has no PSNR line")
    return float(match.group(1))


def check_coding(original: Path, coded: Path, decoded_path: Path, printed: Path) -> float:
    """Decoding `coded` again gives `decoded_path`, whose PSNR against `original` is the one
    printed in `printed`; returns it."""
    decoded = mpeg4face.read_fap(decoded_path)
    again = mpeg4face.decode_fba(coded.read_bytes())
    if not (np.array_equal(again.values, decoded.values)
            and np.array_equal(again.mask, decoded.mask)):
        fail(f"decoding {coded.name} again differs from {decoded_path.name}")
    psnr = mpeg4face.psnr(mpeg4face.read_fap(original), decoded)
    shown = printed_psnr(printed)
    if psnr is None or not (math.isinf(psnr) and math.isinf(shown) or abs(psnr - shown) <= 0.005):
        fail(f"{coded.name}: PSNR of the decoded stream is {psnr}, the demo printed {shown}")
    return psnr


def check_streams(out: Path) -> None:
    for mode in ("predictive", "dct"):
        psnr = check_coding(out / "hello.fap", out / f"hello_{mode}.fba",
                            out / f"hello_{mode}_decoded.fap", out / f"coding_{mode}.txt")
        ok(f"{mode}: PSNR of hello_{mode}_decoded.fap {psnr:.2f} dB, as printed")


def png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()[:24]
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        fail(f"{path} is not a PNG")
    return struct.unpack(">II", data[16:24])


def check_preview(out: Path) -> None:
    stream = mpeg4face.read_fap(out / "hello.fap")
    frames = sorted((out / "preview/frames").glob("frame_*.png"))
    expected = round(stream.duration * stream.frame_rate)
    if abs(len(frames) - expected) > 1:
        fail(f"{len(frames)} rendered frames for a stream of {expected}")
    width, height = png_size(frames[0])
    sheet = png_size(out / "preview/contact_sheet.png")
    if sheet[0] < 4 * width or sheet[1] < 3 * height:
        fail(f"contact sheet {sheet} is smaller than 4 x 3 frames of {width} x {height}")
    video = (out / "preview/preview.mp4").read_bytes()
    if video[4:8] != b"ftyp" or len(video) < 10_000:
        fail("preview.mp4 is not an MPEG-4 file of some size")
    ok(f"preview: {len(frames)} frames of {width} x {height}, contact sheet {sheet[0]} x "
       f"{sheet[1]}, video {len(video) // 1024} KiB")


def read_csv_rows(path: Path) -> list[list[str]]:
    return [line.split(",") for line in path.read_text().splitlines()[1:] if line]


def check_portrait(out: Path) -> None:
    folder = out / "portrait"
    decoded = mpeg4face.decode_mesh2d((folder / "portrait.m2d").read_bytes())
    written = mpeg4face.read_mesh2d(folder / "portrait.json")
    frames = decoded["frames"]
    if not (np.allclose(frames, written["frames"], atol=1e-6)
            and np.array_equal(decoded["triangles"], written["triangles"])):
        fail("portrait.m2d decoded again differs from portrait.json")
    stream = mpeg4face.read_fap(out / "hello.fap")
    if len(frames) != len(stream):
        fail(f"the portrait has {len(frames)} planes, the sentence {len(stream)} frames")
    # Triangles are clockwise on the screen (y down): positive cross products, in every plane.
    a, b, c = (frames[:, decoded["triangles"][:, k]] for k in range(3))
    cross = ((b - a)[..., 0] * (c - a)[..., 1] - (b - a)[..., 1] * (c - a)[..., 0])
    if cross.min() <= 0:
        plane, triangle = np.unravel_index(cross.argmin(), cross.shape)
        fail(f"portrait: triangle {triangle} folds over in plane {plane}")
    # Each feature point that is a node follows its track (frame 0 is the neutral picture).
    neutral = {fp: (float(x), float(y)) for fp, x, y in read_csv_rows(folder / "feature_points.csv")}
    tracks: dict[str, np.ndarray] = {fp: np.zeros((len(frames), 2)) for fp in neutral}
    for frame, fp, x, y in read_csv_rows(folder / "tracks.csv"):
        tracks[fp][int(frame)] = float(x), float(y)
    step = 0.5
    followed, worst, opening = 0, 0.0, 0.0
    for fp, position in neutral.items():
        distance = np.linalg.norm(frames[0] - position, axis=1)
        if distance.min() > step:
            continue  # merged into a point close by (the closed mouth's inner lips)
        node = int(distance.argmin())
        moved = frames[1:, node] - frames[0, node]
        tracked = tracks[fp][1:] - np.array(position)
        worst = max(worst, float(np.abs(moved - tracked).max()))
        followed += 1
        if fp == "8.2":  # the lower lip's middle: down when the mouth opens
            opening = float(moved[:, 1].max())
    if followed < 40 or worst > step + 1e-6:
        fail(f"portrait: {followed} feature point nodes, off their tracks by up to {worst:.2f} px")
    if opening < 5:
        fail(f"portrait: the lower lip moves down {opening:.1f} px at most; the mouth never opens")
    probe = subprocess.run(
        ["ffprobe", "-v", "error", "-show_entries", "stream=codec_type:format=duration", "-of",
         "default=noprint_wrappers=1", str(folder / "portrait.mp4")],
        capture_output=True, text=True)
    fields = probe.stdout.split()
    seconds = float(next((f.split("=")[1] for f in fields if f.startswith("duration=")), "0"))
    if "codec_type=audio" not in fields or abs(seconds - stream.duration) > 0.2:
        fail(f"portrait.mp4: {probe.stdout!r}; expected video and audio of {stream.duration:.2f} s")
    width, height = png_size(folder / "contact_sheet.png")
    if width < 4 * 300 or height < 3 * 260:
        fail(f"portrait/contact_sheet.png is {width} x {height}, not 4 x 3 frames")
    ok(f"portrait: {len(frames)} planes of {frames.shape[1]} nodes, none folded; {followed} "
       f"feature points on their tracks within {worst:.2f} px, the lower lip down "
       f"{opening:.1f} px at most; video {seconds:.2f} s with sound")


def check_capture(out: Path) -> None:
    capture = mpeg4face.read_livelink_csv(
        ROOT / "tests/data/livelink-face/MySlate_3_Jason_Millers_iPhone.csv")
    stream = mpeg4face.read_fap(out / "capture.fap")
    seconds = capture.times[-1] - capture.times[0]
    if abs(stream.duration - seconds) > 2 / stream.frame_rate or stream.frame_rate != 25:
        fail(f"capture.fap lasts {stream.duration:.2f} s at {stream.frame_rate} fps, the "
             f"capture {seconds:.2f} s")
    jaw = stream.values[:, 2][stream.mask[:, 2]]  # FAP 3, open_jaw
    if jaw.size == 0 or jaw.max() <= 0:
        fail("capture.fap never opens the jaw (FAP 3)")
    psnr = check_coding(out / "capture.fap", out / "capture_dct.fba",
                        out / "capture_dct_decoded.fap", out / "coding_capture.txt")
    width, height = png_size(out / "capture_sheet.png")
    if width < 3 * 100 or height < 6 * 100 or not 1 < height / width < 5:
        fail(f"capture_sheet.png is {width} x {height}, not 3 x 6 face tiles")
    ok(f"capture: {len(stream)} frames over {stream.duration:.2f} s, FAP 3 up to {jaw.max()}, "
       f"DCT PSNR {psnr:.2f} dB as printed, side-by-side sheet {width} x {height}")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("out", type=Path)
    parser.add_argument("--samples", type=Path, default=ROOT / "samples/build")
    parser.add_argument("--validator", default="node tests/tools/validate_gltf.mjs")
    args = parser.parse_args()
    check_files(args.out)
    check_gltf([args.out / "makehuman_head.glb", args.out / "hello_animated.glb",
                args.out / "capture_animated.glb",
                args.samples / "makehuman_head.glb", args.samples / "candide3.glb"],
               args.validator)
    check_vrml(args.out)
    check_streams(args.out)
    check_preview(args.out)
    check_portrait(args.out)
    check_capture(args.out)
    print("the demo's output checks out")


if __name__ == "__main__":
    sys.exit(main())
