# SPDX-License-Identifier: GPL-3.0-or-later
"""The live preview's arithmetic without bpy (testable with plain pytest): the axes the
core places the evaluated vertices in (FatEvaluator.object_coordinates gives them in each
object's frame, float32), and the normals turned as the core's placement turns the
vertices (the normals come from the core's vertex_normals)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

# The standard's Y-up axes to Blender's Z-up ones, (x, y, z) -> (x, -z, y), as a matrix.
TO_BLENDER = np.array(((1.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0)))

Array32 = npt.NDArray[np.float32]


def placed_normals(normals: npt.ArrayLike, placement: np.ndarray) -> Array32:
    """Normals of standard-axes coordinates, turned as `placement` (4, 4, from
    object_coordinates: into the object's frame, in Blender's axes) turns the coordinates
    (unnormalised under a scale: the shader normalises)."""
    rotation = np.asarray(placement)[:3, :3].astype(np.float32)
    return np.asarray(normals, dtype=np.float32) @ rotation.T
