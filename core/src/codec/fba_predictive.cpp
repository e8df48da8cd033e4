// SPDX-License-Identifier: GPL-3.0-or-later
#include "codec/fba_predictive.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <optional>
#include <string>

#include "codec/fba_trellis.hpp"
#include "codec/start_code_guard.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face::fba {
namespace {

// Range codes are 5 bits in units of 60 quantiser steps at fap_quant 1 (the reference's
// RANGE_DELTA); a range in levels is code * 60 / fap_quant.
constexpr int kRangeUnit = 60;
constexpr uint32_t kMaxRangeCode = 31;
// A decoder refuses reconstructions beyond this (the encoder's stay within kMaxFbaValue plus
// half a step).
constexpr int64_t kMaxReconstruction = int64_t{2} * kMaxFbaValue;

struct FieldInfo {
  const char* name;
  int maxValue;
  bool quantised;  // by fap_quant (QP of FAP 1 and 2 is 1); selects are sent as they are
};
constexpr std::array<FieldInfo, kVisemeExpressionFields> kFields{{
    {"viseme_select1", 14, false},
    {"viseme_select2", 14, false},
    {"viseme_blend", 63, true},
    {"expression_select1", 6, false},
    {"expression_intensity1", 63, true},
    {"expression_select2", 6, false},
    {"expression_intensity2", 63, true},
}};
constexpr int kFirstExpressionField = 3;

// The four range flags, in syntax order.
enum RangeFlag { kIntraMax, kIntraMin, kInterMax, kInterMin };
constexpr std::array<const char*, 4> kFlagNames{"is_i_new_max", "is_i_new_min", "is_p_new_max",
                                                "is_p_new_min"};
constexpr std::array<const char*, 4> kCodeNames{"i_new_max", "i_new_min", "p_new_max", "p_new_min"};

int levelsOf(uint32_t code, int fapQuant) {
  return static_cast<int>(code) * kRangeUnit / (fapQuant != 0 ? fapQuant : 1);
}

// The reference rounds a default range up to whole range units.
uint32_t defaultCode(int range) {
  return static_cast<uint32_t>((range + kRangeUnit - 1) / kRangeUnit);
}

// The smallest code whose range holds `need` levels (31 if none: the values get clipped).
uint32_t fitCode(int64_t need, int fapQuant) {
  for (uint32_t code = 0; code < kMaxRangeCode; ++code) {
    if (levelsOf(code, fapQuant) >= need) return code;
  }
  return kMaxRangeCode;
}

void applyRangeCode(PredictiveState& state, int flag, size_t i, uint32_t code) {
  const int levels = levelsOf(code, state.fapQuant);
  switch (flag) {
    case kIntraMax:
      state.intraRange[i].max = levels;
      break;
    case kIntraMin:
      state.intraRange[i].min = -levels;
      break;
    case kInterMax:
      state.interRange[i].max = levels;
      break;
    default:
      state.interRange[i].min = -levels;
      break;
  }
}

// The range-code slots of FAP 3..68: a marker bit before every 4th FAP counted from each group
// start (for masked and unmasked FAPs alike), a 5-bit code for each masked FAP.
template <typename F>
void forEachRangeSlot(F&& slot) {
  for (const FapGroupInfo& group : fapGroupTable()) {
    if (group.number == 1) continue;
    for (int fap = group.firstFap; fap <= group.lastFap; ++fap) {
      slot(fap, (fap - group.firstFap) % 4 == 0);
    }
  }
}

int markerBitsPerFlag() {
  int markers = 0;
  forEachRangeSlot([&](int, bool marker) { markers += marker ? 1 : 0; });
  return markers;
}

// Bits an adaptive model with counts starting at 1 spends on N symbols over n, beyond what
// depends on the symbols' histogram: log2((N + n - 1)! / (n - 1)!) (halving ignored).
double learningBits(int n, int64_t count) {
  return (std::lgamma(static_cast<double>(count + n)) - std::lgamma(static_cast<double>(n))) /
         std::numbers::ln2;
}

// Writes the state's reconstruction into `frame` (number and def bits are the caller's).
void fillFrame(const PredictiveState& state, FapFrame& frame) {
  frame.mask = state.mask;
  for (int fap = 3; fap <= kFapCount; ++fap) {
    const auto i = static_cast<size_t>(fap - 1);
    if (state.mask[i]) frame.values[i] = static_cast<int>(state.previous[i]);
  }
  const auto& p = state.visemeExpressionPrevious;
  const auto field = [&](int k) {
    return static_cast<int>(std::clamp<int64_t>(p[static_cast<size_t>(k)], 0,
                                                kFields[static_cast<size_t>(k)].maxValue));
  };
  if (state.mask[0]) {
    frame.viseme.select1 = field(0);
    frame.viseme.select2 = field(1);
    frame.viseme.blend = field(2);
  }
  if (state.mask[1]) {
    frame.expression.select1 = field(3);
    frame.expression.intensity1 = field(4);
    frame.expression.select2 = field(5);
    frame.expression.intensity2 = field(6);
  }
}

std::array<int, kVisemeExpressionFields> visemeExpressionValues(const FapFrame& frame) {
  return {frame.viseme.select1,       frame.viseme.select2,        frame.viseme.blend,
          frame.expression.select1,   frame.expression.intensity1, frame.expression.select2,
          frame.expression.intensity2};
}

}  // namespace

