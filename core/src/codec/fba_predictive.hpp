// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: the predictive FAP coding mode (coding_type 0). Intra planes send quantised values,
// inter planes quantised differences to the previous reconstruction, each through an adaptive
// arithmetic model per FAP; FAP 1 (viseme), FAP 2 (expression) and the low-level FAPs are three
// coder segments per plane.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "codec/arithmetic_coder.hpp"
#include "codec/fba_syntax.hpp"

namespace mpeg4face::fba {

// A symbol range in quantiser levels, min <= 0 <= max.
struct LevelRange {
  int min = 0;
  int max = 0;
  int size() const { return max - min + 1; }
};

// The FAP 1 and 2 fields in coding order.
inline constexpr int kVisemeExpressionFields = 7;

// What encoder and decoder both track, so both run the same code: ranges, models and the
// previous reconstruction.
struct PredictiveState {
  int fapQuant = 1;
  std::bitset<kFapCount> mask;
  bool rangesSet = false;  // the default ranges are set at the first intra plane
  int blendTop = 63;       // the largest level of blend and intensities (beginIntra)
  std::array<LevelRange, kFapCount> intraRange{}, interRange{};  // FAP 3..68 (index fap - 1)
  std::array<LevelRange, kVisemeExpressionFields> visemeExpressionIntra{}, visemeExpressionInter{};
  // Inter models; an intra plane codes each FAP once between resets, so its symbols are coded
  // with all counts 1 (ArithmeticEncoder::encodeUniform) and need no model.
  std::vector<AdaptiveModel> interModel;  // index fap - 1
  std::vector<AdaptiveModel> visemeExpressionInterModel;
  std::array<int64_t, kFapCount> previous{};  // reconstruction, FAP units
  std::array<int64_t, kVisemeExpressionFields> visemeExpressionPrevious{};

  // fap_quant and mask of a new intra plane; the default ranges the first time.
  void beginIntra(int quant, const std::bitset<kFapCount>& newMask);
  // Fresh inter models for the masked FAPs (after the new ranges).
  void resetModels();
  int64_t step(int fap) const { return steps[static_cast<size_t>(fap - 1)]; }
  std::array<int64_t, kFapCount> steps{};  // QP * fap_quant (0: no quantisation), index fap - 1
};

// Encodes `frames` (numbers increasing, from 0) as predictive planes.
void encodePredictive(std::span<const FapFrame> frames, const FbaEncodeOptions& options,
                      const FrameRateCode& rate, EncodeOutput& output);

class PredictiveDecoder {
 public:
  // The rest of an intra plane after readIntraSettings: new ranges, then the coded values.
  void decodeIntra(BitReader& in, const IntraSettings& settings, FapFrame& frame);
  void decodeInter(BitReader& in, FapFrame& frame);

 private:
  void decodeData(BitReader& in, bool intra, FapFrame& frame);

  PredictiveState state_;
};

}  // namespace mpeg4face::fba
