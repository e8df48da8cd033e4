// SPDX-License-Identifier: GPL-3.0-or-later
// A FAP stream: frames of Face Animation Parameters as the .fap file and the FBA bitstream
// carry them. A frame holds only what was sent; resolving a stream (applyFrame,
// resolveFapStream) turns it into the full state a decoder animates with.
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
  // The .fap header's version, "2.0", "2.1" or "2.2" (io/fap_file.hpp), kept so that a file is
  // written back as it was read; values in `frames` are always in FAPU whatever the version.
  std::string version = "2.1";
  bool headerLine = true;  // false: the .fap file had no header line and is written without
  bool operator==(const FapStream&) const = default;
};

// Time of a frame in seconds: its number / frameRate (frame 0 is at time 0).
double frameTime(const FapStream& stream, const FapFrame& frame);
// Seconds the stream spans: (last number - first number + 1) / frameRate, so that skipped
// frame numbers count; 0 for a stream without frames.
double streamDuration(const FapStream& stream);

// The left/right partner of a FAP: the FAP whose standard name (spec.hpp) differs only in an
// `l`/`r` or `lm`/`rm` part, e.g. 19 close_t_l_eyelid <-> 20 close_t_r_eyelid, 8
// lower_t_lip_lm <-> 9 lower_t_lip_rm; 0 if it has none. There are 23 pairs.
int fapMirror(int fap);

// What a decoder animates with after a frame: every FAP's current value. A frame carries only
// the FAPs it sends; the rules that complete it (docs/fap-format.md, "Resolution"):
// - a FAP keeps its last value until it is sent again (Tekalp-Ostermann 2.2.1);
// - a FAP of a left/right pair that has never been sent takes its partner's current value,
//   so a stream that only sends one side moves the face symmetrically (the decoder
//   extrapolation of 2.2.1 and Tao et al.'s left/right FIT, f_i = F_i). Equal values are
//   symmetric motion because the standard defines each pair's directions mirror-wise
//   (stretch_l: left, stretch_r: right); for eyeball yaw (both: left) they keep the gaze
//   parallel. Once the FAP itself is sent, its own value holds from then on;
// - FAPs never sent (and without a sent partner) are inactive: the neutral face.
// A FapState is a frame that sends every active FAP (what an evaluator takes): number is
// the frame last applied, mask the active FAPs (sent so far, or mirrored), values their
// current values (0 for inactive FAPs), viseme / expression valid where mask[0] / mask[1].
struct FapState : FapFrame {
  std::bitset<kFapCount> mirrored;  // active only through its partner (never sent itself)

  // Sent in this or an earlier frame (active and not mirrored).
  bool sent(int fap) const { return has(fap) && !mirrored[static_cast<size_t>(fap - 1)]; }
  bool operator==(const FapState&) const = default;
};

// Applies one frame to `state` (start from FapState{} before the first frame): the resolved
// state after it. Decoders call it frame by frame.
void applyFrame(FapState& state, const FapFrame& frame);
// The resolved state after each frame of the stream (one per frame).
std::vector<FapState> resolveFapStream(const FapStream& stream);

}  // namespace mpeg4face
