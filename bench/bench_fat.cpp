// SPDX-License-Identifier: GPL-3.0-or-later
// FAT speed on a synthetic 26,000-vertex head (an ellipsoid grid: MakeHuman's base.obj has
// only 19,158 vertices, most of them body): one frame of 60 FAPs, each moving the 20% of
// the vertices nearest a point of the head with 2 or 3 intervals, against a dense baseline
// (every FAP a dense morph target over all vertices, float, as glTF stores them) run in the
// same process; and the generator making 68 tables from 68 shapes. Single thread,
// medians of several runs.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <functional>
#include <numeric>
#include <random>
#include <utility>
#include <vector>

#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/fat/generate.hpp"

using namespace mpeg4face;

namespace {

constexpr int kAround = 200, kRings = 130;  // 26,000 vertices
constexpr int kActiveFaps = 60;
constexpr double kRegion = 0.2;
constexpr double kPi = 3.14159265358979323846;

// The machine may be shared: time is this thread's CPU time (CLOCK_THREAD_CPUTIME_ID), which
// other processes do not inflate (they still share caches and memory bandwidth: the best run
// shows what a quiet machine does); the wall-clock median is printed beside it.
double thisThreadMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) / 1e6;
}

// CPU time is not the same as a core: on a VM, the physical core under this thread may run
// another tenant's thread on its other hyperthread, and then this one issues about half as
// many instructions in the same CPU time (docs/fat.md). The probe measures the share of the
// core this thread has: a loop that issues as fast as the core lets it (an add a step, kept
// by an empty asm from being folded), in steps per ms. The fastest probe in the process is
// the whole core; runs with probes near it on both sides were measured on one whole core.
// Not inlined: one copy of the loop, the same for every call (inlined copies, placed
// differently, ran at different rates).
double fastestProbe = 0;
[[gnu::noinline]] double probe() {
  constexpr int kSteps = 1000000;
  std::uint64_t x = 0;
  const double t0 = thisThreadMs();
  for (int i = 0; i < kSteps; ++i) {
    x += 1;
    __asm__ volatile("" : "+r"(x));
  }
  const double rate = static_cast<double>(x) / (thisThreadMs() - t0);
  fastestProbe = std::max(fastestProbe, rate);
  return rate;
}
constexpr double kWholeCore = 0.9;  // a run counts as on one whole core above this share

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}
struct Timing {
  double cpuMs, wallMs, bestCpuMs;
  std::vector<double> runCpuMs, runProbe;  // per run; the probe is the slower of the two sides
  // The median CPU time of the runs on a whole core (once the fastest probe is known), and
  // how many there were; 0 ms if none.
  std::pair<double, std::size_t> wholeCore() const {
    std::vector<double> kept;
    for (std::size_t i = 0; i < runCpuMs.size(); ++i) {
      if (runProbe[i] >= kWholeCore * fastestProbe) kept.push_back(runCpuMs[i]);
    }
    return {kept.empty() ? 0.0 : median(kept), kept.size()};
  }
};
// Times the works in turn, run by run (so that what the machine does at a moment falls on all
// of them alike), each run `repeats` calls of one work.
std::vector<Timing> medianMilliseconds(int runs, int repeats,
                                       const std::vector<std::function<void()>>& works) {
  std::vector<Timing> t(works.size());
  std::vector<std::vector<double>> wall(works.size());
  double before = probe();
  for (int i = 0; i < runs; ++i) {
    for (std::size_t k = 0; k < works.size(); ++k) {
      const double c0 = thisThreadMs();
      const auto w0 = std::chrono::steady_clock::now();
      for (int r = 0; r < repeats; ++r) works[k]();
      wall[k].push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - w0).count() /
          repeats);
      t[k].runCpuMs.push_back((thisThreadMs() - c0) / repeats);
      const double after = probe();
      t[k].runProbe.push_back(std::min(before, after));
      before = after;
    }
  }
  for (std::size_t k = 0; k < works.size(); ++k) {
    t[k].cpuMs = median(t[k].runCpuMs);
    t[k].wallMs = median(wall[k]);
    t[k].bestCpuMs = *std::min_element(t[k].runCpuMs.begin(), t[k].runCpuMs.end());
  }
  return t;
}
Timing medianMilliseconds(int runs, int repeats, const std::function<void()>& work) {
  return medianMilliseconds(runs, repeats, std::vector<std::function<void()>>{work})[0];
}

