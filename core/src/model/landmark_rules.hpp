// SPDX-License-Identifier: GPL-3.0-or-later
// Internal to findFeaturePoints (model/landmarks.cpp): the target's meshes as it searches them,
// and the rules of their own that place some points better than the template's fit
// (docs/landmarks.md, "Rules of their own"). Not installed.
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <utility>
#include <vector>

#include "model/surface_closest_point.hpp"
#include "mpeg4face/model/landmarks.hpp"

namespace mpeg4face::landmark_fit {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// A mesh in model space with its closest-point search.
struct Surface {
  int mesh = -1;
  Points3 points;
  std::vector<int> triangles;
  std::unique_ptr<SurfaceClosestPoint> search;
  std::vector<std::pair<int, int>> edges;  // each once, (lower, higher) vertex, sorted
  std::vector<bool> boundary;  // per vertex: on an edge of one triangle (a cut, a hole)

  int triangleCount() const { return static_cast<int>(triangles.size() / 3); }
  Vector3d corner(int t, int k) const {
    return points.row(triangles[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>(k)]);
  }
  Vector3d triangleNormal(int t) const {
    return (corner(t, 1) - corner(t, 0)).cross(corner(t, 2) - corner(t, 0)).normalized();
  }
};

// Vertex normals of a triangle set over `points`.
std::vector<Vector3d> normalsOf(const Points3& points, const std::vector<int>& triangles);

// Moves the points of `result` that have a rule of their own: the midline points onto the
// head's symmetry plane, the nose tip, the subnasale, the eyelids' 3.1-3.4 and the outer eye
// corners 3.7 / 3.12 (onto the edge of the eye's opening seen from the front, against the eye
// in `parts` that holds the pupil). `rotation` turns the template's axes into the target's,
// `es0` is the target's.
void refineByRules(const FaceModel& templateHead, const Surface& face,
                   const std::vector<Surface>& parts, const Matrix3d& rotation, double es0,
                   LandmarkResult& result);

}  // namespace mpeg4face::landmark_fit
