// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: the closest point on a triangle set in 3D (CGAL's AABB tree), with the barycentric
// weights of its triangle, for Facial Motion Cloning's hidden layers (docs/clone.md) and for
// binding free feature points to vertices (model/feature_point_snap.hpp). CGAL is heavy to
// compile: it stays in model/surface_closest_point.cpp.
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <span>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face {

struct ClosestPoint {
  int triangle = -1;                                  // index into the triangle list; -1: none
  std::array<int, 3> corners{};                       // point indices
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();  // barycentric, >= 0, sum 1
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

// The corner of `c`'s triangle nearest `to` (the query, or c.point itself): the vertex a point
// found on the surface binds to.
inline int nearestCorner(const Points3& points, const ClosestPoint& c, const Eigen::Vector3d& to) {
  int vertex = c.corners[0];
  for (const int k : c.corners) {
    if ((points.row(k).transpose() - to).norm() < (points.row(vertex).transpose() - to).norm()) {
      vertex = k;
    }
  }
  return vertex;
}

class SurfaceClosestPoint {
 public:
  // `triangles`: three point indices each; `ids`: those of them to search.
  SurfaceClosestPoint(const Points3& points, std::span<const int> triangles,
                      std::span<const int> ids);
  ~SurfaceClosestPoint();
  SurfaceClosestPoint(const SurfaceClosestPoint&) = delete;
  SurfaceClosestPoint& operator=(const SurfaceClosestPoint&) = delete;

  // `hint`, a point on one of the searched triangles near q, saves the search its start
  // (without one CGAL builds a k-d tree of the triangles first).
  ClosestPoint closest(const Eigen::Vector3d& q, const ClosestPoint* hint = nullptr) const;

 private:
  struct Tree;
  std::unique_ptr<Tree> tree_;
};

}  // namespace mpeg4face
