// SPDX-License-Identifier: GPL-3.0-or-later
// The motion check's self-intersection test (core/src/fat/pose_intersections.hpp): for poses
// from barely moved to folded through, the pairs it finds new are exactly those CGAL's
// self_intersections finds on the whole pose that the neutral does not have.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <random>
#include <vector>

#include "fat/pose_intersections.hpp"

using namespace mpeg4face;
using mpeg4face::fat::PoseIntersections;

namespace {

struct Sheets {
  Points3 coord;
  std::vector<int> triangles;
  int lower = 0, upper = 0, flat = 0;  // each sheet's first vertex
  int n = 10;
};

// Three n x n sheets of step 1: two jittered ones a third of a step apart, one above the
// other (lips), and a flat one far off where a triangle can fold exactly onto its neighbour.
Sheets sheets() {
  Sheets s;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.15, 0.15);
  const int n = s.n;
  s.coord.resize(3 * n * n, 3);
  const auto sheet = [&](int first, double z, double x0, bool jittered) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const double dz = jittered ? jitter(rng) * 0.2 : 0.0;
        s.coord.row(first + j * n + i) << x0 + i + (jittered ? jitter(rng) : 0),
            j + (jittered ? jitter(rng) : 0), z + dz;
      }
    }
    for (int j = 0; j + 1 < n; ++j) {
      for (int i = 0; i + 1 < n; ++i) {
        const int a = first + j * n + i, b = a + 1, c = a + n, d = c + 1;
        s.triangles.insert(s.triangles.end(), {a, b, d, a, d, c});
      }
    }
  };
  s.lower = 0, s.upper = n * n, s.flat = 2 * n * n;
  sheet(s.lower, 0, 0, true);
  sheet(s.upper, 0.33, 0.5, true);
  sheet(s.flat, 0, 40, false);
  return s;
}

std::vector<std::uint64_t> newByCgal(const Sheets& s, const Points3& pose,
                                     const std::vector<std::uint64_t>& neutral) {
  const std::vector<std::uint64_t> all = fat::allIntersectingPairs(pose, s.triangles);
  std::vector<std::uint64_t> fresh;
  std::set_difference(all.begin(), all.end(), neutral.begin(), neutral.end(),
                      std::back_inserter(fresh));
  return fresh;
}

TEST(PoseIntersections, FindsExactlyTheNewPairsCgalFindsFromSlightToFoldedPoses) {
  const Sheets s = sheets();
  PoseIntersections test(s.coord, s.triangles);
  EXPECT_EQ(test.neutralPairs(), fat::allIntersectingPairs(s.coord, s.triangles));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0, 1);
  int posesWithNewPairs = 0, posesWithout = 0;
  for (int k = 0; k < 60; ++k) {
    // Smooth bumps of 0.02 to 2 steps, each on one of the lips' sheets: the larger ones close
    // the gap or fold a sheet.
    const double amplitude = 0.02 * std::pow(100.0, k / 59.0);
    Points3 pose = s.coord;
    for (int bump = 0; bump < 3; ++bump) {
      const Eigen::Vector3d centre(unit(rng) * 10, unit(rng) * 10, 0);
      const Eigen::Vector3d move =
          amplitude * Eigen::Vector3d(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5) * 2;
      const int first = bump % 2 ? s.lower : s.upper;
      for (int v = first; v < first + s.n * s.n; ++v) {
        const double r = (Eigen::Vector3d(s.coord.row(v).transpose()) - centre).head<2>().norm();
        pose.row(v) += std::exp(-r * r / 4) * move.transpose();
      }
    }
    const std::vector<std::uint64_t> expected = newByCgal(s, pose, test.neutralPairs());
    EXPECT_EQ(test.newPairs(pose), expected) << "pose " << k << ", amplitude " << amplitude;
    (expected.empty() ? posesWithout : posesWithNewPairs) += 1;
  }
  // Both kinds of pose were met: the comparison says something either way.
  EXPECT_GE(posesWithNewPairs, 10);
  EXPECT_GE(posesWithout, 10);
}

TEST(PoseIntersections, FindsATriangleFoldedFlatOntoItsNeighbour) {
  const Sheets s = sheets();
  PoseIntersections test(s.coord, s.triangles);
  // Face (a, d, c) of the flat sheet's first square, a at (40, 0) and d at (41, 1), folded
  // over their diagonal onto (a, b, d): c from (40, 1) to b's side, still in the plane z = 0.
  const int c = s.flat + s.n;
  Points3 pose = s.coord;
  pose.row(c) << 40.75, 0.25, 0;
  const std::vector<std::uint64_t> expected = newByCgal(s, pose, test.neutralPairs());
  ASSERT_FALSE(expected.empty());
  EXPECT_EQ(test.newPairs(pose), expected);
}

TEST(PoseIntersections, ARigidMoveOfTheUpperSheetThroughTheLowerIsFound) {
  const Sheets s = sheets();
  PoseIntersections test(s.coord, s.triangles);
  Points3 pose = s.coord;
  for (int v = s.upper; v < s.upper + s.n * s.n; ++v) pose(v, 2) -= 0.35;
  const std::vector<std::uint64_t> expected = newByCgal(s, pose, test.neutralPairs());
  EXPECT_GT(expected.size(), 20u);
  EXPECT_EQ(test.newPairs(pose), expected);
}

// A triangle flat as a line in the neutral has no clearance to measure against the others; once
// a pose opens it, it is tested like any other.
TEST(PoseIntersections, ATriangleDegenerateInTheNeutralIsTestedOnceItOpens) {
  Sheets s = sheets();
  const int first = static_cast<int>(s.coord.rows());
  s.coord.conservativeResize(first + 6, 3);
  s.coord.bottomRows(6) << 20, 0, 0.5, 21, 0, 0.5, 22, 0, 0.5,  // along a line
      19, -1, 0, 23, -1, 0, 21, 2, 0;                            // beneath it
  s.triangles.insert(s.triangles.end(), {first, first + 1, first + 2, first + 3, first + 4,
                                         first + 5});
  PoseIntersections test(s.coord, s.triangles);
  Points3 pose = s.coord;
  pose(first + 1, 2) = -0.5;  // through the one beneath
  const std::vector<std::uint64_t> expected = newByCgal(s, pose, test.neutralPairs());
  ASSERT_EQ(expected.size(), 1u);
  EXPECT_EQ(test.newPairs(pose), expected);
}

}  // namespace
