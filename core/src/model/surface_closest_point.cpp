// SPDX-License-Identifier: GPL-3.0-or-later
#include "model/surface_closest_point.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <vector>

namespace mpeg4face {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Triangle = Kernel::Triangle_3;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, std::vector<Triangle>::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

Kernel::Point_3 point(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

// Barycentric weights of p, a point of triangle (a, b, c), clamped onto it.
Eigen::Vector3d weightsOn(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                          const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d v0 = b - a, v1 = c - a, v2 = p - a;
  const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1);
  const double d20 = v2.dot(v0), d21 = v2.dot(v1);
  const double den = d00 * d11 - d01 * d01;
  if (!(den > 0)) return {1, 0, 0};  // degenerate: its first corner
  const double l1 = (d11 * d20 - d01 * d21) / den, l2 = (d00 * d21 - d01 * d20) / den;
  const Eigen::Vector3d w = Eigen::Vector3d(1 - l1 - l2, l1, l2).cwiseMax(0.0);
  return w / w.sum();
}

}  // namespace

struct SurfaceClosestPoint::Tree {
  std::vector<Triangle> shapes;
  std::vector<int> ids;                     // triangle index of each shape
  std::vector<int> shapeOf;                 // shape of each triangle index, -1: not searched
  std::vector<std::array<int, 3>> corners;  // its point indices
  ::mpeg4face::Tree tree;
};

SurfaceClosestPoint::SurfaceClosestPoint(const Points3& points, std::span<const int> triangles,
                                         std::span<const int> ids)
    : tree_(std::make_unique<Tree>()) {
  tree_->shapes.reserve(ids.size());
  for (int t : ids) {
    const int* c = &triangles[3 * static_cast<std::size_t>(t)];
    tree_->shapes.emplace_back(point(points.row(c[0])), point(points.row(c[1])),
                               point(points.row(c[2])));
    tree_->ids.push_back(t);
    tree_->corners.push_back({c[0], c[1], c[2]});
    if (static_cast<std::size_t>(t) >= tree_->shapeOf.size())
      tree_->shapeOf.resize(static_cast<std::size_t>(t) + 1, -1);
    tree_->shapeOf[static_cast<std::size_t>(t)] = static_cast<int>(tree_->ids.size()) - 1;
  }
  tree_->tree.insert(tree_->shapes.cbegin(), tree_->shapes.cend());
  tree_->tree.build();
}

SurfaceClosestPoint::~SurfaceClosestPoint() = default;

ClosestPoint SurfaceClosestPoint::closest(const Eigen::Vector3d& q,
                                          const ClosestPoint* hint) const {
  ClosestPoint r;
  if (tree_->shapes.empty()) return r;
  int start = -1;  // the hint's shape, if its triangle is searched
  if (hint && hint->triangle >= 0 &&
      static_cast<std::size_t>(hint->triangle) < tree_->shapeOf.size()) {
    start = tree_->shapeOf[static_cast<std::size_t>(hint->triangle)];
  }
  // Not a structured binding: a lambda below uses the primitive, and clang before 16 cannot
  // capture a binding (the fuzz and sanitizer builds use clang).
  const auto found = start < 0
                         ? tree_->tree.closest_point_and_primitive(point(q))
                         : tree_->tree.closest_point_and_primitive(
                               point(q), {point(hint->point), tree_->shapes.cbegin() + start});
  const auto& p = found.first;
  const auto shape = found.second;
  const auto i = static_cast<std::size_t>(shape - tree_->shapes.cbegin());
  r.triangle = tree_->ids[i];
  r.corners = tree_->corners[i];
  r.point = {p.x(), p.y(), p.z()};
  const auto corner = [&](int k) {
    const Kernel::Point_3& v = shape->vertex(k);
    return Eigen::Vector3d(v.x(), v.y(), v.z());
  };
  r.weights = weightsOn(r.point, corner(0), corner(1), corner(2));
  return r;
}

}  // namespace mpeg4face
