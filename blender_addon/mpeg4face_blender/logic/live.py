# SPDX-License-Identifier: GPL-3.0-or-later
"""The live preview's per-frame arithmetic without bpy (testable with plain pytest): the
evaluated vertices of an object, and their normals, placed in Blender's axes in one
product each (the normals come from the core's vertex_normals)."""

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


def placed_normals(normals: npt.ArrayLike, matrix: np.ndarray) -> Array32:
    """Normals of standard-axes coordinates, turned as `placed` turns the coordinates
    (unnormalised under a scale: the shader normalises)."""
    rotation, _ = blender_placement(matrix)
    return np.asarray(normals, dtype=np.float32) @ rotation.T.astype(np.float32)


def placed(coords: npt.ArrayLike, matrix: np.ndarray) -> Array32:
    """The standard-axes coordinates moved by `matrix` (4, 4), in Blender's axes, float32
    (N, 3) as a vertex buffer holds them."""
    rotation, translation = blender_placement(matrix)
    shown = np.asarray(coords, dtype=np.float32) @ rotation.T.astype(np.float32)
    shown += translation.astype(np.float32)
    return shown
