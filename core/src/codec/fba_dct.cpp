// SPDX-License-Identifier: GPL-3.0-or-later
// The DCT coding mode (codec/fba_dct.hpp). The syntax is the project's own and is defined element
// by element in docs/dct-mode.md, whose names the comments here use.
#include "codec/fba_dct.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "codec/start_code_guard.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face::fba {
namespace {

constexpr int kN = kDctSegmentLength;
constexpr int kDcDivisorBits = 4;
// |level * step| of every coefficient: what an input within kDctMaxValue can produce, with
// room for rounding (reconstructDctSegment sums in 128 bits).
constexpr std::int64_t kCoefficientLimit = std::int64_t{1} << 24;
constexpr std::int64_t kCoefficientLimit256 = kCoefficientLimit << kStepFractionBits;
constexpr int kStepPrediction = 48;   // the first step index of a plane is sent against this
constexpr int kLevelPrefixBins = 14;  // |level| - 1 below this is unary only (CABAC's UEG0)
constexpr std::array<std::int64_t, 8> kStepMantissa = {64, 70, 76,  83,
                                                       91, 99, 108, 117};  // 64 * 2^(j/8)
// The RDOQ weight of a bit: lambda = kLambda * step^2 (squared FAPU per bit).
// 0.05 measured best of 0, 0.05, 0.1, 0.2, 0.35, 0.5 for the cheapest encoding at 20-35 dB
// robust PSNR on the Xface and long 30 Hz streams (bench_codec_rd): larger values zero too many
// coefficients of the FAPs that move least, which the robust PSNR weighs most.
constexpr double kLambda = 0.05;

int levelBucket(int k) { return k <= 2 ? 0 : 1; }
int groupIndex(int fap) { return fapInfo(fap).group - 1; }

int sizeClass(std::int64_t v) {
  return static_cast<int>(std::bit_width(static_cast<std::uint64_t>(v < 0 ? -v : v)));
}

bool bitOf(std::uint16_t bits, int n) { return ((bits >> n) & 1) != 0; }

// One segment as a plane carries it.
struct Segment {
  int length = 0;  // frames, 1..16
  std::array<int, kN> numbers{};
  std::bitset<kFapCount> mask;                                   // union over the frames
  std::array<std::uint16_t, kFapCount> presence{};               // bit n: frame n has the FAP
  std::array<std::array<std::int64_t, kN>, kFapCount> levels{};  // FAP 3..68; [0] is DC
  // The encoder's: the transformed samples each FAP's levels are chosen for.
  std::array<std::array<double, kN>, kFapCount> coefficients{};
  std::vector<Viseme> visemes;          // one per frame with FAP 1, in frame order
  std::vector<Expression> expressions;  // one per frame with FAP 2

  std::uint16_t allFrames() const { return static_cast<std::uint16_t>((1u << length) - 1); }
  bool hasLowLevel() const { return (mask >> 2).any(); }
};

// The decoder's output for a segment: its frames with FAP 1/2 and the reconstructed values.
// Encoder and decoder both call it, so that both produce the same frames.
void appendFrames(const Segment& seg, const DctState& st, std::vector<FapFrame>& out) {
  const std::size_t first = out.size();
  out.resize(first + static_cast<std::size_t>(seg.length));
  std::size_t v = 0, e = 0;
  for (int n = 0; n < seg.length; ++n) {
    FapFrame& f = out[first + static_cast<std::size_t>(n)];
    f.number = seg.numbers[n];
    for (int i = 0; i < kFapCount; ++i) f.mask[i] = seg.mask[i] && bitOf(seg.presence[i], n);
    if (f.mask[0]) f.viseme = seg.visemes[v++];
    if (f.mask[1]) f.expression = seg.expressions[e++];
  }
  for (int fap = 3; fap <= kFapCount; ++fap) {
    const int i = fap - 1;
    if (!seg.mask[i]) continue;
    const auto x = reconstructDctSegment(seg.levels[i], dctStep256(st.stepIndex[i]), st.dcDivisor,
                                         kStepFractionBits);
    for (int n = 0; n < seg.length; ++n) {
      if (bitOf(seg.presence[i], n)) out[first + static_cast<std::size_t>(n)].values[i] = x[n];
    }
  }
}

}  // namespace

std::int64_t dctStep256(int stepIndex) {
  return kStepMantissa[static_cast<std::size_t>(stepIndex % 8)] << (stepIndex / 8);
}

