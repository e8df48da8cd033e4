// SPDX-License-Identifier: GPL-3.0-or-later
// The antialiasing filter of Facial Motion Cloning (Pandzic 2003, Figure 8): motion of a
// dense source, sampled at the few vertices of a coarse target, aliases; the filter averages
// it over its support, so the cloned motion is smoother. Roughness as in clone_fixture.hpp;
// the figures are printed (bench_clone prints them too, for larger heads).
#include <gtest/gtest.h>

#include <cstdio>

#include "clone_fixture.hpp"
#include "mpeg4face/clone/clone.hpp"
#include "test_support.hpp"

using namespace mpeg4face;
namespace fixture = mpeg4face::clone_fixture;

namespace {

// Mean roughness of the cloned motion of every copy on `target`.
double clonedRoughness(const FaceModel& source, const std::vector<FaceShape>& copies,
                       const FaceModel& target, CloneOptions options) {
  options.rigidParts = false;
  const CloneResult result = cloneDeformedCopies(source, copies, target, options);
  const IndexedFaceSet& mesh = result.targetNeutral.meshes[0];
  double sum = 0;
  for (const FaceShape& c : result.copies) {
    sum += fixture::roughness(mesh, denseDisplacement(c, 0, mesh.vertexCount()));
  }
  return sum / static_cast<double>(result.copies.size());
}

double sourceRoughness(const FaceModel& source, const std::vector<FaceShape>& copies) {
  double sum = 0;
  for (const FaceShape& c : copies) {
    sum += fixture::roughness(source.meshes[0],
                              denseDisplacement(c, 0, source.meshes[0].vertexCount()));
  }
  return sum / static_cast<double>(copies.size());
}

struct Roughness {
  double off, adaptive, fixed;
};

// Without the filter (nor the smoothing), with the default (adaptive) one and with the
// paper's fixed support.
Roughness roughnessOf(const FaceModel& source, const std::vector<FaceShape>& copies,
                      const FaceModel& target) {
  CloneOptions off, fixed;
  off.filterSupport = 0;
  off.smoothSupport = 0;
  fixed.adaptiveFilter = false;
  const Roughness r{clonedRoughness(source, copies, target, off),
                    clonedRoughness(source, copies, target, CloneOptions{}),
                    clonedRoughness(source, copies, target, fixed)};
  std::printf("  target %6d vertices: filter off %.4f, adaptive %.4f, fixed %.4f\n",
              target.meshes[0].vertexCount(), r.off, r.adaptive, r.fixed);
  return r;
}

}  // namespace

TEST(CloneSmoothness, FilterSmoothsDenseSourceOnCoarseTarget) {
  const FaceModel candide = fixture::candide(mpeg4face::test::kData);
  const FaceModel dense = fixture::resampled(candide, 20000);
  const std::vector<FaceShape> copies = fixture::syntheticCopies(dense, 1.0);
  ASSERT_EQ(copies.size(), 68u);
  std::printf(
      "roughness of the cloned motion (68 shapes with per-vertex detail, source %d vertices, "
      "its own %.4f)\n",
      dense.meshes[0].vertexCount(), sourceRoughness(dense, copies));
  for (const int vertices : {400, 4000}) {  // decimated targets
    const Roughness r = roughnessOf(dense, copies, fixture::resampled(candide, vertices));
    EXPECT_LT(r.adaptive, r.off) << vertices;
    EXPECT_LT(r.fixed, r.off) << vertices;
  }
}

// Onto a much denser target the motion, interpolated linearly inside the source's triangles,
// bends at their borders; the default options smooth it there (CloneOptions::smoothSupport),
// the fixed filter blurs it too.
TEST(CloneSmoothness, DenserTargetGetsSmoothMotion) {
  const FaceModel candide = fixture::candide(mpeg4face::test::kData);
  const FaceModel coarse = fixture::resampled(candide, 300);
  const std::vector<FaceShape> copies = fixture::syntheticCopies(coarse, 1.0);
  const double own = sourceRoughness(coarse, copies);
  std::printf("roughness onto a denser target (source %d vertices, its own %.4f)\n",
              coarse.meshes[0].vertexCount(), own);
  const Roughness r = roughnessOf(coarse, copies, fixture::resampled(candide, 20000));
  EXPECT_LT(r.off, 0.5 * own);
  EXPECT_LT(r.adaptive, 0.8 * r.off);
  EXPECT_LE(r.fixed, r.off);
}
