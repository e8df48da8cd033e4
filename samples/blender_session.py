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


def head_object():
    """The scene's head: the root mesh object holding feature points (FP_ vertex groups)."""
    import bpy
    from mpeg4face_blender.logic import feature_points

    for obj in bpy.context.scene.objects:
        if obj.type == "MESH" and obj.parent is None and any(
                feature_points.feature_point_of_group(g.name) for g in obj.vertex_groups):
            return obj
    raise SystemExit("the scene has no head (a mesh with FP_ vertex groups)")


# Regions to render: the mouth between the nose and the chin, as wide as the cheeks; the
# face from the hairline to the chin.
REGIONS = {"mouth": ("9.15", "2.1", "5.3", "5.4"), "face": ("11.1", "4.5", "4.6", "2.1")}


def crop_to(head, points: tuple[str, ...], resolution: int, margin: float = 0.04) -> None:
    """A render border around the head's feature points in the camera's view (with `margin`
    of the view around them), cropped to it, of a frame `resolution` pixels square."""
    import bpy
    from bpy_extras.object_utils import world_to_camera_view

    scene = bpy.context.scene
    corners = []
    for name in points:
        group = head.vertex_groups.get(f"FP_{name}")
        if group is None:
            raise SystemExit(f"the head has no feature point {name}")
        vertex = next(v for v in head.data.vertices
                      if any(g.group == group.index for g in v.groups))
        corners.append(world_to_camera_view(scene, scene.camera, head.matrix_world @ vertex.co))
    render = scene.render
    render.border_min_x = max(0.0, min(c.x for c in corners) - margin)
    render.border_max_x = min(1.0, max(c.x for c in corners) + margin)
    render.border_min_y = max(0.0, min(c.y for c in corners) - margin)
    render.border_max_y = min(1.0, max(c.y for c in corners) + margin)
    render.use_border = render.use_crop_to_border = True
    render.resolution_x = render.resolution_y = resolution
    render.resolution_percentage = 100


def stamp_note(size: int) -> None:
    """Only a note burnt into each render (its text set per tile: render.stamp_note_text)."""
    import bpy

    render = bpy.context.scene.render
    render.image_settings.file_format = "PNG"
    render.use_stamp = True
    for flag in ("date", "time", "render_time", "camera", "lens", "scene", "filename",
                 "memory", "frame"):
        setattr(render, f"use_stamp_{flag}", False)
    render.use_stamp_note = True
    render.stamp_font_size = size


def save_sheet(paths: list[Path], out: Path, columns: int) -> None:
    """The images tiled `columns` wide, in reading order, each centred in a cell as large as
    the largest, as a PNG written through a .part name. Inside Blender: bpy loads and saves
    the images."""
    import bpy
    import numpy as np

    tiles = []
    for path in paths:
        image = bpy.data.images.load(str(path))
        w, h = image.size
        tiles.append(np.array(image.pixels[:], dtype=np.float32).reshape(h, w, 4))
        bpy.data.images.remove(image)
    height, width = max(t.shape[0] for t in tiles), max(t.shape[1] for t in tiles)
    gap = 6
    rows = -(-len(tiles) // columns)
    sheet = np.ones((rows * (height + gap) + gap, columns * (width + gap) + gap, 4),
                    dtype=np.float32)
    for i, tile in enumerate(tiles):
        # Blender's pixel rows run bottom to top: the first tile goes at the top.
        r, c = rows - 1 - i // columns, i % columns
        y = gap + r * (height + gap) + (height - tile.shape[0]) // 2
        x = gap + c * (width + gap) + (width - tile.shape[1]) // 2
        sheet[y:y + tile.shape[0], x:x + tile.shape[1]] = tile
    image = bpy.data.images.new("contact sheet", sheet.shape[1], sheet.shape[0], alpha=False)
    image.pixels.foreach_set(sheet.ravel())
    part = out.with_name(out.stem + ".part.png")
    # Saved as the scene's render output, 8-bit RGB at the highest compression (docs keep
    # these sheets), through the Standard view so the tiles' colours come back unchanged.
    scene = bpy.context.scene
    scene.view_settings.view_transform, scene.view_settings.look = "Standard", "None"
    scene.view_settings.exposure, scene.view_settings.gamma = 0.0, 1.0
    settings = scene.render.image_settings
    settings.file_format, settings.color_mode, settings.color_depth = "PNG", "RGB", "8"
    settings.compression = 100
    image.save_render(str(part), scene=scene)
    bpy.data.images.remove(image)
    part.replace(out)
