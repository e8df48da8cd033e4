# SPDX-License-Identifier: GPL-3.0-or-later
"""The live preview's object-space coordinates, computed by the core
(FatEvaluator.object_coordinates), against the numpy arithmetic the add-on did before: each
Transform's evaluated local matrix, their product along the object's chain, the inverse of
the chain's neutral product, Blender's axes, float32."""

import functools

import numpy as np
import pytest

import mpeg4face
from mpeg4face_blender.logic import live as live_logic

Path_ = mpeg4face.TransformChannel.Path


def quaternion(axis, angle):
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return [*(axis * np.sin(angle / 2)), np.cos(angle / 2)]


def pose(fap, amplitude, transform, axis, angle):
    """A pose animation in the shape-key grammar: generate_face makes it a FaceDefTransform."""
    channel = mpeg4face.TransformChannel(transform, Path_.ROTATION, times=[0.0],
                                         values=quaternion(axis, angle))
    return mpeg4face.MorphWeightAnimation(mpeg4face.format_shape_key_name(fap, amplitude),
                                          transform_channels=[channel])


@pytest.fixture()
def face(data_dir):
    """CANDIDE-3 under a posed head Transform with its jaw unit (FAP 3), and an eye mesh
    under a child Transform off its rest: FAP 49 turns the head, FAP 23 the eye."""
    candide = mpeg4face.read_model(data_dir / "candide3" / "candide3.wfm")
    points, _ = mpeg4face.read_feature_point_csv(data_dir / "candide3" / "feature_points.csv",
                                                 candide)
    head = candide.meshes[0]
    jaw = next(t for t in head.morph_targets
               if t.name.startswith("FAP") and int(t.name[3:].split()[0]) == 3)
    head.morph_targets = [mpeg4face.MorphTarget(mpeg4face.format_shape_key_name(3, 512),
                                                jaw.displacements * 0.2)]
    eye = mpeg4face.IndexedFaceSet("eye", [[0, 0, 0.1], [0.05, 0, 0], [0, 0.05, 0]],
                                   [0, 1, 2, -1])
    transforms = [
        mpeg4face.Transform("head", translation=[0.1, -0.2, 0.3], center=[0, -0.5, 0],
                            rotation=quaternion([0, 1, 0], 0.2), children=[1], meshes=[0]),
        mpeg4face.Transform("eye", translation=[0.2, 0.3, 0.1], center=[0.01, 0.02, 0.03],
                            rotation=quaternion([1, 0, 0], 0.3), scale=[1, 1.5, 1], meshes=[1]),
    ]
    model = mpeg4face.FaceModel(meshes=[head, eye], transforms=transforms, roots=[0],
                                feature_points=points,
                                animations=[pose(49, 20000, 0, [0, 1, 0], 0.5),
                                            pose(23, 20000, 1, [0, 1, 0], 0.4)])
    return model, mpeg4face.generate_face(model)["face"]


def old_arithmetic(model, result, chain):
    """The add-on's former per-frame numpy: coordinates and matrix of one object."""
    product = functools.partial(functools.reduce, np.matmul)
    neutral = [t.local_matrix() for t in model.transforms]
    local = [mpeg4face.Transform(translation=t, rotation=r, scale=s, center=c.center).local_matrix()
             for t, r, s, c in zip(result["translation"], result["rotation"], result["scale"],
                                   model.transforms)]
    matrix = np.linalg.inv(product(neutral[i] for i in chain)) @ product(local[i] for i in chain)
    turn = live_logic.TO_BLENDER
    rotation, translation = turn @ matrix[:3, :3], turn @ matrix[:3, 3]
    return matrix, rotation, translation


def test_object_coordinates_are_the_former_numpy_placement(face):
    model, mpeg_face = face
    evaluator = mpeg4face.FatEvaluator(mpeg_face)
    mask = np.zeros((3, mpeg4face.FAP_COUNT), dtype=bool)
    mask[:, [2, 22, 48]] = True
    values = np.zeros((3, mpeg4face.FAP_COUNT), dtype=np.int32)
    values[1, [2, 22, 48]] = (400, 15000, -10000)  # FAP 3, 23, 49
    values[2, [2, 22, 48]] = (-200, -25000, 30000)
    stream = mpeg4face.FapStream.from_arrays([0, 1, 2], mask, values)
    chains = [(0,), (0, 1)]
    for index in range(3):
        result = evaluator.evaluate(stream, index)
        core = evaluator.object_coordinates(stream, index, chains, live_logic.TO_BLENDER)
        assert len(core["placed"]) == 2 and core["placement"].shape == (2, 4, 4)
        for i, chain in enumerate(chains):
            coords = result["coord"][i]
            np.testing.assert_array_equal(core["coord"][i], coords)
            _, rotation, translation = old_arithmetic(model, result, chain)
            placed = np.asarray(coords, dtype=np.float32) @ rotation.T.astype(np.float32)
            placed += translation.astype(np.float32)
            assert core["placed"][i].dtype == np.float32
            np.testing.assert_allclose(core["placed"][i], placed, atol=1e-5)
            np.testing.assert_allclose(core["placement"][i][:3, :3], rotation, atol=1e-12)
            np.testing.assert_allclose(core["placement"][i][:3, 3], translation, atol=1e-12)
        if index > 0:  # the eye turned and the head nodded: the placements are no axis change
            for placement in core["placement"]:
                assert np.abs(placement[:3, :3] - live_logic.TO_BLENDER).max() > 0.01
    # At rest, without an axis change, each object shows its mesh as it is.
    rest = evaluator.object_coordinates(stream, 0, chains)
    for placement in rest["placement"]:
        np.testing.assert_allclose(placement, np.eye(4), atol=1e-12)
    with pytest.raises(mpeg4face.Error, match="chain"):
        evaluator.object_coordinates(stream, 0, [(0, 5)])
    with pytest.raises(mpeg4face.Error, match="axes"):
        evaluator.object_coordinates(stream, 0, chains, np.eye(2))
