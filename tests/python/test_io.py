# SPDX-License-Identifier: GPL-3.0-or-later
"""Reading and writing files, feature points and FAPU from Python."""

import os
from pathlib import Path

import numpy as np
import pytest

import mpeg4face

FAPU_DISTANCES = ("es0", "irisd0", "ens0", "mns0", "mw0")


@pytest.fixture(scope="module")
def candide_dir(data_dir):
    return data_dir / "candide3"


@pytest.fixture()
def candide(candide_dir):
    """CANDIDE-3 as a FaceModel with its feature points bound."""
    model = mpeg4face.read_model(candide_dir / "candide3.wfm")
    points, warnings = mpeg4face.read_feature_point_csv(candide_dir / "feature_points.csv", model)
    model.feature_points.update(points)
    return model


def test_read_wfm(candide_dir):
    candide = mpeg4face.read_wfm(candide_dir / "candide3.wfm")
    model = candide.model
    assert isinstance(model, mpeg4face.FaceModel)
    assert len(model.meshes) == 1
    mesh = model.meshes[0]
    assert mesh.name == "candide3"
    assert mesh.coord.shape == (113, 3) and mesh.coord.dtype == np.float64
    assert mesh.face_count == 184
    triangles = mesh.triangles()
    assert triangles.shape == (184, 3)
    assert triangles.min() >= 0 and triangles.max() < 113
    np.testing.assert_allclose(mesh.coord[0], [0.0, 1.061, -0.371])
    mpeg4_units = [u for u in candide.animation_units if u.fap]
    assert len(mpeg4_units) == 54
    jaw = next(u for u in mpeg4_units if u.fap == 3)
    assert jaw.fapu == "MNS"
    assert jaw.vertices.dtype == np.int32
    assert jaw.displacements.shape == (len(jaw.vertices), 3)
    assert candide.shape_units
    assert all(u.name for u in candide.shape_units)


def test_candide_to_face_model(candide_dir):
    candide = mpeg4face.read_wfm(str(candide_dir / "candide3.wfm"))  # str paths work too
    model = mpeg4face.candide_to_face_model(candide)
    mesh = model.meshes[0]
    assert len(mesh.morph_targets) == len(candide.animation_units)
    for unit, target in zip(candide.animation_units, mesh.morph_targets):
        assert target.name == unit.name
        assert target.displacements.shape == (113, 3)
        expected = np.zeros((113, 3))
        np.add.at(expected, unit.vertices, unit.displacements)  # a vertex listed twice adds up
        np.testing.assert_allclose(target.displacements, expected)
    # read_model does the same for .wfm
    same = mpeg4face.read_model(candide_dir / "candide3.wfm")
    np.testing.assert_array_equal(same.meshes[0].coord, mesh.coord)
    # A unit that points past the mesh is refused, not read out of bounds.
    candide.animation_units[0].vertices = [500] * len(candide.animation_units[0].vertices)
    with pytest.raises(mpeg4face.Error, match="out of range"):
        mpeg4face.candide_to_face_model(candide)



def test_name_candide_fap_units(candide_dir):
    candide = mpeg4face.read_wfm(candide_dir / "candide3.wfm")
    model = mpeg4face.candide_to_face_model(candide)
    with pytest.raises(mpeg4face.Error, match="not measured"):
        mpeg4face.name_candide_fap_units(model, candide)  # no feature points, no FAPU
    points, _ = mpeg4face.read_feature_point_csv(candide_dir / "feature_points.csv", model)
    model.feature_points = points
    named = mpeg4face.name_candide_fap_units(model, candide)
    fapu = mpeg4face.measure_fapu(named)
    by_name = {t.name: t for t in named.meshes[0].morph_targets}
    jaw = next(u for u in candide.animation_units if u.fap == 3)
    # open_jaw (MNS, unidirectional) at 1000 moves its vertices 1000 * MNS * the unit's offset.
    target = by_name["fap3_open_jaw@1000"]
    expected = np.zeros((113, 3))
    np.add.at(expected, jaw.vertices, jaw.displacements)
    np.testing.assert_allclose(target.displacements, 1000 * fapu.unit("MNS") * expected, rtol=1e-12)
    assert "fap3_open_jaw@-1000" not in by_name
    assert all(mpeg4face.parse_shape_key_name(name) for name in by_name if name.startswith("fap"))
    assert named is not model and model.meshes[0].morph_targets[0].name == candide.animation_units[0].name

def test_feature_point_csv(candide_dir, candide):
    points, warnings = mpeg4face.read_feature_point_csv(
        candide_dir / "feature_points.csv", candide)
    assert isinstance(points, dict) and isinstance(warnings, list)
    assert all(isinstance(w, str) for w in warnings)
    assert points["2.1"].mesh == 0 and points["2.1"].vertex == 10
    assert points["9.3"].vertex == 5
    assert all(isinstance(b, mpeg4face.FeaturePointBinding) for b in points.values())
    assert candide.feature_points["2.1"].vertex == 10
    np.testing.assert_allclose(candide.feature_point_position("2.1"), candide.meshes[0].coord[10])


