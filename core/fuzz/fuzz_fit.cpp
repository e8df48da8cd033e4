// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the FAP Interpolation Table's JSON form (fit/json.hpp) and what reads a
// table: mpeg4face::Error is the expected outcome for malformed input. A table that is read
// must write back to the same table, through JSON and through the BIFS FIT node's fields, and
// interpolating a frame with it may fail only with mpeg4face::Error.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "mpeg4face/error.hpp"
#include "mpeg4face/fit/json.hpp"
#include "mpeg4face/fit/node.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace mpeg4face;
  const std::string text(reinterpret_cast<const char*>(data), size);
  FitTable table;
  try {
    table = fitTableFromJson(text, "fuzz.json");
  } catch (const Error&) {
    return 0;
  }
  if (fitTableFromJson(fitTableToJson(table)) != table) std::abort();
  if (fitTableFromNode(fitNodeFields(table)) != table) std::abort();
  // Every FAP sent but the children of the first link, all at values taken from the input.
  FapFrame frame;
  for (int fap = 3; fap <= kFapCount; ++fap) frame.set(fap, static_cast<int>(size % 97) - 48 + fap);
  frame.set(1, 0);
  frame.set(2, 0);
  frame.expression = {static_cast<int>(size % 7), 40, 1, 20};
  if (!table.links.empty()) {
    for (int fap : table.nodes[static_cast<std::size_t>(table.links[0].child)]) {
      if (fap >= 3) frame.mask.reset(static_cast<std::size_t>(fap - 1));
    }
  }
  try {
    interpolateFitFrame(table, frame);
  } catch (const Error&) {
  }
  return 0;
}