int dctStepIndex(std::int64_t range, int quantStep, int fapQuant) {
  // A step proportional to the FAP's range spends the bits where the robust PSNR needs them
  // (every moving FAP the same relative error); fap_quant 31 is the range itself, each step
  // of fap_quant 2^(1/6) finer (about 1 dB), down to range / 32 at fap_quant 1. A FAP that does not
  // move only needs its DC: the predictive mode's step.
  const double step = range > 0 ? static_cast<double>(range) * std::exp2((fapQuant - 31) / 6.0)
                                : static_cast<double>(quantStep * fapQuant);
  const long e = std::lround(8 * std::log2(step * 4));
  return static_cast<int>(std::clamp<long>(e, 0, kMaxStepIndex));
}

void DctState::beginIntra(int quant, int divisor, const std::bitset<kFapCount>& intraMask) {
  fapQuant = quant;
  dcDivisor = divisor;
  contexts = DctContexts{};
  mask = intraMask;
  dc.fill(0);
  stepIndex.fill(-1);
  lastStepIndex = kStepPrediction;
  lastDcZero.reset();
  lastCoded.reset();
  viseme = {};
  expression = {};
}

// ---------------------------------------------------------------------------------- encoder

namespace {

void checkInput(std::span<const FapFrame> frames, const FbaEncodeOptions& options) {
  if (options.fapQuant < 1)
    throw Error({}, 0, "fapQuant",
                "0 (lossless) is the predictive mode's; the DCT mode takes 1..31");
  if (options.dcDivisor < 1 || options.dcDivisor > kMaxDcDivisor)
    throw Error({}, 0, "dcDivisor", std::to_string(options.dcDivisor) + " is outside 1..15");
  for (std::size_t k = 0; k < frames.size(); ++k) {
    for (int fap = 3; fap <= kFapCount; ++fap) {
      const FapFrame& f = frames[k];
      if (f.has(fap) && std::abs(std::int64_t{f.value(fap)}) > kDctMaxValue)
        throw Error({}, 0, "FAP " + std::to_string(fap),
                    "frame " + std::to_string(k) + " (number " + std::to_string(f.number) +
                        "): " + std::to_string(f.value(fap)) + " is beyond the DCT mode's +-" +
                        std::to_string(kDctMaxValue));
    }
  }
}

// The 16 samples the encoder transforms for a FAP: the values the segment has, linear
// interpolation between them where a frame lacks the FAP, the nearest value before the first
// and after the last (and in the frames a short last segment does not have). The decoder
// discards the reconstruction of those frames, so this is the encoder's free choice; a smooth
// fill keeps the AC levels small.
std::array<double, kN> segmentSamples(std::span<const FapFrame> frames, int length, int fap,
                                      std::uint16_t presence) {
  std::array<double, kN> x{};
  int previous = -1;
  for (int n = 0; n < length; ++n) {
    if (!bitOf(presence, n)) continue;
    x[n] = frames[static_cast<std::size_t>(n)].value(fap);
    if (previous < 0) {
      std::fill(x.begin(), x.begin() + n, x[n]);
    } else {
      for (int m = previous + 1; m < n; ++m)
        x[m] = x[previous] + (x[n] - x[previous]) * (m - previous) / (n - previous);
    }
    previous = n;
  }
  std::fill(x.begin() + previous + 1, x.end(), x[previous]);
  return x;
}

// The predictive mode's quantiser (codec/fba_syntax.hpp) on a real coefficient: the nearest level,
// halves towards zero.
std::int64_t quantiseCoefficient(double c, double step) {
  const double level = std::ceil(std::abs(c) / step - 0.5);
  return static_cast<std::int64_t>(c < 0 ? -level : level);
}

// The segment's frames, masks and FAP 1/2, and each masked FAP's DCT of its samples.
Segment planSegment(std::span<const FapFrame> frames) {
  Segment seg;
  seg.length = static_cast<int>(frames.size());
  for (int n = 0; n < seg.length; ++n) {
    const FapFrame& f = frames[static_cast<std::size_t>(n)];
    seg.numbers[n] = f.number;
    for (int i = 0; i < kFapCount; ++i) {
      if (f.mask[i]) seg.presence[i] |= static_cast<std::uint16_t>(1u << n);
    }
    if (f.has(1)) seg.visemes.push_back(f.viseme);
    if (f.has(2)) seg.expressions.push_back(f.expression);
  }
  for (int i = 0; i < kFapCount; ++i) seg.mask[i] = seg.presence[i] != 0;
  for (int fap = 3; fap <= kFapCount; ++fap) {
    const int i = fap - 1;
    if (seg.mask[i])
      seg.coefficients[i] = forwardDct16(segmentSamples(frames, seg.length, fap, seg.presence[i]));
  }
  return seg;
}

// What a binarisation costs with the contexts' current state, in bits (for RDOQ).
double uegBits(std::int64_t m, std::span<const BinaryContext> prefix) {
  double bits = 0;
  const std::int64_t unary = std::min<std::int64_t>(m, kLevelPrefixBins);
  const auto context = [&](std::int64_t i) -> const BinaryContext& {
    return prefix[static_cast<std::size_t>(std::min<std::int64_t>(i, std::ssize(prefix) - 1))];
  };
  for (std::int64_t i = 0; i < unary; ++i) bits += context(i).idealBits(true);
  if (m < kLevelPrefixBins) return bits + context(m).idealBits(false);
  return bits + 2 * sizeClass(m - kLevelPrefixBins + 1) - 1;  // the exp-Golomb suffix
}

class SegmentWriter {
 public:
  SegmentWriter(BitWriter& out, DctState& st, std::span<const int> stepIndex)
      : enc_(out), st_(st), c_(st.contexts), stepIndex_(stepIndex) {}

