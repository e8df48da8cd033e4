// SPDX-License-Identifier: GPL-3.0-or-later
// The antialiasing filter of Facial Motion Cloning (Pandzic 2003, Figure 8): motion of a
// dense source, sampled at the few vertices of a coarse target, aliases; the filter averages
// it over its support, so the cloned motion is smoother. Roughness as in clone_fixture.hpp;
// the figures are printed (bench_clone prints them too, for larger heads).
#include <gtest/gtest.h>

#include <cstdio>

#include "clone_fixture.hpp"
#include "mpeg4face/clone.hpp"
#include "test_support.hpp"

using namespace mpeg4face;
namespace fixture = mpeg4face::clone_fixture;

namespace {

// Mean roughness of the cloned motion of every copy on `target`.
double clonedRoughness(const FaceModel& source, const std::vector<DeformedCopy>& copies,
                       const FaceModel& target, double filterSupport) {
  CloneOptions options;
  options.filterSupport = filterSupport;
  options.rigidParts = false;
  const CloneResult result = cloneDeformedCopies(source, copies, target, options);
  const IndexedFaceSet& mesh = result.targetNeutral.meshes[0];
  double sum = 0;
  for (const DeformedCopy& c : result.copies) {
    sum += fixture::roughness(mesh, c.model.meshes[0].coord - mesh.coord);
  }
  return sum / static_cast<double>(result.copies.size());
}

}  // namespace

TEST(CloneSmoothness, FilterSmoothsDenseSourceOnCoarseTarget) {
  const FaceModel candide = fixture::candide(mpeg4face::test::kData);
  const FaceModel dense = fixture::resampled(candide, 20000);
  const FaceModel coarse = fixture::resampled(candide, 400);  // decimated
  const FaceModel medium = fixture::resampled(candide, 4000);
  const std::vector<DeformedCopy> copies = fixture::syntheticCopies(dense, 1.0);
  ASSERT_EQ(copies.size(), 68u);
  const double coarseOff = clonedRoughness(dense, copies, coarse, 0);
  const double coarseOn = clonedRoughness(dense, copies, coarse, CloneOptions{}.filterSupport);
  const double mediumOff = clonedRoughness(dense, copies, medium, 0);
  const double mediumOn = clonedRoughness(dense, copies, medium, CloneOptions{}.filterSupport);
  std::printf(
      "roughness of the cloned motion (68 shapes with per-vertex detail, source %d vertices)\n"
      "  target %6d vertices: filter off %.4f, on %.4f\n"
      "  target %6d vertices: filter off %.4f, on %.4f\n",
      dense.meshes[0].vertexCount(), coarse.meshes[0].vertexCount(), coarseOff, coarseOn,
      medium.meshes[0].vertexCount(), mediumOff, mediumOn);
  EXPECT_LT(coarseOn, coarseOff);
  EXPECT_LT(mediumOn, mediumOff);
  // The source's own motion is rough: what is cloned without the filter stays so.
  double sourceRoughness = 0;
  for (const DeformedCopy& c : copies) {
    sourceRoughness +=
        fixture::roughness(dense.meshes[0], c.model.meshes[0].coord - dense.meshes[0].coord);
  }
  std::printf("  source: %.4f\n", sourceRoughness / static_cast<double>(copies.size()));
}