void PredictiveState::beginIntra(int quant, const std::bitset<kFapCount>& newMask) {
  fapQuant = quant;
  mask = newMask;
  for (size_t i = 0; i < steps.size(); ++i) steps[i] = int64_t{fapTable()[i].quantStep} * quant;
  // As the reference decoders do: an intra range [0, 0] of FAP 4 means "ranges not set", and
  // every range goes back to its default (the encoder never sends it: chooseRanges).
  const LevelRange& fap4 = intraRange[3];
  if (!rangesSet || (fap4.min == 0 && fap4.max == 0)) {
    for (int fap = 3; fap <= kFapCount; ++fap) {
      const FapInfo& info = fapTable()[static_cast<size_t>(fap - 1)];
      const int intra = levelsOf(defaultCode(info.intraRange), fapQuant);
      const int inter = levelsOf(defaultCode(info.interRange), fapQuant);
      intraRange[static_cast<size_t>(fap - 1)] = {-intra, intra};
      interRange[static_cast<size_t>(fap - 1)] = {-inter, inter};
    }
    rangesSet = true;
  }
  // Blend and intensities (0..63) in levels of fap_quant, rounded as the quantiser rounds 63.
  // A plane at fap_quant 0 keeps the bound an earlier plane set, as the reference decoders
  // do, so that their streams decode (docs/bitstream.md, "Predictive intra plane: ranges").
  if (fapQuant != 0) blendTop = (63 + fapQuant / 2) / fapQuant;
  for (size_t k = 0; k < kFields.size(); ++k) {
    const int max = kFields[k].quantised ? blendTop : kFields[k].maxValue;
    visemeExpressionIntra[k] = {0, max};
    visemeExpressionInter[k] = {-max, max};
  }
}

void PredictiveState::resetModels() {
  interModel.resize(kFapCount);
  visemeExpressionInterModel.resize(kVisemeExpressionFields);
  for (int fap = 3; fap <= kFapCount; ++fap) {
    const auto i = static_cast<size_t>(fap - 1);
    if (mask[i]) interModel[i] = AdaptiveModel(interRange[i].size());
  }
  for (size_t k = 0; k < kFields.size(); ++k) {
    if (mask[k < kFirstExpressionField ? 0 : 1]) {
      visemeExpressionInterModel[k] = AdaptiveModel(visemeExpressionInter[k].size());
    }
  }
}

// ---------------------------------------------------------------------------------- encoder

