# SPDX-License-Identifier: GPL-3.0-or-later
"""The pictures of docs/blender.md's "Rigged heads": Rigify's meta-rig face bound to the
MakeHuman head (as tests/blender/test_addon_rigify.py binds it), posed to FAPs by "Pose
FAPs with Bones", rendered at its markers; and the FaceDefTables generated from that rig,
evaluated at the same amplitudes by the live preview, rendered the same way.

    blender -b --factory-startup --python-exit-code 1 --python samples/rig_pictures.py -- \\
        docs/images/rigify_poses.png docs/images/rigify_tables.png [--amplitude 256]

Workbench; writes each sheet through a .part name.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import blender_session  # noqa: E402

ARGS = blender_session.start()

import bpy  # noqa: E402
import numpy as np  # noqa: E402
import mpeg4face  # noqa: E402
from mathutils import Vector  # noqa: E402

sys.path.insert(0, str(blender_session.ROOT / "tests" / "blender"))
from test_addon_rigify import face_metarig, makehuman_skin  # noqa: E402

from mpeg4face_blender.logic import shape_keys  # noqa: E402
from mpeg4face_blender.scene import live_preview, stream_data  # noqa: E402
from mpeg4face_blender.ui.operators import faces as operators_faces  # noqa: E402

FAPS = (3, 15, 4, 5, 6, 12, 19, 21, 31, 35)


def stage(head: bpy.types.Object) -> None:
    """A Workbench scene with an orthographic camera looking at the face (along +Y)."""
    scene = bpy.context.scene
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.light = "STUDIO"
    scene.display.shading.color_type = "SINGLE"
    scene.display.shading.single_color = (0.8, 0.65, 0.55)
    scene.view_settings.view_transform = "Standard"
    corners = [head.matrix_world @ Vector(c) for c in head.bound_box]
    centre = sum(corners, Vector()) / 8
    size = max((c - centre).length for c in corners)
    data = bpy.data.cameras.new("camera")
    data.type = "ORTHO"
    data.ortho_scale = 1.6 * size
    camera = bpy.data.objects.new("camera", data)
    scene.collection.objects.link(camera)
    camera.location = centre + Vector((0.0, -4 * size, 0.0))
    camera.rotation_euler = (math.pi / 2, 0.0, 0.0)
    scene.camera = camera
    scene.render.resolution_x = scene.render.resolution_y = 480  # square, before crop_to
    bpy.context.view_layer.update()  # the camera's matrix, for crop_to


def render_sheet(head, frames: list[tuple[int, str]], out: Path, columns: int) -> None:
    scene = bpy.context.scene
    render = scene.render
    tiles = []
    with tempfile.TemporaryDirectory() as folder:
        for n, (frame, note) in enumerate(frames):
            scene.frame_set(frame)
            render.stamp_note_text = note
            render.filepath = str(Path(folder) / f"{n:02d}.png")
            bpy.ops.render.render(write_still=True)
            tiles.append(Path(render.filepath))
        blender_session.save_sheet(tiles, out, columns)


def main() -> None:
    parser = argparse.ArgumentParser(prog="rig_pictures.py")
    parser.add_argument("poses_png", type=Path)
    parser.add_argument("tables_png", type=Path)
    parser.add_argument("--amplitude", type=int, default=256)
    args = parser.parse_args(ARGS)
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    scene = bpy.context.scene
    head, fp_vertices = makehuman_skin()
    face_metarig(head, fp_vertices)
    if bpy.ops.mpeg4face.pose_faps_bones(amplitude=args.amplitude) != {"FINISHED"}:
        raise SystemExit("rig_pictures: Pose FAPs with Bones failed")
    stage(head)
    blender_session.crop_to(head, blender_session.REGIONS["face"], 480)
    blender_session.stamp_note(11)
    markers = {m.name: m.frame for m in scene.timeline_markers}
    names = [shape_keys.key_name("FAP", f, args.amplitude) for f in FAPS]
    shown = [(markers["neutral"], "neutral")] + [(markers[n], n) for n in names if n in markers]
    render_sheet(head, shown, args.poses_png, 4)

    # The tables: frame i of a stream sends FAP i of the sheet at the amplitude, alone.
    faps = [0] + [int(n.split("_")[0][3:]) for _, n in shown[1:]]
    mask = np.zeros((len(faps), 68), dtype=bool)
    values = np.zeros((len(faps), 68), dtype=np.int32)
    mask[:, 2:] = True  # every low-level FAP: an unsent partner (7 of 6) would follow it
    for i, fap in enumerate(faps):
        if fap:
            values[i, fap - 1] = args.amplitude
    stream = mpeg4face.FapStream.from_arrays(np.arange(len(faps)), mask, values,
                                             frame_rate=scene.render.fps)
    start = max(markers.values()) + 10
    keys = stream_data.grammar_keys(head)
    live_preview.start_live(head, scene, keys, stream, start)
    render_sheet(head, [(start + i, f"table {note}") for i, (_, note) in enumerate(shown)],
                 args.tables_png, 4)
    live_preview.stop_live(head)
    report = operators_faces.generate(head, 0.01, scene)[1]
    print(f"rig_pictures: {len(shown) - 1} poses, {report.lines()[0]} -> {args.poses_png}, "
          f"{args.tables_png}")


main()
