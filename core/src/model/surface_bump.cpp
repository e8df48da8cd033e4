// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/model/surface_bump.hpp"

#include <algorithm>
#include <cmath>
#include <compare>
#include <cstddef>
#include <limits>
#include <numeric>
#include <string>

#include "mpeg4face/error.hpp"
#include "percentile.hpp"

namespace mpeg4face {

WeldedRings weldedRings(const Eigen::Ref<const Points3>& coord, std::span<const int> triangles) {
  const int n = static_cast<int>(coord.rows());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    if (triangles[i] < 0 || triangles[i] >= n) {
      throw Error({}, 0, "triangles[" + std::to_string(i / 3) + "]",
                  "vertex index out of range 0.." + std::to_string(n - 1));
    }
  }
  WeldedRings rings;

  // Weld: sort the vertices by position (IEEE total order, -0 made +0 first so that it
  // welds with 0; a NaN welds with nothing) and number the runs of equal positions.
  const Points3 key = (coord.array() + 0.0).matrix();
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    for (int k = 0; k < 3; ++k) {
      const std::strong_ordering c = std::strong_order(key(a, k), key(b, k));
      if (c != 0) return c < 0;
    }
    return a < b;
  });
  rings.weld.assign(static_cast<std::size_t>(n), -1);
  for (std::size_t i = 0; i < order.size(); ++i) {
    const int v = order[i];
    if (i == 0 || key.row(v) != key.row(order[i - 1])) rings.copies.push_back(0);
    rings.weld[static_cast<std::size_t>(v)] = static_cast<int>(rings.copies.size()) - 1;
    ++rings.copies.back();
  }

  // Each triangle's three edges in both directions, bucketed by their first end.
  const std::size_t welded = rings.copies.size();
  std::vector<int> count(welded + 1, 0);
  const auto each = [&](auto&& edge) {
    for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
      for (std::size_t k = 0; k < 3; ++k) {
        const int a = rings.weld[static_cast<std::size_t>(triangles[t + k])];
        const int b = rings.weld[static_cast<std::size_t>(triangles[t + (k + 1) % 3])];
        if (a == b) continue;
        edge(a, b);
        edge(b, a);
      }
    }
  };
  each([&](int a, int) { ++count[static_cast<std::size_t>(a) + 1]; });
  std::partial_sum(count.begin(), count.end(), count.begin());
  std::vector<int> all(static_cast<std::size_t>(count.back()));
  std::vector<int> fill(count.begin(), count.end() - 1);
  each([&](int a, int b) {
    all[static_cast<std::size_t>(fill[static_cast<std::size_t>(a)]++)] = b;
  });

  // Sorted and unique per ring (an inner edge comes from both of its triangles).
  rings.offset.assign(welded + 1, 0);
  rings.neighbour.reserve(all.size() / 2 + 1);
  for (std::size_t w = 0; w < welded; ++w) {
    const auto begin = all.begin() + count[w], end = all.begin() + count[w + 1];
    std::sort(begin, end);
    rings.neighbour.insert(rings.neighbour.end(), begin, std::unique(begin, end));
    rings.offset[w + 1] = static_cast<int>(rings.neighbour.size());
  }
  return rings;
}

WeldedRings weldedRings(const IndexedFaceSet& mesh) {
  const std::vector<int> triangles = mesh.triangles();
  return weldedRings(mesh.coord, triangles);
}

namespace {

void requireRows(const WeldedRings& rings, const Eigen::Ref<const Points3>& displacement) {
  if (static_cast<std::size_t>(displacement.rows()) != rings.weld.size()) {
    throw Error({}, 0, "displacement",
                "has " + std::to_string(displacement.rows()) + " rows, the mesh " +
                    std::to_string(rings.weld.size()) + " vertices");
  }
}

// Per welded vertex: the mean displacement of its copies, and the mean of those over its
// ring (0 for an empty ring).
struct WeldedMeans {
  Points3 own, ring;
};

WeldedMeans weldedMeans(const WeldedRings& rings, const Eigen::Ref<const Points3>& displacement) {
  const std::size_t n = rings.weld.size(), welded = rings.copies.size();
  WeldedMeans out{Points3::Zero(static_cast<Eigen::Index>(welded), 3),
                  Points3::Zero(static_cast<Eigen::Index>(welded), 3)};
  for (std::size_t v = 0; v < n; ++v) {
    out.own.row(rings.weld[v]) += displacement.row(static_cast<Eigen::Index>(v));
  }
  for (std::size_t w = 0; w < welded; ++w) {
    out.own.row(static_cast<Eigen::Index>(w)) /= rings.copies[w];
  }
  for (std::size_t w = 0; w < welded; ++w) {
    const int begin = rings.offset[w], end = rings.offset[w + 1];
    const auto row = static_cast<Eigen::Index>(w);
    for (int k = begin; k < end; ++k) {
      out.ring.row(row) += out.own.row(rings.neighbour[static_cast<std::size_t>(k)]);
    }
    if (end > begin) out.ring.row(row) /= end - begin;
  }
  return out;
}

}  // namespace