  void write(Segment& seg, bool intra) {
    enc_.encodeUniform(seg.length - 1, kN);
    writeNumbers(seg);
    if (!intra) writeMask(seg.mask);
    st_.mask = seg.mask;
    writePresence(seg);
    writeHighLevel(seg);
    writeSteps(seg.mask);
    for (int i = 2; i < kFapCount; ++i) {
      if (seg.mask[i]) writeBlock(i, seg.coefficients[i], seg.levels[i], intra);
    }
    enc_.flush();
  }

 private:
  void bit(bool b, BinaryContext& context) { enc_.encodeBit(b, context); }

  // The low `count` bits of `value` as bypass (raw-bit) symbols of at most kMaxRawBits, most
  // significant first.
  void rawBits(std::uint64_t value, int count) {
    for (; count > 0;) {
      const int n = std::min(count, kMaxRawBits);
      count -= n;
      enc_.encodeBits(static_cast<std::uint32_t>((value >> count) & ((1u << n) - 1)), n);
    }
  }

  // An unsigned m as its size class s = bit length of m in unary (s ones and a zero, bin i with
  // classes[i]), then the s - 1 bits of m below its leading 1: exp-Golomb with adaptive prefix.
  // `first` codes bin 0 when given.
  void writeClassed(std::uint64_t m, std::span<BinaryContext> classes,
                    BinaryContext* first = nullptr) {
    const int size = static_cast<int>(std::bit_width(m));
    for (int i = 0; i <= size && i < kMaxLevelClass; ++i)
      bit(i < size, i == 0 && first ? *first : classes[static_cast<std::size_t>(i)]);
    if (size > 1) rawBits(m, size - 1);
  }
  void writeSignedClassed(std::int64_t v, std::span<BinaryContext> classes,
                          BinaryContext* first = nullptr) {
    writeClassed(static_cast<std::uint64_t>(v < 0 ? -v : v), classes, first);
    if (v != 0) enc_.encodeBits(v < 0 ? 1 : 0, 1);
  }

  // CABAC's UEG0: min(m, 14) in unary (bin i with prefix[min(i, 4)]), then m - 14, if m >= 14,
  // in exp-Golomb order 0 as bypass bits.
  void writeUeg(std::uint64_t m, std::span<BinaryContext> prefix) {
    const auto unary = std::min<std::uint64_t>(m, kLevelPrefixBins);
    const auto context = [&](std::uint64_t i) -> BinaryContext& {
      return prefix[std::min<std::size_t>(i, prefix.size() - 1)];
    };
    for (std::uint64_t i = 0; i < unary; ++i) bit(true, context(i));
    if (m < kLevelPrefixBins) {
      bit(false, context(m));
      return;
    }
    const std::uint64_t suffix = m - kLevelPrefixBins + 1;
    const int size = static_cast<int>(std::bit_width(suffix));
    for (int n = 1; n < size; ++n) enc_.encodeBits(1, 1);  // size - 1 ones and a zero
    enc_.encodeBits(0, 1);
    rawBits(suffix, size - 1);
  }

