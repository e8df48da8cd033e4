# SPDX-License-Identifier: GPL-3.0-or-later
"""Building and editing a FaceModel from Python with numpy arrays."""

import numpy as np
import pytest

import mpeg4face
from mpeg4face import FaceModel, FeaturePointBinding, IndexedFaceSet, MorphTarget, Transform

QUAD = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float64)


def quad_mesh(name="quad"):
    """A unit square as one quad face."""
    return IndexedFaceSet(name, QUAD, [0, 1, 2, 3, -1])


def test_mesh_from_numpy_arrays():
    mesh = IndexedFaceSet(
        "face",
        QUAD.astype(np.float32),
        np.array([0, 1, 2, -1, 0, 2, 3, -1], dtype=np.int64),
        normal=np.tile([0.0, 0.0, 1.0], (4, 1)),
        tex_coord=QUAD[:, :2],
        weights=[0.5],
        morph_targets=[MorphTarget("up", np.ones((4, 3)))],
    )
    assert mesh.name == "face"
    assert mesh.coord.dtype == np.float64 and mesh.coord.shape == (4, 3)
    assert mesh.coord.flags.c_contiguous
    np.testing.assert_array_equal(mesh.coord, QUAD)
    assert mesh.coord_index.dtype == np.int32 and mesh.coord_index.shape == (8,)
    assert mesh.normal.shape == (4, 3)
    assert mesh.tex_coord.shape == (4, 2)
    assert mesh.tex_coord_index.shape == (0,) and mesh.tex_coord_index.dtype == np.int32
    assert mesh.source_index.shape == (0,)
    assert mesh.weights.dtype == np.float64 and list(mesh.weights) == [0.5]
    assert mesh.vertex_count == 4
    assert mesh.face_count == 2
    triangles = mesh.triangles()
    assert triangles.shape == (2, 3)
    assert np.issubdtype(triangles.dtype, np.integer)
    np.testing.assert_array_equal(triangles, [[0, 1, 2], [0, 2, 3]])
    assert "face" in repr(mesh)


def test_empty_defaults():
    mesh = IndexedFaceSet()
    assert mesh.name == ""
    assert mesh.coord.shape == (0, 3)
    assert mesh.normal.shape == (0, 3)
    assert mesh.tex_coord.shape == (0, 2)
    assert mesh.coord_index.shape == (0,)
    assert mesh.morph_targets == []
    assert mesh.vertex_count == 0 and mesh.face_count == 0
    assert mesh.triangles().shape == (0, 3)
    t = Transform("t")
    np.testing.assert_array_equal(t.rotation, [0, 0, 0, 1])
    np.testing.assert_array_equal(t.scale, [1, 1, 1])
    np.testing.assert_array_equal(t.local_matrix(), np.eye(4))
    b = FeaturePointBinding()
    assert (b.mesh, b.vertex) == (-1, -1)
    model = FaceModel()
    assert (model.meshes, model.transforms, model.roots, model.feature_points, model.animations) == (
        [], [], [], {}, [])
    model.validate()


def test_fan_triangulation_of_a_quad():
    np.testing.assert_array_equal(quad_mesh().triangles(), [[0, 1, 2], [0, 2, 3]])


def test_assignment_copies_and_converts():
    mesh = IndexedFaceSet()
    source = np.arange(12, dtype=np.int16).reshape(4, 3)
    mesh.coord = source
    assert mesh.coord.dtype == np.float64
    source[0, 0] = 99  # the mesh holds its own copy
    assert mesh.coord[0, 0] == 0
    mesh.coord = QUAD.tolist()  # nested lists work too
    np.testing.assert_array_equal(mesh.coord, QUAD)
    mesh.coord = np.asfortranarray(QUAD * 2)
    assert mesh.coord.flags.c_contiguous
    mesh.coord = []  # empty
    assert mesh.coord.shape == (0, 3)
    mesh.coord_index = np.array([0, 1, 2, -1], dtype=np.int8)
    assert mesh.coord_index.dtype == np.int32


def test_in_place_edits_reach_the_mesh():
    mesh = quad_mesh()
    mesh.coord[:, 2] += 5.0
    assert np.all(mesh.coord[:, 2] == 5.0)
    coord = mesh.coord
    coord[0] = (7, 8, 9)
    np.testing.assert_array_equal(mesh.coord[0], [7, 8, 9])
    assert mesh.coord is coord
    mesh.coord = QUAD  # a new array; the old one stays valid and no longer belongs to the mesh
    coord[0] = (1, 1, 1)
    np.testing.assert_array_equal(mesh.coord[0], [0, 0, 0])


