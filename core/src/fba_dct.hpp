// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: the DCT FAP coding mode (coding_type 1), the project's own syntax
// (docs/dct-mode.md). Each plane carries a segment of up to 16 frames: per low-level FAP the
// segment's 16-point DCT, the DC level predicted from the previous segment's and the AC levels
// as (zero run, level) pairs, everything in one arithmetic-coder segment per plane.
#pragma once

#include <array>
#include <bitset>
#include <cstdint>
#include <span>
#include <vector>

#include "fba_syntax.hpp"
#include "mpeg4face/arithmetic_coder.hpp"
#include "mpeg4face/dct_transform.hpp"

namespace mpeg4face::fba {

inline constexpr int kMaxDcDivisor = 15;

// The adaptive models of the DCT planes, one per symbol kind; an intra plane starts them
// afresh. The sizes are the symbol alphabets of docs/dct-mode.md.
struct DctModels {
  AdaptiveModel skips{2};
  AdaptiveModel countSize{32};  // size class of a frame skip count
  AdaptiveModel sameMask{2};
  AdaptiveModel partial{2};
  AdaptiveModel full{2};
  AdaptiveModel present{2};
  AdaptiveModel visemeRepeat{2};
  AdaptiveModel expressionRepeat{2};
  AdaptiveModel dcSize{30};  // size class 0..29 of a DC level difference
  // Zero runs 0..14 and end_of_segment; [0] from coefficient 1, [1] after a non-zero level.
  std::array<AdaptiveModel, 2> acRun{AdaptiveModel(16), AdaptiveModel(16)};
  // Size class 1..25 of a non-zero AC level, less 1; [0] coefficients 1-2, [1] 3-15.
  std::array<AdaptiveModel, 2> acSize{AdaptiveModel(25), AdaptiveModel(25)};
};

// What later planes refer to, tracked alike by encoder and decoder; an intra plane resets it.
struct DctState {
  int fapQuant = 1;
  int dcDivisor = 4;
  DctModels models;
  std::bitset<kFapCount> mask;               // the previous segment's
  std::array<std::int64_t, kFapCount> dc{};  // the previous DC level of each FAP
  Viseme viseme;                             // the last FAP 1 and 2 sent
  Expression expression;

  void beginIntra(int quant, int divisor, const std::bitset<kFapCount>& intraMask);
};

// Encodes `frames` (numbers increasing, from 0; |values| <= kDctMaxValue, checked here) as
// DCT planes. Throws mpeg4face::Error for fapQuant 0 (the DCT mode is never lossless), a
// dcDivisor outside 1..15 or a value beyond kDctMaxValue.
void encodeDct(std::span<const FapFrame> frames, const FbaEncodeOptions& options,
               const FrameRateCode& rate, EncodeOutput& output);

class DctDecoder {
 public:
  explicit DctDecoder(const FbaDecodeLimits& limits) : limits_(limits) {}
  // The rest of an intra plane after readIntraSettings, and of an inter plane after its
  // header: appends the segment's frames to `frames`, the first numbered `number`.
  void decodeIntra(BitReader& in, const IntraSettings& settings, std::int64_t number,
                   std::vector<FapFrame>& frames);
  void decodeInter(BitReader& in, std::int64_t number, std::vector<FapFrame>& frames);

 private:
  void decodeSegment(BitReader& in, bool intra, std::int64_t number, std::vector<FapFrame>& frames);

  FbaDecodeLimits limits_;
  DctState state_;
};

}  // namespace mpeg4face::fba