  void writeNumbers(const Segment& seg) {
    bool skips = false;
    for (int n = 1; n < seg.length; ++n) skips |= seg.numbers[n] != seg.numbers[n - 1] + 1;
    bit(skips, c_.skips);
    for (int n = 1; skips && n < seg.length; ++n)
      writeClassed(static_cast<std::uint64_t>(seg.numbers[n] - seg.numbers[n - 1] - 1),
                   c_.skipClass);
  }

  void writeMask(const std::bitset<kFapCount>& mask) {
    const bool same = mask == st_.mask;
    bit(same, c_.sameMask);
    if (same) return;
    for (const FapGroupInfo& g : fapGroupTable()) {
      int count = 0;
      for (int fap = g.firstFap; fap <= g.lastFap; ++fap) count += mask[fap - 1];
      const int type = count == 0 ? 0 : count == g.lastFap - g.firstFap + 1 ? 2 : 1;
      enc_.encodeUniform(type, 3);
      for (int fap = g.firstFap; type == 1 && fap <= g.lastFap; ++fap)
        enc_.encodeUniform(mask[fap - 1] ? 1 : 0, 2);
    }
  }

  void writePresence(const Segment& seg) {
    bool partial = false;
    for (int i = 0; i < kFapCount; ++i)
      partial |= seg.mask[i] && seg.presence[i] != seg.allFrames();
    bit(partial, c_.partial);
    for (int i = 0; partial && i < kFapCount; ++i) {
      if (!seg.mask[i]) continue;
      const bool full = seg.presence[i] == seg.allFrames();
      bit(full, c_.full);
      for (int n = 0; !full && n < seg.length; ++n) bit(bitOf(seg.presence[i], n), c_.present);
    }
  }

  void writeHighLevel(const Segment& seg) {
    for (const Viseme& v : seg.visemes) {
      bit(v == st_.viseme, c_.visemeRepeat);
      if (v == st_.viseme) continue;
      enc_.encodeUniform(v.select1, 15);
      enc_.encodeUniform(v.select2, 15);
      enc_.encodeUniform(v.blend, 64);
      enc_.encodeUniform(v.def ? 1 : 0, 2);
      st_.viseme = v;
    }
    for (const Expression& e : seg.expressions) {
      bit(e == st_.expression, c_.expressionRepeat);
      if (e == st_.expression) continue;
      enc_.encodeUniform(e.select1, 7);
      enc_.encodeUniform(e.intensity1, 64);
      enc_.encodeUniform(e.select2, 7);
      enc_.encodeUniform(e.intensity2, 64);
      enc_.encodeUniform(e.initFace ? 1 : 0, 2);
      enc_.encodeUniform(e.def ? 1 : 0, 2);
      st_.expression = e;
    }
  }

  // step_index of each masked FAP whose step has not been sent since the intra plane: the
  // difference to the last one sent.
  void writeSteps(const std::bitset<kFapCount>& mask) {
    for (int i = 2; i < kFapCount; ++i) {
      if (!mask[i] || st_.stepIndex[i] >= 0) continue;
      const int e = stepIndex_[static_cast<std::size_t>(i)];
      writeSignedClassed(e - st_.lastStepIndex, c_.stepClass);
      st_.stepIndex[i] = st_.lastStepIndex = e;
    }
  }

  // The AC levels by rate-distortion optimised quantisation: each coefficient takes the level
  // of least squared error + lambda * bits among the nearest level, the one below it in
  // magnitude and 0, bits from the contexts' current state; then the whole block is dropped
  // (coded_block 0) if that costs less.
  void chooseAcLevels(int i, const std::array<double, kN>& c, std::array<std::int64_t, kN>& levels,
                      double step) {
    const double lambda = kLambda * step * step;
    const int group = groupIndex(i + 1);
    double codedCost = 0, droppedDistortion = 0;
    for (int k = 1; k < kN; ++k) {
      const double a = std::abs(c[k]);
      droppedDistortion += a * a;
      const auto nearest = static_cast<std::int64_t>(std::ceil(a / step - 0.5));
      const BinaryContext& significant = c_.significant[group][static_cast<std::size_t>(k - 1)];
      double best = a * a + lambda * significant.idealBits(false);
      std::int64_t level = 0;
      for (std::int64_t m = std::max<std::int64_t>(1, nearest - 1); m <= nearest; ++m) {
        const double e = a - static_cast<double>(m) * step;
        const double cost =
            e * e +
            lambda * (significant.idealBits(true) + 1 +
                      uegBits(m - 1, c_.levelPrefix[static_cast<std::size_t>(levelBucket(k))]));
        if (cost < best) best = cost, level = m;
      }
      levels[k] = c[k] < 0 ? -level : level;
      codedCost += best;
    }
    const auto& coded = c_.coded[static_cast<std::size_t>(group)][st_.lastCoded[i]];
    if (droppedDistortion + lambda * coded.idealBits(false) <=
        codedCost + lambda * coded.idealBits(true))
      std::fill(levels.begin() + 1, levels.end(), 0);
  }

