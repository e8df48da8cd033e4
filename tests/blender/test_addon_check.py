# SPDX-License-Identifier: GPL-3.0-or-later
"""The Motion Check panel's operators on CANDIDE-3: a key that pulls the chin far down
fails the check, and selecting its offending vertices selects the chin in Edit Mode. Run
through run_in_blender.py."""

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="runs inside Blender only (see run_in_blender.py)")

import mpeg4face  # noqa: E402

from mpeg4face_blender.logic import check as check_logic  # noqa: E402
from mpeg4face_blender.scene import mesh_data  # noqa: E402
from mpeg4face_blender.ui.operators import check as operators_check  # noqa: E402


def test_check_and_select(candide_head, tmp_path):
    obj, _, fp_vertices = candide_head
    chin = fp_vertices["2.1"]
    obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name="expression1_pull", from_mix=False)
    coords = mesh_data.shape_key_coords(key)
    coords[chin] += (0, 0, -0.5)  # Blender's -Z: far down, the chin's edges stretch
    mesh_data.set_shape_key_coords(key, coords)

    assert bpy.ops.mpeg4face.check_motion() == {"FINISHED"}
    result = operators_check.results[obj.name]
    assert not result["passed"]
    rows = check_logic.worst(result, "keys")
    assert [r.name for r in rows] == ["expression1_pull"]
    assert "edge ratio p99" in rows[0].text

    assert bpy.ops.mpeg4face.select_offending(kind="keys", index=rows[0].index) == {"FINISHED"}
    assert obj.mode == "EDIT"
    with mesh_data.face_bmesh(obj) as bm:
        selected = mesh_data.selected_vertices(bm)
    assert chin in selected
    assert set(selected) == set(check_logic.offending_vertices(result, "keys", rows[0].index))
    # Without a stream imported, "with the stream" says so instead of checking; with one,
    # its frames are checked through the tables made from the keys.
    bpy.ops.object.mode_set(mode="OBJECT")
    with pytest.raises(RuntimeError, match="No stream imported"):
        bpy.ops.mpeg4face.check_motion(with_stream=True)
    mask = np.zeros((2, 68), bool)
    mask[1, 1] = True  # frame 1: expression 1 fully on
    stream = mpeg4face.FapStream.from_arrays(
        [0, 1], mask, np.zeros((2, 68), np.int32),
        expressions=[[0, 0, 0, 0, 0, 0], [1, 63, 0, 0, 0, 0]])
    mpeg4face.write_fap(stream, tmp_path / "pull.fap")
    obj.mpeg4face_stream.filepath = str(tmp_path / "pull.fap")
    assert bpy.ops.mpeg4face.check_motion(with_stream=True) == {"FINISHED"}
    result = operators_check.results[obj.name]
    assert [r.name for r in check_logic.worst(result, "frames")] == ["pull.fap frame 1"]
