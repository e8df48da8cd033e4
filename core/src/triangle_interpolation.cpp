// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/triangle_interpolation.hpp"

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
                                           std::vector<std::uint8_t> tags)
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
  Eigen::AlignedBox2d box;
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
    box.extend(a);
    box.extend(b);
    box.extend(d);
    edges.push_back(std::max({(b - a).norm(), (d - b).norm(), (a - d).norm()}));
  }
  const int n = triangleCount();
  if (n == 0) return;
  // The few triangles with an edge over 4x the median are scanned by every fallback query, so
  // that the ring search's bound uses the longest edge of the others.
  std::vector<double> sorted = edges;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double longEdge = 4 * sorted[static_cast<std::size_t>(n / 2)];
  for (int t = 0; t < n; ++t) {
    if (edges[static_cast<std::size_t>(t)] > longEdge) {
      longTriangles_.push_back(t);
    } else {
      maxEdge_ = std::max(maxEdge_, edges[static_cast<std::size_t>(t)]);
    }
  }
  // Square cells holding about one triangle each, at most 4096 along a side.
  const Eigen::Vector2d size = box.sizes();
  cell_ = std::max({std::sqrt(size.x() * size.y() / n), size.maxCoeff() / 4096,
                    1e-12 * (1 + box.max().cwiseAbs().maxCoeff())});
  origin_ = box.min();
  nx_ = std::max(1, static_cast<int>(std::ceil(size.x() / cell_)));
  ny_ = std::max(1, static_cast<int>(std::ceil(size.y() / cell_)));
  const auto cellRange = [&](int t, int& x0, int& y0, int& x1, int& y1) {
    Eigen::AlignedBox2d b;
    for (int k = 0; k < 3; ++k) b.extend(Eigen::Vector2d(points_.row(triangles_[3 * t + k])));
    x0 = std::clamp(static_cast<int>(std::floor((b.min().x() - origin_.x()) / cell_)), 0, nx_ - 1);
    y0 = std::clamp(static_cast<int>(std::floor((b.min().y() - origin_.y()) / cell_)), 0, ny_ - 1);
    x1 = std::clamp(static_cast<int>(std::floor((b.max().x() - origin_.x()) / cell_)), 0, nx_ - 1);
    y1 = std::clamp(static_cast<int>(std::floor((b.max().y() - origin_.y()) / cell_)), 0, ny_ - 1);
  };
  std::vector<int> count(static_cast<std::size_t>(nx_) * ny_ + 1, 0);
  for (int t = 0; t < n; ++t) {
    int x0, y0, x1, y1;
    cellRange(t, x0, y0, x1, y1);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) ++count[static_cast<std::size_t>(y) * nx_ + x + 1];
    }
  }
  for (std::size_t i = 1; i < count.size(); ++i) count[i] += count[i - 1];
  cellStart_ = count;
  cellTriangles_.resize(static_cast<std::size_t>(count.back()));
  for (int t = 0; t < n; ++t) {
    int x0, y0, x1, y1;
    cellRange(t, x0, y0, x1, y1);
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        cellTriangles_[static_cast<std::size_t>(count[static_cast<std::size_t>(y) * nx_ + x]++)] =
            t;
      }
    }
  }
}

Eigen::Vector3d TriangleInterpolator::weightsIn(int t, const Eigen::Vector2d& p) const {
  const int* c = &triangles_[3 * static_cast<std::size_t>(t)];
  return barycentric2d(p, points_.row(c[0]), points_.row(c[1]), points_.row(c[2]));
}

double TriangleInterpolator::depthAt(int t, const Eigen::Vector3d& b) const {
  if (depth_.empty()) return 0;
  const int* c = &triangles_[3 * static_cast<std::size_t>(t)];
  return b[0] * depth_[c[0]] + b[1] * depth_[c[1]] + b[2] * depth_[c[2]];
}

