// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/model/vertex_normals.hpp"

#include <Eigen/Geometry>
#include <string>

#include "mpeg4face/error.hpp"

namespace mpeg4face {

Normals3f vertexNormals(
    const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>& coord,
    const Eigen::Ref<const Triangles3i>& triangles) {
  const Eigen::Index n = coord.rows();
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> sum =
      Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>::Zero(n, 3);
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    const int a = triangles(t, 0), b = triangles(t, 1), c = triangles(t, 2);
    if (a < 0 || b < 0 || c < 0 || a >= n || b >= n || c >= n) {
      throw Error({}, 0, "triangles[" + std::to_string(t) + "]",
                  "vertex index out of range 0.." + std::to_string(n - 1));
    }
    const Eigen::Vector3d u = (coord.row(b) - coord.row(a)).transpose();
    const Eigen::Vector3d w = (coord.row(c) - coord.row(a)).transpose();
    const Eigen::RowVector3d face = u.cross(w).transpose();
    sum.row(a) += face;
    sum.row(b) += face;
    sum.row(c) += face;
  }
  Normals3f out(n, 3);
  for (Eigen::Index v = 0; v < n; ++v) {
    const double length = sum.row(v).norm();
    if (length > 0) {
      out.row(v) = (sum.row(v) / length).cast<float>();
    } else {
      out.row(v) << 0.0F, 0.0F, 1.0F;
    }
  }
  return out;
}

}  // namespace mpeg4face
