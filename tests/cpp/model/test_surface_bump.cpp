// SPDX-License-Identifier: GPL-3.0-or-later
// Bumps and spikes of a displacement field (model/surface_bump.hpp): a smooth Gaussian over a
// fine grid has none, one vertex pushed from it (or left behind) is the one spike, and a grid
// split along a seam gives the answers of the whole one.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "mpeg4face/error.hpp"
#include "mpeg4face/model/surface_bump.hpp"

namespace {

using namespace mpeg4face;

constexpr int kSide = 41;                 // vertices per side, over [-0.5, 0.5]^2
constexpr double kStep = 1.0 / (kSide - 1);

int at(int i, int j) { return j * kSide + i; }  // column i (x), row j (y)

// The grid, two triangles per square; with `seam`, the column x = 0 (i = kSide / 2) is split:
// the triangles right of it use copies of its vertices, appended in row order, at -0.0.
IndexedFaceSet grid(bool seam) {
  IndexedFaceSet mesh;
  mesh.coord.resize(kSide * kSide + (seam ? kSide : 0), 3);
  for (int j = 0; j < kSide; ++j) {
    for (int i = 0; i < kSide; ++i) {
      mesh.coord.row(at(i, j)) << -0.5 + i * kStep, -0.5 + j * kStep, 0;
    }
  }
  mesh.coord.col(0).segment(0, kSide * kSide) =
      mesh.coord.col(0).segment(0, kSide * kSide).unaryExpr([](double x) {
        return std::abs(x) < 1e-12 ? 0.0 : x;
      });
  const int mid = kSide / 2;
  const auto copy = [&](int i, int j) { return seam && i == mid ? kSide * kSide + j : at(i, j); };
  if (seam) {
    for (int j = 0; j < kSide; ++j) mesh.coord.row(kSide * kSide + j) << -0.0, -0.5 + j * kStep, 0;
  }
  for (int j = 0; j + 1 < kSide; ++j) {
    for (int i = 0; i + 1 < kSide; ++i) {
      // the square's left column is a copy when it is the seam and the square lies right of it
      const int a = copy(i, j), b = at(i + 1, j), c = copy(i, j + 1), d = at(i + 1, j + 1);
      mesh.coordIndex.insert(mesh.coordIndex.end(), {a, b, d, c, -1});
    }
  }
  return mesh;
}

// A Gaussian of height 1 and sigma 0.15 along z, centred at (0.1, 0): smooth at this
// resolution (6 edges per sigma). One row per vertex of `mesh`.
Points3 gaussian(const IndexedFaceSet& mesh) {
  Points3 d = Points3::Zero(mesh.vertexCount(), 3);
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    const double x = mesh.coord(v, 0) - 0.1, y = mesh.coord(v, 1);
    d(v, 2) = std::exp(-(x * x + y * y) / (2 * 0.15 * 0.15));
  }
  return d;
}

TEST(SurfaceBump, ASmoothGaussianHasNoSpike) {
  const IndexedFaceSet mesh = grid(false);
  const SurfaceBump b = surfaceBump(weldedRings(mesh), gaussian(mesh));
  EXPECT_NEAR(b.peak, 1.0, 1e-3);  // the centre (0.1, 0) is a grid vertex
  const SurfaceSpikes s = surfaceSpikes(b, 0.05, 0.75);
  EXPECT_TRUE(s.vertices.empty());
  // The umbrella Laplacian of the Gaussian: about h^2 / 3 * 2 / sigma^2 = 2% of the peak at
  // the top, less elsewhere; no vertex reaches 5% of the peak.
  EXPECT_LT(s.bumpP99, 0.03);
  EXPECT_GT(s.bumpP99, 0.005);
  EXPECT_EQ(s.localRatioMax, 0.0);
  // A translation has no bump at all.
  Points3 shift = Points3::Zero(mesh.vertexCount(), 3);
  shift.col(0).setConstant(0.3);
  const SurfaceBump flat = surfaceBump(weldedRings(mesh), shift);
  EXPECT_LT(flat.bump.maxCoeff(), 1e-12);
  EXPECT_TRUE(surfaceSpikes(flat, 0.05, 0.75).vertices.empty());
}

