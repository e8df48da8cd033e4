// SPDX-License-Identifier: GPL-3.0-or-later
// How long the motion check takes on the MakeHuman sample (samples/build.sh makes it): its
// shape keys alone, and with the demo's 190-frame sentence; the median of several runs.
//   bench_motion_check [HEAD.glb [STREAM.fap]]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/motion_check.hpp"
#include "mpeg4face/io/read_any.hpp"

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
        const auto start = std::chrono::steady_clock::now();
        check = mpeg4face::checkMotion(
            model, withStream ? std::span(streams) : std::span<const mpeg4face::FapStream>{});
        ms.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count());
      }
      std::nth_element(ms.begin(), ms.begin() + kRuns / 2, ms.end());
      const double median = ms[kRuns / 2];
      const std::size_t poses = check.keys.size() + check.frames.size();
      std::printf("%s (%ld vertices): %zu keys, %zu frames: %.0f ms (median of %d), %.2f ms/pose\n",
                  head.filename().c_str(), vertices, check.keys.size(), check.frames.size(), median,
                  kRuns, median / static_cast<double>(poses));
    }
  } catch (const mpeg4face::Error& e) {
    std::fprintf(stderr, "bench_motion_check: %s (run samples/build.sh first)\n", e.what());
    return 1;
  }
}