namespace {

// What RDO quantisation needs of each low-level FAP: the robust PSNR's weight 1 / R^2 (R its
// range over the frames that send it, at least 1 and the FAP's step, so that a FAP that never
// moves is still held to its step), and a coarser grid of levels, every `multiple`-th, whose
// step suits R: at high rate a step D costs e^2 / R^2 = D^2 / (12 R^2) and lambda = -dD/dR =
// 2 ln 2 D^2 / (12 R^2), so the step lambda asks for is R sqrt(6 lambda / ln 2).
struct RdoFap {
  double weight = 0;
  int64_t multiple = 1;
};
std::array<RdoFap, kFapCount> rdoFaps(std::span<const FapFrame> frames, int fapQuant,
                                      double lambda) {
  std::array<int64_t, kFapCount> lo{}, hi{};
  std::array<bool, kFapCount> seen{};
  for (const FapFrame& f : frames) {
    for (size_t i = 2; i < kFapCount; ++i) {
      if (!f.mask[i]) continue;
      const int64_t v = f.values[i];
      lo[i] = seen[i] ? std::min(lo[i], v) : v;
      hi[i] = seen[i] ? std::max(hi[i], v) : v;
      seen[i] = true;
    }
  }
  std::array<RdoFap, kFapCount> out{};
  for (size_t i = 0; i < kFapCount; ++i) {
    const double step = double(fapTable()[i].quantStep) * std::max(fapQuant, 1);
    const double r = std::max({double(hi[i] - lo[i]), step, 1.0});
    out[i].weight = 1.0 / (r * r);
    out[i].multiple =
        std::max<int64_t>(1, std::llround(r * std::sqrt(6.0 * lambda / std::numbers::ln2) / step));
  }
  return out;
}

// Candidate levels for `residual`: the nearest level, one step nearer zero, zero, and the
// nearest two on the FAP's coarser grid; of those inside `range`, the one with the least
// weight * e^2 + lambda * bits(level).
template <typename Bits>
int64_t rdoLevel(int64_t residual, int64_t nearest, int64_t step, const RdoFap& fap, double lambda,
                 const LevelRange& range, Bits&& bits) {
  const int64_t m = fap.multiple;
  const int64_t down = (nearest >= 0 ? nearest / m : -((-nearest + m - 1) / m)) * m;
  const std::array<int64_t, 5> candidates{nearest,
                                          nearest > 0   ? nearest - 1
                                          : nearest < 0 ? nearest + 1
                                                        : 0,
                                          0, down, down + m};
  int64_t best = std::clamp<int64_t>(nearest, range.min, range.max);
  double bestCost = std::numeric_limits<double>::infinity();
  for (const int64_t level : candidates) {
    if (level < range.min || level > range.max) continue;
    const auto e = static_cast<double>(residual - dequantise(level, step));
    const double cost = fap.weight * e * e + lambda * bits(level);
    if (cost < bestCost) {
      bestCost = cost;
      best = level;
    }
  }
  return best;
}

// A model-free estimate of an inter level's bits for choosing ranges before the models exist:
// about what an adaptive model that has seen mostly zeros spends.
double staticLevelBits(int64_t level) {
  return level == 0 ? 0.5 : 2.0 + 2.0 * std::log2(static_cast<double>(std::llabs(level)) + 1.0);
}

class PredictiveEncoder {
 public:
  PredictiveEncoder(std::span<const FapFrame> frames, const FbaEncodeOptions& options,
                    const FrameRateCode& rate, EncodeOutput& output)
      : frames_(frames), options_(options), rate_(rate), output_(output), out_(output.out),
        guard_(output.out) {
    if (options.rdoLambda > 0) rdo_ = rdoFaps(frames, options.fapQuant, options.rdoLambda);
  }

  // One intra plane for frames_[begin] and inter planes for the frames after it up to `end`,
  // none of them emulating or hiding behind a start code (secure()). Returns where the group
  // ended: `end`, or earlier if an inter plane could not be written safely; the next group
  // then starts there, with an intra plane, whose bits differ.
  size_t encodeGroup(size_t begin, size_t end) {
    kept_ = {state_.rangesSet, state_.blendTop, state_.intraRange, state_.interRange};
    for (int attempt = 0;; ++attempt) {
      if (attempt == kIntraAttempts) {
        throw Error({}, 0, "start code emulation",
                    "frame " + std::to_string(frames_[begin].number) +
                        ": no intra plane the encoder tried avoids a byte-aligned 0x000001");
      }
      if (writeGroup(begin, end, attempt)) return begin + guard_.planes().size();
      rollBack(0);
    }
  }

 private:
  // Alternatives for an intra plane that emulates a start code: the same plane with a time
  // code (19 bits more, so the segments after it lie differently against the byte
  // boundaries), and wider intra ranges (i_new_max codes 1-3 larger: other intra symbols).
  static constexpr int kIntraAttempts = 8;

  // What rollBack() restores of each plane of the group (guard_ has where it lies in out_).
  struct PlaneStats {
    size_t frame = 0;  // its index in stats.frameBits and the reconstruction
    int clippedBefore = 0;
  };
  // What an intra plane changes in the state beyond the plane itself.
  struct KeptRanges {
    bool rangesSet = false;
    int blendTop = 63;
    std::array<LevelRange, kFapCount> intraRange{}, interRange{};
  };

