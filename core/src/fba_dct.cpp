// SPDX-License-Identifier: GPL-3.0-or-later
// The DCT coding mode (fba_dct.hpp). The syntax is the project's own and is defined element
// by element in docs/dct-mode.md, whose names the comments here use.
#include "fba_dct.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face::fba {
namespace {

constexpr int kN = kDctSegmentLength;
constexpr int kDcDivisorBits = 4;
// |level * step| of every coefficient: what an input within kDctMaxValue can produce, with
// room for rounding, and what keeps reconstructDctSegment inside 64 bits.
constexpr std::int64_t kCoefficientLimit = std::int64_t{1} << 24;
constexpr int kEndOfSegment = 15;  // the acRun symbol after the last non-zero AC level

// The AC models' contexts (docs/dct-mode.md, "Models"): the run to the first non-zero level
// and the size of levels 1-2 have their own statistics (smooth motion lives there).
int runContext(int k) { return k == 1 ? 0 : 1; }
int sizeContext(int k) { return k <= 2 ? 0 : 1; }

int acStep(int fap, int fapQuant) { return fapInfo(fap).quantStep * fapQuant; }

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
    const auto x = reconstructDctSegment(seg.levels[i], acStep(fap, st.fapQuant), st.dcDivisor);
    for (int n = 0; n < seg.length; ++n) {
      if (bitOf(seg.presence[i], n)) out[first + static_cast<std::size_t>(n)].values[i] = x[n];
    }
  }
}

}  // namespace

void DctState::beginIntra(int quant, int divisor, const std::bitset<kFapCount>& intraMask) {
  fapQuant = quant;
  dcDivisor = divisor;
  models = DctModels{};
  mask = intraMask;
  dc.fill(0);
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

// The predictive mode's quantiser (fba_syntax.hpp) on a real coefficient: the nearest level,
// halves towards zero.
std::int64_t quantiseCoefficient(double c, double step) {
  const double level = std::ceil(std::abs(c) / step - 0.5);
  return static_cast<std::int64_t>(c < 0 ? -level : level);
}

Segment planSegment(std::span<const FapFrame> frames, const FbaEncodeOptions& options) {
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
    if (!seg.mask[i]) continue;
    const auto c = forwardDct16(segmentSamples(frames, seg.length, fap, seg.presence[i]));
    const double step = acStep(fap, options.fapQuant);
    seg.levels[i][0] = quantiseCoefficient(c[0], step / options.dcDivisor);
    for (int k = 1; k < kN; ++k) seg.levels[i][k] = quantiseCoefficient(c[k], step);
  }
  return seg;
}

class SegmentWriter {
 public:
  SegmentWriter(BitWriter& out, DctState& st) : enc_(out), st_(st), m_(st.models) {}

  void write(const Segment& seg, bool intra) {
    enc_.encodeUniform(seg.length - 1, kN);
    writeNumbers(seg);
    if (!intra) writeMask(seg.mask);
    st_.mask = seg.mask;
    writePresence(seg);
    writeHighLevel(seg);
    for (int i = 2; i < kFapCount; ++i) {
      if (seg.mask[i]) writeLevels(seg.levels[i], st_.dc[i]);
    }
    enc_.flush();
  }

 private:
  void bit(bool b, AdaptiveModel& model) { enc_.encode(b ? 1 : 0, model); }

  // The low `count` bits of `value` as raw-bit symbols of at most kMaxRawBits, most
  // significant first.
  void rawBits(std::uint64_t value, int count) {
    for (; count > 0;) {
      const int n = std::min(count, kMaxRawBits);
      count -= n;
      enc_.encodeBits(static_cast<std::uint32_t>((value >> count) & ((1u << n) - 1)), n);
    }
  }

  void writeNumbers(const Segment& seg) {
    bool skips = false;
    for (int n = 1; n < seg.length; ++n) skips |= seg.numbers[n] != seg.numbers[n - 1] + 1;
    bit(skips, m_.skips);
    for (int n = 1; skips && n < seg.length; ++n) {
      const std::int64_t skip = std::int64_t{seg.numbers[n]} - seg.numbers[n - 1] - 1;
      enc_.encode(sizeClass(skip), m_.countSize);
      if (skip > 0) rawBits(static_cast<std::uint64_t>(skip), sizeClass(skip) - 1);
    }
  }

  void writeMask(const std::bitset<kFapCount>& mask) {
    const bool same = mask == st_.mask;
    bit(same, m_.sameMask);
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
    bit(partial, m_.partial);
    for (int i = 0; partial && i < kFapCount; ++i) {
      if (!seg.mask[i]) continue;
      const bool full = seg.presence[i] == seg.allFrames();
      bit(full, m_.full);
      for (int n = 0; !full && n < seg.length; ++n) bit(bitOf(seg.presence[i], n), m_.present);
    }
  }

