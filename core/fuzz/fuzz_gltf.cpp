// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the glTF reader: any bytes must give a FaceModel or mpeg4face::Error,
// never a crash, a hang or another exception. No baseDir, so no external files are read. A
// model read is then taken as a sculpted head (morph targets and animations in the shape-key
// grammar, animations as poses), which must also end in copies or an Error.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/io/gltf.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const mpeg4face::FaceModel model = mpeg4face::parseGltf(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.gltf", {});
    (void)mpeg4face::shapesFromShapeKeys(model);
  } catch (const mpeg4face::Error&) {
  }
  return 0;
}
