# SPDX-License-Identifier: GPL-3.0-or-later
"""Smoke test of mpeg4face inside Blender: the module loads, and its numpy arrays build a
Blender mesh. Run through run_in_blender.py, not directly."""

from pathlib import Path

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import mpeg4face  # noqa: E402

DATA = Path(__file__).resolve().parent.parent / "data"


def test_module_loads_in_blender():
    assert mpeg4face.__version__
    assert mpeg4face.fap(3).name == "open_jaw"
    assert mpeg4face.fap(3).quant_step == 4
    assert len(mpeg4face.faps()) == mpeg4face.FAP_COUNT == 68


def test_candide_becomes_a_blender_mesh():
    model = mpeg4face.read_model(DATA / "candide3" / "candide3.wfm")
    mesh = model.meshes[0]
    coord = mesh.coord
    triangles = mesh.triangles()
    assert coord.shape == (113, 3) and triangles.shape == (184, 3)

    data = bpy.data.meshes.new("candide3")
    data.from_pydata(coord.tolist(), [], triangles.tolist())
    data.update()
    obj = bpy.data.objects.new("candide3", data)
    bpy.context.scene.collection.objects.link(obj)
    assert len(obj.data.vertices) == mesh.vertex_count == 113
    assert len(obj.data.polygons) == 184

    # numpy in both directions: Blender's buffers read back equal to the model's arrays.
    back = np.empty(len(data.vertices) * 3, dtype=np.float32)
    data.vertices.foreach_get("co", back)
    np.testing.assert_allclose(back.reshape(-1, 3), coord, atol=1e-6)

    # A morph target as a shape key.
    target = mesh.morph_targets[0]
    obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name=target.name)
    key.data.foreach_set("co", (coord + target.displacements).astype(np.float32).ravel())
    assert obj.data.shape_keys.key_blocks[target.name].name == target.name

    bpy.data.objects.remove(obj)
    bpy.data.meshes.remove(data)
