// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the .fap reader. mpeg4face::Error is the expected outcome for broken
// input; any other exception, a crash or a sanitizer report is a bug. A stream the reader
// accepts must write back to a file that reads as the same stream, and resolve and compare
// with itself as an exact match.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "mpeg4face/codec/measure.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/fap_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  mpeg4face::FapStream stream;
  try {
    stream = mpeg4face::parseFap(text, "fuzz.fap");
  } catch (const mpeg4face::Error&) {
    return 0;
  }
  // From here on an Error escapes and aborts: it would be a bug.
  if (mpeg4face::parseFap(mpeg4face::fapText(stream), "again.fap") != stream) std::abort();
  if (mpeg4face::resolveFapStream(stream).size() != stream.frames.size()) std::abort();
  const mpeg4face::FapComparison c = mpeg4face::compareFapStreams(stream, stream);
  if (c.psnr && !std::isinf(*c.psnr)) std::abort();
  return 0;
}