  // The group as encodeGroup describes it, with `attempt`'s intra plane; false if that plane
  // cannot be made safe (the caller rolls the group back and tries the next attempt).
  bool writeGroup(size_t begin, size_t end, int attempt) {
    state_.beginIntra(options_.fapQuant, frames_[begin].mask);
    if (trellis()) planGroup(begin, end);
    widen_ = attempt / 2;
    const std::array<std::array<std::optional<uint32_t>, kFapCount>, 4> codes =
        chooseRanges(begin, end);

    guard_.clear();
    planeStats_.clear();
    openPlane(true);
    std::optional<TimeCode> timeCode;
    if (attempt % 2 == 1) timeCode = timeCodeOf(frames_[begin].number);
    writePlaneHeader(out_, {true, rate_, timeCode, framesToSkipAfter(frames_, begin)});
    writeIntraSettings(out_, {options_.fapQuant, state_.mask, false, kCodingTypePredictive});
    for (int flag = 0; flag < 4; ++flag) out_.writeBit(anyCode(codes[flag]));
    for (int flag = 0; flag < 4; ++flag) {
      if (!anyCode(codes[flag])) continue;
      forEachRangeSlot([&](int fap, bool marker) {
        const auto i = static_cast<size_t>(fap - 1);
        if (marker) out_.writeBit(true);
        if (!state_.mask[i]) return;
        out_.writeBits(*codes[flag][i], 5);
        applyRangeCode(state_, flag, i, *codes[flag][i]);
      });
    }
    state_.resetModels();
    encodeData(frames_[begin], true, 0);
    closePlane();
    ++output_.stats.intraFrames;

    for (size_t k = begin + 1; k < end; ++k) {
      openPlane(false);
      writePlaneHeader(out_, {false, std::nullopt, std::nullopt, framesToSkipAfter(frames_, k)});
      encodeData(frames_[k], false, k - begin);
      closePlane();
      // The plane before this one is checked now that the bits after it are known.
      const size_t j = guard_.planes().size() - 2;
      if (secure(j, false)) continue;
      if (j == 0) return false;
      rollBack(j);  // the group ends before frame j, and the next starts there
      break;
    }
    // A start code follows the group's last plane: the next intra plane's or the end code.
    while (!secure(guard_.planes().size() - 1, true)) {
      if (guard_.planes().size() == 1) return false;
      rollBack(guard_.planes().size() - 1);
    }
    return true;
  }

  void openPlane(bool startCode) {
    guard_.open(startCode);
    planeStats_.push_back({output_.stats.frameBits.size(), output_.stats.clippedValues});
  }
  void closePlane() {
    guard_.close();
    const PlaneGuard::Span& plane = guard_.planes().back();
    output_.stats.frameBits.push_back(plane.end - plane.start);
  }

  // guard_.secure(j), with the frames' bits counted again where a start code moved planes.
  bool secure(size_t j, bool codeFollows) {
    const bool safe = guard_.secure(j, codeFollows);
    if (const std::optional<size_t> moved = guard_.takeMoved()) {
      for (size_t m = *moved; m < guard_.planes().size(); ++m) {
        const PlaneGuard::Span& plane = guard_.planes()[m];
        output_.stats.frameBits[planeStats_[m].frame] = plane.end - plane.start;
      }
    }
    return safe;
  }

  // Drops planes j.. of the group (all of it and what its intra plane set, for j = 0).
  void rollBack(size_t j) {
    const PlaneStats plane = planeStats_[j];
    guard_.rollBack(j);
    planeStats_.resize(j);
    output_.stats.frameBits.resize(plane.frame);
    output_.reconstruction.frames.resize(plane.frame);
    output_.stats.clippedValues = plane.clippedBefore;
    if (j == 0) {
      --output_.stats.intraFrames;
      state_.rangesSet = kept_.rangesSet;
      state_.blendTop = kept_.blendTop;
      state_.intraRange = kept_.intraRange;
      state_.interRange = kept_.interRange;
    }
  }

  TimeCode timeCodeOf(int number) const {
    const auto seconds = static_cast<uint32_t>(number / framesPerSecond(rate_));
    return {seconds / 3600 % 32, seconds / 60 % 60, seconds % 60};
  }

  bool trellis() const { return options_.rdoTrellis && options_.rdoLambda > 0; }