  void writeBlock(int i, const std::array<double, kN>& c, std::array<std::int64_t, kN>& levels,
                  bool intra) {
    const double step = static_cast<double>(dctStep256(st_.stepIndex[i])) /
                        static_cast<double>(1 << kStepFractionBits);
    levels[0] = quantiseCoefficient(c[0], step / st_.dcDivisor);
    chooseAcLevels(i, c, levels, step);
    const auto group = static_cast<std::size_t>(groupIndex(i + 1));
    const std::int64_t dc = levels[0] - st_.dc[i];
    writeSignedClassed(dc, c_.dcClass[intra ? 0 : 1], &c_.dcZero[group][st_.lastDcZero[i]]);
    st_.dc[i] = levels[0];
    st_.lastDcZero[i] = dc == 0;
    int last = 0;
    for (int k = 1; k < kN; ++k) last = levels[k] != 0 ? k : last;
    bit(last > 0, c_.coded[group][st_.lastCoded[i]]);
    st_.lastCoded[i] = last > 0;
    for (int k = 1; k <= last; ++k) {
      const auto j = static_cast<std::size_t>(k - 1);
      const std::int64_t v = levels[k];
      if (k < kN - 1) bit(v != 0, c_.significant[group][j]);
      if (v == 0) continue;
      writeUeg(static_cast<std::uint64_t>(v < 0 ? -v : v) - 1,
               c_.levelPrefix[static_cast<std::size_t>(levelBucket(k))]);
      enc_.encodeBits(v < 0 ? 1 : 0, 1);
      if (k < kN - 1) bit(k == last, c_.last[group][j]);
    }
  }

  ArithmeticEncoder enc_;
  DctState& st_;
  DctContexts& c_;
  std::span<const int> stepIndex_;
};

// Each FAP's step index from its range over the whole stream.
std::array<int, kFapCount> chooseStepIndices(std::span<const FapFrame> frames, int fapQuant) {
  std::array<int, kFapCount> lo{}, hi{};
  lo.fill(std::numeric_limits<int>::max());
  hi.fill(std::numeric_limits<int>::min());
  for (const FapFrame& f : frames) {
    for (int i = 2; i < kFapCount; ++i) {
      if (!f.mask[i]) continue;
      lo[i] = std::min(lo[i], f.values[i]);
      hi[i] = std::max(hi[i], f.values[i]);
    }
  }
  std::array<int, kFapCount> e{};
  for (int fap = 3; fap <= kFapCount; ++fap) {
    const auto i = static_cast<std::size_t>(fap - 1);
    const std::int64_t range = hi[i] >= lo[i] ? std::int64_t{hi[i]} - lo[i] : 0;
    e[i] = dctStepIndex(range, fapInfo(fap).quantStep, fapQuant);
  }
  return e;
}

}  // namespace

