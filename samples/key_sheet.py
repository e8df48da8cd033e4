# SPDX-License-Identifier: GPL-3.0-or-later
"""Renders a head's viseme and expression keys as a contact sheet, each key alone at 1 with
its pose (the timeline marker of the same name: the jaw's teeth), around the mouth or the
whole face.

    blender -b samples/build/makehuman_head.blend --python-exit-code 1 \\
        --python samples/key_sheet.py -- OUT.png [--keys viseme|expression|all] \\
        [--region mouth|face] [--columns N] [--title TEXT] [--resolution PIXELS]

Workbench, as the .blend is staged (samples/make_blend.py). Writes OUT.png through a .part
name; the tiles go to a temporary folder.
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
from bpy_extras.object_utils import world_to_camera_view  # noqa: E402
from mpeg4face_blender import fp_logic, poses  # noqa: E402

KEY = re.compile(r"(viseme|expression)(\d+)")
# The regions rendered: the mouth between the nose and the chin, as wide as the cheeks; the
# face from the hairline to the chin.
REGIONS = {"mouth": ("9.15", "2.1", "5.3", "5.4"), "face": ("11.1", "4.5", "4.6", "2.1")}
MARGIN = 0.04  # of the camera view, around those points


def head_object() -> bpy.types.Object:
    for obj in bpy.context.scene.objects:
        if obj.type == "MESH" and obj.parent is None and any(
                fp_logic.feature_point_of_group(g.name) for g in obj.vertex_groups):
            return obj
    raise SystemExit("key_sheet: the scene has no head (a mesh with FP_ vertex groups)")


def frame(head: bpy.types.Object, points: tuple[str, ...], resolution: int) -> None:
    """A render border around the feature points in the camera's view, cropped to it, of a
    frame `resolution` pixels square."""
    scene = bpy.context.scene
    corners = []
    for name in points:
        group = head.vertex_groups.get(f"FP_{name}")
        if group is None:
            raise SystemExit(f"key_sheet: the head has no feature point {name}")
        vertex = next(v for v in head.data.vertices
                      if any(g.group == group.index for g in v.groups))
        corners.append(world_to_camera_view(scene, scene.camera, head.matrix_world @ vertex.co))
    render = scene.render
    render.border_min_x = max(0.0, min(c.x for c in corners) - MARGIN)
    render.border_max_x = min(1.0, max(c.x for c in corners) + MARGIN)
    render.border_min_y = max(0.0, min(c.y for c in corners) - MARGIN)
    render.border_max_y = min(1.0, max(c.y for c in corners) + MARGIN)
    render.use_border = render.use_crop_to_border = True
    render.resolution_x = render.resolution_y = resolution


def main() -> None:
    parser = argparse.ArgumentParser(prog="key_sheet.py")
    parser.add_argument("out", type=Path)
    parser.add_argument("--keys", choices=("viseme", "expression", "all"), default="all")
    parser.add_argument("--region", choices=sorted(REGIONS), default="mouth")
    parser.add_argument("--columns", type=int, default=5)
    parser.add_argument("--title", default="")
    parser.add_argument("--resolution", type=int, default=900,
                        help="of the whole camera frame, of which the mouth is a part")
    args = parser.parse_args(ARGS)
    scene = bpy.context.scene
    head = head_object()
    blocks = head.data.shape_keys.key_blocks
    found = {k.name: KEY.fullmatch(k.name.split("_")[0]) for k in blocks}
    keys = sorted((n for n, m in found.items() if m and args.keys in ("all", m[1])),  # visemes first, by number
                  key=lambda n: (found[n][1] != "viseme", int(found[n][2])))
    if not keys:
        raise SystemExit(f"key_sheet: the head has no {args.keys} keys")
    markers = {m.name: m.frame for m in scene.timeline_markers}
    frame(head, REGIONS[args.region], args.resolution)
    render = scene.render
    render.image_settings.file_format = "PNG"
    render.use_stamp = True
    for flag in ("date", "time", "render_time", "camera", "lens", "scene", "filename",
                 "memory", "frame"):
        setattr(render, f"use_stamp_{flag}", False)
    render.use_stamp_note = True
    render.stamp_font_size = 16
    tiles = []
    with tempfile.TemporaryDirectory() as folder:
        for n, name in enumerate(keys, 1):
            for block in blocks:
                block.value = 0.0
            blocks[name].value = 1.0
            scene.frame_set(markers.get(name, markers.get(poses.NEUTRAL_MARKER, 1)))
            render.stamp_note_text = f"{args.title} {name}".strip()
            render.filepath = str(Path(folder) / f"{n:02d}.png")
            bpy.ops.render.render(write_still=True)
            tiles.append(Path(render.filepath))
        blender_session.save_sheet(tiles, args.out, args.columns)
    print(f"key_sheet: {len(keys)} keys -> {args.out}")


main()