  // Trellis quantisation (codec/fba_trellis.hpp) of every masked low-level FAP over the group.
  void planGroup(size_t begin, size_t end) {
    std::vector<int> sides;
    for (uint32_t code = 0; code <= kMaxRangeCode; ++code) {
      const int levels = levelsOf(code, options_.fapQuant);
      if (sides.empty() || levels > sides.back()) sides.push_back(levels);
    }
    std::vector<int64_t> values(end - begin);
    for (size_t i = 2; i < kFapCount; ++i) {
      if (!state_.mask[i]) continue;
      for (size_t k = begin; k < end; ++k) values[k - begin] = frames_[k].values[i];
      plan_[i] = trellisQuantise({values, state_.steps[i], rdo_[i].weight, options_.rdoLambda,
                                  levelsOf(kMaxRangeCode, options_.fapQuant), sides});
    }
  }

  static bool anyCode(const std::array<std::optional<uint32_t>, kFapCount>& codes) {
    return std::any_of(codes.begin(), codes.end(), [](const auto& c) { return c.has_value(); });
  }

  // Which of the four ranges to send for this group of frames, and their codes: each pair
  // (intra, inter) takes the cheapest of keeping or fitting max and min, counting the range
  // codes against the bits an adaptive model of that size spends learning (fitted ranges
  // follow the group's prediction loop).
  std::array<std::array<std::optional<uint32_t>, kFapCount>, 4> chooseRanges(size_t begin,
                                                                             size_t end) {
    std::array<int64_t, kFapCount> needMax[2]{}, needMin[2]{};  // [intra / inter][fap - 1]
    // Levels beyond the largest range get clipped in the loop as they will be when coded.
    const int cap = levelsOf(kMaxRangeCode, options_.fapQuant);
    std::vector<size_t> masked;  // indices fap - 1 of the low-level FAPs sent
    for (size_t i = 2; i < kFapCount; ++i) {
      if (state_.mask[i]) masked.push_back(i);
    }
    // With RDO quantisation its loop runs too (on a static rate estimate: the models do not
    // exist yet), and the ranges hold what either loop needs.
    const int loops = trellis() ? 0 : options_.rdoLambda > 0 ? 2 : 1;
    for (int loop = 0; loop < loops; ++loop) {
      std::array<int64_t, kFapCount> reconstruction{};
      for (size_t k = begin; k < end; ++k) {  // frame by frame: the frames lie in a row
        const int inter = k == begin ? 0 : 1;
        for (size_t i : masked) {
          const int64_t step = state_.steps[i];
          const int64_t residual = frames_[k].values[i] - reconstruction[i];
          int64_t level = std::clamp<int64_t>(quantise(residual, step), -cap, cap);
          if (inter && loop == 1) {
            level = rdoLevel(residual, level, step, rdo_[i], options_.rdoLambda, {-cap, cap},
                             staticLevelBits);
          }
          reconstruction[i] += dequantise(level, step);
          needMax[inter][i] = std::max(needMax[inter][i], level);
          needMin[inter][i] = std::min(needMin[inter][i], level);
        }
      }
    }
    if (trellis()) {
      for (size_t i : masked) {
        const TrellisLevels& plan = plan_[i];
        needMax[0][i] = std::max<int64_t>(plan.levels[0], 0);
        needMin[0][i] = std::min<int64_t>(plan.levels[0], 0);
        needMax[1][i] = plan.interMax;
        needMin[1][i] = plan.interMin;
      }
    } else if (options_.rdoLambda > 0) {
      for (size_t i : masked) shrinkInterRange(begin, end, i, cap, needMin[1][i], needMax[1][i]);
    }
    const double codeBits = markerBitsPerFlag() + 5.0 * static_cast<double>(masked.size());
    const int64_t counts[2] = {1, static_cast<int64_t>(end - begin) - 1};

    // Reference decoders take an intra range [0, 0] of FAP 4 for "ranges not set yet" and put
    // every range back to its default at the next intra plane; so FAP 4 keeps Imax > 0.
    const auto fitted = [&](int inter, bool max, size_t i) {
      const uint32_t code = max ? fitCode(needMax[inter][i], options_.fapQuant)
                                : fitCode(-needMin[inter][i], options_.fapQuant);
      if (inter || !max) return code;
      const uint32_t wide = std::min(code + static_cast<uint32_t>(widen_), kMaxRangeCode);
      return i == 3 ? std::max(wide, 1u) : wide;
    };
    std::array<std::array<std::optional<uint32_t>, kFapCount>, 4> codes{};
    for (int inter = 0; inter < 2; ++inter) {
      const auto& current = inter ? state_.interRange : state_.intraRange;
      std::optional<double> best;
      int bestCombo = 0;
      for (int combo = 0; combo < 4; ++combo) {  // bit 0: send max, bit 1: send min
        if (!inter && widen_ > 0 && !(combo & 1)) continue;  // the wider Imax is sent
        const bool sendMax = combo & 1, sendMin = combo & 2;
        double bits = codeBits * ((sendMax ? 1 : 0) + (sendMin ? 1 : 0));
        bool fits = true;
        for (size_t i : masked) {
          const int max =
              sendMax ? levelsOf(fitted(inter, true, i), options_.fapQuant) : current[i].max;
          const int min =
              sendMin ? -levelsOf(fitted(inter, false, i), options_.fapQuant) : current[i].min;
          fits = (sendMax || max >= needMax[inter][i]) && (sendMin || min <= needMin[inter][i]);
          bits += learningBits(max - min + 1, counts[inter]);
          if (!fits) break;
        }
        if (fits && (!best || bits < *best)) {
          best = bits;
          bestCombo = combo;
        }
      }
      for (size_t i : masked) {
        if (bestCombo & 1) codes[inter ? kInterMax : kIntraMax][i] = fitted(inter, true, i);
        if (bestCombo & 2) codes[inter ? kInterMin : kIntraMin][i] = fitted(inter, false, i);
      }
    }
    return codes;
  }