def test_measure_fapu(candide):
    fapu = mpeg4face.measure_fapu(candide)
    assert fapu.missing() == []
    for name in FAPU_DISTANCES:
        distance = getattr(fapu, name)
        assert distance.measured, name
        assert distance.value > 0, name
        assert distance.points_used, name
        assert distance.method, name
        assert fapu.unit(name.upper()) == pytest.approx(distance.value / 1024)
        assert fapu.unit(name.upper().rstrip("0")) == pytest.approx(distance.value / 1024)
    assert fapu.unit("AU") == pytest.approx(1e-5)
    # Eye separation is wider than the iris.
    assert fapu.es0.value > fapu.irisd0.value
    with pytest.raises(ValueError, match="unknown FAPU"):
        fapu.unit("XYZ")
    warnings = mpeg4face.check_location_constraints(candide, fapu)
    assert isinstance(warnings, list)
    for w in warnings:
        assert isinstance(w, mpeg4face.ConstraintWarning)
        assert w.axis in ("x", "y", "z")
        assert mpeg4face.feature_point(w.feature_point) is not None
        assert w.message
    # A strict tolerance can only add warnings.
    strict = mpeg4face.check_location_constraints(candide, fapu, tolerance=0.0)
    assert len(strict) >= len(warnings)


def test_fapu_without_feature_points(candide):
    candide.feature_points.clear()
    fapu = mpeg4face.measure_fapu(candide)
    assert sorted(fapu.missing()) == sorted(n.upper() for n in FAPU_DISTANCES)
    assert not fapu.es0.measured
    assert fapu.unit("ES") == 0.0
    manual = mpeg4face.FapuMeasurement()
    manual.es0.measured = True  # nested attributes are editable in place
    manual.es0.value = 2048.0
    assert manual.unit("ES") == 2.0
    assert "ES0" not in manual.missing() and "MW0" in manual.missing()


@pytest.mark.parametrize("suffix", [".gltf", ".glb"])
def test_gltf_round_trip(candide, tmp_path, suffix):
    mesh = candide.meshes[0]
    mesh.weights = np.linspace(0, 1, len(mesh.morph_targets))
    candide.feature_points["9.3"] = mpeg4face.FeaturePointBinding(position=[0.1, 0.2, 0.3])
    path = tmp_path / f"candide{suffix}"
    mpeg4face.write_gltf(candide, path)
    assert path.is_file()
    assert not list(tmp_path.glob("*.part"))
    back = mpeg4face.read_gltf(path)
    assert len(back.meshes) == 1
    got = back.meshes[0]
    assert got.name == mesh.name
    assert got.coord.dtype == np.float64
    # glTF stores float32.
    np.testing.assert_allclose(got.coord, mesh.coord, atol=1e-6)
    np.testing.assert_array_equal(got.triangles(), mesh.triangles())
    assert [t.name for t in got.morph_targets] == [t.name for t in mesh.morph_targets]
    for a, b in zip(got.morph_targets, mesh.morph_targets):
        np.testing.assert_allclose(a.displacements, b.displacements, atol=1e-6)
    np.testing.assert_allclose(got.weights, mesh.weights, atol=1e-6)
    assert set(back.feature_points) == set(candide.feature_points)
    for fp in candide.feature_points:
        np.testing.assert_allclose(
            back.feature_point_position(fp), candide.feature_point_position(fp), atol=1e-6)
    # read_model dispatches on the extension.
    again = mpeg4face.read_model(str(path))
    np.testing.assert_array_equal(again.meshes[0].coord, got.coord)


def test_gltf_round_trip_of_a_model_built_in_python(tmp_path):
    coord = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float32)
    mesh = mpeg4face.IndexedFaceSet("quad", coord, [0, 1, 2, 3, -1])
    mesh.morph_targets.append(mpeg4face.MorphTarget("lift", np.tile([0, 0, 1.0], (4, 1))))
    model = mpeg4face.FaceModel()
    model.add_mesh_with_transform(mesh)
    model.transforms[0].translation = [0, 0, 2]
    Interpolation = mpeg4face.MorphWeightChannel.Interpolation
    model.animations.append(mpeg4face.MorphWeightAnimation(
        "lift", [mpeg4face.MorphWeightChannel(0, Interpolation.LINEAR, [0, 1, 2], [0, 1, 0])]))
    path = tmp_path / "quad.glb"
    mpeg4face.write_gltf(model, path)
    back = mpeg4face.read_gltf(path)
    got = back.meshes[0]
    np.testing.assert_allclose(got.coord, coord)
    np.testing.assert_array_equal(got.triangles(), [[0, 1, 2], [0, 2, 3]])
    np.testing.assert_allclose(back.mesh_world_matrices()[0][:3, 3], [0, 0, 2])
    assert got.morph_targets[0].name == "lift"
    assert len(back.animations) == 1
    channel = back.animations[0].channels[0]
    np.testing.assert_allclose(channel.times, [0, 1, 2])
    np.testing.assert_allclose(channel.weights, [0, 1, 0])


