// SPDX-License-Identifier: GPL-3.0-or-later
#include "clone/triangle_interpolation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "mpeg4face/error.hpp"

namespace mpeg4face {

Eigen::Vector3d barycentric2d(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                              const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d v0 = b - a, v1 = c - a, v2 = p - a;
  const double den = v0.x() * v1.y() - v1.x() * v0.y();
  const double scale = std::max(v0.squaredNorm(), v1.squaredNorm());
  if (!(std::abs(den) > 1e-14 * scale)) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan, nan};
  }
  const double l1 = (v2.x() * v1.y() - v1.x() * v2.y()) / den;
  const double l2 = (v0.x() * v2.y() - v2.x() * v0.y()) / den;
  return {1 - l1 - l2, l1, l2};
}

double excessBarycentricDistance(const Eigen::Vector3d& b) {
  double distance = 0;
  for (int k = 0; k < 3; ++k) {
    if (b[k] < 0) distance += -b[k];
    if (b[k] > 1) distance += b[k] - 1;
  }
  return distance;
}

Eigen::Vector3d clampBarycentric(const Eigen::Vector3d& b) {
  const Eigen::Vector3d c = b.cwiseMax(0.0).cwiseMin(1.0);
  return c / c.sum();  // a point's coordinates sum to 1, so at least one is > 0 after clamping
}

TriangleInterpolator::TriangleInterpolator(Points2 points, std::vector<int> triangles,
                                           std::vector<double> depth,
                                           std::vector<std::uint8_t> tags, bool closestFallback)
    : points_(std::move(points)), depth_(std::move(depth)) {
  if (triangles.size() % 3 != 0) throw Error("triangle list length is not a multiple of 3");
  if (!depth_.empty() && depth_.size() != static_cast<std::size_t>(points_.rows())) {
    throw Error("depth count differs from the point count");
  }
  const bool tagged = !tags.empty();
  if (tagged && tags.size() * 3 != triangles.size()) {
    throw Error("tag count differs from the triangle count");
  }
  // Keep the non-degenerate triangles only.
  std::vector<double> edges;
  for (std::size_t t = 0; t < triangles.size() / 3; ++t) {
    const int* c = &triangles[3 * t];
    for (int k = 0; k < 3; ++k) {
      if (c[k] < 0 || c[k] >= points_.rows()) throw Error("triangle corner out of range");
    }
    const Eigen::Vector2d a = points_.row(c[0]), b = points_.row(c[1]), d = points_.row(c[2]);
    if (std::isnan(barycentric2d(a, a, b, d)[0])) continue;
    triangles_.insert(triangles_.end(), c, c + 3);
    if (tagged) tags_.push_back(tags[t]);
    // b1 and b2 as affine functions of p (barycentric2d's formulas, solved once).
    const Eigen::Vector2d v0 = b - a, v1 = d - a;
    const double den = v0.x() * v1.y() - v1.x() * v0.y();
    const std::array<double, 6> k = {v1.y() / den,  -v1.x() / den, 0,
                                     -v0.y() / den, v0.x() / den,  0};
    affine_.push_back(
        {k[0], k[1], -(k[0] * a.x() + k[1] * a.y()), k[3], k[4], -(k[3] * a.x() + k[4] * a.y())});
    edges.push_back(std::max({(b - a).norm(), (d - b).norm(), (a - d).norm()}));
  }
  const int n = triangleCount();
  if (n == 0) return;
  const double base = *std::min_element(edges.begin(), edges.end());
  std::vector<int> levelOf(static_cast<std::size_t>(n));
  int levelCount = 1;
  for (int t = 0; t < n; ++t) {
    const int k = std::clamp(
        static_cast<int>(std::ceil(std::log2(edges[static_cast<std::size_t>(t)] / base))), 0, 63);
    levelOf[static_cast<std::size_t>(t)] = k;
    levelCount = std::max(levelCount, k + 1);
  }
  std::vector<std::vector<int>> members(static_cast<std::size_t>(levelCount));
  for (int t = 0; t < n; ++t)
    members[static_cast<std::size_t>(levelOf[static_cast<std::size_t>(t)])].push_back(t);
  for (const std::vector<int>& ids : members) {
    if (ids.empty() || !closestFallback) continue;
    Level& level = levels_.emplace_back();
    for (int t : ids) level.maxEdge = std::max(level.maxEdge, edges[static_cast<std::size_t>(t)]);
    // Cells of about the level's edge, at most about 4 per triangle.
    buildGrid(level, ids, level.maxEdge, 4);
  }
  // The inside test's grid: every triangle in every cell its box touches, cells of about the
  // median edge (at most about 8 per triangle), so that a query reads one cell of a few
  // triangles instead of one cell per level.
  std::vector<int> all(static_cast<std::size_t>(n));
  for (int t = 0; t < n; ++t) all[static_cast<std::size_t>(t)] = t;
  std::vector<double> sorted = edges;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  buildGrid(inside_, all, sorted[static_cast<std::size_t>(n / 2)], 8);
}

