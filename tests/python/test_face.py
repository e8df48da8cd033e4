# SPDX-License-Identifier: GPL-3.0-or-later
"""MPEG-4 faces from Python: shape-key names, tables from shape keys, VRML and glTF, animating
a face with a stream, Facial Motion Cloning and FAP Interpolation Tables."""

import numpy as np
import pytest

import mpeg4face

# CANDIDE-3 animation units carried over as FAP shape keys: (unit's FAP, amplitude, scale of
# the unit's displacement).
SHAPES = [(3, 512, 0.2), (5, 300, 0.1), (33, 400, 0.05)]


@pytest.fixture()
def candide(data_dir):
    """CANDIDE-3 with its feature points and three of its units as FAP shape keys, and one
    shape key of another naming."""
    model = mpeg4face.read_model(data_dir / "candide3" / "candide3.wfm")
    points, _ = mpeg4face.read_feature_point_csv(data_dir / "candide3" / "feature_points.csv", model)
    model.feature_points.update(points)
    mesh = model.meshes[0]
    units = {int(t.name[3:].split()[0]): t for t in mesh.morph_targets if t.name.startswith("FAP")}
    targets = [mpeg4face.MorphTarget(mpeg4face.format_shape_key_name(fap, amplitude),
                                     units[fap].displacements * scale)
               for fap, amplitude, scale in SHAPES]
    targets.append(mpeg4face.MorphTarget("Smile", units[3].displacements))
    mesh.morph_targets = targets
    return model


def stream_of(fap: int, value: int) -> mpeg4face.FapStream:
    mask = np.zeros((1, 68), bool)
    values = np.zeros((1, 68), np.int32)
    mask[0, fap - 1] = True
    values[0, fap - 1] = value
    return mpeg4face.FapStream.from_arrays([0], mask, values)


def test_shape_key_names():
    assert mpeg4face.parse_shape_key_name("fap3_open_jaw@512") == {
        "fap": 3, "select": 0, "amplitude": 512, "label": "open_jaw"}
    assert mpeg4face.parse_shape_key_name("viseme4") == {
        "fap": 1, "select": 4, "amplitude": 63, "label": ""}
    assert mpeg4face.parse_shape_key_name("Basis") is None
    with pytest.raises(mpeg4face.Error, match="fap3@"):
        mpeg4face.parse_shape_key_name("fap3@")
    assert mpeg4face.format_shape_key_name(3, 512, label="open_jaw") == "fap3_open_jaw@512"
    assert mpeg4face.format_shape_key_name(2, 40, select=1) == "expression1@40"
    assert mpeg4face.format_shape_key_name(1, select=7) == "viseme7"