def test_write_gltf_refuses_an_invalid_model(tmp_path):
    model = mpeg4face.FaceModel()
    model.add_mesh_with_transform(mpeg4face.IndexedFaceSet("bad", np.zeros((3, 3)), [0, 1, 9, -1]))
    path = tmp_path / "bad.gltf"
    with pytest.raises(mpeg4face.Error) as error:
        mpeg4face.write_gltf(model, path)
    assert "coordIndex" in error.value.field
    assert error.value.file.endswith("bad.gltf")
    assert not path.exists()


def test_read_gltf_test_file(data_dir):
    model = mpeg4face.read_gltf(data_dir / "gltf" / "morph_cube.gltf")
    assert model.find_mesh("Cube") is not None
    cube = model.meshes[model.find_mesh("Cube")]
    assert [t.name for t in cube.morph_targets] == ["thin", "angle"]
    np.testing.assert_allclose(cube.weights, [0.25, 0.0])
    assert model.find_transform("AnimatedMorphCube") is not None
    assert model.animations


def test_read_obj_makehuman(data_dir):
    model = mpeg4face.read_obj(data_dir / "makehuman" / "base.obj")
    assert len(model.meshes) > 3
    total = 0
    for mesh in model.meshes:
        assert mesh.name
        assert mesh.coord.shape[1] == 3
        assert mesh.source_index.shape == (mesh.vertex_count,)
        assert mesh.face_count > 0
        total += mesh.vertex_count
        tris = mesh.triangles()
        assert tris.max() < mesh.vertex_count
    assert total >= 19158  # every vertex that a face uses, in some mesh
    model.validate()


def test_path_like_objects(candide_dir):
    class MyPath(os.PathLike):
        def __fspath__(self):
            return str(candide_dir / "candide3.wfm")

    assert mpeg4face.read_wfm(MyPath()).model.meshes[0].vertex_count == 113
    with pytest.raises(TypeError):
        mpeg4face.read_wfm(42)


def test_missing_file_raises_error(tmp_path):
    missing = tmp_path / "nope.obj"
    with pytest.raises(mpeg4face.Error) as error:
        mpeg4face.read_obj(missing)
    assert error.value.file is not None and "nope.obj" in error.value.file
    with pytest.raises(mpeg4face.Error, match="unknown model format"):
        mpeg4face.read_model(tmp_path / "face.stl")


@pytest.mark.parametrize(
    "name, reader, line",
    [
        ("obj_bad_number.obj", mpeg4face.read_obj, 2),
        ("obj_short_vertex.obj", mpeg4face.read_obj, 2),
        ("wfm_bad_number.wfm", mpeg4face.read_wfm, 4),
    ],
)
def test_malformed_text_files_name_file_and_line(malformed_dir, name, reader, line):
    with pytest.raises(mpeg4face.Error) as error:
        reader(malformed_dir / name)
    e = error.value
    assert e.file is not None and e.file.endswith(name)
    assert e.line == line
    assert e.reason
    assert f"{name}:{line}" in str(e)


def test_malformed_csv_names_file_and_line(malformed_dir, candide):
    with pytest.raises(mpeg4face.Error) as error:
        mpeg4face.read_feature_point_csv(malformed_dir / "csv_bad_vertex.csv", candide)
    assert error.value.file.endswith("csv_bad_vertex.csv")
    assert error.value.line == 4


@pytest.mark.parametrize(
    "name",
    sorted(p.name for p in (Path(__file__).resolve().parent.parent / "data" / "malformed").glob("*")
           if p.suffix in (".obj", ".wfm", ".gltf", ".glb")),
)
def test_every_malformed_model_raises_error(malformed_dir, name):
    with pytest.raises(mpeg4face.Error) as error:
        mpeg4face.read_model(malformed_dir / name)
    assert error.value.file is not None and error.value.file.endswith(name)
    assert error.value.reason


def test_malformed_files_written_here(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n")
    with pytest.raises(mpeg4face.Error) as error:
        mpeg4face.read_obj(bad)
    assert error.value.line == 4
    glb = tmp_path / "bad.gltf"
    glb.write_text('{"asset": {"version": "2.0"}, "meshes": [')
    with pytest.raises(mpeg4face.Error) as error:
        mpeg4face.read_gltf(glb)
    assert error.value.file.endswith("bad.gltf")
    latin1 = tmp_path / "latin1.obj"  # bytes that are not UTF-8 must not break the message
    latin1.write_bytes(b"v 0 0 0\nv 1 0 \xe9\n")
    with pytest.raises(mpeg4face.Error) as error:
        mpeg4face.read_obj(latin1)
    assert isinstance(str(error.value), str)


def test_reading_from_threads(data_dir):
    """The readers release the GIL; concurrent reads must give the same result."""
    from concurrent.futures import ThreadPoolExecutor

    path = data_dir / "makehuman" / "base.obj"
    with ThreadPoolExecutor(max_workers=4) as pool:
        models = list(pool.map(mpeg4face.read_obj, [path] * 4))
    first = models[0]
    for model in models[1:]:
        assert [m.name for m in model.meshes] == [m.name for m in first.meshes]
        for a, b in zip(model.meshes, first.meshes):
            np.testing.assert_array_equal(a.coord, b.coord)
