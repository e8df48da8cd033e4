// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the VRML97 reader. mpeg4face::Error is the expected outcome for broken
// input; any other exception, a crash or a sanitizer report is a bug. A face the reader
// accepted must validate, be writable, and read back with the same structure.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "mpeg4face/error.hpp"
#include "mpeg4face/vrml.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  mpeg4face::MpegFace face;
  try {
    face = mpeg4face::parseVrml(text, "fuzz.wrl");
  } catch (const mpeg4face::Error&) {
    return 0;
  }
  // From here on an Error escapes and aborts: the reader let through something it should not.
  face.faceSceneGraph.validate();
  const mpeg4face::MpegFace again = mpeg4face::parseVrml(mpeg4face::vrmlText(face), "again.wrl");
  const auto& a = face.faceSceneGraph;
  const auto& b = again.faceSceneGraph;
  if (a.meshes.size() != b.meshes.size() || a.transforms.size() != b.transforms.size() ||
      a.roots != b.roots || a.featurePoints.size() != b.featurePoints.size() ||
      face.faceDefTables.size() != again.faceDefTables.size()) {
    std::abort();
  }
  for (size_t m = 0; m < a.meshes.size(); ++m) {
    if (a.meshes[m].coordIndex != b.meshes[m].coordIndex || a.meshes[m].name != b.meshes[m].name) {
      std::abort();
    }
  }
  return 0;
}
