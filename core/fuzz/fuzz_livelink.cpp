// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the Live Link Face CSV reader. mpeg4face::Error is the expected outcome
// for broken input; a capture read must be well formed and survive being written and read
// back; anything else is a bug.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/livelink.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  mpeg4face::LiveLinkCapture capture;
  try {
    capture = mpeg4face::parseLiveLinkCsv(text, "fuzz.csv");
  } catch (const mpeg4face::Error&) {
    return 0;
  }
  if (capture.frameCount() == 0 || capture.values.rows() != capture.frameCount() ||
      capture.values.cols() != mpeg4face::kLiveLinkChannelCount || !capture.values.allFinite()) {
    std::abort();
  }
  for (int k = 0; k < mpeg4face::kLiveLinkWeightCount; ++k) {
    if (capture.values.col(k).minCoeff() < 0 || capture.values.col(k).maxCoeff() > 1) std::abort();
  }
  for (std::size_t i = 1; i < capture.times.size(); ++i) {
    if (!(capture.times[i] >= capture.times[i - 1])) std::abort();
  }
  // What we write we read back (times to the written precision).
  const mpeg4face::LiveLinkCapture back =
      mpeg4face::parseLiveLinkCsv(mpeg4face::formatLiveLinkCsv(capture), "written.csv");
  if (back.frameCount() != capture.frameCount()) std::abort();
  return 0;
}
