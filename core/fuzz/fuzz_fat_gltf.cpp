// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for reading an MPEG-4 face with its Face Animation Tables from glTF (the
// tables in the scene's extras): any bytes must give a FatGltf or mpeg4face::Error, never a
// crash, a hang or another exception. No baseDir, so no external files are read.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/fat_gltf.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)mpeg4face::parseFatGltf(std::string_view(reinterpret_cast<const char*>(data), size),
                                  "fuzz.gltf", {});
  } catch (const mpeg4face::Error&) {
  }
  return 0;
}
