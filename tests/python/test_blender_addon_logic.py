# SPDX-License-Identifier: GPL-3.0-or-later
"""The Blender add-on's bpy-free layer: finding the native module, feature point tables,
FAPU read-out and the mirror helper, on CANDIDE-3."""

import re
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

import mpeg4face
from mpeg4face_blender import native
from mpeg4face_blender.logic import feature_points

DOCS = Path(__file__).resolve().parent.parent.parent / "docs"


@pytest.fixture(scope="module")
def candide(data_dir):
    """CANDIDE-3 with its feature points: (model, coords, coord_index, feature point -> vertex)."""
    model = mpeg4face.read_model(data_dir / "candide3" / "candide3.wfm")
    points, _ = mpeg4face.read_feature_point_csv(data_dir / "candide3" / "feature_points.csv", model)
    model.feature_points = points
    mesh = model.meshes[0]
    return model, mesh.coord, mesh.coord_index, {fp: b.vertex for fp, b in points.items()}


def groups_of(fp_vertices):
    return {feature_points.group_name(fp): [(v, 1.0)] for fp, v in fp_vertices.items()}


def test_native_module_found_on_sys_path(tmp_path):
    status = native.load(lib_dir=tmp_path)
    assert status.ok and status.module is mpeg4face
    assert native.problem(status) == []
    assert native.description(status).startswith(f"mpeg4face {mpeg4face.__version__} from ")


def test_native_module_missing(tmp_path):
    status = native.load(lib_dir=tmp_path, name="mpeg4face_not_built")
    assert not status.ok
    text = "\n".join(native.problem(status, lib_dir=tmp_path))
    assert "ModuleNotFoundError: No module named 'mpeg4face_not_built'" in text
    assert f"Python {native.python_version()}" in text
    assert str(tmp_path / "mpeg4face" / native.expected_file_name()) in text
    assert "run scripts/install_blender_addon.sh" in text
    assert re.fullmatch(r"_core\.cpython-3\d+-.*\.so", native.expected_file_name())


def test_native_module_built_for_another_python(tmp_path):
    # The package's own __init__.py next to an extension this Python cannot load.
    package = tmp_path / "mpeg4face_other"
    package.mkdir()
    shutil.copy(Path(mpeg4face.__file__), package / "__init__.py")
    (package / "_core.cpython-39-x86_64-linux-gnu.so").write_bytes(b"")
    status = native.load(lib_dir=tmp_path, name="mpeg4face_other")
    assert not status.ok
    assert "ImportError" in status.error and "_core.cpython-39" in status.error
    assert sys.path[0] == str(tmp_path)  # lib/ comes first when it has the package
    sys.path.remove(str(tmp_path))


def test_group_names():
    assert feature_points.group_name("2.1") == "FP_2.1"
    assert feature_points.feature_point_of_group("FP_9.15") == "9.15"
    assert feature_points.feature_point_of_group("Group") is None


def test_fapu_points_come_from_the_core():
    assert feature_points.fapu_feature_points() == {
        "ES0": ("3.5", "3.6"),
        "IRISD0": ("3.1", "3.3", "3.2", "3.4"),
        "ENS0": ("3.5", "3.6", "9.15"),
        "MNS0": ("9.15", "2.2"),
        "MW0": ("8.3", "8.4"),
    }
    assert feature_points.fapu_points() == {"3.1", "3.2", "3.3", "3.4", "3.5", "3.6", "9.15", "2.2",
                                      "8.3", "8.4"}


def test_cloning_points_match_docs_clone_md():
    text = (DOCS / "clone.md").read_text()
    section = text.split("## Feature points required", 1)[1].split("\n## ", 1)[0]
    table = re.findall(r"^\| [a-z ,]+ \| ([\d., ]+) \|$", section, re.MULTILINE)
    documented = {p.strip() for row in table for p in row.split(",")}
    assert len(documented) == 43
    assert feature_points.cloning_points() == documented


def test_mirror_partners():
    partners = feature_points.mirror_partners()
    for left, right in [("3.5", "3.6"), ("2.4", "2.5"), ("3.7", "3.12"), ("3.11", "3.8"),
                        ("2.6", "2.7"), ("2.8", "2.9"), ("8.5", "8.6"), ("8.9", "8.10"),
                        ("4.1", "4.2"), ("11.3", "11.2"), ("10.9", "10.10"), ("9.1", "9.2")]:
        assert partners[left] == right and partners[right] == left
    assert all(partners[b] == a and a != b for a, b in partners.items())
    assert all(a.split(".")[0] == b.split(".")[0] for a, b in partners.items())
    # The rest lie on the middle line: their Table 6 x is 7.1.x, or they are 7.1 / 7.2.
    for p in mpeg4face.feature_points():
        if p.id not in partners:
            assert p.constraint_x in ("=7.1.x", "=11.4.x", "") and p.id in {
                "2.1", "2.2", "2.3", "2.10", "6.1", "6.2", "7.1", "7.2", "8.1", "8.2", "9.3",
                "9.8", "9.9", "9.10", "9.11", "9.12", "9.15", "11.1", "11.4", "11.5", "11.6"}
    assert len(partners) == 64