@pytest.mark.parametrize(
    "field, value, expected",
    [
        ("coord", np.zeros((4, 2)), r"IndexedFaceSet\.coord.*\(N, 3\).*\(4, 2\)"),
        ("coord", np.zeros(12), r"IndexedFaceSet\.coord.*\(N, 3\)"),
        ("normal", np.zeros((2, 3, 1)), r"IndexedFaceSet\.normal.*\(N, 3\)"),
        ("tex_coord", np.zeros((4, 3)), r"IndexedFaceSet\.tex_coord.*\(N, 2\)"),
        ("coord_index", np.zeros((2, 3), dtype=int), r"IndexedFaceSet\.coord_index.*\(N,\)"),
        ("weights", np.zeros((1, 1)), r"IndexedFaceSet\.weights.*\(N,\)"),
        ("coord", [[0, 0, 0], [1, 1]], r"IndexedFaceSet\.coord"),
    ],
)
def test_wrong_shapes_raise_value_error_naming_the_field(field, value, expected):
    mesh = quad_mesh()
    with pytest.raises(ValueError, match=expected):
        setattr(mesh, field, value)
    np.testing.assert_array_equal(mesh.coord, QUAD)  # unchanged


def test_wrong_types_raise_type_error():
    mesh = quad_mesh()
    with pytest.raises(TypeError, match="coord_index.*integers"):
        mesh.coord_index = [0.0, 1.5, 2.0, -1.0]
    with pytest.raises(TypeError, match="coord"):
        mesh.coord = np.array([["a", "b", "c"]])
    with pytest.raises(TypeError, match=r"morph_targets\[1\].*MorphTarget"):
        mesh.morph_targets = [MorphTarget("a"), "b"]
    with pytest.raises(ValueError, match="32-bit"):
        mesh.coord_index = [2**40]
    t = Transform()
    with pytest.raises(ValueError, match=r"Transform\.rotation.*\(4,\)"):
        t.rotation = [0, 0, 1]
    with pytest.raises(TypeError, match=r"Transform\.children\[1\]"):
        t.children = [1, "x"]
    model = FaceModel()
    with pytest.raises(TypeError, match="feature_points"):
        model.feature_points = {2.1: FeaturePointBinding()}
    with pytest.raises(TypeError, match="FeaturePointBinding"):
        model.feature_points = {"2.1": (0, 1)}
    with pytest.raises(TypeError, match="IndexedFaceSet"):
        model.add_mesh_with_transform("not a mesh")


def test_model_lists_are_live():
    model = FaceModel()
    assert model.add_mesh_with_transform(quad_mesh("a")) == 0
    assert model.add_mesh_with_transform(quad_mesh("b")) == 1
    assert [m.name for m in model.meshes] == ["a", "b"]
    assert [t.name for t in model.transforms] == ["a", "b"]
    assert model.roots == [0, 1]
    assert model.transforms[1].meshes == [1]
    # Editing an element in place changes the model.
    model.meshes[0].name = "renamed"
    model.meshes[0].coord[0, 0] = -1.0
    assert model.meshes[0].name == "renamed"
    assert model.meshes[0].coord[0, 0] == -1.0
    assert model.find_mesh("renamed") == 0
    assert model.find_mesh("a") is None
    assert model.find_transform("b") == 1
    # A reference taken earlier stays valid while the list grows and shrinks.
    first = model.meshes[0]
    for i in range(50):
        model.add_mesh_with_transform(quad_mesh(f"extra{i}"))
    first.name = "still here"
    assert model.meshes[0].name == "still here"
    del model.meshes[2:]
    del model.transforms[2:]
    model.roots[:] = [0, 1]
    model.validate()
    removed = model.meshes.pop()
    removed.coord[:] = 0  # still a usable object of its own
    assert model.meshes == [first]
    # The same object, not a copy.
    assert model.meshes[0] is first


def test_morph_targets_are_live():
    mesh = quad_mesh()
    mesh.morph_targets.append(MorphTarget("smile", np.zeros((4, 3))))
    mesh.morph_targets[0].displacements[1] = (0, 0.5, 0)
    mesh.morph_targets[0].name = "grin"
    mesh.weights = [0.25]
    model = FaceModel()
    model.add_mesh_with_transform(mesh)
    target = model.meshes[0].morph_targets[0]
    assert target.name == "grin"
    assert target.displacements[1, 1] == 0.5
    model.validate()
    mesh.morph_targets.append(MorphTarget("bad", np.zeros((3, 3))))
    mesh.weights = [0.0, 0.0]
    with pytest.raises(mpeg4face.Error) as error:
        model.validate()
    assert "bad" in error.value.field
    assert "displacements" in error.value.reason


