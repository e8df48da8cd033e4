# SPDX-License-Identifier: GPL-3.0-or-later
"""The live preview's per-frame arithmetic without bpy (testable with plain pytest): the
evaluated vertices of an object placed in Blender's axes in one product, and smooth vertex
normals of a triangle mesh whose vertices move, fast enough for every frame of a dense head
(the incidence is sorted once, so a frame is a cross product and one numpy reduction)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

# The standard's Y-up axes to Blender's Z-up ones, (x, y, z) -> (x, -z, y), as a matrix.
TO_BLENDER = np.array(((1.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0)))

Array32 = npt.NDArray[np.float32]


def blender_placement(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(R, t) such that coords @ R.T + t is `matrix` (4, 4, standard axes) applied to
    standard-axes coordinates and the result turned into Blender's axes."""
    return TO_BLENDER @ matrix[:3, :3], TO_BLENDER @ matrix[:3, 3]


def placed(coords: npt.ArrayLike, matrix: np.ndarray) -> Array32:
    """The standard-axes coordinates moved by `matrix` (4, 4), in Blender's axes, float32
    (N, 3) as a vertex buffer holds them."""
    rotation, translation = blender_placement(matrix)
    shown = np.asarray(coords, dtype=np.float32) @ rotation.T.astype(np.float32)
    shown += translation.astype(np.float32)
    return shown


def normal_rotation(matrix: np.ndarray) -> np.ndarray:
    """The (3, 3) that turns Blender-axes normals of an unmoved mesh into those of the mesh
    `placed` by `matrix` (a rotation, with uniform scale at most)."""
    return TO_BLENDER @ matrix[:3, :3] @ TO_BLENDER.T


class VertexNormals:
    """Area-weighted vertex normals of a fixed triangulation (T, 3) over `vertex_count`
    vertices; a vertex on no triangle gets (0, 0, 1)."""

    def __init__(self, triangles: npt.ArrayLike, vertex_count: int) -> None:
        triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
        self._corners = [np.ascontiguousarray(triangles[:, i]) for i in range(3)]
        self._incidence = triangles.T.ravel()  # corner i of every triangle, then i + 1
        self.vertex_count = vertex_count

    def __call__(self, coords: npt.ArrayLike) -> Array32:
        x, y, z = np.asarray(coords, dtype=np.float32).T
        a, b, c = self._corners
        ux, uy, uz = x[b] - x[a], y[b] - y[a], z[b] - z[a]
        vx, vy, vz = x[c] - x[a], y[c] - y[a], z[c] - z[a]
        out = np.empty((self.vertex_count, 3), dtype=np.float32)
        for axis, face in enumerate((uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx)):
            out[:, axis] = np.bincount(self._incidence, np.tile(face, 3), self.vertex_count)
        length = np.sqrt(np.einsum("ij,ij->i", out, out))
        lonely = length == 0
        out[lonely] = (0.0, 0.0, 1.0)
        length[lonely] = 1.0
        out /= length[:, None]
        return out