void encodeDct(std::span<const FapFrame> frames, const FbaEncodeOptions& options,
               const FrameRateCode& rate, EncodeOutput& output) {
  checkInput(frames, options);
  const std::array<int, kFapCount> stepIndex = chooseStepIndices(frames, options.fapQuant);
  DctState st;
  std::size_t lastIntra = 0;
  // Each plane made safe for a standard decoder once the bits after it are known, as the
  // predictive encoder's (codec/start_code_guard.hpp); planeFrames: where each plane's frames
  // are in stats.frameBits, and how many.
  PlaneGuard guard(output.out);
  std::vector<std::pair<std::size_t, int>> planeFrames;
  const auto countBits = [&](std::size_t m) {  // the plane's bits, spread over its frames
    const PlaneGuard::Span& plane = guard.planes()[m];
    const std::uint64_t bits = plane.end - plane.start;
    const auto [first, length] = planeFrames[m];
    const auto n = static_cast<std::uint64_t>(length);
    for (std::uint64_t k = 0; k < n; ++k)
      output.stats.frameBits[first + k] = bits / n + (k < bits % n);
  };
  const auto secure = [&](std::size_t m, bool codeFollows) {
    if (!guard.secure(m, codeFollows)) {
      throw Error({}, 0, "start code emulation",
                  "frame " + std::to_string(frames[planeFrames[m].first].number) +
                      ": a DCT plane emulates a start code that no plane start code avoids");
    }
    if (const std::optional<std::size_t> moved = guard.takeMoved()) {
      for (std::size_t k = *moved; k < guard.planes().size(); ++k) countBits(k);
    }
  };
  for (std::size_t first = 0; first < frames.size(); first += kN) {
    const auto segmentFrames =
        frames.subspan(first, std::min<std::size_t>(kN, frames.size() - first));
    Segment seg = planSegment(segmentFrames);
    const bool intra =
        first == 0 || (options.intraPeriod > 0 &&
                       first - lastIntra >= static_cast<std::size_t>(options.intraPeriod));
    const std::size_t last = first + segmentFrames.size() - 1;
    guard.open(intra);
    if (intra) {
      lastIntra = first;
      st.beginIntra(options.fapQuant, options.dcDivisor, seg.mask);
      writePlaneHeader(output.out, {true, rate, std::nullopt, framesToSkipAfter(frames, last)});
      writeIntraSettings(output.out, {options.fapQuant, seg.mask, false, kCodingTypeDct});
      output.out.writeBits(static_cast<std::uint32_t>(options.dcDivisor), kDcDivisorBits);
      ++output.stats.intraFrames;
    } else {
      writePlaneHeader(output.out,
                       {false, std::nullopt, std::nullopt, framesToSkipAfter(frames, last)});
    }
    SegmentWriter(output.out, st, stepIndex).write(seg, intra);
    guard.close();
    appendFrames(seg, st, output.reconstruction.frames);
    planeFrames.emplace_back(output.stats.frameBits.size(), seg.length);
    output.stats.frameBits.resize(output.stats.frameBits.size() +
                                  static_cast<std::size_t>(seg.length));
    countBits(planeFrames.size() - 1);
    // The plane before this one is checked now that the bits after it are known.
    if (planeFrames.size() >= 2) secure(planeFrames.size() - 2, false);
  }
  // A start code follows the last plane: the end code.
  if (!planeFrames.empty()) secure(planeFrames.size() - 1, true);
}

// ---------------------------------------------------------------------------------- decoder

namespace {

class SegmentReader {
 public:
  SegmentReader(BitReader& in, DctState& st, const FbaDecodeLimits& limits)
      : in_(in), dec_(in), st_(st), c_(st.contexts), limits_(limits) {}

  // Reads the segment; its first frame is numbered `number`, and `framesSoFar` precede it.
  void read(Segment& seg, bool intra, std::int64_t number, std::size_t framesSoFar) {
    seg.length = dec_.decodeUniform(kN) + 1;
    if (framesSoFar + static_cast<std::size_t>(seg.length) > limits_.maxFrames)
      in_.fail("segment_length",
               "more than " + std::to_string(limits_.maxFrames) + " frames (FbaDecodeLimits)");
    firstNumber_ = number;
    readNumbers(seg, number);
    seg.mask = intra ? st_.mask : readMask();
    st_.mask = seg.mask;
    readPresence(seg);
    readHighLevel(seg);
    readSteps(seg.mask);
    for (fap_ = 3; fap_ <= kFapCount; ++fap_) {
      if (seg.mask[fap_ - 1]) readBlock(fap_ - 1, seg.levels[fap_ - 1], intra);
    }
    dec_.finish("DCT segment");
  }

 private:
  bool bit(BinaryContext& context) { return dec_.decodeBit(context); }

  std::uint64_t rawBits(int count) {
    std::uint64_t value = 0;
    for (; count > 0;) {
      const int n = std::min(count, kMaxRawBits);
      count -= n;
      value = (value << n) | dec_.decodeBits(n);
    }
    return value;
  }

  // The reader runs ahead of the arithmetic decoder, which reads 0 bits past the end of the
  // data: errors name the reader's position, the segment, and whether the data had ended.
  [[noreturn]] void fail(const std::string& element, const std::string& message) const {
    in_.fail(
        element,
        message + " (segment from frame " + std::to_string(firstNumber_) + ")" +
            (in_.position() > in_.size() ? "; the data ended before this point: truncated?" : ""));
  }

