// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the 2D mesh object decoder (.m2d, mesh2d/codec.hpp): mpeg4face::Error
// is the expected outcome for broken input. A decoded sequence must be valid, its triangles in
// range, and code again at the finest step to a stream that decodes to the same triangles.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "mpeg4face/error.hpp"
#include "mpeg4face/mesh2d/codec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace mpeg4face;
  Mesh2dSequence s;
  try {
    s = decodeMesh2d(std::span(data, size), "fuzz.m2d", 1 << 12);  // small, so runs are fast
  } catch (const Error&) {
    return 0;
  }
  validateMesh2d(s);  // an Error here escapes and aborts: the decoder let something through
  try {
    const Mesh2dSequence again = decodeMesh2d(encodeMesh2d(s, 1.0 / 256));
    if (again.triangles != s.triangles) std::abort();
  } catch (const Error&) {
    // Decoded coordinates can lie beyond the range the encoder accepts.
  }
  return 0;
}