SurfaceBump surfaceBump(const WeldedRings& rings, const Eigen::Ref<const Points3>& displacement) {
  requireRows(rings, displacement);
  const std::size_t n = rings.weld.size(), welded = rings.copies.size();
  SurfaceBump out;
  out.motion = displacement.rowwise().norm();
  const WeldedMeans means = weldedMeans(rings, displacement);
  // Per welded vertex: the largest motion of its copies, then of its ring.
  Eigen::VectorXd largest = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(welded));
  for (std::size_t v = 0; v < n; ++v) {
    const auto w = static_cast<Eigen::Index>(rings.weld[v]);
    largest[w] = std::max(largest[w], out.motion[static_cast<Eigen::Index>(v)]);
  }
  Eigen::VectorXd ringLargest = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(welded));
  for (std::size_t w = 0; w < welded; ++w) {
    for (int k = rings.offset[w]; k < rings.offset[w + 1]; ++k) {
      const auto row = static_cast<Eigen::Index>(w);
      ringLargest[row] =
          std::max(ringLargest[row], largest[rings.neighbour[static_cast<std::size_t>(k)]]);
    }
  }
  out.bump.resize(static_cast<Eigen::Index>(n));
  out.localMotion.resize(static_cast<Eigen::Index>(n));
  for (std::size_t v = 0; v < n; ++v) {
    const auto i = static_cast<Eigen::Index>(v);
    const std::size_t w = static_cast<std::size_t>(rings.weld[v]);
    const auto row = static_cast<Eigen::Index>(w);
    if (rings.offset[w] == rings.offset[w + 1]) {
      out.bump[i] = std::numeric_limits<double>::quiet_NaN();
      out.localMotion[i] = out.motion[i];
      continue;
    }
    out.bump[i] = (displacement.row(i) - means.ring.row(row)).norm();
    out.localMotion[i] = std::max(out.motion[i], ringLargest[row]);
    out.peak = std::max(out.peak, out.motion[i]);
  }
  return out;
}

void relaxDisplacement(const WeldedRings& rings, Points3& displacement, int passes,
                       const std::vector<bool>& where) {
  requireRows(rings, displacement);
  if (!where.empty() && where.size() != rings.weld.size()) {
    throw Error({}, 0, "where",
                "has " + std::to_string(where.size()) + " entries, the mesh " +
                    std::to_string(rings.weld.size()) + " vertices");
  }
  for (int pass = 0; pass < passes; ++pass) {
    const Points3 ring = weldedMeans(rings, displacement).ring;
    for (std::size_t v = 0; v < rings.weld.size(); ++v) {
      const auto w = static_cast<std::size_t>(rings.weld[v]);
      if (rings.offset[w] == rings.offset[w + 1] || (!where.empty() && !where[v])) continue;
      const auto i = static_cast<Eigen::Index>(v);
      displacement.row(i) =
          0.5 * displacement.row(i) + 0.5 * ring.row(static_cast<Eigen::Index>(w));
    }
  }
}

SurfaceSpikes surfaceSpikes(const SurfaceBump& bump, double peak, double bumpOfPeak,
                            double bumpOfLocalMotion, double movingArea) {
  SurfaceSpikes out;
  if (!(peak > 0)) return out;
  std::vector<double> moving;
  for (Eigen::Index i = 0; i < bump.bump.size(); ++i) {
    const double b = bump.bump[i];
    if (std::isnan(b)) continue;
    if (bump.motion[i] >= movingArea * peak) moving.push_back(b / peak);
    if (!(b > bumpOfPeak * peak)) continue;
    // b > 0 here, and b <= |d_i| + mean |d_j| <= 2 m_i, so m_i > 0.
    const double ratio = b / bump.localMotion[i];
    out.localRatioMax = std::max(out.localRatioMax, ratio);
    if (b > bumpOfLocalMotion * bump.localMotion[i]) out.vertices.push_back(static_cast<int>(i));
  }
  out.bumpP99 = percentile(moving, 0.99);
  return out;
}

}  // namespace mpeg4face
