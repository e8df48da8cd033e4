# SPDX-License-Identifier: GPL-3.0-or-later
"""mpeg4face.check_motion on a small head (a 3 x 3 sheet with a key that stretches an edge
3 times, its corner a spike, and one that stays within the limits), its limits, a stream,
the Blender add-on's bpy-free view of the result (mpeg4face_blender.logic.check), and
mpeg4face.surface_bump on a grid."""

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
    small[:] = [0, 0, 0.06]
    small[4] = [0, 0, 0.1]  # a smooth dent: the centre's bump is 40% of its motion
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
    assert stretch["failures"] == ["edge ratio p99 2.24 > 2",
                                   "1 spike vertex (bump 1.00 x the local motion > 0.75)"]
    vertices = stretch["meshes"][0]["offending_vertices"]
    assert vertices.dtype == np.int32 and 0 in vertices.tolist()
    # The corner moved alone, its ring still: bump = local motion.
    assert stretch["spikes"] == 1 and stretch["bump_ratio_max"] == pytest.approx(1.0)
    spikes = stretch["meshes"][0]["spike_vertices"]
    assert spikes.dtype == np.int32 and spikes.tolist() == [0]
    assert small["spikes"] == 0 and small["bump_ratio_max"] == pytest.approx(0.4)
    assert small["meshes"][0]["spike_vertices"].tolist() == []
    assert any("lower-lip share not measured" in n for n in result["notes"])


def test_limits_and_a_stream():
    mask = np.zeros((2, 68), bool)
    mask[1, 1] = True  # FAP 2: expression 2 fully on in frame 1
    stream = mpeg4face.FapStream.from_arrays(
        [0, 1], mask, np.zeros((2, 68), np.int32),
        expressions=[[0, 0, 0, 0, 0, 0], [2, 63, 0, 0, 0, 0]], name="s")
    r = mpeg4face.check_motion(sheet_head(), [stream], max_edge_ratio=3.5)
    assert not r["passed"]  # the spike
    assert r["frames"][1]["failures"] == ["1 spike vertex (bump 1.00 x the local motion > 0.75)"]
    r = mpeg4face.check_motion(sheet_head(), [stream], max_edge_ratio=3.5, max_spikes=1)
    assert r["passed"]
    assert mpeg4face.check_motion(sheet_head(), [stream], max_edge_ratio=3.5,
                                  spike_ratio=1.01)["passed"]
    assert mpeg4face.check_motion(sheet_head(), [stream], max_edge_ratio=3.5,
                                  spike_of_peak=1.0)["passed"]
    assert [f["frame"] for f in r["frames"]] == [0, 1]
    assert r["frames"][1]["edge_ratio_max"] == pytest.approx(3.0, rel=1e-5)
    assert r["streams"][0]["name"] == "s"
    with pytest.raises(TypeError):
        mpeg4face.check_motion("head.glb")


def test_panel_rows_and_selection(result):
    assert check_logic.headline(result) == "FAIL: 1 of 2 keys past the limits"
    rows = check_logic.worst(result, "keys")
    assert [(r.kind, r.index, r.name) for r in rows] == [("keys", 1, "expression2_stretch")]
    assert rows[0].text == ("edge ratio p99 2.24 > 2; "
                            "1 spike vertex (bump 1.00 x the local motion > 0.75)")
    assert check_logic.worst(result, "frames") == []
    assert 0 in check_logic.offending_vertices(result, "keys", 1)
    assert check_logic.offending_vertices(result, "keys", 7) == []
    assert check_logic.offending_vertices(result, "keys", 1, mesh=3) == []
    assert check_logic.spikes(result) == (
        "Spikes: 1 key; worst 1.00 x the local motion (expression2_stretch, 1 vertex)")
    assert check_logic.spike_vertices(result, "keys", 1) == [0]
    assert check_logic.spike_vertices(result, "keys", 0) == []
    assert check_logic.spike_vertices(result, "frames", 0) == []
    assert check_logic.spikes({"keys": [result["keys"][0]], "frames": []}) is None


def grid(n: int, seam: bool = False) -> tuple[mpeg4face.IndexedFaceSet, np.ndarray]:
    """An n x n grid over [-1, 1]^2 (two triangles per square) and, with `seam`, the column
    x = 0 split: the squares right of it use copies of its vertices (appended). Returns the
    mesh and, per vertex, its original vertex."""
    xs = np.linspace(-1, 1, n)
    coord = np.array([[x, y, 0.0] for y in xs for x in xs])
    source = np.arange(n * n)
    mid = n // 2
    copy = {}
    if seam:
        for j in range(n):
            copy[j] = len(coord)
            coord = np.vstack([coord, coord[j * n + mid]])
            source = np.append(source, j * n + mid)
    faces = []
    for j in range(n - 1):
        for i in range(n - 1):
            left = (lambda jj: copy[jj]) if seam and i == mid else (lambda jj: jj * n + i)
            faces += [left(j), j * n + i + 1, (j + 1) * n + i + 1, left(j + 1), -1]
    return mpeg4face.IndexedFaceSet("grid", coord, faces), source


