# SPDX-License-Identifier: GPL-3.0-or-later
"""mpeg4face.vertex_normals (core/include/mpeg4face/model/vertex_normals.hpp), which the Blender
add-on's live preview draws with: equal to the area-weighted sum of the triangles' normals
computed in numpy, (0, 0, 1) for a lone vertex, a bad index named."""

import mpeg4face
import numpy as np
import pytest


def test_normals_are_the_normalised_sum_of_the_area_weighted_face_normals():
    rng = np.random.default_rng(3)
    coords = rng.normal(size=(40, 3))
    triangles = rng.integers(0, 39, size=(90, 3))  # vertex 39 on no triangle
    a, b, c = (coords[triangles[:, i]] for i in range(3))
    face = np.cross(b - a, c - a)
    expected = np.zeros_like(coords)
    for i in range(3):
        np.add.at(expected, triangles[:, i], face)
    used = np.linalg.norm(expected, axis=1) > 0
    expected[used] /= np.linalg.norm(expected[used], axis=1)[:, None]
    expected[~used] = (0, 0, 1)
    normals = mpeg4face.vertex_normals(coords, triangles)
    assert normals.dtype == np.float32 and normals.shape == (40, 3)
    np.testing.assert_allclose(normals, expected, atol=1e-6)
    assert tuple(normals[39]) == (0, 0, 1)


def test_a_bad_triangle_is_named():
    with pytest.raises(mpeg4face.Error, match=r"triangles\[1\].*out of range 0..2"):
        mpeg4face.vertex_normals(np.zeros((3, 3)), [[0, 1, 2], [0, 1, 3]])
    with pytest.raises(mpeg4face.Error, match="coord"):
        mpeg4face.vertex_normals(np.zeros((3, 2)), [[0, 1, 2]])
