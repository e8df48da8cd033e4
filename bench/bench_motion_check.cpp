// SPDX-License-Identifier: GPL-3.0-or-later
// How long the motion check takes on the MakeHuman sample (samples/build.sh makes it): its
// shape keys alone, and with the demo's 190-frame sentence; the median of several runs. Then
// its self-intersection test alone on the largest mesh's shape keys against the baseline,
// CGAL's self_intersections on the whole pose, which it must agree with pair for pair.
//   bench_motion_check [HEAD.glb [STREAM.fap]]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <optional>
#include <vector>

#include "fat/pose_intersections.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/motion_check.hpp"
#include "mpeg4face/io/read_any.hpp"

namespace {

double medianMs(std::vector<double> ms) {
  std::nth_element(ms.begin(), ms.begin() + ms.size() / 2, ms.end());
  return ms[ms.size() / 2];
}

template <typename F>
double millisecondsOf(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// The largest mesh's shape keys, each at 1: the fast test and the baseline, same answers.
int intersectionsAgainstBaseline(const mpeg4face::FaceModel& model, int runs) {
  using namespace mpeg4face;
  const auto largest =
      std::max_element(model.meshes.begin(), model.meshes.end(), [](const auto& a, const auto& b) {
        return a.vertexCount() < b.vertexCount();
      });
  if (largest == model.meshes.end() || largest->morphTargets.empty()) return 0;
  const IndexedFaceSet& mesh = *largest;
  const std::vector<int> triangles = fat::checkedTriangles(mesh);
  std::vector<Points3> poses;
  for (const MorphTarget& t : mesh.morphTargets) poses.push_back(mesh.coord + t.displacements);
  std::vector<double> prepare, fast, baseline;
  std::size_t pairs = 0;
  for (int run = 0; run < runs; ++run) {
    std::optional<fat::PoseIntersections> test;
    prepare.push_back(millisecondsOf([&] { test.emplace(mesh.coord, triangles); }));
    std::vector<std::vector<std::uint64_t>> found(poses.size()), expected(poses.size());
    fast.push_back(millisecondsOf([&] {
      for (std::size_t k = 0; k < poses.size(); ++k) found[k] = test->newPairs(poses[k]);
    }));
    baseline.push_back(millisecondsOf([&] {
      for (std::size_t k = 0; k < poses.size(); ++k) {
        const std::vector<std::uint64_t> whole = fat::allIntersectingPairs(poses[k], triangles);
        std::set_difference(whole.begin(), whole.end(), test->neutralPairs().begin(),
                            test->neutralPairs().end(), std::back_inserter(expected[k]));
      }
    }));
    if (found != expected) {
      std::fprintf(stderr, "bench_motion_check: the fast test and CGAL's disagree\n");
      return 1;
    }
    pairs = 0;
    for (const auto& f : found) pairs += f.size();
  }
  const double n = static_cast<double>(poses.size());
  std::printf("self-intersections, mesh %s (%ld vertices, %zu triangles), %zu shape keys with "
              "%zu new pairs in all: %.1f ms/pose (prepared once in %.0f ms) vs CGAL on the "
              "whole pose %.1f ms/pose: %.2fx (medians of %d)\n",
              mesh.name.c_str(), static_cast<long>(mesh.vertexCount()), triangles.size() / 3,
              poses.size(), pairs, medianMs(fast) / n, medianMs(prepare), medianMs(baseline) / n,
              medianMs(baseline) / medianMs(fast), runs);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  constexpr int kRuns = 5;
  const std::filesystem::path head = argc > 1 ? argv[1] : MPEG4FACE_SAMPLES "/makehuman_head.glb";
  const std::filesystem::path streamPath =
      argc > 2 ? argv[2] : MPEG4FACE_SAMPLES "/streams/hello.fap";
  try {
    const mpeg4face::FaceModel model = mpeg4face::readModel(head);
    const std::vector<mpeg4face::FapStream> streams{mpeg4face::readFapStream(streamPath)};
    long vertices = 0;
    for (const auto& mesh : model.meshes) vertices += mesh.vertexCount();
    for (const bool withStream : {false, true}) {
      std::vector<double> ms;
      mpeg4face::MotionCheck check;
      for (int i = 0; i < kRuns; ++i) {
        ms.push_back(millisecondsOf([&] {
          check = mpeg4face::checkMotion(
              model, withStream ? std::span(streams) : std::span<const mpeg4face::FapStream>{});
        }));
      }
      const double median = medianMs(ms);
      const std::size_t poses = check.keys.size() + check.frames.size();
      std::printf("%s (%ld vertices): %zu keys, %zu frames: %.0f ms (median of %d), %.2f ms/pose\n",
                  head.filename().c_str(), vertices, check.keys.size(), check.frames.size(), median,
                  kRuns, median / static_cast<double>(poses));
    }
    return intersectionsAgainstBaseline(model, 3);
  } catch (const mpeg4face::Error& e) {
    std::fprintf(stderr, "bench_motion_check: %s (run samples/build.sh first)\n", e.what());
    return 1;
  }
}
