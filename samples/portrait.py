# SPDX-License-Identifier: GPL-3.0-or-later
"""Renders a head's neutral face as a still portrait and writes where its feature points lie in
the picture, for `mpeg4face mesh2d portrait` (docs/mesh2d.md, "Talking portrait").

    blender -b samples/build/makehuman_head.blend --python-exit-code 1 \\
        --python samples/portrait.py -- OUT.png OUT.csv [--stream STREAM.fap --tracks OUT.csv]

OUT.csv has one `fp,x,y` row per feature point the camera sees (pixels, y down, pixel centres
at whole numbers, as the 2D mesh takes them): points outside the picture or hidden behind the
face (the tongue, the teeth, the back of the head) are left out. With --stream, the stream is
played on the head through the add-on's live preview (the core evaluates the face's
FaceDefTables) and the same points are projected in every frame: rows `frame,fp,x,y`, frame 0
the stream's first. The head's rotation (FAPs 48-50) is left out: a picture warped in 2D
cannot turn a head. Files are written through a .part name. Progress on stdout.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import blender_session  # noqa: E402

ARGS = blender_session.start()

import bpy  # noqa: E402
from bpy_extras.object_utils import world_to_camera_view  # noqa: E402
import mpeg4face  # noqa: E402
from mpeg4face_blender.logic import feature_points  # noqa: E402
from mpeg4face_blender.scene.live_preview import LIVE_KEY  # noqa: E402

FeaturePoint = tuple[str, bpy.types.Object, int]  # fp, its object, its vertex


def all_feature_points(head: bpy.types.Object) -> list[FeaturePoint]:
    """The feature points of the head and its children, in the standard's order."""
    found = []
    for obj in [head, *head.children]:
        if obj.type != "MESH":
            continue
        for group in obj.vertex_groups:
            fp = feature_points.feature_point_of_group(group.name)
            if fp is not None:
                vertex = next(v.index for v in obj.data.vertices
                              if any(g.group == group.index for g in v.groups))
                found.append((fp, obj, vertex))
    return sorted(found, key=lambda f: tuple(int(n) for n in f[0].split(".")))


def pixel(point) -> tuple[float, float, float]:
    """x, y in pixels (centres at whole numbers) and the depth in the camera's view."""
    scene = bpy.context.scene
    view = world_to_camera_view(scene, scene.camera, point)
    return (view.x * scene.render.resolution_x - 0.5,
            (1 - view.y) * scene.render.resolution_y - 0.5, view.z)


def in_view(points: list[FeaturePoint]) -> list[tuple[FeaturePoint, float, float]]:
    """The points the camera sees in the neutral face, with their pixels."""
    scene = bpy.context.scene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    width, height = scene.render.resolution_x, scene.render.resolution_y
    eye = scene.camera.matrix_world.translation
    rows = []
    for fp, obj, vertex in points:
        point = obj.matrix_world @ obj.data.vertices[vertex].co
        x, y, depth = pixel(point)
        if not (depth > 0 and 2 <= x <= width - 3 and 2 <= y <= height - 3):
            continue
        # Hidden if the ray from the camera meets a surface well before the point (a
        # point lies on its own surface: a hair's breadth of the distance is allowed).
        direction = point - eye
        distance = direction.length
        hit, location, *_ = scene.ray_cast(depsgraph, eye, direction.normalized(),
                                           distance=distance)
        if hit and (location - eye).length < distance * (1 - 2e-3):
            continue
        rows.append(((fp, obj, vertex), x, y))
    return rows


def tracks(head: bpy.types.Object, stream: Path, points: list[FeaturePoint]) -> list[str]:
    """Rows frame,fp,x,y: the points in every frame of `stream` (without FAPs 48-50) played
    live on the head; the live preview writes each frame into the objects' live keys."""
    fap = mpeg4face.read_fap_stream(stream)
    mask = fap.mask.copy()
    mask[:, 47:50] = False
    still = mpeg4face.FapStream.from_arrays(fap.frame_numbers, mask, fap.values, fap.visemes,
                                            fap.expressions, fap.frame_rate, fap.name)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "still_head.fap"
        mpeg4face.write_fap(still, path)
        bpy.context.view_layer.objects.active = head
        head.select_set(True)
        if bpy.ops.mpeg4face.import_fap_stream(filepath=str(path), preview="LIVE") != {"FINISHED"}:
            raise SystemExit(f"portrait: the add-on could not import {stream}")
    scene = bpy.context.scene
    rows = []
    for n, frame in enumerate(range(scene.frame_start, scene.frame_end + 1)):
        scene.frame_set(frame)
        for fp, obj, vertex in points:
            keys = obj.data.shape_keys
            live = keys.key_blocks.get(LIVE_KEY) if keys is not None else None
            co = (obj.data.vertices if live is None else live.data)[vertex].co
            x, y, _ = pixel(obj.matrix_world @ co)
            rows.append(f"{n},{fp},{x:.2f},{y:.2f}\n")
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(prog="portrait.py")
    parser.add_argument("image", type=Path, help="OUT.png")
    parser.add_argument("csv", type=Path, help="OUT.csv")
    parser.add_argument("--stream", type=Path, help="STREAM.fap|.fba")
    parser.add_argument("--tracks", type=Path, help="OUT.csv: the points in every frame")
    args = parser.parse_args(ARGS)
    if (args.stream is None) != (args.tracks is None):
        raise SystemExit("portrait: --stream and --tracks go together")
    if args.stream is not None and not args.stream.is_file():
        raise SystemExit(f"portrait: {args.stream}: no such file")
    head = blender_session.head_object()
    scene = bpy.context.scene
    scene.render.use_stamp = False
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    args.image.parent.mkdir(parents=True, exist_ok=True)
    part = args.image.with_name(args.image.stem + ".part.png")
    scene.render.filepath = str(part)
    bpy.ops.render.render(write_still=True)
    part.replace(args.image)
    seen = in_view(all_feature_points(head))
    part = args.csv.with_name(args.csv.name + ".part")
    part.write_text("fp,x,y\n" + "".join(f"{p[0]},{x:.2f},{y:.2f}\n" for p, x, y in seen))
    part.replace(args.csv)
    if args.stream is not None:
        rows = tracks(head, args.stream.resolve(), [p for p, _, _ in seen])
        part = args.tracks.with_name(args.tracks.name + ".part")
        part.write_text("frame,fp,x,y\n" + "".join(rows))
        part.replace(args.tracks)
        print(f"portrait: {args.stream} played on the head, {len(rows) // len(seen)} frames "
              f"of the points -> {args.tracks}")
    print(f"portrait: {args.image} ({scene.render.resolution_x} x "
          f"{scene.render.resolution_y}), {len(seen)} feature points in view -> {args.csv}")


main()