TEST(SurfaceBump, OneVertexPushedIsTheSpike) {
  const IndexedFaceSet mesh = grid(false);
  const WeldedRings rings = weldedRings(mesh);
  Points3 d = gaussian(mesh);
  const int pushed = at(10, 25);  // (-0.25, 0.125): the Gaussian is 0.05 there
  d(pushed, 2) += 0.5;
  const SurfaceBump b = surfaceBump(rings, d);
  const SurfaceSpikes s = surfaceSpikes(b, 0.05, 0.75);
  EXPECT_EQ(s.vertices, std::vector<int>{pushed});
  EXPECT_NEAR(b.bump[pushed], 0.5, 0.01);
  EXPECT_NEAR(s.localRatioMax, b.bump[pushed] / b.localMotion[pushed], 1e-12);
  EXPECT_GT(s.localRatioMax, 0.75);
  // Its ring carries a sixth of the push: bump 0.08, a sixth of its local motion.
  const int neighbour = at(11, 25);
  EXPECT_NEAR(b.bump[neighbour], 0.5 / 6, 0.01);
  EXPECT_NEAR(b.localMotion[neighbour], b.localMotion[pushed], 1e-12);

  // The same push on top of the Gaussian's peak is a small part of the local motion there.
  Points3 top = gaussian(mesh);
  top(at(24, 20), 2) += 0.5;
  EXPECT_TRUE(surfaceSpikes(surfaceBump(rings, top), 0.05, 0.75).vertices.empty());
  // A vertex left behind where the skin around it moves is a spike too.
  Points3 held = gaussian(mesh);
  held.row(at(24, 20)).setZero();
  EXPECT_EQ(surfaceSpikes(surfaceBump(rings, held), 0.05, 0.75).vertices,
            std::vector<int>{at(24, 20)});
}

TEST(SurfaceBump, AVertexOnNoTriangleIsLeftOut) {
  IndexedFaceSet mesh = grid(false);
  mesh.coord.conservativeResize(mesh.vertexCount() + 1, 3);
  mesh.coord.bottomRows(1) << 5, 5, 5;
  Points3 d = gaussian(mesh);
  d.bottomRows(1) << 0, 0, 10;  // far more than the peak
  const SurfaceBump b = surfaceBump(weldedRings(mesh), d);
  EXPECT_TRUE(std::isnan(b.bump[mesh.vertexCount() - 1]));
  EXPECT_NEAR(b.localMotion[mesh.vertexCount() - 1], 10, 1e-12);
  EXPECT_NEAR(b.peak, 1.0, 1e-3);
  EXPECT_TRUE(surfaceSpikes(b, 0.05, 0.75).vertices.empty());
}