  // RDO of the inter range itself: a FAP that moves only now and then pays for the whole
  // alphabet its range opens in every frame (the adaptive model's learning), so keeping one
  // side (or both) of the range at 0 can cost less than the motion it loses. Of the fitted
  // range [lo, hi] and those with a side at 0, the one with the least weighted squared error
  // plus lambda times what an adaptive model spends on the levels, on this group's frames.
  void shrinkInterRange(size_t begin, size_t end, size_t i, int cap, int64_t& lo, int64_t& hi) {
    const int64_t step = state_.steps[i];
    const auto levels = [&](int64_t need) {
      return int64_t{levelsOf(fitCode(need, options_.fapQuant), options_.fapQuant)};
    };
    std::optional<double> best;
    int64_t bestLo = lo, bestHi = hi;
    const std::array<std::pair<int64_t, int64_t>, 4> options{
        {{lo, hi}, {int64_t{0}, hi}, {lo, int64_t{0}}, {int64_t{0}, int64_t{0}}}};
    for (size_t o = 0; o < options.size(); ++o) {
      const auto [l, h] = options[o];
      if (std::find(options.begin(), options.begin() + static_cast<std::ptrdiff_t>(o),
                    options[o]) != options.begin() + static_cast<std::ptrdiff_t>(o)) {
        continue;  // the same as one tried (a side of the fitted range is 0 already)
      }
      const LevelRange range{static_cast<int>(-levels(-l)), static_cast<int>(levels(h))};
      std::vector<int>& histogram = histogram_;
      histogram.assign(static_cast<size_t>(range.size()), 0);
      int64_t reconstruction = dequantise(
          std::clamp<int64_t>(quantise(frames_[begin].values[i], step), -cap, cap), step);
      double distortion = 0;
      for (size_t k = begin + 1; k < end; ++k) {
        const int64_t residual = frames_[k].values[i] - reconstruction;
        const int64_t nearest = std::clamp<int64_t>(quantise(residual, step), -cap, cap);
        const int64_t level =
            rdoLevel(residual, nearest, step, rdo_[i], options_.rdoLambda, range, staticLevelBits);
        reconstruction += dequantise(level, step);
        const auto e = static_cast<double>(frames_[k].values[i] - reconstruction);
        distortion += rdo_[i].weight * e * e;
        ++histogram[static_cast<size_t>(level - range.min)];
      }
      // An adaptive model's code length for this histogram (counts from 1, halving ignored).
      double bits = learningBits(range.size(), static_cast<int64_t>(end - begin) - 1);
      for (const int c : histogram) bits -= std::lgamma(c + 1.0) / std::numbers::ln2;
      const double cost = distortion + options_.rdoLambda * bits;
      if (!best || cost < *best) {
        best = cost;
        bestLo = l;
        bestHi = h;
      }
    }
    lo = bestLo;
    hi = bestHi;
  }

  // Codes a level under the intra range (uniform, see PredictiveState) or the inter range and
  // model; returns it clipped to the range.
  static int codeLevel(ArithmeticEncoder& coder, int64_t level, bool intra,
                       const LevelRange& range, AdaptiveModel& interModel) {
    level = std::clamp<int64_t>(level, range.min, range.max);
    const auto symbol = static_cast<int>(level - range.min);
    if (intra) {
      coder.encodeUniform(symbol, range.size());
    } else {
      coder.encode(symbol, interModel);
    }
    return static_cast<int>(level);
  }