  void writeHighLevel(const Segment& seg) {
    for (const Viseme& v : seg.visemes) {
      bit(v == st_.viseme, m_.visemeRepeat);
      if (v == st_.viseme) continue;
      enc_.encodeUniform(v.select1, 15);
      enc_.encodeUniform(v.select2, 15);
      enc_.encodeUniform(v.blend, 64);
      enc_.encodeUniform(v.def ? 1 : 0, 2);
      st_.viseme = v;
    }
    for (const Expression& e : seg.expressions) {
      bit(e == st_.expression, m_.expressionRepeat);
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

  // A level: its size class s (less sizeOffset) in `sizes`, then for v != 0 s raw bits: the
  // sign (1 = negative) and the s - 1 bits of |v| below its leading 1.
  void writeLevel(AdaptiveModel& sizes, int sizeOffset, std::int64_t v) {
    const int size = sizeClass(v);
    enc_.encode(size - sizeOffset, sizes);
    if (size == 0) return;
    const auto magnitude = static_cast<std::uint64_t>(v < 0 ? -v : v);
    const std::uint64_t leadingOne = std::uint64_t{1} << (size - 1);
    rawBits((v < 0 ? leadingOne : 0) | (magnitude - leadingOne), size);
  }

  void writeLevels(const std::array<std::int64_t, kN>& levels, std::int64_t& dc) {
    writeLevel(m_.dcSize, 0, levels[0] - dc);
    dc = levels[0];
    for (int k = 1; k < kN;) {
      int next = k;
      while (next < kN && levels[next] == 0) ++next;
      if (next == kN) {
        enc_.encode(kEndOfSegment, m_.acRun[runContext(k)]);
        return;
      }
      enc_.encode(next - k, m_.acRun[runContext(k)]);
      writeLevel(m_.acSize[sizeContext(next)], 1, levels[next]);
      k = next + 1;
    }
  }

  ArithmeticEncoder enc_;
  DctState& st_;
  DctModels& m_;
};

}  // namespace

void encodeDct(std::span<const FapFrame> frames, const FbaEncodeOptions& options,
               const FrameRateCode& rate, EncodeOutput& output) {
  checkInput(frames, options);
  DctState st;
  std::size_t lastIntra = 0;
  for (std::size_t first = 0; first < frames.size(); first += kN) {
    const auto segmentFrames =
        frames.subspan(first, std::min<std::size_t>(kN, frames.size() - first));
    const Segment seg = planSegment(segmentFrames, options);
    const bool intra =
        first == 0 || (options.intraPeriod > 0 &&
                       first - lastIntra >= static_cast<std::size_t>(options.intraPeriod));
    const std::size_t last = first + segmentFrames.size() - 1;
    const std::uint64_t start = output.out.bitCount();
    if (intra) {
      lastIntra = first;
      st.beginIntra(options.fapQuant, options.dcDivisor, seg.mask);
      output.out.writeStartCode(kFbaObjectPlaneStartCode);
      writePlaneHeader(output.out, {true, rate, std::nullopt, framesToSkipAfter(frames, last)});
      writeIntraSettings(output.out, {options.fapQuant, seg.mask, false, kCodingTypeDct});
      output.out.writeBits(static_cast<std::uint32_t>(options.dcDivisor), kDcDivisorBits);
      ++output.stats.intraFrames;
    } else {
      writePlaneHeader(output.out,
                       {false, std::nullopt, std::nullopt, framesToSkipAfter(frames, last)});
    }
    SegmentWriter(output.out, st).write(seg, intra);
    appendFrames(seg, st, output.reconstruction.frames);
    // The plane's bits, spread over its frames.
    const std::uint64_t bits = output.out.bitCount() - start;
    for (int n = 0; n < seg.length; ++n)
      output.stats.frameBits.push_back(
          bits / static_cast<std::uint64_t>(seg.length) +
          (static_cast<std::uint64_t>(n) < bits % static_cast<std::uint64_t>(seg.length)));
  }
}

// ---------------------------------------------------------------------------------- decoder

namespace {

class SegmentReader {
 public:
  SegmentReader(BitReader& in, DctState& st, const FbaDecodeLimits& limits)
      : in_(in), dec_(in), st_(st), m_(st.models), limits_(limits) {}

  // Reads the segment; its first frame is numbered `number`, and `framesSoFar` precede it.
  void read(Segment& seg, bool intra, std::int64_t number, std::size_t framesSoFar) {
    seg.length = dec_.decodeUniform(kN) + 1;
    if (framesSoFar + static_cast<std::size_t>(seg.length) > limits_.maxFrames)
      in_.fail("segment_length",
               "more than " + std::to_string(limits_.maxFrames) + " frames (FbaDecodeLimits)");
    readNumbers(seg, number);
    seg.mask = intra ? st_.mask : readMask();
    st_.mask = seg.mask;
    readPresence(seg);
    readHighLevel(seg);
    for (fap_ = 3; fap_ <= kFapCount; ++fap_) {
      if (seg.mask[fap_ - 1]) readLevels(seg.levels[fap_ - 1], st_.dc[fap_ - 1]);
    }
    dec_.finish("DCT segment");
  }

 private:
  bool bit(AdaptiveModel& model) { return dec_.decode(model) != 0; }

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

