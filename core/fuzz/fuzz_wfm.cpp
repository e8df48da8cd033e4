// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the CANDIDE .wfm reader. mpeg4face::Error is the expected outcome for
// broken input; any other exception, a crash or a sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/wfm.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  mpeg4face::CandideModel candide;
  try {
    candide = mpeg4face::parseWfm(text, "fuzz.wfm");
  } catch (const mpeg4face::Error&) {
    return 0;
  }
  // A model the reader accepted must convert and validate; an Error here escapes and aborts.
  candide.model.validate();
  mpeg4face::candideToFaceModel(candide).validate();
  return 0;
}