  // Clipped are the values no range code reaches on the prediction loop without RDO's
  // choices (`unclipped_`, as the encoder runs at lambda 0): RDO's coarse levels let the
  // reconstruction lag and a later difference outgrow every range, but that is distortion,
  // which `encode` reports as such, not a value the syntax cannot code.
  void countClipped(size_t i, int64_t value, bool intra, int64_t step) {
    const int64_t prediction = intra ? 0 : unclipped_[i];
    const int64_t reach = levelsOf(kMaxRangeCode, state_.fapQuant);
    int64_t level = quantise(value - prediction, step);
    if (std::llabs(level) > reach) {
      ++output_.stats.clippedValues;
      level = std::clamp(level, -reach, reach);
    }
    unclipped_[i] = prediction + dequantise(level, step);
  }

  // `t`: the frame's index in its group (for the trellis's levels).
  void encodeData(const FapFrame& frame, bool intra, size_t t) {
    ArithmeticEncoder coder(out_);
    const std::array<int, kVisemeExpressionFields> values = visemeExpressionValues(frame);
    const auto fields = [&](size_t first, size_t last) {
      for (size_t k = first; k < last; ++k) {
        int64_t& previous = state_.visemeExpressionPrevious[k];
        const int64_t step = kFields[k].quantised ? state_.fapQuant : 0;
        const int64_t prediction = intra ? 0 : previous;
        const int64_t wanted = quantise(values[k] - prediction, step);
        const int level =
            codeLevel(coder, wanted, intra,
                      intra ? state_.visemeExpressionIntra[k] : state_.visemeExpressionInter[k],
                      state_.visemeExpressionInterModel[k]);
        if (level != wanted) ++output_.stats.clippedValues;
        previous = prediction + dequantise(level, step);
      }
      coder.flush();
    };
    if (state_.mask[0]) {
      fields(0, kFirstExpressionField);
      out_.writeBit(frame.viseme.def);
    }
    if (state_.mask[1]) {
      fields(kFirstExpressionField, kFields.size());
      out_.writeBit(frame.expression.initFace);
      out_.writeBit(frame.expression.def);
    }
    for (int fap = 3; fap <= kFapCount; ++fap) {
      const auto i = static_cast<size_t>(fap - 1);
      if (!state_.mask[i]) continue;
      const int64_t step = state_.step(fap);
      const int64_t prediction = intra ? 0 : state_.previous[i];
      const int64_t residual = frame.values[i] - prediction;
      countClipped(i, frame.values[i], intra, step);
      int64_t wanted = quantise(residual, step);
      if (trellis()) {
        wanted = plan_[i].levels[t];
      } else if (!intra && options_.rdoLambda > 0) {
        const LevelRange& range = state_.interRange[i];
        const AdaptiveModel& model = state_.interModel[i];
        const auto bits = [&](int64_t l) {  // rdoLevel asks only for levels in the range
          return model.idealBits(static_cast<int>(l - range.min));
        };
        wanted = rdoLevel(residual, wanted, step, rdo_[i], options_.rdoLambda, range, bits);
      }
      const int level =
          codeLevel(coder, wanted, intra, intra ? state_.intraRange[i] : state_.interRange[i],
                    state_.interModel[i]);
      state_.previous[i] = prediction + dequantise(level, step);
    }
    coder.flush();

    FapFrame& reconstruction = output_.reconstruction.frames.emplace_back();
    reconstruction.number = frame.number;
    fillFrame(state_, reconstruction);
    if (state_.mask[0]) reconstruction.viseme.def = frame.viseme.def;
    if (state_.mask[1]) {
      reconstruction.expression.initFace = frame.expression.initFace;
      reconstruction.expression.def = frame.expression.def;
    }
  }

  std::span<const FapFrame> frames_;
  const FbaEncodeOptions& options_;
  FrameRateCode rate_;
  EncodeOutput& output_;
  BitWriter& out_;
  PredictiveState state_;
  std::array<RdoFap, kFapCount> rdo_{};        // when rdoLambda > 0
  std::vector<int> histogram_;                 // shrinkInterRange's, kept to spare allocations
  std::array<TrellisLevels, kFapCount> plan_;  // the group's levels, with rdoTrellis
  std::array<int64_t, kFapCount> unclipped_{};  // countClipped's reconstruction
  PlaneGuard guard_;                            // the group's planes, made safe
  std::vector<PlaneStats> planeStats_;          // and what rollBack() restores of each
  KeptRanges kept_;                             // the ranges before the group's intra plane
  int widen_ = 0;  // chooseRanges sends i_new_max this much wider (an intra plane's attempt)
};

}  // namespace