  void readNumbers(Segment& seg, std::int64_t number) {
    firstNumber_ = number;
    seg.numbers[0] = static_cast<int>(number);
    const bool skips = bit(m_.skips);
    for (int n = 1; n < seg.length; ++n) {
      std::int64_t skip = 0;
      if (skips) {
        const int size = dec_.decode(m_.countSize);
        if (size > 0)
          skip = static_cast<std::int64_t>((std::uint64_t{1} << (size - 1)) | rawBits(size - 1));
      }
      number += 1 + skip;
      if (number > limits_.maxFrameNumber)
        fail("frame skip",
             "frame numbers pass " + std::to_string(limits_.maxFrameNumber) + " (FbaDecodeLimits)");
      seg.numbers[n] = static_cast<int>(number);
    }
  }

  std::bitset<kFapCount> readMask() {
    if (bit(m_.sameMask)) return st_.mask;
    std::bitset<kFapCount> mask;
    for (const FapGroupInfo& g : fapGroupTable()) {
      const int type = dec_.decodeUniform(3);
      for (int fap = g.firstFap; fap <= g.lastFap; ++fap)
        mask[fap - 1] = type == 2 || (type == 1 && dec_.decodeUniform(2) == 1);
    }
    return mask;
  }

  void readPresence(Segment& seg) {
    const bool partial = bit(m_.partial);
    for (int i = 0; i < kFapCount; ++i) {
      if (!seg.mask[i]) continue;
      seg.presence[i] = seg.allFrames();
      if (!partial || bit(m_.full)) continue;
      seg.presence[i] = 0;
      for (int n = 0; n < seg.length; ++n) {
        if (bit(m_.present)) seg.presence[i] |= static_cast<std::uint16_t>(1u << n);
      }
      if (seg.presence[i] == 0)
        fail("frame_mask", "FAP " + std::to_string(i + 1) +
                               " is in the segment's mask but in none of its frames");
    }
  }

  void readHighLevel(Segment& seg) {
    for (int n = 0; n < seg.length; ++n) {
      if (!seg.mask[0] || !bitOf(seg.presence[0], n)) continue;
      if (!bit(m_.visemeRepeat)) {
        st_.viseme = {dec_.decodeUniform(15), dec_.decodeUniform(15), dec_.decodeUniform(64),
                      dec_.decodeUniform(2) == 1};
      }
      seg.visemes.push_back(st_.viseme);
    }
    for (int n = 0; n < seg.length; ++n) {
      if (!seg.mask[1] || !bitOf(seg.presence[1], n)) continue;
      if (!bit(m_.expressionRepeat)) {
        st_.expression = {dec_.decodeUniform(7),      dec_.decodeUniform(64),
                          dec_.decodeUniform(7),      dec_.decodeUniform(64),
                          dec_.decodeUniform(2) == 1, dec_.decodeUniform(2) == 1};
      }
      seg.expressions.push_back(st_.expression);
    }
  }

  std::int64_t readLevel(AdaptiveModel& sizes, int sizeOffset) {
    const int size = dec_.decode(sizes) + sizeOffset;
    if (size == 0) return 0;
    const std::uint64_t leadingOne = std::uint64_t{1} << (size - 1);
    const std::uint64_t bits = rawBits(size);
    const auto magnitude = static_cast<std::int64_t>(leadingOne | (bits & (leadingOne - 1)));
    return (bits & leadingOne) != 0 ? -magnitude : magnitude;
  }

  void readLevels(std::array<std::int64_t, kN>& levels, std::int64_t& dc) {
    // Named only when an error needs it: no string per FAP and segment on the way.
    const auto fap = [this] { return "FAP " + std::to_string(fap_); };
    const std::int64_t step = acStep(fap_, st_.fapQuant);
    levels[0] = dc + readLevel(m_.dcSize, 0);
    if (std::abs(levels[0]) * step > kCoefficientLimit * st_.dcDivisor)
      fail(fap() + " DC", "level " + std::to_string(levels[0]) + " at the DC step " +
                              std::to_string(step) + "/" + std::to_string(st_.dcDivisor) +
                              " is a coefficient beyond 2^24");
    dc = levels[0];
    for (int k = 1; k < kN;) {
      const int run = dec_.decode(m_.acRun[runContext(k)]);
      if (run == kEndOfSegment) return;
      if (k + run >= kN)
        fail(fap() + " AC run", "a run of " + std::to_string(run) + " zeros after coefficient " +
                                    std::to_string(k - 1) + " goes past coefficient 15");
      k += run;
      levels[k] = readLevel(m_.acSize[sizeContext(k)], 1);
      if (std::abs(levels[k]) * step > kCoefficientLimit)
        fail(fap() + " AC level", "level " + std::to_string(levels[k]) + " at the AC step " +
                                      std::to_string(step) + " is a coefficient beyond 2^24");
      ++k;
    }
  }

  BitReader& in_;
  ArithmeticDecoder dec_;
  DctState& st_;
  DctModels& m_;
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
