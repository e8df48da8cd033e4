// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the 2D mesh sequence JSON reader (mesh2d/json.hpp) and the geometry it
// implies: mpeg4face::Error is the expected outcome for malformed input. A sequence read must
// write back to the same sequence.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "mpeg4face/error.hpp"
#include "mpeg4face/mesh2d/json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace mpeg4face;
  Mesh2dSequence s;
  try {
    s = parseMesh2dJson(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
  } catch (const Error&) {
    return 0;
  }
  const Mesh2dSequence back = parseMesh2dJson(mesh2dJson(s));
  if (back.frames.size() != s.frames.size() || back.triangles != s.triangles) std::abort();
  try {
    meshTriangles(s);
  } catch (const Error&) {
    // A self-intersecting boundary, coincident nodes: named, not a crash.
  }
  return 0;
}
