// SPDX-License-Identifier: GPL-3.0-or-later
// Decoding and warping a 2D mesh object: a 640x480 texture under a 500-node Delaunay mesh
// over the whole image (tests/cpp/mesh2d_fixture.hpp's, shared with the tests) moving smoothly for
// 200 frames. Pinned to one core (the one it starts on; the warp is single-threaded anyway).
// Prints the medians of several runs of decode + warp of every frame, in frames per second of
// CPU time (what one core does, however loaded the machine) and of wall-clock time.
#include <sched.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <vector>

#include "mesh2d_fixture.hpp"
#include "mpeg4face/mesh2d/codec.hpp"
#include "mpeg4face/mesh2d/warp.hpp"

int main() {
  using namespace mpeg4face;
  constexpr int kRuns = 7, kFrames = 200;
  const int cpu = sched_getcpu();
  bool pinned = false;
  if (cpu >= 0) {
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(static_cast<size_t>(cpu), &one);
    pinned = sched_setaffinity(0, sizeof one, &one) == 0;
  }
  Mesh2dSequence s = test::delaunayImageFixture(500, 640, 480, 40);
  test::addSmoothFrames(s, kFrames);
  const std::vector<uint8_t> bytes = encodeMesh2d(s, 0.5);
  Image texture(640, 480, 3);
  for (size_t i = 0; i < texture.pixels.size(); ++i)
    texture.pixels[i] = static_cast<uint8_t>(i * 7 % 251);
  // CPU time of this (single-threaded) process: the machine may be shared; wall time too.
  auto cpuSeconds = [] {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
  };
  std::vector<double> fps, wallFps, decodeMs;
  for (int run = 0; run < kRuns; ++run) {
    const auto start = std::chrono::steady_clock::now();
    const double cpuStart = cpuSeconds();
    const Mesh2dSequence decoded = decodeMesh2d(bytes);
    const auto decodedAt = std::chrono::steady_clock::now();
    Image frame = texture;
    for (const Mesh2dNodes& plane : decoded.frames) {
      warpMesh2d(texture, decoded.frames[0], plane, decoded.triangles, frame);
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    wallFps.push_back(kFrames / seconds);
    fps.push_back(kFrames / (cpuSeconds() - cpuStart));
    decodeMs.push_back(std::chrono::duration<double, std::milli>(decodedAt - start).count());
  }
  std::nth_element(fps.begin(), fps.begin() + kRuns / 2, fps.end());
  std::nth_element(wallFps.begin(), wallFps.begin() + kRuns / 2, wallFps.end());
  std::nth_element(decodeMs.begin(), decodeMs.begin() + kRuns / 2, decodeMs.end());
  std::printf("mesh2d: 640x480 texture, %ld nodes, %ld triangles, %d frames (%zu bytes coded)\n",
              static_cast<long>(s.frames[0].rows()), static_cast<long>(meshTriangles(s).rows()),
              kFrames, bytes.size());
  if (pinned) {
    std::printf("pinned to CPU %d\n", cpu);
  } else {
    std::printf("not pinned (sched_setaffinity failed): one thread, on any core\n");
  }
  std::printf(
      "decode + warp: %.0f frames/s of CPU time on one core, %.0f wall-clock (medians of %d "
      "runs; decode alone %.1f ms wall)\n",
      fps[kRuns / 2], wallFps[kRuns / 2], kRuns, decodeMs[kRuns / 2]);
}
