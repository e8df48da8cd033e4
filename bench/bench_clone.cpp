// SPDX-License-Identifier: GPL-3.0-or-later
// Facial Motion Cloning speed and smoothness. Heads: CANDIDE-3 resampled to 25,000 and
// 100,000 vertices (subdivided, then decimated: clone_fixture.hpp; the target is CANDIDE-3
// stretched first, so the two faces differ in shape and in mesh), with the 68 synthetic FAP /
// viseme / expression shapes of tests/cpp/clone_fixture.hpp made in-process (local bumps, as
// sculpted shapes are; the share of vertices they move is printed). Single thread, no I/O in the
// timed part: cloneDeformedCopies of 68 shapes and of 1 shape, medians of several runs; the
// difference splits the time into the precomputation (projection, alignment, mapping weights) and
// the cost per shape. Compared with the goal (100 ms for 25k -> 25k, 1 s for 100k ->
// 100k) and with a baseline run in the same process (68 full copies of the target). Then the
// roughness of the cloned motion (clone_fixture.hpp: mean |uniform Laplacian| / mean |motion|) on a
// coarse and a dense target, filter off and on.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <span>
#include <vector>

#include "clone_fixture.hpp"
#include "mpeg4face/clone/clone.hpp"

using namespace mpeg4face;
namespace fixture = mpeg4face::clone_fixture;

namespace {

// The machine may be shared: this thread's CPU time, which other processes do not inflate;
// the wall-clock median is printed beside it.
double threadMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) / 1e6;
}
double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}
struct Timing {
  double cpuMs, wallMs;
};
Timing medianMs(int runs, const std::function<void()>& work) {
  std::vector<double> cpu, wall;
  for (int i = 0; i < runs; ++i) {
    const double c0 = threadMs();
    const auto w0 = std::chrono::steady_clock::now();
    work();
    wall.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - w0).count());
    cpu.push_back(threadMs() - c0);
  }
  return {median(cpu), median(wall)};
}

// CANDIDE-3 made wider, shorter and deeper (and moved): another face with the same features.
FaceModel stretched(FaceModel model) {
  Points3& p = model.meshes[0].coord;
  p = (p * Eigen::DiagonalMatrix<double, 3>(1.15, 0.9, 1.1)).rowwise() +
      Eigen::RowVector3d(0.2, -0.1, 0.05);
  for (auto& [id, binding] : model.featurePoints) {
    if (binding.mesh < 0) {
      binding.position = binding.position.cwiseProduct(Eigen::Vector3d(1.15, 0.9, 1.1)) +
                         Eigen::Vector3d(0.2, -0.1, 0.05);
    }
  }
  return model;
}

double meanRoughness(const FaceModel& source, std::span<const FaceShape> copies,
                     const FaceModel& target, double filterSupport) {
  CloneOptions options;
  options.filterSupport = filterSupport;
  const CloneResult r = cloneDeformedCopies(source, copies, target, options);
  const IndexedFaceSet& mesh = r.targetNeutral.meshes[0];
  double sum = 0;
  for (const FaceShape& c : r.copies) {
    sum += fixture::roughness(mesh, denseDisplacement(c, 0, mesh.vertexCount()));
  }
  return sum / static_cast<double>(r.copies.size());
}

}  // namespace

int main(int argc, char** argv) {
  // An argument (25000 or 100000) runs that size alone, without the roughness figures.
  const int only = argc > 1 ? std::atoi(argv[1]) : 0;
  constexpr int kRuns = 5;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // each figure as soon as it is measured
  const FaceModel base = fixture::candide(MPEG4FACE_TEST_DATA);
  std::printf(
      "Facial Motion Cloning, 68 shapes (FAP 3..68, viseme 1, expression 1), single thread\n"
      "thread CPU time, median of %d runs (wall-clock median in brackets)\n",
      kRuns);
  struct Case {
    int vertices;
    double goalMs;
  };
  for (const Case c : {Case{25000, 100}, Case{100000, 1000}}) {
    if (only != 0 && only != c.vertices) continue;
    const FaceModel source = fixture::resampled(base, c.vertices);
    const FaceModel target = fixture::resampled(stretched(base), c.vertices);
    const std::vector<FaceShape> copies = fixture::syntheticCopies(source, 0.3);
    // The baseline: 68 full FaceModel copies of the target, what returning each cloned copy
    // as a whole model would cost before any cloning; CloneResult keeps only what moves.
    const Timing baseline = medianMs(kRuns, [&] {
      std::vector<FaceModel> kept(copies.size(), target);
      if (kept.back().meshes.empty()) std::abort();
    });
    std::printf("%6d vertices: baseline, %zu full copies of the target FaceModel: %.1f ms\n",
                target.meshes[0].vertexCount(), copies.size(), baseline.cpuMs);
    std::size_t moved = 0;
    for (const FaceShape& copy : cloneDeformedCopies(source, copies, target).copies) {
      for (const MeshDisplacement& d : copy.meshes) moved += d.vertices.size();
    }
    std::printf("%6d vertices: a cloned shape moves %.1f%% of the target's vertices on average\n",
                target.meshes[0].vertexCount(),
                100.0 * static_cast<double>(moved) /
                    static_cast<double>(copies.size() *
                                        static_cast<std::size_t>(target.meshes[0].vertexCount())));
    // Default options (the adaptive filter: source and target are about as dense here, so
    // it does not filter), then the paper's fixed filter at every vertex, for comparison.
    CloneOptions fixed;
    fixed.adaptiveFilter = false;
    for (const auto& [label, options] :
         {std::pair{"", CloneOptions{}}, std::pair{" (fixed filter)", fixed}}) {
      const Timing all =
          medianMs(kRuns, [&] { cloneDeformedCopies(source, copies, target, options); });
      const Timing one = medianMs(
          kRuns, [&] { cloneDeformedCopies(source, std::span(copies).first(1), target, options); });
      const double perShape = (all.cpuMs - one.cpuMs) / static_cast<double>(copies.size() - 1);
      std::printf(
          "%6d -> %6d vertices%s: %8.1f ms [%8.1f] for %zu shapes; precompute %7.1f ms, "
          "per shape %6.2f ms; goal %4.0f ms: %.2fx the goal's time (%s)\n",
          source.meshes[0].vertexCount(), target.meshes[0].vertexCount(), label, all.cpuMs,
          all.wallMs, copies.size(), one.cpuMs - perShape, perShape, c.goalMs, all.cpuMs / c.goalMs,
          all.cpuMs <= c.goalMs ? "met" : "NOT met");
    }
  }

  if (only != 0) return 0;
  // Smoothness: a 25k source with per-vertex detail onto two coarser targets (1,000 and 6,000
  // vertices); a denser target is CloneSmoothness.DenserTargetGetsSmoothMotion's case.
  const FaceModel source = fixture::resampled(base, 25000);
  const std::vector<FaceShape> copies = fixture::syntheticCopies(source, 1.0);
  std::printf(
      "roughness of the cloned motion (mean |Laplacian| / mean |motion|), source %d "
      "vertices with per-vertex detail:\n",
      source.meshes[0].vertexCount());
  for (const FaceModel& target :
       {fixture::resampled(stretched(base), 1000), fixture::resampled(stretched(base), 6000)}) {
    const double off = meanRoughness(source, copies, target, 0);
    const double on = meanRoughness(source, copies, target, CloneOptions{}.filterSupport);
    std::printf("  target %6d vertices: filter off %.4f, on (adaptive, support %.2f) %.4f: %.2fx\n",
                target.meshes[0].vertexCount(), off, CloneOptions{}.filterSupport, on, on / off);
  }
  return 0;
}
