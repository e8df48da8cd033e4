// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the OBJ reader. mpeg4face::Error is the expected outcome for broken
// input; any other exception, a crash or a sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/obj.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  mpeg4face::FaceModel model;
  try {
    model = mpeg4face::parseObj(text, "fuzz.obj");
  } catch (const mpeg4face::Error&) {
    return 0;
  }
  // What the reader returns must be consistent; an Error here escapes and aborts.
  model.validate();
  return 0;
}