def test_rows_flags_and_missing(candide):
    _, _, _, fp_vertices = candide
    rows = feature_points.feature_point_rows(fp_vertices)
    assert len(rows) == len(mpeg4face.feature_points()) == 85  # 84 and Pandzic's 7.2
    by_id = {r.id: r for r in rows}
    assert by_id["3.5"].needed_for_fapu and not by_id["3.5"].needed_for_cloning
    assert not by_id["3.5"].is_set  # CANDIDE-3 has no pupils
    assert by_id["9.15"].is_set and by_id["9.15"].vertex == fp_vertices["9.15"]
    assert by_id["9.15"].needed_for_fapu and by_id["9.15"].needed_for_cloning
    assert by_id["2.1"].description == "Bottom of the chin"
    assert feature_points.missing(rows, feature_points.fapu_points()) == ["3.5", "3.6"]
    assert feature_points.missing(rows, feature_points.cloning_points()) == []


def test_groups_to_feature_points():
    vertices, warnings = feature_points.fp_vertices_from_groups({
        "FP_2.1": [(7, 1.0)],
        "FP_3.5": [(1, 0.5), (4, 1.0)],
        "FP_3.6": [],
        "FP_99.9": [(3, 1.0)],
        "Group": [(2, 1.0)],
    })
    assert vertices == {"2.1": 7, "3.5": 4}
    assert warnings == ["vertex group FP_3.5 holds 2 vertices; vertex 4 is used",
                        "vertex group FP_99.9: 99.9 is not a feature point"]


def test_axes():
    np.testing.assert_array_equal(feature_points.to_standard_axes([[1, 2, 3]]), [[1, 3, -2]])


def test_face_state_equals_measure_fapu(candide):
    model, coords, coord_index, fp_vertices = candide
    state = feature_points.face_state_from_arrays(coords, coord_index, groups_of(fp_vertices))
    expected = mpeg4face.measure_fapu(model)
    assert [r.name for r in state.fapu] == list(feature_points.FAPU_DISTANCES)
    for reading in state.fapu:
        distance = getattr(expected, reading.name.lower())
        assert reading.measured and reading.value == pytest.approx(distance.value)
        assert reading.unit == pytest.approx(distance.value / 1024)
        assert reading.points_used == distance.points_used
    es0 = state.fapu[0]
    assert es0.points_used == ("3.7", "3.11", "3.8", "3.12")  # no pupils: the eye corners
    assert es0.lines() == [f"ES0 = {es0.value:.5g}   FAPU = {es0.value / 1024:.5g}",
                           "    from 3.7, 3.11, 3.8, 3.12: |(3.7+3.11)/2 - (3.8+3.12)/2|"]
    expected_warnings = mpeg4face.check_location_constraints(model, expected)
    assert [w.message for w in state.location_warnings] == [w.message for w in expected_warnings]
    assert len(state.location_warnings) == 5


def test_unmeasured_fapu_says_what_it_needs(candide):
    _, coords, coord_index, fp_vertices = candide
    without = {fp: v for fp, v in fp_vertices.items() if fp not in ("9.15", "8.3")}
    state = feature_points.face_state_from_arrays(coords, coord_index, groups_of(without))
    by_name = {r.name: r for r in state.fapu}
    assert by_name["MNS0"].lines() == ["MNS0 unmeasured: needs 9.15 and 2.2"]
    assert not by_name["ENS0"].measured
    assert by_name["MW0"].measured and by_name["MW0"].points_used == ("2.4", "2.5")
    assert by_name["ES0"].measured


def test_mirror_matches(candide):
    _, coords, _, fp_vertices = candide
    one_side = {fp: v for fp, v in fp_vertices.items() if coords[v, 0] > 0}
    tolerance = feature_points.mirror_tolerance(coords, 0.01)
    assert tolerance == pytest.approx(0.01 * np.linalg.norm(np.ptp(coords, axis=0)))
    matches = feature_points.mirror_matches(coords, one_side, "MISSING", tolerance)
    # CANDIDE-3 is symmetric: every partner lands where the CSV puts it; its closed mouth
    # has two vertices there for each inner-lip point.
    assert matches and all(m.accepted and m.distance < 1e-9 for m in matches)
    for m in matches:
        if m.partner in fp_vertices:
            np.testing.assert_array_equal(coords[m.vertex], coords[fp_vertices[m.partner]])
            assert m.vertex == fp_vertices[m.partner] or m.ties > 1, m
    tied = next(m for m in matches if m.source == "2.8")
    assert tied.ties == 2 and tied.message(tolerance).endswith(
        "(2 vertices are that near: check which one is meant)")
    partners = feature_points.mirror_partners()
    assert {m.source for m in matches} == {fp for fp in one_side if fp in partners}
    assert matches[0].message(tolerance).startswith(f"{matches[0].partner} = vertex ")
    # Only missing partners: none on the full set.
    assert feature_points.mirror_matches(coords, fp_vertices, "MISSING", tolerance) == []
    left = feature_points.mirror_matches(coords, fp_vertices, "LEFT", tolerance)
    right = feature_points.mirror_matches(coords, fp_vertices, "RIGHT", tolerance)
    assert {m.source for m in left} == {m.partner for m in right}


def test_mirror_refuses_far_vertices(candide):
    _, coords, _, fp_vertices = candide
    moved = coords.copy()
    v = fp_vertices["3.12"]
    moved[v] += (0.0, 0.1, 0.0)  # the right eye's outer corner no longer mirrors 3.7
    far = feature_points.mirror_matches(moved, {"3.7": fp_vertices["3.7"]}, "MISSING", 0.01)
    assert len(far) == 1 and not far[0].accepted and far[0].distance > 0.01
    assert far[0].message(0.01).startswith("3.12 skipped: the vertex nearest to the mirror image")
    with pytest.raises(ValueError, match="mirror source"):
        feature_points.mirror_matches(coords, fp_vertices, "UP", 0.01)