  // SegmentWriter::writeClassed's counterpart (at most kMaxLevelClass bits: callers check the
  // value's range).
  std::uint64_t readClassed(std::span<BinaryContext> classes, BinaryContext* first = nullptr) {
    int size = 0;
    while (size < kMaxLevelClass &&
           bit(size == 0 && first ? *first : classes[static_cast<std::size_t>(size)]))
      ++size;
    if (size == 0) return 0;
    return (std::uint64_t{1} << (size - 1)) | rawBits(size - 1);
  }
  std::int64_t readSignedClassed(std::span<BinaryContext> classes, BinaryContext* first = nullptr) {
    const auto m = static_cast<std::int64_t>(readClassed(classes, first));
    return m != 0 && dec_.decodeBits(1) != 0 ? -m : m;
  }

  std::uint64_t readUeg(std::span<BinaryContext> prefix) {
    std::uint64_t m = 0;
    while (m < kLevelPrefixBins && bit(prefix[std::min<std::size_t>(m, prefix.size() - 1)])) ++m;
    if (m < kLevelPrefixBins) return m;
    int size = 1;
    while (dec_.decodeBits(1) != 0) {
      if (++size > kMaxLevelClass)
        fail("FAP " + std::to_string(fap_) + " AC level",
             "an exp-Golomb suffix of more than 40 bits");
    }
    return m - 1 + ((std::uint64_t{1} << (size - 1)) | rawBits(size - 1));
  }

  void readNumbers(Segment& seg, std::int64_t number) {
    seg.numbers[0] = static_cast<int>(number);
    const bool skips = bit(c_.skips);
    for (int n = 1; n < seg.length; ++n) {
      if (skips) number += static_cast<std::int64_t>(readClassed(c_.skipClass));
      ++number;
      if (number > limits_.maxFrameNumber)
        fail("frame skip",
             "frame numbers pass " + std::to_string(limits_.maxFrameNumber) + " (FbaDecodeLimits)");
      seg.numbers[n] = static_cast<int>(number);
    }
  }

  std::bitset<kFapCount> readMask() {
    if (bit(c_.sameMask)) return st_.mask;
    std::bitset<kFapCount> mask;
    for (const FapGroupInfo& g : fapGroupTable()) {
      const int type = dec_.decodeUniform(3);
      for (int fap = g.firstFap; fap <= g.lastFap; ++fap)
        mask[fap - 1] = type == 2 || (type == 1 && dec_.decodeUniform(2) == 1);
    }
    return mask;
  }

  void readPresence(Segment& seg) {
    const bool partial = bit(c_.partial);
    for (int i = 0; i < kFapCount; ++i) {
      if (!seg.mask[i]) continue;
      seg.presence[i] = seg.allFrames();
      if (!partial || bit(c_.full)) continue;
      seg.presence[i] = 0;
      for (int n = 0; n < seg.length; ++n) {
        if (bit(c_.present)) seg.presence[i] |= static_cast<std::uint16_t>(1u << n);
      }
      if (seg.presence[i] == 0)
        fail("frame_mask", "FAP " + std::to_string(i + 1) +
                               " is in the segment's mask but in none of its frames");
    }
  }

  void readHighLevel(Segment& seg) {
    for (int n = 0; n < seg.length; ++n) {
      if (!seg.mask[0] || !bitOf(seg.presence[0], n)) continue;
      if (!bit(c_.visemeRepeat)) {
        st_.viseme = {dec_.decodeUniform(15), dec_.decodeUniform(15), dec_.decodeUniform(64),
                      dec_.decodeUniform(2) == 1};
      }
      seg.visemes.push_back(st_.viseme);
    }
    for (int n = 0; n < seg.length; ++n) {
      if (!seg.mask[1] || !bitOf(seg.presence[1], n)) continue;
      if (!bit(c_.expressionRepeat)) {
        st_.expression = {dec_.decodeUniform(7),      dec_.decodeUniform(64),
                          dec_.decodeUniform(7),      dec_.decodeUniform(64),
                          dec_.decodeUniform(2) == 1, dec_.decodeUniform(2) == 1};
      }
      seg.expressions.push_back(st_.expression);
    }
  }