TEST(SurfaceBump, ASeamSplitGivesTheAnswersOfTheWholeGrid) {
  const IndexedFaceSet whole = grid(false), split = grid(true);
  const int n = kSide * kSide, mid = kSide / 2;
  const WeldedRings rings = weldedRings(split);
  EXPECT_EQ(rings.copies.size(), static_cast<std::size_t>(n));  // -0.0 welds with 0
  const int seamVertex = at(mid, 35), copy = n + 35;  // (0, 0.375): the Gaussian is 0.04
  EXPECT_EQ(rings.weld[seamVertex], rings.weld[copy]);
  const int w = rings.weld[seamVertex];
  EXPECT_EQ(rings.offset[w + 1] - rings.offset[w], 6);  // both sides of the seam

  Points3 d = gaussian(whole), dSplit = gaussian(split);
  d(seamVertex, 2) += 0.5;  // a spike on the seam, in both copies
  dSplit(seamVertex, 2) += 0.5;
  dSplit(copy, 2) += 0.5;
  const SurfaceBump b = surfaceBump(weldedRings(whole), d);
  const SurfaceBump bs = surfaceBump(rings, dSplit);
  for (int v = 0; v < n; ++v) {
    ASSERT_NEAR(bs.bump[v], b.bump[v], 1e-12) << v;
    ASSERT_NEAR(bs.localMotion[v], b.localMotion[v], 1e-12) << v;
  }
  for (int j = 0; j < kSide; ++j) {
    ASSERT_NEAR(bs.bump[n + j], b.bump[at(mid, j)], 1e-12) << j;
  }
  EXPECT_EQ(surfaceSpikes(b, 0.05, 0.75).vertices, std::vector<int>{seamVertex});
  EXPECT_EQ(surfaceSpikes(bs, 0.05, 0.75).vertices, (std::vector<int>{seamVertex, copy}));
  const SurfaceSpikes s = surfaceSpikes(b, 0.05, 0.75), ss = surfaceSpikes(bs, 0.05, 0.75);
  EXPECT_NEAR(ss.localRatioMax, s.localRatioMax, 1e-12);
}

TEST(SurfaceBump, RelaxingFlattensTheSpikeAndKeepsTheSmoothField) {
  const IndexedFaceSet mesh = grid(false);
  const WeldedRings rings = weldedRings(mesh);
  Points3 d = gaussian(mesh);
  const int pushed = at(10, 25);
  d(pushed, 2) += 0.5;
  Points3 relaxed = d;
  relaxDisplacement(rings, relaxed, 4);
  EXPECT_TRUE(surfaceSpikes(surfaceBump(rings, relaxed), 0.05, 0.75).vertices.empty());
  // The spike spreads over its rings; the Gaussian's peak (6 edges per sigma) drops 3.6%.
  EXPECT_LT(relaxed(pushed, 2) - gaussian(mesh)(pushed, 2), 0.1);
  EXPECT_NEAR(relaxed(at(24, 20), 2), 1.0, 0.04);

  // One pass by hand: halfway to the mean of the ring (6 neighbours inside the grid).
  Points3 once = d;
  relaxDisplacement(rings, once, 1);
  double ring = 0;
  for (const auto& [i, j] : {std::pair{9, 25}, {11, 25}, {10, 24}, {10, 26}, {9, 24}, {11, 26}}) {
    ring += d(at(i, j), 2) / 6;
  }
  EXPECT_NEAR(once(pushed, 2), 0.5 * d(pushed, 2) + 0.5 * ring, 1e-12);

  // `where` leaves the vertices it excludes as they were.
  std::vector<bool> where(static_cast<std::size_t>(mesh.vertexCount()), true);
  where[static_cast<std::size_t>(pushed)] = false;
  Points3 kept = d;
  relaxDisplacement(rings, kept, 2, where);
  EXPECT_EQ(kept(pushed, 2), d(pushed, 2));
  EXPECT_NE(kept(at(11, 25), 2), d(at(11, 25), 2));
  Points3 wrong = d;
  EXPECT_THROW(relaxDisplacement(rings, wrong, 1, std::vector<bool>(3, true)), Error);
}

TEST(SurfaceBump, BadInput) {
  const IndexedFaceSet mesh = grid(false);
  const std::vector<int> triangles = {0, 1, kSide * kSide};
  try {
    weldedRings(mesh.coord, triangles);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "triangles[0]");
  }
  EXPECT_THROW(surfaceBump(weldedRings(mesh), Points3::Zero(3, 3)), Error);
  // No motion, no spike.
  const SurfaceBump still = surfaceBump(weldedRings(mesh), Points3::Zero(mesh.vertexCount(), 3));
  EXPECT_EQ(still.peak, 0.0);
  EXPECT_TRUE(surfaceSpikes(still, 0.05, 0.75).vertices.empty());
}

}  // namespace
