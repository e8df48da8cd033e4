// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the shape-key name grammar (fat/names.hpp). mpeg4face::Error is the
// expected outcome for a malformed name; a name that is read must format to a name that
// reads back the same.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/names.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view name(reinterpret_cast<const char*>(data), size);
  std::optional<mpeg4face::ShapeKeyName> key;
  try {
    key = mpeg4face::parseShapeKeyName(name);
  } catch (const mpeg4face::Error&) {
    return 0;
  }
  if (!key) return 0;
  const auto back = mpeg4face::parseShapeKeyName(mpeg4face::formatShapeKeyName(*key));
  if (!back || back->fapID != key->fapID || back->highLevelSelect != key->highLevelSelect ||
      back->amplitude != key->amplitude || back->label != key->label) {
    std::abort();
  }
  return 0;
}
