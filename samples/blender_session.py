# SPDX-License-Identifier: GPL-3.0-or-later
"""What the sample scripts run inside Blender share: the built module and the add-on on
sys.path (MPEG4FACE_PYTHONPATH is the build's python folder), the add-on enabled, and the
script's own arguments (those after Blender's `--`)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ADDON = "mpeg4face_blender"


def start() -> list[str]:
    """Prepares the session; returns the script's arguments."""
    build = os.environ.get("MPEG4FACE_PYTHONPATH", str(ROOT / "build/release/python"))
    for path in (build, str(ROOT / "blender_addon")):
        if path not in sys.path:
            sys.path.insert(0, path)
    sys.dont_write_bytecode = True
    import addon_utils

    if addon_utils.enable(ADDON, default_set=True) is None:
        raise SystemExit(f"{ADDON}: the add-on did not enable (see the messages above)")
    argv = sys.argv
    return argv[argv.index("--") + 1:] if "--" in argv else []


def save_sheet(paths: list[Path], out: Path, columns: int) -> None:
    """The images (all of one size) tiled `columns` wide, in reading order, as a PNG written
    through a .part name. Inside Blender: bpy loads and saves the images."""
    import bpy
    import numpy as np

    tiles = []
    for path in paths:
        image = bpy.data.images.load(str(path))
        width, height = image.size
        tiles.append(np.array(image.pixels[:], dtype=np.float32).reshape(height, width, 4))
        bpy.data.images.remove(image)
    gap = 6
    rows = -(-len(tiles) // columns)
    sheet = np.ones((rows * (height + gap) + gap, columns * (width + gap) + gap, 4),
                    dtype=np.float32)
    for i, tile in enumerate(tiles):
        # Blender's pixel rows run bottom to top: the first tile goes at the top.
        r, c = rows - 1 - i // columns, i % columns
        y, x = gap + r * (height + gap), gap + c * (width + gap)
        sheet[y:y + height, x:x + width] = tile
    image = bpy.data.images.new("contact sheet", sheet.shape[1], sheet.shape[0], alpha=False)
    image.pixels.foreach_set(sheet.ravel())
    part = out.with_name(out.stem + ".part.png")
    image.filepath_raw = str(part)
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)
    part.replace(out)