  void readSteps(const std::bitset<kFapCount>& mask) {
    for (int i = 2; i < kFapCount; ++i) {
      if (!mask[i] || st_.stepIndex[i] >= 0) continue;
      const std::int64_t e = st_.lastStepIndex + readSignedClassed(c_.stepClass);
      if (e < 0 || e > kMaxStepIndex)
        fail("step_index", "FAP " + std::to_string(i + 1) + ": " + std::to_string(e) +
                               " is outside 0.." + std::to_string(kMaxStepIndex));
      st_.stepIndex[i] = st_.lastStepIndex = static_cast<int>(e);
    }
  }

  void readBlock(int i, std::array<std::int64_t, kN>& levels, bool intra) {
    // Named only when an error needs it: no string per FAP and segment on the way.
    const auto fap = [this] { return "FAP " + std::to_string(fap_); };
    const auto group = static_cast<std::size_t>(groupIndex(fap_));
    const std::int64_t step = dctStep256(st_.stepIndex[i]);
    const std::int64_t dc =
        readSignedClassed(c_.dcClass[intra ? 0 : 1], &c_.dcZero[group][st_.lastDcZero[i]]);
    levels[0] = st_.dc[i] + dc;
    if (std::abs(levels[0]) > kCoefficientLimit256 * st_.dcDivisor / step)
      fail(fap() + " DC", "level " + std::to_string(levels[0]) + " at the DC step " +
                              std::to_string(step) + "/256/" + std::to_string(st_.dcDivisor) +
                              " is a coefficient beyond 2^24");
    st_.dc[i] = levels[0];
    st_.lastDcZero[i] = dc == 0;
    const bool coded = bit(c_.coded[group][st_.lastCoded[i]]);
    st_.lastCoded[i] = coded;
    for (int k = 1; coded && k < kN; ++k) {
      const auto j = static_cast<std::size_t>(k - 1);
      if (k < kN - 1 && !bit(c_.significant[group][j])) continue;
      const std::uint64_t m = readUeg(c_.levelPrefix[static_cast<std::size_t>(levelBucket(k))]) + 1;
      if (m > static_cast<std::uint64_t>(kCoefficientLimit256 / step))
        fail(fap() + " AC level", "level " + std::to_string(m) + " at the AC step " +
                                      std::to_string(step) + "/256 is a coefficient beyond 2^24");
      const auto magnitude = static_cast<std::int64_t>(m);
      levels[k] = dec_.decodeBits(1) != 0 ? -magnitude : magnitude;
      if (k < kN - 1 && bit(c_.last[group][j])) break;
    }
  }

  BitReader& in_;
  ArithmeticDecoder dec_;
  DctState& st_;
  DctContexts& c_;
  const FbaDecodeLimits& limits_;
  std::int64_t firstNumber_ = 0;
  int fap_ = 0;
};

}  // namespace

void DctDecoder::decodeIntra(BitReader& in, const IntraSettings& settings, std::int64_t number,
                             std::vector<FapFrame>& frames) {
  if (settings.fapQuant == 0) in.fail("fap_quant", "0 (no quantisation) is not a DCT mode step");
  const int divisor = static_cast<int>(in.readBits(kDcDivisorBits, "dc_divisor"));
  if (divisor == 0) in.failAt(in.position() - kDcDivisorBits, "dc_divisor", "is 0 (1..15)");
  state_.beginIntra(settings.fapQuant, divisor, settings.mask);
  decodeSegment(in, true, number, frames);
}

void DctDecoder::decodeInter(BitReader& in, std::int64_t number, std::vector<FapFrame>& frames) {
  decodeSegment(in, false, number, frames);
}

void DctDecoder::decodeSegment(BitReader& in, bool intra, std::int64_t number,
                               std::vector<FapFrame>& frames) {
  Segment seg;
  SegmentReader(in, state_, limits_).read(seg, intra, number, frames.size());
  const std::size_t first = frames.size();
  appendFrames(seg, state_, frames);
  for (std::size_t t = first; t < frames.size(); ++t) {
    for (int fap = 3; fap <= kFapCount; ++fap) {
      if (frames[t].has(fap) && std::abs(frames[t].value(fap)) > kMaxFbaValue)
        in.fail("FAP " + std::to_string(fap), "the reconstruction reaches " +
                                                  std::to_string(frames[t].value(fap)) +
                                                  ", beyond +-" + std::to_string(kMaxFbaValue));
    }
  }
}

}  // namespace mpeg4face::fba
