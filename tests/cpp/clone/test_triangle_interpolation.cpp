// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "clone/triangle_interpolation.hpp"

using namespace mpeg4face;

namespace {

Points2 pointsOf(std::initializer_list<std::pair<double, double>> xy) {
  Points2 p(static_cast<Eigen::Index>(xy.size()), 2);
  Eigen::Index i = 0;
  for (const auto& [x, y] : xy) p.row(i++) << x, y;
  return p;
}

double interpolate(const TriangleWeights& w, const std::vector<double>& f) {
  double sum = 0;
  for (int k = 0; k < 3; ++k)
    sum += w.weights[k] * f[static_cast<std::size_t>(w.corners[static_cast<std::size_t>(k)])];
  return sum;
}

}  // namespace

// By hand: in A(0,0) B(2,0) C(0,2), P(0.5,0.5) has b = (0.5, 0.25, 0.25).
TEST(TriangleInterpolation, InsideUsesBarycentricWeights) {
  const TriangleInterpolator interp(pointsOf({{0, 0}, {2, 0}, {0, 2}}), {0, 1, 2});
  const TriangleWeights w = interp.locate({0.5, 0.5});
  ASSERT_EQ(w.triangle, 0);
  EXPECT_TRUE(w.inside);
  EXPECT_NEAR(interpolate(w, {1, 3, 5}), 0.5 * 1 + 0.25 * 3 + 0.25 * 5, 1e-12);
}

// The paper's pseudo code by hand: P(3,1) in triangle 0 has b = (-1, 1.5, 0.5), excess 1.5;
// in triangle 1 (D(10,10) E(12,10) F(10,12)) b = (9, -3.5, -4.5), excess 16. Triangle 0 wins;
// clamped (0, 1, 0.5) / 1.5 = (0, 2/3, 1/3).
TEST(TriangleInterpolation, OutsideUsesClosestTriangleByExcessBarycentricDistance) {
  const Eigen::Vector3d b = barycentric2d({3, 1}, {0, 0}, {2, 0}, {0, 2});
  EXPECT_NEAR(b[0], -1, 1e-12);
  EXPECT_NEAR(b[1], 1.5, 1e-12);
  EXPECT_NEAR(b[2], 0.5, 1e-12);
  EXPECT_NEAR(excessBarycentricDistance(b), 1.5, 1e-12);
  EXPECT_NEAR(excessBarycentricDistance(barycentric2d({3, 1}, {10, 10}, {12, 10}, {10, 12})), 16,
              1e-12);
  const Eigen::Vector3d c = clampBarycentric(b);
  EXPECT_NEAR(c[0], 0, 1e-12);
  EXPECT_NEAR(c[1], 2.0 / 3, 1e-12);
  EXPECT_NEAR(c[2], 1.0 / 3, 1e-12);

  const TriangleInterpolator interp(
      pointsOf({{10, 10}, {12, 10}, {10, 12}, {0, 0}, {2, 0}, {0, 2}}), {0, 1, 2, 3, 4, 5});
  const TriangleWeights w = interp.locate({3, 1});
  EXPECT_FALSE(w.inside);
  ASSERT_EQ(w.triangle, 1);
  EXPECT_NEAR(interpolate(w, {0, 0, 0, 1, 3, 5}), 2.0 / 3 * 3 + 1.0 / 3 * 5, 1e-12);
}

// Without the fallback (closestFallback false) a point inside no triangle gets none; inside,
// the same weights.
TEST(TriangleInterpolation, WithoutFallbackOutsideGetsNone) {
  const TriangleInterpolator interp(pointsOf({{0, 0}, {2, 0}, {0, 2}}), {0, 1, 2}, {}, {}, false);
  EXPECT_EQ(interp.locate({3, 1}).triangle, -1);
  const TriangleWeights w = interp.locate({0.5, 0.5});
  ASSERT_EQ(w.triangle, 0);
  EXPECT_NEAR(interpolate(w, {1, 3, 5}), 0.5 * 1 + 0.25 * 3 + 0.25 * 5, 1e-12);
}

// The measure is the paper's, not the Euclidean distance: P(-0.5, 5) is 0.5 from the long
// thin triangle (0,0)(0,10)(0.1,5) (b = (3, 3, -5), excess 9) and sqrt(1.25) from
// (-3,6)(-1,6)(-3,8) (b = (0.25, 1.25, -0.5), excess 0.75), which the paper's rule takes,
// with weights (0.25, 1, 0) / 1.25.
TEST(TriangleInterpolation, OutsideFollowsThePaperNotEuclid) {
  const TriangleInterpolator interp(
      pointsOf({{0, 0}, {0, 10}, {0.1, 5}, {-3, 6}, {-1, 6}, {-3, 8}}), {0, 1, 2, 3, 4, 5});
  const TriangleWeights w = interp.locate({-0.5, 5});
  EXPECT_EQ(w.triangle, 1);
  EXPECT_NEAR(w.weights[0], 0.2, 1e-12);
  EXPECT_NEAR(w.weights[1], 0.8, 1e-12);
  EXPECT_NEAR(w.weights[2], 0, 1e-12);
}

