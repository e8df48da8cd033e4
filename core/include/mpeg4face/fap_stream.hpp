// SPDX-License-Identifier: GPL-3.0-or-later
// A FAP stream: frames of Face Animation Parameters as the .fap file and the FBA bitstream
// carry them. A frame holds only what was sent; resolving a stream (fap_stream.cpp) turns it
// into the full state a decoder animates with.
#pragma once

#include <array>
#include <bitset>
#include <string>
#include <vector>

#include "mpeg4face/spec.hpp"

namespace mpeg4face {

// FAP 1 (BIFS Viseme node): viseme_select1/2 in 0..14, viseme_blend in 0..63
// (63 = select1 fully, 0 = select2 fully).
struct Viseme {
  int select1 = 0;
  int select2 = 0;
  int blend = 0;
  bool def = false;
  bool operator==(const Viseme&) const = default;
};

// FAP 2 (BIFS Expression node): expression_select1/2 in 0..6, intensities in 0..63.
struct Expression {
  int select1 = 0;
  int intensity1 = 0;
  int select2 = 0;
  int intensity2 = 0;
  bool initFace = false;
  bool def = false;
  bool operator==(const Expression&) const = default;
};

// One frame. mask[i] says FAP i + 1 is present; values[i] is FAP i + 1 in its FAPU
// (entries 0 and 1 are unused: FAP 1 and 2 live in viseme and expression).
struct FapFrame {
  int number = 0;  // frame number as sent (may skip)
  std::bitset<kFapCount> mask;
  std::array<int, kFapCount> values{};
  Viseme viseme;
  Expression expression;

  bool has(int fap) const { return mask[static_cast<size_t>(fap - 1)]; }
  int value(int fap) const { return values[static_cast<size_t>(fap - 1)]; }
  void set(int fap, int v) {
    mask.set(static_cast<size_t>(fap - 1));
    values[static_cast<size_t>(fap - 1)] = v;
  }
  bool operator==(const FapFrame&) const = default;
};

struct FapStream {
  std::string name;         // the .fap header's name field
  double frameRate = 25.0;  // frames per second
  std::vector<FapFrame> frames;
  // The .fap header's version, "2.0", "2.1" or "2.2" (fap_file.hpp), kept so that a file is
  // written back as it was read; values in `frames` are always in FAPU whatever the version.
  std::string version = "2.1";
  bool headerLine = true;  // false: the .fap file had no header line and is written without
  bool operator==(const FapStream&) const = default;
};

}  // namespace mpeg4face
