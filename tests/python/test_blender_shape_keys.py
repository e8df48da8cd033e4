# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's bpy-free shape-key layer: grammar names, slider ranges, suggestions for keys
named otherwise, partner FAPs, mirrored displacements, the FaceModel and the tables report,
on CANDIDE-3."""

import numpy as np
import pytest

import mpeg4face
from mpeg4face_blender.logic import feature_points, shape_keys


@pytest.fixture(scope="module")
def candide(data_dir):
    model = mpeg4face.read_model(data_dir / "candide3" / "candide3.wfm")
    points, _ = mpeg4face.read_feature_point_csv(data_dir / "candide3" / "feature_points.csv", model)
    mesh = model.meshes[0]
    return mesh.coord, mesh.coord_index, {fp: b.vertex for fp, b in points.items()}


def test_axes_round_trip():
    c = np.arange(12.0).reshape(4, 3)
    assert np.array_equal(feature_points.to_blender_axes(feature_points.to_standard_axes(c)), c)


def test_key_names_follow_the_grammar():
    assert shape_keys.key_name("FAP", 3) == "fap3_open_jaw@1024"
    assert shape_keys.key_name("FAP", 6, -300) == "fap6_stretch_l_cornerlip@-300"
    assert shape_keys.key_name("VISEME", 1) == "viseme1_p_b_m"
    assert shape_keys.key_name("VISEME", 10) == "viseme10_A"
    assert shape_keys.key_name("EXPRESSION", 1, intensity=40) == "expression1_joy@40"
    assert shape_keys.key_name("EXPRESSION", 6) == "expression6_surprise"
    for kind, n in (("FAP", 68), ("VISEME", 14), ("EXPRESSION", 6)):
        assert shape_keys.is_grammar_name(shape_keys.key_name(kind, n))
    with pytest.raises(ValueError):
        shape_keys.key_name("BONE", 1)


def test_enum_items():
    faps = shape_keys.fap_enum_items()
    assert len(faps) == 66 and faps[0][:2] == ("3", "3 open_jaw")
    assert len(shape_keys.viseme_enum_items()) == 14
    assert [i[1] for i in shape_keys.expression_enum_items()][0] == "1 joy"


def test_grammar_detection():
    assert shape_keys.is_grammar_name("fap3_open_jaw@512")
    for name in ("jawOpen", "Basis", "fap99", "fap3@512.001", "expressionless"):
        assert not shape_keys.is_grammar_name(name)


def test_slider_range():
    assert shape_keys.slider_range("fap6_stretch_l_cornerlip@300") == (-1.0, 1.0)  # bidirectional
    assert shape_keys.slider_range("fap3_open_jaw@512") == (0.0, 1.0)
    assert shape_keys.slider_range("viseme1") == (0.0, 1.0)
    assert shape_keys.slider_range("expression2@30") == (0.0, 1.0)


@pytest.mark.parametrize("name, kind, number", [
    ("jawOpen", "FAP", 3), ("JawOpen", "FAP", 3), ("mouthOpen", "FAP", 3),
    ("blink_L", "FAP", 19), ("eyeBlinkRight", "FAP", 20), ("mouthSmileLeft", "FAP", 12),
    ("mouthStretch_R", "FAP", 7), ("browInnerUp", "FAP", 31), ("cheekPuff", "FAP", 39),
    ("jawForward", "FAP", 14), ("tongueOut", "FAP", 45),
    ("viseme_PP", "VISEME", 1), ("V_aa", "VISEME", 10), ("happy", "EXPRESSION", 1),
    ("Surprise", "EXPRESSION", 6), ("fap6@-30", "FAP", 6), ("viseme2", "VISEME", 2),
])
def test_suggestions(name, kind, number):
    assert shape_keys.suggest(name) == shape_keys.Suggestion(kind, number)


@pytest.mark.parametrize("name", ["Key 1", "Basis", "E", "sculpt"])
def test_no_suggestion(name):
    assert shape_keys.suggest(name) is None


def test_words():
    assert shape_keys.words("eyeBlink_L") == ["eye", "blink", "l"]
    assert shape_keys.words("mouthStretch.R") == ["mouth", "stretch", "r"]


def test_fap_partners():
    partners = shape_keys.fap_partners()
    assert len(partners) == 46  # 23 pairs
    assert partners[6] == 7 and partners[8] == 9 and partners[53] == 54 and partners[67] == 68
    assert all(partners[b] == a for a, b in partners.items())
    assert 3 not in partners and 15 not in partners


def test_mirrored_key():
    m = shape_keys.mirrored_key("fap6_stretch_l_cornerlip@300")
    assert (m.name, m.partner, m.amplitude) == ("fap7_stretch_r_cornerlip@300", 7, 300)
    # Both eyeballs turn left for positive values: the mirror image is the negative value.
    assert shape_keys.mirrored_key("fap23@500").name == "fap24_yaw_r_eyeball@-500"
    with pytest.raises(ValueError, match="no left/right partner"):
        shape_keys.mirrored_key("fap3_open_jaw@512")
    with pytest.raises(ValueError, match="not a FAP key"):
        shape_keys.mirrored_key("viseme1")


def test_mirror_displacements():
    coords = np.array([[1.0, 0, 0], [-1.0, 0, 0], [0, 1, 0], [2.0, 5, 0]])
    partners = shape_keys.mirror_vertices(coords, 1e-6, chunk=2)
    assert partners.tolist() == [1, 0, 2, -1]
    d = np.array([[0.1, 0.2, 0.3], [0, 0, 0], [0.5, 0, 0], [1, 1, 1]])
    mirrored = shape_keys.mirror_displacements(d, partners)
    assert np.allclose(mirrored, [[0, 0, 0], [-0.1, 0.2, 0.3], [-0.5, 0, 0], [0, 0, 0]])


def test_mirror_candide_is_symmetric(candide):
    coords, _, _ = candide
    partners = shape_keys.mirror_vertices(coords, feature_points.mirror_tolerance(coords, 0.001))
    assert (partners >= 0).all()
    # Coinciding vertices (the closed lips) may swap, so compare places, not indices.
    assert np.allclose(coords[partners], coords * (-1.0, 1.0, 1.0), atol=1e-3)


def test_mirror_plane_follows_the_feature_points(candide):
    """A head turned and moved off X = 0 mirrors across the plane its left/right feature
    point pairs give, not across X = 0."""
    coords, _, fp_vertices = candide
    angle = np.radians(10)  # about the standard's vertical Y
    turn = np.array([[np.cos(angle), 0, np.sin(angle)], [0, 1, 0],
                     [-np.sin(angle), 0, np.cos(angle)]])
    moved = coords @ turn.T + (0.3, -0.1, 0.2)
    plane = shape_keys.symmetry_plane(moved, fp_vertices)
    assert plane.pairs >= 20
    assert np.allclose(plane.normal, turn @ (1, 0, 0), atol=1e-3)
    assert abs((np.array([0.3, -0.1, 0.2]) - plane.point) @ plane.normal) < 1e-3
    tolerance = feature_points.mirror_tolerance(moved, 0.001)
    partners = shape_keys.mirror_vertices(moved, tolerance, plane)
    assert (partners >= 0).all()
    assert np.allclose(moved[partners], plane.reflect_points(moved), atol=2e-3)
    # Across X = 0 the moved head has almost no mirror vertices.
    assert (shape_keys.mirror_vertices(moved, tolerance) < 0).sum() > len(moved) // 2
    # A displacement to the left comes back to the right, in the turned frame.
    d = np.zeros_like(moved)
    d[fp_vertices["8.3"]] = turn @ (0.05, 0, 0)
    mirrored = shape_keys.mirror_displacements(d, partners, plane)
    assert np.allclose(mirrored[fp_vertices["8.4"]], turn @ (-0.05, 0, 0), atol=1e-9)
    # Without a pair set: X = 0.
    assert shape_keys.symmetry_plane(moved, {"2.1": fp_vertices["2.1"]}) == shape_keys.X_PLANE


def test_face_model_and_report(candide):
    coords, index, fp_vertices = candide
    d = np.zeros_like(coords)
    d[fp_vertices["2.1"]] = (0, -0.1, 0)
    model = feature_points.face_model_from_arrays(coords, index, fp_vertices,
                                {"fap3_open_jaw@512": d, "jawOpen": d})
    assert [t.name for t in model.meshes[0].morph_targets] == ["fap3_open_jaw@512", "jawOpen"]
    report = shape_keys.tables_report(mpeg4face.generate_face(model))
    assert report.covered == ["fap3 open_jaw"] and report.moved == [1]
    assert report.copies == 1 and report.ignored == ["jawOpen"]
    assert report.lines()[0] == "1 FaceDefTables from 1 shape keys"
    assert "ignored (not in the grammar): jawOpen" in report.lines()
    with_groups = shape_keys.tables_report(mpeg4face.generate_face(model), ["group FP_x"])
    assert with_groups.warnings == ["group FP_x"]
    assert "warning: group FP_x" in with_groups.lines()


def test_table_titles():
    assert shape_keys.table_title(1, 1) == "viseme 1 (p, b, m)"
    assert shape_keys.table_title(2, 3) == "expression 3 (anger)"


def test_cloned_shapes_in_blender_axes():
    copies = [{"name": "fap3@5", "meshes": [{"mesh": 0, "vertices": np.array([4], np.int32),
                                             "displacement": np.array([[1.0, 2.0, 3.0]])}]},
              {"name": "fap4@5", "meshes": []}]
    shapes = shape_keys.cloned_shapes(copies)
    vertices, displacement = shapes["fap3@5"]
    assert vertices.tolist() == [4]
    assert displacement.tolist() == [[1.0, -3.0, 2.0]]
    assert [len(a) for a in shapes["fap4@5"]] == [0, 0]  # moves nothing


def test_moved_coords_whole_or_sparse():
    basis = np.arange(15, dtype=np.float64).reshape(5, 3)
    whole = np.ones((5, 3))
    assert np.array_equal(shape_keys.moved_coords(basis, whole), basis + 1)
    sparse = (np.array([1, 3], np.int32), np.array([[1.0, 0, 0], [0, 0, 2.0]]))
    moved = shape_keys.moved_coords(basis, sparse)
    assert np.array_equal(moved[[0, 2, 4]], basis[[0, 2, 4]])
    assert moved[1].tolist() == [4.0, 4.0, 5.0] and moved[3].tolist() == [9.0, 10.0, 13.0]
    assert np.array_equal(basis, np.arange(15).reshape(5, 3))  # the Basis is not touched
