// SPDX-License-Identifier: GPL-3.0-or-later
// Speed of `arkit to-fap` and `from-fap`: the real Live Link Face capture (tests/data, 328
// frames at 60 fps) on an ARKit head with FAP keys, by default the ICT sample
// (samples/build/ict_head.glb; another head as the first argument). to-fap is timed at the
// capture's own rate (every captured frame solved) and counted in frames per second; the
// face is prepared once, outside the timing, and its preparation is timed apart. Medians of
// several runs, this thread's CPU time (the machine may be shared).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <functional>
#include <vector>

#include "mpeg4face/arkit/capture.hpp"
#include "mpeg4face/io/livelink.hpp"
#include "mpeg4face/io/read_any.hpp"

using namespace mpeg4face;

namespace {

double thisThreadMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) / 1e6;
}

// Median and best of `runs` runs of `work`, milliseconds of this thread's CPU time.
std::pair<double, double> medianMs(int runs, const std::function<void()>& work) {
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    const double t0 = thisThreadMs();
    work();
    ms.push_back(thisThreadMs() - t0);
  }
  std::sort(ms.begin(), ms.end());
  return {ms[ms.size() / 2], ms.front()};
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path headPath =
      argc > 1 ? std::filesystem::path(argv[1])
               : std::filesystem::path(MPEG4FACE_SOURCE_DIR) / "samples" / "build" / "ict_head.glb";
  if (!std::filesystem::exists(headPath)) {
    std::fprintf(stderr, "%s is missing: run samples/build.sh or give a head\n",
                 headPath.string().c_str());
    return 1;
  }
  const LiveLinkCapture capture =
      readLiveLinkCsv(std::filesystem::path(MPEG4FACE_SOURCE_DIR) / "tests" / "data" /
                      "livelink-face" / "MySlate_3_Jason_Millers_iPhone.csv");
  const FaceModel head = readModel(headPath);
  ArkitCaptureFace face;
  const auto [prepareMs, prepareBest] = medianMs(3, [&] { face = prepareArkitCaptureFace(head); });
  std::printf("head %s: %zu face-area vertices, %zu FAP columns (%s)\n", headPath.string().c_str(),
              face.area.size(), face.columnFap.size(),
              face.fromTables ? "from its FAP keys" : "the FAPs' definition");
  std::printf("prepare the face: median %.1f ms (best %.1f) of 3 runs\n", prepareMs, prepareBest);

  FapStream stream;
  const int repeats = 20;  // the capture 20 times per run: 6,560 frames
  const auto [toMs, toBest] = medianMs(7, [&] {
    for (int r = 0; r < repeats; ++r)
      stream = arkitCaptureToFaps(capture, face, {capture.frameRate, {}});
  });
  const double frames = static_cast<double>(stream.frames.size()) * repeats;
  std::printf("to-fap: %zu frames at %g fps: median %.0f frames/s (best %.0f) of 7 runs\n",
              stream.frames.size(), capture.frameRate, frames / toMs * 1e3, frames / toBest * 1e3);

  const auto [fromMs, fromBest] = medianMs(3, [&] { fapsToArkit(stream, face); });
  std::printf("from-fap: %zu frames: median %.0f frames/s (best %.0f) of 3 runs\n",
              stream.frames.size(), static_cast<double>(stream.frames.size()) / fromMs * 1e3,
              static_cast<double>(stream.frames.size()) / fromBest * 1e3);
  return 0;
}