def test_feature_points_and_transforms():
    mesh = quad_mesh()
    model = FaceModel()
    model.add_mesh_with_transform(mesh)
    t = model.transforms[0]
    t.translation = [10, 0, 0]
    t.scale[:] = 2.0
    model.feature_points["2.1"] = FeaturePointBinding(mesh=0, vertex=2)
    model.feature_points["9.3"] = FeaturePointBinding(position=np.array([1.0, 2.0, 3.0]))
    np.testing.assert_allclose(model.feature_point_position("2.1"), [12, 2, 0])
    np.testing.assert_allclose(model.feature_point_position("9.3"), [1, 2, 3])
    assert model.feature_point_position("3.5") is None
    worlds = model.mesh_world_matrices()
    assert worlds.shape == (1, 4, 4)
    expected = np.diag([2.0, 2.0, 2.0, 1.0])
    expected[0, 3] = 10.0
    np.testing.assert_allclose(worlds[0], expected)
    np.testing.assert_allclose(t.local_matrix(), worlds[0])
    # 90 degrees about z: (x, y, z, w)
    t.rotation = [0, 0, np.sqrt(0.5), np.sqrt(0.5)]
    t.scale = [1, 1, 1]
    t.translation = [0, 0, 0]
    np.testing.assert_allclose(model.feature_point_position("2.1"), [-1, 1, 0], atol=1e-12)


def test_scene_graph_nesting():
    model = FaceModel(
        meshes=[quad_mesh("head")],
        transforms=[
            Transform("root", translation=[0, 1, 0], children=[1]),
            Transform("head", translation=[1, 0, 0], meshes=[0]),
        ],
        roots=[0],
    )
    model.validate()
    np.testing.assert_allclose(model.mesh_world_matrices()[0][:3, 3], [1, 1, 0])


@pytest.mark.parametrize(
    "break_it, field",
    [
        (lambda m: m.meshes[0].coord_index.__setitem__(0, 7), "coordIndex"),
        (lambda m: setattr(m.meshes[0], "normal", np.zeros((3, 3))), "normal"),
        (lambda m: m.transforms[0].meshes.append(5), "meshes"),
        (lambda m: m.transforms[0].children.append(0), "children"),
        (lambda m: m.roots.append(3), "roots"),
        (lambda m: m.feature_points.__setitem__("2.1", FeaturePointBinding(0, 99)), "2.1"),
    ],
)
def test_validate_raises_error_with_field(break_it, field):
    model = FaceModel()
    model.add_mesh_with_transform(quad_mesh())
    model.validate()
    break_it(model)
    with pytest.raises(mpeg4face.Error) as error:
        model.validate()
    assert error.value.field is not None
    assert field in error.value.field
    assert error.value.file is None


def test_broken_lists_are_reported_by_validate():
    model = FaceModel()
    model.add_mesh_with_transform(quad_mesh())
    model.meshes.append(42)  # the list accepts anything; the model check does not
    with pytest.raises(TypeError, match=r"FaceModel\.meshes\[1\].*IndexedFaceSet.*int"):
        model.validate()
    model.meshes.pop()
    model.meshes[0].coord.shape = (12,)  # reshaped in place behind the mesh's back
    with pytest.raises(ValueError, match=r"FaceModel\.meshes\[0\]\.coord"):
        model.validate()


def test_animations(tmp_path):
    mesh = quad_mesh()
    mesh.morph_targets = [MorphTarget("a", np.zeros((4, 3))), MorphTarget("b", np.zeros((4, 3)))]
    model = FaceModel()
    model.add_mesh_with_transform(mesh)
    Interpolation = mpeg4face.MorphWeightChannel.Interpolation
    channel = mpeg4face.MorphWeightChannel(0, Interpolation.STEP, [0.0, 1.0], [0, 1, 1, 0])
    model.animations.append(mpeg4face.MorphWeightAnimation("blink", [channel]))
    model.validate()
    assert model.animations[0].channels[0].interpolation == Interpolation.STEP
    mpeg4face.write_gltf(model, tmp_path / "ok.gltf")
    channel.weights = [0.0, 1.0, 1.0]  # 2 times x 2 targets expected
    with pytest.raises(mpeg4face.Error) as error:
        mpeg4face.write_gltf(model, tmp_path / "bad.gltf")
    assert "weights" in error.value.field
    assert error.value.file.endswith("bad.gltf")