// Two triangles over the same point: the one of smallest interpolated depth wins.
TEST(TriangleInterpolation, OverlapTakesSmallestDepth) {
  const Points2 p = pointsOf({{0, 0}, {2, 0}, {0, 2}, {-1, -1}, {3, 0}, {0, 3}});
  const std::vector<int> tris{0, 1, 2, 3, 4, 5};
  const TriangleInterpolator nearFirst(p, tris, {1, 1, 1, 0.5, 0.5, 0.5});
  EXPECT_EQ(nearFirst.locate({0.5, 0.5}).triangle, 1);
  const TriangleInterpolator nearSecond(p, tris, {0.2, 0.2, 0.2, 0.5, 0.5, 0.5});
  EXPECT_EQ(nearSecond.locate({0.5, 0.5}).triangle, 0);
  // Depth interpolated at the point, not per triangle: triangle 1 has depth 2 at (-1,-1) and
  // 0 on its far edge x + y = 3, i.e. 2 (3 - x - y) / 5 by hand: 1.12 at (0.1, 0.1) (deeper
  // than triangle 0's 0.5), 0.42 at (1, 0.95) (nearer).
  const TriangleInterpolator tilted(p, tris, {0.5, 0.5, 0.5, 2, 0, 0});
  EXPECT_EQ(tilted.locate({0.1, 0.1}).triangle, 0);
  EXPECT_EQ(tilted.locate({1, 0.95}).triangle, 1);
}

TEST(TriangleInterpolation, ExcludedTagsAreSkipped) {
  const Points2 p = pointsOf({{0, 0}, {2, 0}, {0, 2}, {5, 0}, {7, 0}, {5, 2}});
  const TriangleInterpolator interp(p, {0, 1, 2, 3, 4, 5}, {}, {1, 2});
  EXPECT_EQ(interp.locate({0.5, 0.5}).triangle, 0);
  EXPECT_EQ(interp.locate({0.5, 0.5}, 1).triangle, 1);
  EXPECT_FALSE(interp.locate({0.5, 0.5}, 1).inside);
  EXPECT_EQ(interp.locate({0.5, 0.5}, 3).triangle, -1);
}

// The grid index answers exactly as a scan of every triangle (the rule written out again).
TEST(TriangleInterpolation, GridAgreesWithBruteForce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3), unit(0, 1);
  constexpr int kSide = 30;
  Points2 p(kSide * kSide + 60, 2);
  std::vector<int> tris;
  for (int i = 0; i < kSide; ++i) {
    for (int j = 0; j < kSide; ++j) p.row(i * kSide + j) << j + jitter(rng), 0.7 * i + jitter(rng);
  }
  for (int i = 0; i + 1 < kSide; ++i) {
    for (int j = 0; j + 1 < kSide; ++j) {
      if (unit(rng) < 0.15) continue;  // holes
      const int v = i * kSide + j;
      tris.insert(tris.end(), {v, v + 1, v + kSide + 1, v, v + kSide + 1, v + kSide});
    }
  }
  // Some large overlapping triangles.
  for (int k = 0; k < 20; ++k) {
    const int base = kSide * kSide + 3 * k;
    for (int c = 0; c < 3; ++c) p.row(base + c) << 30 * unit(rng), 21 * unit(rng);
    tris.insert(tris.end(), {base, base + 1, base + 2});
  }
  std::vector<double> depth(static_cast<std::size_t>(p.rows()));
  for (double& d : depth) d = unit(rng);
  std::vector<std::uint8_t> tags(tris.size() / 3);
  for (auto& t : tags) t = unit(rng) < 0.2 ? 1 : 0;
  const TriangleInterpolator interp(p, tris, depth, tags);

  const auto bruteForce = [&](const Eigen::Vector2d& q, std::uint8_t excluded) {
    int inside = -1, closest = -1;
    double bestDepth = 0, bestE = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < tris.size() / 3; ++t) {
      if (tags[t] & excluded) continue;
      const int a = tris[3 * t], b = tris[3 * t + 1], c = tris[3 * t + 2];
      const Eigen::Vector3d w = barycentric2d(q, p.row(a), p.row(b), p.row(c));
      if (std::isnan(w[0])) continue;
      double minW = std::min({w[0], w[1], w[2]}), e = 0;
      for (int k = 0; k < 3; ++k) e += std::max(0.0, -w[k]) + std::max(0.0, w[k] - 1);
      const double d = w[0] * depth[a] + w[1] * depth[b] + w[2] * depth[c];
      if (minW >= -1e-12 && (inside < 0 || d < bestDepth)) {
        inside = static_cast<int>(t);
        bestDepth = d;
      }
      if (e < bestE) {
        bestE = e;
        closest = static_cast<int>(t);
      }
    }
    return inside >= 0 ? inside : closest;
  };
  std::uniform_real_distribution<double> qx(-15, 45), qy(-10, 30);
  int outside = 0;
  for (int i = 0; i < 4000; ++i) {
    const Eigen::Vector2d q(qx(rng), qy(rng));
    const std::uint8_t excluded = i % 2 ? 1 : 0;
    const TriangleWeights w = interp.locate(q, excluded);
    outside += !w.inside;
    ASSERT_EQ(w.triangle, bruteForce(q, excluded)) << "query " << q.transpose();
  }
  EXPECT_GT(outside, 1000);  // both branches exercised
}
