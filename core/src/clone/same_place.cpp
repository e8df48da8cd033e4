// SPDX-License-Identifier: GPL-3.0-or-later
// Facial Motion Cloning: the source vertex at a target point's place, for the exact motion of
// coincident vertices (clone/clone_internal.hpp).
#include <algorithm>
#include <limits>
#include <vector>

#include "clone/clone_internal.hpp"

namespace mpeg4face::clone {

std::vector<double> samePlaceTolerance(const Projected& p) {
  std::vector<double> sum(static_cast<std::size_t>(p.uv.rows()), 0.0);
  std::vector<int> count(sum.size(), 0);
  const auto at = [&](int r) {
    return Eigen::Vector3d(p.uv(r, 0), p.uv(r, 1), p.depth[static_cast<std::size_t>(r)]);
  };
  for (std::size_t t = 0; t + 2 < p.triangles.size(); t += 3) {
    for (std::size_t k = 0; k < 3; ++k) {
      const int a = p.triangles[t + k], b = p.triangles[t + (k + 1) % 3];
      const double length = (at(a) - at(b)).norm();
      for (int end : {a, b}) {
        sum[static_cast<std::size_t>(end)] += length;
        ++count[static_cast<std::size_t>(end)];
      }
    }
  }
  for (std::size_t r = 0; r < sum.size(); ++r) {
    if (count[r] > 0) sum[r] *= SamePlace::kSame / count[r];
  }
  return sum;
}

SamePlace::SamePlace(const Projected& source, const Points2& centroid)
    : source_(source), centroid_(centroid), tolerance_(samePlaceTolerance(source)) {
  std::vector<bool> used(static_cast<std::size_t>(source.uv.rows()), false);
  for (int corner : source.triangles) used[static_cast<std::size_t>(corner)] = true;
  for (Eigen::Index r = 0; r < source.uv.rows(); ++r) {
    if (!used[static_cast<std::size_t>(r)]) continue;
    byU_.push_back(static_cast<int>(r));
    widest_ = std::max(widest_, tolerance_[static_cast<std::size_t>(r)]);
  }
  std::sort(byU_.begin(), byU_.end(),
            [&](int a, int b) { return source.uv(a, 0) < source.uv(b, 0); });
}

// The source row at (p, depth): within its tolerance (alignment space and depth), -1 if
// none; of several there (a closed mouth's lips, a mesh split along a seam), the one not of
// lip `excluded` whose triangles lie on the side of `centroid` (the target point's mean
// triangle centroid).
int SamePlace::find(const Eigen::Vector2d& p, double depth, const Eigen::Vector2d& centroid,
                    LipRegion excluded, const std::vector<LipRegion>& lips) const {
  auto it = std::lower_bound(byU_.begin(), byU_.end(), p.x() - widest_,
                             [&](int r, double u) { return source_.uv(r, 0) < u; });
  int best = -1;
  double bestSide = std::numeric_limits<double>::infinity();
  for (; it != byU_.end() && source_.uv(*it, 0) <= p.x() + widest_; ++it) {
    const auto r = static_cast<std::size_t>(*it);
    if (excluded != LipRegion::Outside && lips[r] == excluded) continue;
    const double d = Eigen::Vector3d(source_.uv(*it, 0) - p.x(), source_.uv(*it, 1) - p.y(),
                                     source_.depth[r] - depth)
                         .norm();
    if (d > tolerance_[r]) continue;
    const double side = (centroid_.row(*it).transpose() - centroid).squaredNorm();
    if (side < bestSide) {
      bestSide = side;
      best = *it;
    }
  }
  return best;
}

}  // namespace mpeg4face::clone