FaceModel syntheticHead() {
  IndexedFaceSet mesh;
  mesh.name = "Head";
  mesh.coord.resize(kAround * kRings, 3);
  for (int r = 0; r < kRings; ++r) {
    const double theta = kPi * (r + 0.5) / kRings;
    for (int a = 0; a < kAround; ++a) {
      const double phi = 2 * kPi * a / kAround;
      mesh.coord.row(r * kAround + a) << 0.08 * std::sin(theta) * std::sin(phi),
          0.12 * std::cos(theta), 0.1 * std::sin(theta) * std::cos(phi);
      if (r + 1 < kRings) {
        const int v = r * kAround + a, right = r * kAround + (a + 1) % kAround;
        mesh.coordIndex.insert(mesh.coordIndex.end(), {v, right, right + kAround, v + kAround, -1});
      }
    }
  }
  FaceModel model;
  model.addMeshWithTransform(mesh);
  const auto bind = [&](const char* id, double x, double y, double z) {
    model.featurePoints[id] = {-1, -1, {x, y, z}};
  };
  bind("3.5", 0.032, 0.03, 0.08);
  bind("3.6", -0.032, 0.03, 0.08);
  bind("3.1", 0.032, 0.036, 0.08);
  bind("3.3", 0.032, 0.024, 0.08);
  bind("9.15", 0, -0.015, 0.1);
  bind("2.2", 0, -0.045, 0.09);
  bind("8.3", 0.025, -0.045, 0.09);
  bind("8.4", -0.025, -0.045, 0.09);
  return model;
}

// The kRegion share of the vertices nearest a random vertex, in index order.
std::vector<int> region(const Points3& coord, std::mt19937& rng) {
  const int n = static_cast<int>(coord.rows());
  const Eigen::RowVector3d centre = coord.row(std::uniform_int_distribution<int>(0, n - 1)(rng));
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  const auto keep = static_cast<std::ptrdiff_t>(kRegion * n);
  std::nth_element(order.begin(), order.begin() + keep, order.end(), [&](int a, int b) {
    return (coord.row(a) - centre).squaredNorm() < (coord.row(b) - centre).squaredNorm();
  });
  order.resize(static_cast<std::size_t>(keep));
  std::sort(order.begin(), order.end());
  return order;
}

}  // namespace