void TriangleInterpolator::buildGrid(Level& level, std::span<const int> ids, double cellSize,
                                     double maxCellsPerTriangle) const {
  const auto boxOf = [&](int t) {
    Eigen::AlignedBox2d b;
    for (int k = 0; k < 3; ++k) {
      b.extend(Eigen::Vector2d(
          points_.row(triangles_[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>(k)])));
    }
    return b;
  };
  Eigen::AlignedBox2d box;
  for (int t : ids) box.extend(boxOf(t));
  // At most 4096 cells along a side.
  const Eigen::Vector2d size = box.sizes();
  const double count = static_cast<double>(ids.size());
  level.cell = std::max({cellSize, std::sqrt(size.x() * size.y() / (maxCellsPerTriangle * count)),
                         size.maxCoeff() / 4096, 1e-12 * (1 + box.max().cwiseAbs().maxCoeff())});
  level.origin = box.min();
  level.nx = std::max(1, static_cast<int>(std::ceil(size.x() / level.cell)));
  level.ny = std::max(1, static_cast<int>(std::ceil(size.y() / level.cell)));
  const auto cellRange = [&](int t, int& x0, int& y0, int& x1, int& y1) {
    const Eigen::AlignedBox2d b = boxOf(t);
    level.cellOf(b.min(), x0, y0);
    level.cellOf(b.max(), x1, y1);
  };
  std::vector<int> start(
      static_cast<std::size_t>(level.nx) * static_cast<std::size_t>(level.ny) + 1, 0);
  for (int t : ids) {
    int x0, y0, x1, y1;
    cellRange(t, x0, y0, x1, y1);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x)
        ++start[static_cast<std::size_t>(y) * static_cast<std::size_t>(level.nx) +
                static_cast<std::size_t>(x) + 1];
    }
  }
  for (std::size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
  level.cellStart = start;
  level.cellTriangles.resize(static_cast<std::size_t>(start.back()));
  for (int t : ids) {
    int x0, y0, x1, y1;
    cellRange(t, x0, y0, x1, y1);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        level.cellTriangles[static_cast<std::size_t>(
            start[static_cast<std::size_t>(y) * static_cast<std::size_t>(level.nx) +
                  static_cast<std::size_t>(x)]++)] = t;
      }
    }
  }
}

Eigen::Vector3d TriangleInterpolator::weightsIn(int t, const Eigen::Vector2d& p) const {
  const std::array<double, 6>& k = affine_[static_cast<std::size_t>(t)];
  const double b1 = k[0] * p.x() + k[1] * p.y() + k[2];
  const double b2 = k[3] * p.x() + k[4] * p.y() + k[5];
  return {1 - b1 - b2, b1, b2};
}

double TriangleInterpolator::depthAt(int t, const Eigen::Vector3d& b) const {
  if (depth_.empty()) return 0;
  const int* c = &triangles_[3 * static_cast<std::size_t>(t)];
  return b[0] * depth_[c[0]] + b[1] * depth_[c[1]] + b[2] * depth_[c[2]];
}

bool TriangleInterpolator::Level::cellOf(const Eigen::Vector2d& p, int& cx, int& cy) const {
  const double fx = std::floor((p.x() - origin.x()) / cell);
  const double fy = std::floor((p.y() - origin.y()) / cell);
  const bool inGrid = fx >= 0 && fx < nx && fy >= 0 && fy < ny;
  cx = static_cast<int>(std::clamp(fx, 0.0, nx - 1.0));
  cy = static_cast<int>(std::clamp(fy, 0.0, ny - 1.0));
  return inGrid;
}