void encodePredictive(std::span<const FapFrame> frames, const FbaEncodeOptions& options,
                      const FrameRateCode& rate, EncodeOutput& output) {
  PredictiveEncoder encoder(frames, options, rate, output);
  // A group runs from an intra frame to the next frame with another mask (inter planes code
  // the intra plane's mask) or to the intra period.
  for (size_t begin = 0; begin < frames.size();) {
    size_t end = begin + 1;
    while (end < frames.size() && frames[end].mask == frames[begin].mask &&
           (options.intraPeriod == 0 || end - begin < static_cast<size_t>(options.intraPeriod))) {
      ++end;
    }
    begin = encoder.encodeGroup(begin, end);
  }
}

// ---------------------------------------------------------------------------------- decoder

void PredictiveDecoder::decodeIntra(BitReader& in, const IntraSettings& settings, FapFrame& frame) {
  state_.beginIntra(settings.fapQuant, settings.mask);
  bool flags[4];
  for (int flag = 0; flag < 4; ++flag) flags[flag] = in.readBit(kFlagNames[flag]);
  for (int flag = 0; flag < 4; ++flag) {
    if (!flags[flag]) continue;
    forEachRangeSlot([&](int fap, bool marker) {
      if (marker && !in.readBit("marker_bit")) {
        in.failAt(in.position() - 1, "marker_bit",
                  std::string("is 0 in the ") + kCodeNames[flag] + " codes");
      }
      const auto i = static_cast<size_t>(fap - 1);
      if (state_.mask[i]) applyRangeCode(state_, flag, i, in.readBits(5, kCodeNames[flag]));
    });
  }
  state_.resetModels();
  decodeData(in, true, frame);
}

void PredictiveDecoder::decodeInter(BitReader& in, FapFrame& frame) {
  decodeData(in, false, frame);
}

void PredictiveDecoder::decodeData(BitReader& in, bool intra, FapFrame& frame) {
  const auto fields = [&](size_t first, size_t last, const char* segment) {
    ArithmeticDecoder coder(in);
    for (size_t k = first; k < last; ++k) {
      int64_t& previous = state_.visemeExpressionPrevious[k];
      const LevelRange& range =
          intra ? state_.visemeExpressionIntra[k] : state_.visemeExpressionInter[k];
      const int symbol = intra ? coder.decodeUniform(range.size())
                               : coder.decode(state_.visemeExpressionInterModel[k]);
      const int64_t step = kFields[k].quantised ? state_.fapQuant : 0;
      previous = (intra ? 0 : previous) + dequantise(symbol + range.min, step);
      if (!kFields[k].quantised && (previous < 0 || previous > kFields[k].maxValue)) {
        in.fail(kFields[k].name, "decodes to " + std::to_string(previous) + ", outside 0.." +
                                     std::to_string(kFields[k].maxValue));
      }
    }
    coder.finish(segment);
  };
  if (state_.mask[0]) {
    fields(0, kFirstExpressionField, "viseme (FAP 1) data");
    frame.viseme.def = in.readBit("viseme_def");
  }
  if (state_.mask[1]) {
    fields(kFirstExpressionField, kFields.size(), "expression (FAP 2) data");
    frame.expression.initFace = in.readBit("init_face");
    frame.expression.def = in.readBit("expression_def");
  }
  ArithmeticDecoder coder(in);
  for (int fap = 3; fap <= kFapCount; ++fap) {
    const auto i = static_cast<size_t>(fap - 1);
    if (!state_.mask[i]) continue;
    const LevelRange& range = intra ? state_.intraRange[i] : state_.interRange[i];
    const int symbol =
        intra ? coder.decodeUniform(range.size()) : coder.decode(state_.interModel[i]);
    int64_t& previous = state_.previous[i];
    previous = (intra ? 0 : previous) + dequantise(symbol + range.min, state_.step(fap));
    if (previous < -kMaxReconstruction || previous > kMaxReconstruction) {
      in.fail("FAP " + std::to_string(fap), "the reconstruction reaches " +
                                                std::to_string(previous) + ", beyond +-" +
                                                std::to_string(kMaxReconstruction));
    }
  }
  coder.finish("low-level FAP data");
  fillFrame(state_, frame);
}

}  // namespace mpeg4face::fba
