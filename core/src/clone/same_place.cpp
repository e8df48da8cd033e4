// SPDX-License-Identifier: GPL-3.0-or-later
// Facial Motion Cloning: the source vertex at a target point's place, for the exact motion of
// coincident vertices (clone/clone_internal.hpp).
#include <algorithm>
#include <limits>

#include "clone/clone_internal.hpp"

namespace mpeg4face::clone {

SamePlace::SamePlace(const Projected& source, const Points2& centroid)
    : source_(source), centroid_(centroid) {
  std::vector<bool> used(static_cast<std::size_t>(source.uv.rows()), false);
  for (int corner : source.triangles) used[static_cast<std::size_t>(corner)] = true;
  for (Eigen::Index r = 0; r < source.uv.rows(); ++r) {
    if (used[static_cast<std::size_t>(r)]) byU_.push_back(static_cast<int>(r));
  }
  std::sort(byU_.begin(), byU_.end(),
            [&](int a, int b) { return source.uv(a, 0) < source.uv(b, 0); });
}

// The source row nearest to (p, depth) within `radius` (alignment space and depth), -1 if
// none; of several at one place (a closed mouth's lips, a mesh split along a seam), the one
// not of lip `excluded` whose triangles lie on the side of `centroid` (the target point's
// mean triangle centroid).
int SamePlace::find(const Eigen::Vector2d& p, double depth, double radius,
                    const Eigen::Vector2d& centroid, LipRegion excluded,
                    const std::vector<LipRegion>& lips) const {
  auto it = std::lower_bound(byU_.begin(), byU_.end(), p.x() - radius,
                             [&](int r, double u) { return source_.uv(r, 0) < u; });
  int best = -1;
  double bestD = std::numeric_limits<double>::infinity(), bestSide = bestD;
  for (; it != byU_.end() && source_.uv(*it, 0) <= p.x() + radius; ++it) {
    const auto r = static_cast<std::size_t>(*it);
    if (excluded != LipRegion::Outside && lips[r] == excluded) continue;
    double d = Eigen::Vector3d(source_.uv(*it, 0) - p.x(), source_.uv(*it, 1) - p.y(),
                               source_.depth[r] - depth)
                   .norm();
    if (d > radius) continue;
    if (d <= kSame) d = 0;
    const double side = (centroid_.row(*it).transpose() - centroid).squaredNorm();
    if (d < bestD || (d == bestD && side < bestSide)) {
      bestD = d;
      bestSide = side;
      best = *it;
    }
  }
  return best;
}

}  // namespace mpeg4face::clone