def test_transform_channels_round_trip_and_poses(tmp_path):
    """Transform keyframes survive glTF; an animation named in the shape-key grammar is a
    pose that generate_face turns into a FaceDefTransform."""
    model = FaceModel()
    model.add_mesh_with_transform(quad_mesh())
    Path_ = mpeg4face.TransformChannel.Path
    turn = [0.0, np.sin(0.1), 0.0, np.cos(0.1)]  # 0.2 rad about Y, quaternion x y z w
    channel = mpeg4face.TransformChannel(0, Path_.ROTATION, times=[0.0], values=turn)
    model.animations.append(
        mpeg4face.MorphWeightAnimation("fap49_head_yaw@20000", transform_channels=[channel]))
    mpeg4face.write_gltf(model, tmp_path / "pose.gltf")
    [back] = mpeg4face.read_gltf(tmp_path / "pose.gltf").animations
    [read] = back.transform_channels
    assert (back.name, read.transform, read.path) == ("fap49_head_yaw@20000", 0, Path_.ROTATION)
    assert np.allclose(read.values, turn)
    generated = mpeg4face.generate_face(model, absolute_threshold=1e-6)  # no feature points
    [table] = generated["face"].tables
    assert table["fap"] == 49 and table["transforms"] == [0] and table["meshes"] == []
    with pytest.raises(TypeError, match=r"transform_channels\[1\]: expected TransformChannel"):
        mpeg4face.MorphWeightAnimation("x", transform_channels=[channel, "not a channel"])


def test_cut_face_model_keeps_the_faces_above_the_plane():
    # Two quads stacked in y (y = 0..1 and 1..2), and a second mesh that is not cut.
    coord = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [1, 2, 0], [0, 2, 0]]
    strip = IndexedFaceSet("strip", coord, [0, 1, 2, 3, -1, 3, 2, 4, 5, -1],
                           morph_targets=[MorphTarget("up", np.tile([0, 1.0, 0], (6, 1)))],
                           source_index=[10, 11, 12, 13, 14, 15])
    other = IndexedFaceSet("other", [[0, -5, 0], [1, -5, 0], [0, -4, 0]], [0, 1, 2, -1])
    model = FaceModel(meshes=[strip, other], transforms=[Transform("t", meshes=[0, 1])],
                      roots=[0],
                      feature_points={"2.1": FeaturePointBinding(0, 4),
                                      "2.2": FeaturePointBinding(0, 0),
                                      "7.1": FeaturePointBinding(position=[0, 9, 0])})
    cut = mpeg4face.cut_face_model(model, (0, 0.5, 0), (0, 1, 0))
    kept = cut.meshes[0]
    np.testing.assert_array_equal(kept.coord, np.array(coord, dtype=float)[2:])
    np.testing.assert_array_equal(kept.coord_index, [1, 0, 2, 3, -1])
    np.testing.assert_array_equal(kept.source_index, [12, 13, 14, 15])
    assert kept.morph_targets[0].displacements.shape == (4, 3)
    assert len(cut.meshes) == 1  # "other" lies below the plane: no face left
    assert cut.feature_points["2.1"].vertex == 2 and "2.2" not in cut.feature_points
    assert "7.1" in cut.feature_points  # a free coordinate stays
    assert model.meshes[0].vertex_count == 6  # the input is not changed
    # Only the meshes named are kept.
    above = mpeg4face.cut_face_model(model, (0, -10, 0), (0, 1, 0), meshes=["other"])
    assert [m.name for m in above.meshes] == ["other"] and above.meshes[0].vertex_count == 3
    with pytest.raises(mpeg4face.Error, match="normal"):
        mpeg4face.cut_face_model(model, (0, 0, 0), (0, 0, 0))
    with pytest.raises(ValueError, match="point"):
        mpeg4face.cut_face_model(model, (0, 0), (0, 1, 0))


def test_snap_feature_points_binds_free_points_on_the_surface():
    # A quad of 2 x 2 units and feature points at its corners, one free on the surface near
    # vertex 2, one free far off it, 7.1 free inside.
    quad = IndexedFaceSet("quad", [[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]], [0, 1, 2, 3, -1])
    model = FaceModel(meshes=[quad], transforms=[Transform("t", meshes=[0])], roots=[0],
                      feature_points={"2.2": FeaturePointBinding(0, 0),
                                      "2.3": FeaturePointBinding(0, 1),
                                      "2.1": FeaturePointBinding(position=[1.9, 1.8, 0.01]),
                                      "9.3": FeaturePointBinding(position=[1, 1, 1]),
                                      "7.1": FeaturePointBinding(position=[1, 1, -0.01])})
    snapped, notes, unbound = mpeg4face.snap_feature_points(model)
    assert snapped.feature_points["2.1"].mesh == 0 and snapped.feature_points["2.1"].vertex == 2
    assert [n.split(" (")[0] for n in notes] == [
        "feature point 2.1 bound to vertex 2 of mesh 'quad'"]
    assert len(unbound) == 1 and unbound[0].startswith("feature point 9.3 is left free")
    assert snapped.feature_points["9.3"].mesh == -1 and snapped.feature_points["7.1"].mesh == -1
    assert model.feature_points["2.1"].mesh == -1  # the input is not changed
    _, notes, _ = mpeg4face.snap_feature_points(model, tolerance=0.5)  # 9.3 too now
    assert len(notes) == 2