def test_surface_bump_of_a_smooth_field_and_a_spike():
    mesh, _ = grid(31)
    xy = mesh.coord[:, :2]
    smooth = np.zeros_like(mesh.coord)
    smooth[:, 2] = np.exp(-((xy ** 2).sum(1)) / (2 * 0.35 ** 2))
    b = mpeg4face.surface_bump(mesh, smooth)
    assert b["bump"].shape == (31 * 31,) and b["local_motion"].dtype == np.float64
    assert b["peak"] == pytest.approx(1.0)
    assert b["spikes"].dtype == np.int32 and b["spikes"].tolist() == []
    assert 0.005 < b["bump_p99_of_peak"] < 0.05
    assert b["bump_ratio_max"] == 0.0
    pushed = 5 * 31 + 7  # far from the top: the field is 0.05 there
    spiky = smooth.copy()
    spiky[pushed] += [0, 0, 0.4]
    s = mpeg4face.surface_bump(mesh, spiky)
    assert s["spikes"].tolist() == [pushed]
    assert s["bump"][pushed] == pytest.approx(0.4, abs=0.01)
    assert s["bump_ratio_max"] == pytest.approx(s["bump"][pushed] / s["local_motion"][pushed])
    assert mpeg4face.surface_bump(mesh, spiky, spike_ratio=0.99)["spikes"].tolist() == []
    assert mpeg4face.surface_bump(mesh, spiky, spike_of_peak=0.5)["spikes"].tolist() == []
    # The same on a grid split along x = 0: a seam vertex pushed is a spike in both copies.
    split, source = grid(31, seam=True)
    seam = 2 * 31 + 15  # (0, -0.87): the field is 0.05 there
    spiky = smooth.copy()
    spiky[seam] += [0, 0, 0.4]
    whole = mpeg4face.surface_bump(mesh, spiky)
    cut = mpeg4face.surface_bump(split, spiky[source])
    np.testing.assert_allclose(cut["bump"], whole["bump"][source], atol=1e-12)
    np.testing.assert_allclose(cut["local_motion"], whole["local_motion"][source], atol=1e-12)
    assert whole["spikes"].tolist() == [seam]
    assert cut["spikes"].tolist() == [seam, 31 * 31 + 2]


def test_surface_bump_bad_input():
    mesh, _ = grid(3)
    with pytest.raises(mpeg4face.Error, match="displacement"):
        mpeg4face.surface_bump(mesh, np.zeros((4, 3)))
    with pytest.raises(ValueError):
        mpeg4face.surface_bump(mesh, np.zeros((9, 2)))
    with pytest.raises(TypeError):
        mpeg4face.surface_bump("mesh", np.zeros((9, 3)))
    on_nothing = mpeg4face.IndexedFaceSet("points", mesh.coord, [])
    b = mpeg4face.surface_bump(on_nothing, np.ones((9, 3)))
    assert np.isnan(b["bump"]).all() and b["peak"] == 0.0 and b["spikes"].tolist() == []


def test_the_heads_own_shapes_spike_is_not_counted():
    """A shape key outside the grammar (the head's own: a scan's ARKit shape) that moves the
    same corner alone makes the stretched key's spike the head's, unless own_shapes=False."""
    head = sheet_head()
    mesh = head.meshes[0]
    own = np.zeros((9, 3))
    own[0] = [-1.5, 0, 0]
    mesh.morph_targets = [*mesh.morph_targets, mpeg4face.MorphTarget("jawOpen", own)]
    head.meshes = [mesh]
    r = mpeg4face.check_motion(head)
    assert r["own_shapes"] == ["jawOpen"]
    stretch = r["keys"][1]
    assert stretch["spikes"] == 0 and stretch["own_shape_faults"] == 1
    assert stretch["meshes"][0]["own_shape_faults"] == 1
    assert stretch["failures"] == ["edge ratio p99 2.24 > 2"]
    strict = mpeg4face.check_motion(head, own_shapes=False)
    assert strict["own_shapes"] == []
    assert strict["keys"][1]["spikes"] == 1
