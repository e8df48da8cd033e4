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

#include "codec/arithmetic_coder.hpp"
#include "codec/dct_transform.hpp"
#include "codec/fba_syntax.hpp"

namespace mpeg4face::fba {

inline constexpr int kMaxDcDivisor = 15;
// AC steps are sent as a step index e per FAP: step = kStepMantissa[e % 8] 2^(e / 8) / 256
// (about 2^(e/8) / 4: 0.25 at e = 0, eight steps per octave) for e in 0..kMaxStepIndex.
inline constexpr int kStepFractionBits = 8;
inline constexpr int kMaxStepIndex = 175;
inline constexpr int kMaxLevelClass = 40;  // bit length of a DC difference, step delta or skip

// The step in 1/256 for a step index (0..kMaxStepIndex).
std::int64_t dctStep256(int stepIndex);
// The encoder's step index for a FAP that varies over `range` in the stream (0: it does not),
// QP its FapInfo::quantStep, at fap_quant `fapQuant` (docs/dct-mode.md, "Steps").
int dctStepIndex(std::int64_t range, int quantStep, int fapQuant);

// The adaptive binary contexts of the DCT planes (docs/dct-mode.md, "Contexts"); an intra plane
// starts them afresh.
struct DctContexts {
  BinaryContext skips, sameMask, partial, full, present, visemeRepeat, expressionRepeat;
  std::array<BinaryContext, kMaxLevelClass + 1> skipClass;
  std::array<BinaryContext, kMaxLevelClass + 1> stepClass;
  // The DC difference's size class: bin 0 (zero or not) per group and whether the FAP's last
  // DC difference was 0; the other bins per bin index, intra and inter apart.
  std::array<std::array<BinaryContext, 2>, kGroupCount> dcZero;
  std::array<std::array<BinaryContext, kMaxLevelClass + 1>, 2> dcClass;
  // coded_block (some AC level non-zero) per group and whether the FAP's last block was coded.
  std::array<std::array<BinaryContext, 2>, kGroupCount> coded;
  // significant / last per group and coefficient 1..15 (index k - 1).
  std::array<std::array<BinaryContext, kDctSegmentLength - 1>, kGroupCount> significant, last;
  // The unary prefix of |level| - 1: coefficients 1-2 and 3-15 apart, per bin (0..3, 4+).
  std::array<std::array<BinaryContext, 5>, 2> levelPrefix;
};

// What later planes refer to, tracked alike by encoder and decoder; an intra plane resets it.
struct DctState {
  int fapQuant = 1;
  int dcDivisor = 4;
  DctContexts contexts;
  std::bitset<kFapCount> mask;                   // the previous segment's
  std::array<std::int64_t, kFapCount> dc{};      // the previous DC level of each FAP
  std::array<int, kFapCount> stepIndex{};        // -1 until the FAP's step has been sent
  int lastStepIndex = 0;                         // the prediction of the next step index sent
  std::bitset<kFapCount> lastDcZero, lastCoded;  // the FAP's previous block
  Viseme viseme;                                 // the last FAP 1 and 2 sent
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
