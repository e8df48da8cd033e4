# SPDX-License-Identifier: GPL-3.0-or-later
"""mpeg4face.check_motion on a small head (a 3 x 3 sheet with a key that stretches an edge
3 times and one that stays within the limits), its limits, a stream, and the Blender
add-on's bpy-free view of the result (mpeg4face_blender.logic.check)."""

import numpy as np
import pytest

import mpeg4face
from mpeg4face_blender.logic import check as check_logic


def sheet_head() -> mpeg4face.FaceModel:
    coord = np.array([[x, y, 0.0] for y in range(3) for x in range(3)]) + [10, 0, 0]
    faces = []
    for j in range(2):
        for i in range(2):
            a = 3 * j + i
            faces += [a, a + 1, a + 4, -1, a, a + 4, a + 3, -1]
    stretch = np.zeros((9, 3))
    stretch[0] = [-2, 0, 0]  # the edge 0-1 of length 1 becomes 3
    small = np.zeros((9, 3))
    small[4] = [0, 0, 0.1]
    mesh = mpeg4face.IndexedFaceSet("skin", coord, faces, morph_targets=[
        mpeg4face.MorphTarget("expression1_small", small),
        mpeg4face.MorphTarget("expression2_stretch", stretch)])
    model = mpeg4face.FaceModel()
    model.add_mesh_with_transform(mesh)
    for fp, x, y in (("3.5", -1, 2), ("3.6", 1, 2), ("9.15", 0, 1), ("2.2", 0, 0)):
        model.feature_points[fp] = mpeg4face.FeaturePointBinding(position=[x, y, 0])
    return model


@pytest.fixture(scope="module")
def result():
    calls = []
    r = mpeg4face.check_motion(sheet_head(), progress=lambda done, total: calls.append(
        (done, total)))
    assert calls[-1] == (2, 2)
    return r


def test_stretched_key_fails_with_its_vertices(result):
    assert not result["passed"]
    small, stretch = result["keys"]
    assert small["failures"] == []
    assert stretch["name"] == "expression2_stretch"
    assert stretch["edge_ratio_max"] == pytest.approx(3.0)
    assert stretch["failures"] == ["edge ratio p99 2.24 > 2"]
    vertices = stretch["meshes"][0]["offending_vertices"]
    assert vertices.dtype == np.int32 and 0 in vertices.tolist()
    assert any("lower-lip share not measured" in n for n in result["notes"])


def test_limits_and_a_stream():
    mask = np.zeros((2, 68), bool)
    mask[1, 1] = True  # FAP 2: expression 2 fully on in frame 1
    stream = mpeg4face.FapStream.from_arrays(
        [0, 1], mask, np.zeros((2, 68), np.int32),
        expressions=[[0, 0, 0, 0, 0, 0], [2, 63, 0, 0, 0, 0]], name="s")
    r = mpeg4face.check_motion(sheet_head(), [stream], max_edge_ratio=3.5)
    assert r["passed"]
    assert [f["frame"] for f in r["frames"]] == [0, 1]
    assert r["frames"][1]["edge_ratio_max"] == pytest.approx(3.0, rel=1e-5)
    assert r["streams"][0]["name"] == "s"
    with pytest.raises(TypeError):
        mpeg4face.check_motion("head.glb")


def test_panel_rows_and_selection(result):
    assert check_logic.headline(result) == "FAIL: 1 of 2 keys past the limits"
    rows = check_logic.worst(result, "keys")
    assert [(r.kind, r.index, r.name) for r in rows] == [("keys", 1, "expression2_stretch")]
    assert rows[0].text == "edge ratio p99 2.24 > 2"
    assert check_logic.worst(result, "frames") == []
    assert 0 in check_logic.offending_vertices(result, "keys", 1)
    assert check_logic.offending_vertices(result, "keys", 7) == []
    assert check_logic.offending_vertices(result, "keys", 1, mesh=3) == []
