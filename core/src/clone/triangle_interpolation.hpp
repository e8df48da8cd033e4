// SPDX-License-Identifier: GPL-3.0-or-later
// Interpolation from a 2D triangle mesh (Pandzic 2003, "Interpolation from 2D triangle
// mesh"): a point inside triangles takes its barycentric weights in the one of smallest depth;
// a point outside all of them takes the clamped, renormalised weights of the triangle of
// smallest excess barycentric distance. A uniform grid over the triangles' bounding boxes
// keeps a query from scanning every triangle. Rules in docs/clone.md.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face {

// Barycentric coordinates of p in triangle (a, b, c); all three NaN for a degenerate one.
Eigen::Vector3d barycentric2d(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                              const Eigen::Vector2d& b, const Eigen::Vector2d& c);
// The paper's distance of a point outside a triangle: the sum of the amounts by which its
// barycentric coordinates fall below 0 or exceed 1 (0 inside).
double excessBarycentricDistance(const Eigen::Vector3d& b);
// The paper's closest point P': each coordinate clamped to [0, 1], then divided by their sum.
Eigen::Vector3d clampBarycentric(const Eigen::Vector3d& b);

struct TriangleWeights {
  int triangle = -1;                                  // -1: no triangle was eligible
  std::array<int, 3> corners{};                       // point indices
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();  // sum 1
  bool inside = false;   // false: the closest-triangle fallback was used
  bool overlap = false;  // inside, and more than one eligible triangle held the point
};

class TriangleInterpolator {
 public:
  // `triangles`: three point indices each. `depth`: one per point (empty: all 0); where
  // triangles overlap, the one with the smallest interpolated depth wins. `tags`: one bit
  // set per triangle (empty: all 0); a query may exclude triangles carrying given bits.
  // Degenerate triangles (zero area) are left out. `closestFallback` false: a point inside no
  // triangle gets none (triangle -1), and the fallback's grids are not made.
  TriangleInterpolator(Points2 points, std::vector<int> triangles, std::vector<double> depth = {},
                       std::vector<std::uint8_t> tags = {}, bool closestFallback = true);

  // `belowTop` > 0: of the triangles holding p, the one whose depth is nearest to the
  // smallest one's plus belowTop (a point under the outer surface: a fold, an inner layer).
  TriangleWeights locate(const Eigen::Vector2d& p, std::uint8_t excludedTags = 0,
                         double belowTop = 0) const;

  const Points2& points() const { return points_; }
  std::span<const int> triangles() const { return triangles_; }
  int triangleCount() const { return static_cast<int>(triangles_.size() / 3); }
  std::uint8_t tag(int triangle) const { return tags_.empty() ? 0 : tags_[triangle]; }

 private:
  // Triangles whose longest edge is in (base * 2^(k-1), base * 2^k], on a grid of their own
  // with cells of about that size: the fallback's bound then stays a few cells wide for
  // meshes whose triangle sizes vary a lot.
  struct Level {
    double maxEdge = 0;
    double cell = 1;
    Eigen::Vector2d origin = Eigen::Vector2d::Zero();
    int nx = 0, ny = 0;
    std::vector<int> cellStart;  // CSR: triangles of cell (y * nx + x)
    std::vector<int> cellTriangles;
    bool cellOf(const Eigen::Vector2d& p, int& cx, int& cy) const;
  };
  // Fills `level` with the triangles `ids` on cells of at least cellSize, and at most about
  // maxCellsPerTriangle cells per triangle.
  void buildGrid(Level& level, std::span<const int> ids, double cellSize,
                 double maxCellsPerTriangle) const;
  Eigen::Vector3d weightsIn(int triangle, const Eigen::Vector2d& p) const;
  double depthAt(int triangle, const Eigen::Vector3d& b) const;

  Points2 points_;
  std::vector<int> triangles_;
  std::vector<double> depth_;
  std::vector<std::uint8_t> tags_;
  std::vector<std::array<double, 6>> affine_;  // per triangle: b1, b2 = k0 x + k1 y + k2, ...
  std::vector<Level> levels_;                  // for the closest-triangle fallback
  Level inside_;                               // every triangle, for the inside test
};

}  // namespace mpeg4face