TriangleWeights TriangleInterpolator::locate(const Eigen::Vector2d& p, std::uint8_t excludedTags,
                                             double belowTop) const {
  TriangleWeights result;
  if (triangleCount() == 0 || !p.allFinite()) return result;
  const auto eligible = [&](int t) { return (tag(t) & excludedTags) == 0; };
  const auto finish = [&](int t, const Eigen::Vector3d& b, bool inside) {
    result.triangle = t;
    for (int k = 0; k < 3; ++k) {
      result.corners[static_cast<std::size_t>(k)] =
          triangles_[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>(k)];
    }
    result.weights = clampBarycentric(b);
    result.inside = inside;
    return result;
  };
  const auto cellTriangles = [](const Level& level, int x, int y) {
    const std::size_t cell = static_cast<std::size_t>(y) * static_cast<std::size_t>(level.nx) +
                             static_cast<std::size_t>(x);
    return std::span<const int>(level.cellTriangles.data() + level.cellStart[cell],
                                level.cellTriangles.data() + level.cellStart[cell + 1]);
  };
  // Inside: every triangle holding p is registered in p's cell of the inside grid. Where several
  // hold it (overlap after projection), the smallest depth wins, or with belowTop > 0 the
  // depth nearest to the smallest + belowTop; ties go to the lowest index.
  {
    int best = -1;
    double bestDepth = 0;
    Eigen::Vector3d bestB;
    constexpr double kOnEdge = -1e-12;
    int cx, cy;
    if (inside_.cellOf(p, cx, cy)) {
      const std::span<const int> cell = cellTriangles(inside_, cx, cy);
      for (int t : cell) {
        if (!eligible(t)) continue;
        const Eigen::Vector3d b = weightsIn(t, p);
        if (b.minCoeff() < kOnEdge) continue;
        const double d = depthAt(t, b);
        result.overlap = best >= 0;
        if (best < 0 || d < bestDepth || (d == bestDepth && t < best)) {
          best = t;
          bestDepth = d;
          bestB = b;
        }
      }
      if (best >= 0 && belowTop > 0) {
        const double wanted = bestDepth + belowTop;
        double bestGap = belowTop;
        for (int t : cell) {
          if (!eligible(t)) continue;
          const Eigen::Vector3d b = weightsIn(t, p);
          if (b.minCoeff() < kOnEdge) continue;
          const double gap = std::abs(depthAt(t, b) - wanted);
          if (gap < bestGap || (gap == bestGap && t < best)) {
            best = t;
            bestGap = gap;
            bestB = b;
          }
        }
      }
    }
    if (best >= 0) return finish(best, bestB, true);
  }
  // Outside: the smallest excess barycentric distance e. A triangle at Euclidean distance D
  // from p has e >= D / (2 * its longest edge) (docs/clone.md), so on each level the rings of
  // cells around p stop once the cells not yet searched are too far to hold a better one.
  int best = -1;
  double bestE = std::numeric_limits<double>::infinity();
  Eigen::Vector3d bestB;
  const auto consider = [&](int t) {
    if (!eligible(t)) return;
    const Eigen::Vector3d b = weightsIn(t, p);
    const double e = excessBarycentricDistance(b);
    if (e < bestE || (e == bestE && t < best)) {
      best = t;
      bestE = e;
      bestB = b;
    }
  };
  const auto ring = [&](const Level& level, int cx, int cy, int r) {
    for (int y = cy - r; y <= cy + r; ++y) {
      if (y < 0 || y >= level.ny) continue;
      const bool edgeRow = y == cy - r || y == cy + r;
      for (int x = cx - r; x <= cx + r; x += (edgeRow || r == 0) ? 1 : 2 * r) {
        if (x < 0 || x >= level.nx) continue;
        for (int t : cellTriangles(level, x, y)) consider(t);
      }
    }
  };
  // Each level's own cell first, so that the bound below starts from a near triangle.
  for (const Level& level : levels_) {
    int cx, cy;
    level.cellOf(p, cx, cy);
    ring(level, cx, cy, 0);
  }
  for (const Level& level : levels_) {
    int cx, cy;
    level.cellOf(p, cx, cy);
    for (int r = 1;; ++r) {
      // Cells outside the square searched so far lie beyond one of its sides that is not
      // the grid's edge: p is at least `bound` from all of them.
      const double left = level.origin.x() + (cx - r + 1) * level.cell;
      const double right = level.origin.x() + (cx + r) * level.cell;
      const double bottom = level.origin.y() + (cy - r + 1) * level.cell;
      const double top = level.origin.y() + (cy + r) * level.cell;
      double bound = std::numeric_limits<double>::infinity();
      if (cx - r + 1 > 0) bound = std::min(bound, p.x() - left);
      if (cx + r - 1 < level.nx - 1) bound = std::min(bound, right - p.x());
      if (cy - r + 1 > 0) bound = std::min(bound, p.y() - bottom);
      if (cy + r - 1 < level.ny - 1) bound = std::min(bound, top - p.y());
      if (std::isinf(bound)) break;  // the whole level is searched
      if (best >= 0 && 2 * level.maxEdge * bestE <= std::max(bound, 0.0)) break;
      ring(level, cx, cy, r);
    }
  }
  if (best < 0) return result;
  return finish(best, bestB, false);
}

}  // namespace mpeg4face