int main() {
  constexpr int kRuns = 21, kStreamRuns = 301;
  std::mt19937 rng(1);
  const FaceModel head = syntheticHead();
  const FapuMeasurement fapu = measureFapu(head);
  const Points3& p0 = head.meshes[0].coord;
  const int vertices = static_cast<int>(p0.rows());

  // Tables: FAPs 3..62, 2 or 3 intervals each.
  MpegFace face{head, {}};
  std::uniform_real_distribution<double> d(-1, 1);
  long displacementsPerFrame = 0;
  for (int fap = 3; fap < 3 + kActiveFaps; ++fap) {
    FaceDefTables& t = face.faceDefTables.emplace_back();
    t.fapID = fap;
    FaceDefMesh& m = t.faceDefMesh.emplace_back();
    m.mesh = 0;
    m.intervalBorders = fap % 3 == 0   ? std::vector<int>{-600, 0, 500}
                        : fap % 3 == 1 ? std::vector<int>{-800, -300, 0, 600}
                                       : std::vector<int>{-400, 0, 400, 900};
    m.coordIndex = region(p0, rng);
    m.displacements.resize(static_cast<Eigen::Index>(m.coordIndex.size()) * m.intervalCount(), 3);
    for (Eigen::Index r = 0; r < m.displacements.rows(); ++r) {
      m.displacements.row(r) << d(rng), d(rng), d(rng);
    }
    displacementsPerFrame += static_cast<long>(m.coordIndex.size());
  }
  // Frames: every FAP present. A FAP stream moves smoothly: 10 s at 25 fps of sine waves
  // (a period of 2 to 4.4 s per FAP) over and beyond the borders. As a worst case, random
  // values each frame: then each frame reads other intervals than the one before.
  std::vector<FapFrame> stream(250), random(250);
  std::uniform_int_distribution<int> value(-1000, 1000);
  for (int t = 0; t < 250; ++t) {
    for (int fap = 3; fap < 3 + kActiveFaps; ++fap) {
      stream[t].set(
          fap,
          static_cast<int>(std::lround(1000 * std::sin(2 * kPi * (t / (50.0 + fap) + fap / 7.0)))));
      random[t].set(fap, value(rng));
    }
  }

  // The 16-bit tables (for playback) and the float ones (the default) beside them.
  const FatEvaluator eval(face, fapu, FatStorage::Int16);
  const FatEvaluator evalFloat(face, fapu);
  FatState state = eval.neutralState();
  int frame = 0;
  // Many short runs, so that enough of them fall where the core is the thread's alone.
  const auto evaluateNext = [&](const FatEvaluator& e, const std::vector<FapFrame>& frames) {
    return [&] { e.evaluate(frames[frame++ % 250], state); };
  };
  // Beside the stream, in alternate runs: what every frame costs whatever its tables (the
  // summed motion added to the double neutral positions into the state's double coordinates,
  // the sums reset), timed alone as frames in which no FAP is present.
  const std::vector<FapFrame> empty(250);
  const std::vector<Timing> streamAndPass =
      medianMilliseconds(kStreamRuns, 20, {evaluateNext(eval, stream), evaluateNext(eval, empty)});
  const Timing& fat = streamAndPass[0];
  const Timing& finalPass = streamAndPass[1];
  const Timing fatFloat = medianMilliseconds(kStreamRuns, 20, evaluateNext(evalFloat, stream));
  const Timing fatRandom = medianMilliseconds(kStreamRuns, 20, evaluateNext(eval, random));
  const Timing fatFloatRandom =
      medianMilliseconds(kStreamRuns, 20, evaluateNext(evalFloat, random));

  // What 16 bits cost: the largest difference from float over the stream, against the
  // largest motion of a vertex in the same frames.
  double largestError = 0, largestMotion = 0;
  FatState floatState = evalFloat.neutralState();
  for (const FapFrame& f : stream) {
    eval.evaluate(f, state);
    evalFloat.evaluate(f, floatState);
    largestError =
        std::max(largestError, (state.coord[0] - floatState.coord[0]).cwiseAbs().maxCoeff());
    largestMotion = std::max(largestMotion, (floatState.coord[0] - p0).rowwise().norm().maxCoeff());
  }

  // Dense baseline: neutral + sum over FAPs of value * target, every target covering every
  // vertex (one linear morph target per FAP: the cost of the same frame without FAT).
  std::vector<std::vector<float>> dense(kActiveFaps, std::vector<float>(3 * std::size_t(vertices)));
  for (int k = 0; k < kActiveFaps; ++k) {
    const FaceDefMesh& m = face.faceDefTables[k].faceDefMesh[0];
    for (std::size_t i = 0; i < m.coordIndex.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        dense[k][3 * std::size_t(m.coordIndex[i]) + c] = static_cast<float>(
            fapScale(fapu, k + 3) *
            m.displacements(static_cast<Eigen::Index>(i) * m.intervalCount(), c));
      }
    }
  }
  Points3 out = p0;
  frame = 0;
  const Timing baseline = medianMilliseconds(kRuns, 64, [&] {
    const FapFrame& f = stream[frame++ % 250];
    out = p0;
    double* p = out.data();
    for (int k = 0; k < kActiveFaps; ++k) {
      const double w = f.value(k + 3);
      const float* t = dense[k].data();
      for (int j = 0; j < 3 * vertices; ++j) p[j] += w * t[j];
    }
  });

  std::printf(
      "synthetic head (ellipsoid grid): %d vertices; %d FAPs per frame, %ld vertex "
      "displacements (%.0f%% of the vertices each, 2-3 intervals); a 250-frame FAP stream\n"
      "thread CPU time per frame: median of %d runs (%d for the evaluator) [best run], "
      "wall-clock median in brackets;\n"
      "and the median of the runs on one whole core (a probe either side at >= %.0f%% of the "
      "fastest)\n",
      vertices, kActiveFaps, displacementsPerFrame, 100 * kRegion, kRuns, kStreamRuns,
      100 * kWholeCore);
  const auto rate = [](double count, double ms) { return ms > 0 ? count / ms / 1e6 : 0.0; };
  const auto row = [&](const char* what, const Timing& t, double displacements) {
    const auto [wholeMs, wholeRuns] = t.wholeCore();
    std::printf(
        "%-32s %6.3f ms/frame [%6.3f] (%6.3f)  %5.2f [%5.2f] G vertex displacements/s; "
        "whole core %6.3f ms, %5.2f G/s (%zu of %zu runs)\n",
        what, t.cpuMs, t.bestCpuMs, t.wallMs, rate(displacements, t.cpuMs),
        rate(displacements, t.bestCpuMs), wholeMs, rate(displacements, wholeMs), wholeRuns,
        t.runCpuMs.size());
  };
  row("evaluate, 16-bit tables", fat, double(displacementsPerFrame));
  {
    const auto [passMs, passRuns] = finalPass.wholeCore();
    const auto [fatMs, fatRuns] = fat.wholeCore();
    std::printf(
        "%-32s %6.3f ms/frame; whole core %6.3f ms (%zu of %zu runs), %.0f%% of a 16-bit frame; "
        "the frame less it: %.2f G/s\n",
        "  of which: the final pass", finalPass.cpuMs, passMs, passRuns, finalPass.runCpuMs.size(),
        passRuns && fatRuns ? 100 * passMs / fatMs : 0.0,
        passRuns && fatRuns && fatMs > passMs ? rate(double(displacementsPerFrame), fatMs - passMs)
                                              : 0.0);
  }
  row("  same, random values (worst)", fatRandom, double(displacementsPerFrame));
  row("evaluate, float tables", fatFloat, double(displacementsPerFrame));
  row("  same, random values (worst)", fatFloatRandom, double(displacementsPerFrame));
  row("dense morph targets (baseline)", baseline, double(kActiveFaps) * vertices);
  std::vector<double> probes;
  for (const Timing* t : {&fat, &fatRandom, &fatFloat, &fatFloatRandom, &finalPass, &baseline}) {
    probes.insert(probes.end(), t->runProbe.begin(), t->runProbe.end());
  }
  std::printf("%-32s %.2f of the whole core as a median, %.2f at the least (%.2f G steps/s)\n",
              "this thread had", median(probes) / fastestProbe,
              *std::min_element(probes.begin(), probes.end()) / fastestProbe, fastestProbe / 1e6);
  std::printf("%-32s %7.2f x faster per frame (random values %.2f x)\n", "16-bit / float",
              fatFloat.cpuMs / fat.cpuMs, fatFloatRandom.cpuMs / fatRandom.cpuMs);
  std::printf("%-32s %7.2f x faster per frame\n", "FAT / baseline", baseline.cpuMs / fat.cpuMs);
  std::printf("%-32s %.3g model units, %.2g of the largest vertex motion (%.3g)\n",
              "16-bit - float, largest", largestError, largestError / largestMotion, largestMotion);

  // Generator: 68 copies, one per FAP 3..68 plus viseme 1 and expression 1, each moving 20%
  // of the vertices (building the copies is not timed).
  std::vector<FaceShape> copies;
  for (int k = 0; k < 68; ++k) {
    FaceShape& c = copies.emplace_back();
    c.fapID = k < 66 ? k + 3 : k - 65;
    c.highLevelSelect = c.fapID <= 2 ? 1 : 0;
    c.amplitude = c.fapID <= 2 ? 63 : 500;
    c.name = "copy " + std::to_string(k);
    Points3 motion = Points3::Zero(p0.rows(), 3);
    for (int v : region(p0, rng))
      motion.row(v) += 0.002 * Eigen::RowVector3d(d(rng), d(rng), d(rng));
    c.meshes.push_back(sparseDisplacement(0, motion));
  }
  GeneratedTables generated;
  const Timing gen =
      medianMilliseconds(7, 1, [&] { generated = generateFaceDefTables(head, fapu, copies); });
  long affected = 0;
  for (const FaceDefTables& t : generated.faceDefTables) {
    for (const FaceDefMesh& m : t.faceDefMesh) affected += static_cast<long>(m.coordIndex.size());
  }
  std::printf(
      "%-32s %6.2f ms [%6.2f] (%6.2f) for %zu tables from %zu copies, %ld affected "
      "vertices\n",
      "generateFaceDefTables", gen.cpuMs, gen.bestCpuMs, gen.wallMs, generated.faceDefTables.size(),
      copies.size(), affected);
  const auto [wholeMs, wholeRuns] = fat.wholeCore();
  char onWholeCore[64] = "no run on a whole core";
  if (wholeRuns > 0) {
    std::snprintf(onWholeCore, sizeof onWholeCore, "%.2f of it on a whole core",
                  rate(double(displacementsPerFrame), wholeMs) / 2.0);
  }
  std::printf(
      "targets: evaluate >= 2.0 G displacements/s on one core (%s, %.2f over all runs); "
      "generate <= 50 ms (%.2f of it)\n",
      onWholeCore, rate(double(displacementsPerFrame), fat.cpuMs) / 2.0, gen.cpuMs / 50);
}
