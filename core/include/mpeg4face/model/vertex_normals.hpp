// SPDX-License-Identifier: GPL-3.0-or-later
// Smooth vertex normals of a triangle mesh whose vertices move every frame (the Blender
// add-on's live preview draws the evaluated face with them; numpy costs ~10x more).
#pragma once

#include <Eigen/Core>

namespace mpeg4face {

using Normals3f = Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Triangles3i = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

// Area-weighted vertex normals (the sum of the cross products of the triangles around a
// vertex, normalised) of `triangles` over `coord`; a vertex on no triangle, or whose
// triangles cancel, gets (0, 0, 1). Throws Error naming the triangle whose index is out of
// range.
Normals3f vertexNormals(
    const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>& coord,
    const Eigen::Ref<const Triangles3i>& triangles);

}  // namespace mpeg4face
