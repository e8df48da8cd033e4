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
from mpeg4face_blender.scene import poses  # noqa: E402

KEY = re.compile(r"(viseme|expression)(\d+)")


def main() -> None:
    parser = argparse.ArgumentParser(prog="key_sheet.py")
    parser.add_argument("out", type=Path)
    parser.add_argument("--keys", choices=("viseme", "expression", "all"), default="all")
    parser.add_argument("--region", choices=sorted(blender_session.REGIONS), default="mouth")
    parser.add_argument("--columns", type=int, default=5)
    parser.add_argument("--title", default="")
    parser.add_argument("--resolution", type=int, default=900,
                        help="of the whole camera frame, of which the mouth is a part")
    args = parser.parse_args(ARGS)
    scene = bpy.context.scene
    head = blender_session.head_object()
    blocks = head.data.shape_keys.key_blocks
    found = {k.name: KEY.fullmatch(k.name.split("_")[0]) for k in blocks}
    keys = sorted((n for n, m in found.items() if m and args.keys in ("all", m[1])),  # visemes first, by number
                  key=lambda n: (found[n][1] != "viseme", int(found[n][2])))
    if not keys:
        raise SystemExit(f"key_sheet: the head has no {args.keys} keys")
    markers = {m.name: m.frame for m in scene.timeline_markers}
    blender_session.crop_to(head, blender_session.REGIONS[args.region], args.resolution)
    blender_session.stamp_note(16)
    render = scene.render
    tiles = []
    with tempfile.TemporaryDirectory() as folder:
        # A key is on every mesh it moves (the ICT head's lower teeth and gums open with
        # the jaw): each object's block of that name is set, not only the head's.
        keyed = [o.data.shape_keys.key_blocks for o in scene.objects
                 if o.type == "MESH" and o.data.shape_keys]
        for n, name in enumerate(keys, 1):
            for object_blocks in keyed:
                for block in object_blocks:
                    block.value = 0.0
                if name in object_blocks:
                    object_blocks[name].value = 1.0
            scene.frame_set(markers.get(name, markers.get(poses.NEUTRAL_MARKER, 1)))
            render.stamp_note_text = f"{args.title} {name}".strip()
            render.filepath = str(Path(folder) / f"{n:02d}.png")
            bpy.ops.render.render(write_still=True)
            tiles.append(Path(render.filepath))
        blender_session.save_sheet(tiles, args.out, args.columns)
    print(f"key_sheet: {len(keys)} keys -> {args.out}")


main()