bool TriangleInterpolator::cellOf(const Eigen::Vector2d& p, int& cx, int& cy) const {
  const double fx = std::floor((p.x() - origin_.x()) / cell_);
  const double fy = std::floor((p.y() - origin_.y()) / cell_);
  const bool inGrid = fx >= 0 && fx < nx_ && fy >= 0 && fy < ny_;
  cx = static_cast<int>(std::clamp(fx, 0.0, nx_ - 1.0));
  cy = static_cast<int>(std::clamp(fy, 0.0, ny_ - 1.0));
  return inGrid;
}

TriangleWeights TriangleInterpolator::locate(const Eigen::Vector2d& p,
                                             std::uint8_t excludedTags) const {
  TriangleWeights result;
  if (triangleCount() == 0 || !p.allFinite()) return result;
  const auto eligible = [&](int t) { return (tag(t) & excludedTags) == 0; };
  const auto finish = [&](int t, const Eigen::Vector3d& b, bool inside) {
    result.triangle = t;
    for (int k = 0; k < 3; ++k) result.corners[k] = triangles_[3 * static_cast<std::size_t>(t) + k];
    result.weights = clampBarycentric(b);
    result.inside = inside;
    return result;
  };
  int cx, cy;
  // Inside: every triangle holding p is registered in p's cell. Where several hold it
  // (overlap after projection), the smallest depth wins; ties go to the lowest index.
  if (cellOf(p, cx, cy)) {
    const std::size_t cell = static_cast<std::size_t>(cy) * nx_ + cx;
    int best = -1;
    double bestDepth = 0;
    Eigen::Vector3d bestB;
    constexpr double kOnEdge = -1e-12;
    for (int i = cellStart_[cell]; i < cellStart_[cell + 1]; ++i) {
      const int t = cellTriangles_[static_cast<std::size_t>(i)];
      if (!eligible(t)) continue;
      const Eigen::Vector3d b = weightsIn(t, p);
      if (b.minCoeff() < kOnEdge) continue;
      const double d = depthAt(t, b);
      if (best < 0 || d < bestDepth || (d == bestDepth && t < best)) {
        best = t;
        bestDepth = d;
        bestB = b;
      }
    }
    if (best >= 0) return finish(best, bestB, true);
  }
  // Outside: the smallest excess barycentric distance e. A triangle at Euclidean distance D
  // from p has e >= D / (2 * its longest edge) (docs/clone.md), so after the long triangles
  // the rings of cells around p stop once the cells not yet searched are too far to hold a
  // better triangle.
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
  for (int t : longTriangles_) consider(t);
  for (int r = 0;; ++r) {
    if (r > 0) {
      double bound = std::numeric_limits<double>::infinity();
      if (cx - r + 1 > 0) bound = std::min(bound, p.x() - (origin_.x() + (cx - r + 1) * cell_));
      if (cx + r - 1 < nx_ - 1) bound = std::min(bound, origin_.x() + (cx + r) * cell_ - p.x());
      if (cy - r + 1 > 0) bound = std::min(bound, p.y() - (origin_.y() + (cy - r + 1) * cell_));
      if (cy + r - 1 < ny_ - 1) bound = std::min(bound, origin_.y() + (cy + r) * cell_ - p.y());
      if (std::isinf(bound)) break;  // the whole grid is searched
      if (best >= 0 && 2 * maxEdge_ * bestE <= std::max(bound, 0.0)) break;
    }
    for (int y = cy - r; y <= cy + r; ++y) {
      if (y < 0 || y >= ny_) continue;
      const bool edgeRow = y == cy - r || y == cy + r;
      for (int x = cx - r; x <= cx + r; x += (edgeRow || r == 0) ? 1 : 2 * r) {
        if (x < 0 || x >= nx_) continue;
        const std::size_t cell = static_cast<std::size_t>(y) * nx_ + x;
        for (int i = cellStart_[cell]; i < cellStart_[cell + 1]; ++i) {
          consider(cellTriangles_[static_cast<std::size_t>(i)]);
        }
      }
    }
  }
  if (best < 0) return result;
  return finish(best, bestB, false);
}

}  // namespace mpeg4face