def test_tables_from_shape_keys_reproduce_them(candide):
    result = mpeg4face.generate_face(candide)
    face = result["face"]
    assert result["copies"] == 3
    assert result["ignored"] == ["Smile"]
    assert isinstance(face, mpeg4face.MpegFace)
    assert [t["fap"] for t in face.tables] == [3, 5, 33]
    assert face.tables[0]["meshes"][0]["interval_borders"] == [0, 512]
    assert not face.scene_graph.meshes[0].morph_targets  # the neutral
    face.validate()
    evaluator = mpeg4face.FatEvaluator(face)
    basis = candide.meshes[0].coord
    np.testing.assert_allclose(evaluator.neutral()["coord"][0], basis)
    for (fap, amplitude, _), target in zip(SHAPES, candide.meshes[0].morph_targets):
        state = evaluator.evaluate(stream_of(fap, amplitude), 0)
        np.testing.assert_allclose(state["coord"][0], basis + target.displacements, atol=1e-6)
        half = evaluator.evaluate(stream_of(fap, amplitude // 2), 0)
        np.testing.assert_allclose(half["coord"][0], basis + target.displacements / 2, atol=1e-6)
    assert state["rotation"].shape == (len(candide.transforms), 4)
    with pytest.raises(IndexError, match="frame index 1 outside the stream's 1 frames"):
        evaluator.evaluate(stream_of(3, 1), 1)
    # The 16-bit tables for playback: each key off by at most 1/32768 of its largest motion.
    fast = mpeg4face.FatEvaluator(face, storage="int16")
    for (fap, amplitude, _), target in zip(SHAPES, candide.meshes[0].morph_targets):
        coord = fast.evaluate(stream_of(fap, amplitude), 0)["coord"][0]
        exact = evaluator.evaluate(stream_of(fap, amplitude), 0)["coord"][0]
        assert np.abs(coord - exact).max() <= np.abs(target.displacements).max() / 32768 + 1e-7
    with pytest.raises(ValueError, match="storage: 'half' is not 'float' or 'int16'"):
        mpeg4face.FatEvaluator(face, storage="half")


def test_vrml_and_gltf_files(candide, tmp_path):
    face = mpeg4face.generate_face(candide)["face"]
    face.fit = mpeg4face.fit_preset("left-right")
    wrl = tmp_path / "candide.wrl"
    mpeg4face.write_vrml(face, wrl)
    again = mpeg4face.read_vrml(wrl)
    assert again.tables == face.tables
    assert again.fit == face.fit
    glb = tmp_path / "candide.glb"
    joy_like = stream_of(3, 256)
    mpeg4face.write_face_gltf(face, glb, [joy_like])
    model = mpeg4face.read_gltf(glb)
    assert len(model.meshes[0].morph_targets) == 3  # one per interval
    assert len(model.animations) == 1
    with pytest.raises(mpeg4face.Error) as e:
        mpeg4face.read_vrml(tmp_path / "missing.wrl")
    assert "missing.wrl" in str(e.value)


def test_cloning_onto_a_scaled_copy_scales_the_motion(candide, data_dir):
    target = mpeg4face.read_model(data_dir / "candide3" / "candide3.wfm")
    target.meshes[0].coord = candide.meshes[0].coord * 2.0
    target.meshes[0].morph_targets = []
    target.feature_points = dict(candide.feature_points)
    stages = []
    result = mpeg4face.clone_face(candide, target,
                                  progress=lambda stage, fraction: stages.append(fraction))
    assert [c["name"] for c in result["copies"]] == [t.name for t in candide.meshes[0].morph_targets[:3]]
    for copy, source in zip(result["copies"], candide.meshes[0].morph_targets):
        # Sparse: the vertices that move, ascending, and their displacements.
        [moved] = copy["meshes"]
        assert moved["mesh"] == 0
        vertices, displacement = moved["vertices"], moved["displacement"]
        assert vertices.dtype == np.int32 and np.all(np.diff(vertices) > 0)
        assert 0 < len(vertices) <= 113 and displacement.shape == (len(vertices), 3)
        assert np.all(np.linalg.norm(displacement, axis=1) > 0)
        assert len(copy["transforms"]) >= len(target.transforms)  # the target's, rigid motion set
        scale = np.linalg.norm(displacement) / np.linalg.norm(source.displacements)
        assert scale == pytest.approx(2.0, rel=0.02), copy["name"]
    assert stages and stages[-1] == pytest.approx(1.0) and stages == sorted(stages)
    assert [t["fap"] for t in result["face"].tables] == [3, 5, 33]
    # Cloning from the tables gives the same motion.
    face = mpeg4face.generate_face(candide)["face"]
    again = mpeg4face.clone_face(face, target)
    def every_vertex(copy):
        out = np.zeros((113, 3))
        out[copy["meshes"][0]["vertices"]] = copy["meshes"][0]["displacement"]
        return out
    np.testing.assert_allclose(every_vertex(again["copies"][0]),
                               every_vertex(result["copies"][0]), atol=1e-6)
    target.feature_points = {}
    with pytest.raises(mpeg4face.Error, match="target"):
        mpeg4face.clone_face(candide, target)
    assert "2.1" in mpeg4face.clone_feature_points()


def test_fit_tables(tmp_path):
    table = mpeg4face.fit_preset("left-right")
    assert table.problems() == []
    assert [6] in table.nodes
    filled = table.interpolate(stream_of(6, 40))  # stretch_l_cornerlip -> stretch_r_cornerlip
    assert filled.mask[0, 6] and filled.values[0, 6] == 40
    path = tmp_path / "lr.json"
    path.write_text(table.to_json())
    assert mpeg4face.read_fit_json(path) == table
    with pytest.raises(mpeg4face.Error, match="unknown FIT preset .smile."):
        mpeg4face.fit_preset("smile")
    with pytest.raises(mpeg4face.Error, match="bad.json"):
        mpeg4face.fit_table_from_json("{", "bad.json")


def test_border_weights_are_the_fat_rule():
    w = mpeg4face.border_weights([-1000, 0, 500, 1000], [600, -500, 1500])
    np.testing.assert_allclose(w, [[0, 0, 0.8, 0.2], [0.5, 0.5, 0, 0], [0, 0, -1, 2]])
    with pytest.raises(mpeg4face.Error, match="intervalBorders: borders must increase"):
        mpeg4face.border_weights([0, 0], [1])
