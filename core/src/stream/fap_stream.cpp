// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/stream/fap_stream.hpp"

#include <algorithm>
#include <array>
#include <string>
#include <string_view>

namespace mpeg4face {
namespace {

// The name with its side swapped ("raise_l_i_eyebrow" -> "raise_r_i_eyebrow"), or "" if no
// part of it names a side.
std::string otherSide(std::string_view name) {
  std::string out;
  bool swapped = false;
  while (!name.empty()) {
    const size_t end = std::min(name.find('_'), name.size());
    std::string_view part = name.substr(0, end);
    if (part == "l" || part == "r" || part == "lm" || part == "rm") {
      out += part[0] == 'l' ? 'r' : 'l';
      out += part.substr(1);
      swapped = true;
    } else {
      out += part;
    }
    if (end < name.size()) out += '_';
    name.remove_prefix(std::min(end + 1, name.size()));
  }
  return swapped ? out : std::string();
}

std::array<int, kFapCount + 1> mirrorTable() {
  std::array<int, kFapCount + 1> table{};
  for (const FapInfo& info : fapTable()) {
    const std::string other = otherSide(info.name);
    if (!other.empty()) table[static_cast<size_t>(info.number)] = fapNumber(other).value_or(0);
  }
  return table;
}

}  // namespace

double frameTime(const FapStream& stream, const FapFrame& frame) {
  return frame.number / stream.frameRate;
}

double streamDuration(const FapStream& stream) {
  if (stream.frames.empty()) return 0.0;
  return (stream.frames.back().number - stream.frames.front().number + 1.0) / stream.frameRate;
}

int fapMirror(int fap) {
  static const std::array<int, kFapCount + 1> table = mirrorTable();
  return fap >= 1 && fap <= kFapCount ? table[static_cast<size_t>(fap)] : 0;
}

void applyFrame(FapState& state, const FapFrame& frame) {
  std::bitset<kFapCount> sent = (state.mask & ~state.mirrored) | frame.mask;
  state.number = frame.number;
  if (frame.has(1)) state.viseme = frame.viseme;
  if (frame.has(2)) state.expression = frame.expression;
  for (int fap = 3; fap <= kFapCount; ++fap) {
    if (frame.has(fap)) state.values[static_cast<size_t>(fap - 1)] = frame.value(fap);
  }
  state.mirrored.reset();
  for (int fap = 3; fap <= kFapCount; ++fap) {
    const int partner = fapMirror(fap);
    const auto i = static_cast<size_t>(fap - 1);
    if (partner == 0 || sent[i] || !sent[static_cast<size_t>(partner - 1)]) continue;
    state.values[i] = state.values[static_cast<size_t>(partner - 1)];
    state.mirrored.set(i);
  }
  state.mask = sent | state.mirrored;
}

std::vector<FapState> resolveFapStream(const FapStream& stream) {
  std::vector<FapState> out;
  out.reserve(stream.frames.size());
  FapState state;
  for (const FapFrame& frame : stream.frames) {
    applyFrame(state, frame);
    out.push_back(state);
  }
  return out;
}

}  // namespace mpeg4face
