# SPDX-License-Identifier: GPL-3.0-or-later
"""File > Import > 2D mesh sequence: a textured plane whose vertices follow the frames.
Run through run_in_blender.py."""

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import mpeg4face  # noqa: E402


def test_import_mesh2d(tmp_path):
    y, x = np.mgrid[0:40, 0:60]
    image = tmp_path / "t.png"
    bpy_image = bpy.data.images.new("t", 60, 40)
    pixels = np.ones((40, 60, 4), np.float32)
    pixels[..., 0] = x / 60
    bpy_image.pixels.foreach_set(pixels.reshape(-1))
    bpy_image.filepath_raw = str(image)
    bpy_image.file_format = "PNG"
    bpy_image.save()
    frame0 = np.array([[x0, y0] for y0 in (0, 19.5, 39) for x0 in (0, 29.5, 59)], float)
    frames = np.array([frame0, frame0 + [[2, 0]] * 9, frame0 + [[4, -1]] * 9])
    uniform = {"nodes_x": 3, "nodes_y": 3, "x0": 0, "y0": 0, "dx": 29.5, "dy": 19.5,
               "topology": 0}
    sequence = {"width": 60, "height": 40, "mesh": "uniform", "uniform": uniform,
                "frames": frames}
    # A node that is not where the parameters put it is named.
    bad = frames.copy()
    bad[0, 6, 1] += 1
    with pytest.raises(mpeg4face.Error, match=r"frames\[0\]\[6\]"):
        mpeg4face.write_mesh2d(dict(sequence, frames=bad), tmp_path / "bad.json")
    data, _ = mpeg4face.encode_mesh2d(sequence)
    (tmp_path / "seq.m2d").write_bytes(data)
    assert bpy.ops.mpeg4face.import_mesh2d(filepath=str(tmp_path / "seq.m2d"), image=str(image),
                                           scale=10.0) == {"FINISHED"}
    obj = bpy.context.view_layer.objects.active
    assert len(obj.data.vertices) == 9 and len(obj.data.polygons) == 8
    assert [k.name for k in obj.data.shape_keys.key_blocks] == ["Basis", "frame_00001",
                                                               "frame_00002"]
    assert obj.data.materials[0].node_tree.nodes["Image Texture"].image is not None
    bpy.context.scene.frame_set(3)  # start frame 1: sequence frame 2
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    co = np.array([v.co[:] for v in evaluated.vertices])
    assert np.allclose(co[:, 0], frames[2][:, 0] / 10, atol=1e-5)
    assert np.allclose(co[:, 2], -frames[2][:, 1] / 10, atol=1e-5)
    # Faces point at the front view (-Y).
    assert all(p.normal.y < 0 for p in obj.data.polygons)
