// SPDX-License-Identifier: GPL-3.0-or-later
// Facial Motion Cloning: the modified butterfly rule's midpoint stencils over a mesh's edges
// (clone/clone_internal.hpp).
#include <algorithm>

#include "clone/clone_internal.hpp"

namespace mpeg4face::clone {

ButterflyMidpoints::ButterflyMidpoints(std::span<const int> triangles, Eigen::Index pointCount) {
  // Per point, the edges to points of higher index with each edge's opposite corner (CSR).
  start_.assign(static_cast<std::size_t>(pointCount) + 1, 0);
  const auto forEdges = [&](auto f) {
    for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
      for (std::size_t k = 0; k < 3; ++k) {
        const int a = triangles[t + k], b = triangles[t + (k + 1) % 3];
        f(std::min(a, b), std::max(a, b), triangles[t + (k + 2) % 3]);
      }
    }
  };
  forEdges([&](int lo, int, int) { ++start_[static_cast<std::size_t>(lo) + 1]; });
  for (std::size_t i = 1; i < start_.size(); ++i) start_[i] += start_[i - 1];
  edges_.resize(static_cast<std::size_t>(start_.back()));
  std::vector<int> next(start_.begin(), start_.end() - 1);
  forEdges([&](int lo, int hi, int opposite) {
    edges_[static_cast<std::size_t>(next[static_cast<std::size_t>(lo)]++)] = {hi, opposite};
  });
}

// The opposite corners of edge (x, y) when exactly two triangles share it, else (-1, -1).
std::pair<int, int> ButterflyMidpoints::opposite(int x, int y) const {
  const auto lo = static_cast<std::size_t>(std::min(x, y));
  const int hi = std::max(x, y);
  std::array<int, 3> found{-1, -1, -1};
  std::size_t count = 0;
  for (int i = start_[lo]; i < start_[lo + 1]; ++i) {
    const auto& [end, corner] = edges_[static_cast<std::size_t>(i)];
    if (end == hi && count < 3) found[count++] = corner;
  }
  return count == 2 ? std::pair{found[0], found[1]} : std::pair{-1, -1};
}

}  // namespace mpeg4face::clone
