// SPDX-License-Identifier: GPL-3.0-or-later
// The DCT coding mode (see dct_codec.hpp). The format is the project's own and is defined
// in docs/dct-mode.md; the section names there are used in the comments below.
#include "mpeg4face/dct_codec.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <span>
#include <string>

#include "mpeg4face/arithmetic_coder.hpp"
#include "mpeg4face/bit_io.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

constexpr int kN = kDctSegmentLength;
constexpr std::array<std::uint8_t, 4> kMagic = {'M', '4', 'F', 'D'};
constexpr std::uint8_t kVersion = 1;
constexpr std::size_t kHeaderBytes = 21;  // up to and including the name length
constexpr int kMaxFapQuant = 31;
constexpr int kMaxDcDivisor = 15;
// |level * step| of every coefficient; what an input within kDctMaxValue can produce, with
// room for rounding, and what keeps reconstructDctSegment inside 64 bits.
constexpr std::int64_t kCoefficientLimit = std::int64_t{1} << 24;
constexpr int kDcSizes = 30;     // size classes 0..29 of a DC level or DC difference
constexpr int kAcSizes = 25;     // size classes 1..25 of a non-zero AC level
constexpr int kRunSymbols = 16;  // zero runs 0..14 and end_of_segment
constexpr int kEndOfSegment = 15;
constexpr int kCountBits = 5;  // size class of an unsigned count (frame numbers, skips)
// is_intra, skips, same_mask, partial: the least a segment can take.
constexpr std::uint64_t kMinSegmentBits = 4;

constexpr std::size_t kCrcBytes = 4;

// CRC-32 of IEEE 802.3 / zlib (reflected polynomial 0xEDB88320), over the whole stream before
// it: without it most bit errors in the entropy-coded data would decode to another stream.
std::uint32_t crc32(std::span<const std::uint8_t> bytes) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (const std::uint8_t b : bytes) c = table[(c ^ b) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

int acStepOf(int fap, int fapQuant) { return fapInfo(fap).quantStep * fapQuant; }

// The adaptive models of the arithmetic-coded part, one per symbol kind; an intra segment
// starts them afresh.
struct Models {
  AdaptiveModel dcSize{kDcSizes};
  AdaptiveModel acRun{kRunSymbols};
  AdaptiveModel acSize{kAcSizes};
  AdaptiveModel sign{2};
  AdaptiveModel mantissa{2};
};

// ---- Segments -----------------------------------------------------------------------------------

// One segment as the format carries it.
struct Segment {
  int length = 0;  // frames: 16, fewer in the last segment
  bool intra = false;
  std::array<int, kN> numbers{};
  std::bitset<kFapCount> mask;                                   // union over the segment's frames
  std::array<std::uint16_t, kFapCount> presence{};               // bit n: frame n has the FAP
  std::array<std::array<std::int64_t, kN>, kFapCount> levels{};  // FAP 3..68; [0] is DC
  std::vector<Viseme> visemes;          // one per frame with FAP 1, in frame order
  std::vector<Expression> expressions;  // one per frame with FAP 2
  std::uint16_t allFrames() const { return static_cast<std::uint16_t>((1u << length) - 1); }
};

// What a segment may refer to in the segments before it; an intra segment resets it (the
// frame number excepted: an intra segment sends its first one in full).
struct CodingState {
  Models models;
  bool haveMask = false;
  std::bitset<kFapCount> mask;
  std::array<std::int64_t, kFapCount> dc{};
  Viseme viseme;
  Expression expression;
  std::int64_t lastNumber = -1;

  void startIntra() {
    models = Models{};
    haveMask = false;
    dc.fill(0);
    viseme = {};
    expression = {};
  }
};

int sizeClass(std::int64_t v) {
  return static_cast<int>(std::bit_width(static_cast<std::uint64_t>(v < 0 ? -v : v)));
}

// The decoder's output for one segment: FAP 1/2 and the reconstructed values of the frames
// that have them. Shared by encoder and decoder so that both produce the same frames.
void appendFrames(const Segment& seg, int fapQuant, int dcDivisor, std::vector<FapFrame>& out) {
  const std::size_t first = out.size();
  out.resize(first + static_cast<std::size_t>(seg.length));
  for (int n = 0; n < seg.length; ++n) out[first + n].number = seg.numbers[n];
  std::size_t v = 0, e = 0;
  for (int n = 0; n < seg.length; ++n) {
    FapFrame& f = out[first + static_cast<std::size_t>(n)];
    for (int i = 0; i < kFapCount; ++i) f.mask[i] = seg.mask[i] && ((seg.presence[i] >> n) & 1);
    if (f.mask[0]) f.viseme = seg.visemes[v++];
    if (f.mask[1]) f.expression = seg.expressions[e++];
  }
  for (int fap = 3; fap <= kFapCount; ++fap) {
    const int i = fap - 1;
    if (!seg.mask[i]) continue;
    const auto x = reconstructDctSegment(seg.levels[i], acStepOf(fap, fapQuant), dcDivisor);
    for (int n = 0; n < seg.length; ++n) {
      if ((seg.presence[i] >> n) & 1) out[first + static_cast<std::size_t>(n)].values[i] = x[n];
    }
  }
}

// ---- Encoder ------------------------------------------------------------------------------------

[[noreturn]] void inputError(std::size_t frame, int fap, const std::string& message) {
  std::string field = "frame " + std::to_string(frame);
  if (fap > 0) field += " FAP " + std::to_string(fap);
  throw Error({}, 0, field, message);
}

void checkInput(const FapStream& stream, const DctOptions& options) {
  if (options.fapQuant < 1 || options.fapQuant > kMaxFapQuant)
    throw Error({}, 0, "fapQuant", "must be 1..31, not " + std::to_string(options.fapQuant));
  if (options.dcDivisor < 1 || options.dcDivisor > kMaxDcDivisor)
    throw Error({}, 0, "dcDivisor", "must be 1..15, not " + std::to_string(options.dcDivisor));
  if (options.intraInterval < 0) throw Error({}, 0, "intraInterval", "must be >= 0");
  if (stream.name.size() > 0xFFFF) throw Error({}, 0, "name", "longer than 65535 bytes");
  if (!std::isfinite(stream.frameRate) || stream.frameRate <= 0)
    throw Error({}, 0, "frameRate", "must be finite and > 0");
  if (stream.frames.size() > std::numeric_limits<std::uint32_t>::max())
    throw Error({}, 0, "frames", "more than 2^32 - 1");
  std::int64_t previous = -1;
  for (std::size_t t = 0; t < stream.frames.size(); ++t) {
    const FapFrame& f = stream.frames[t];
    if (f.number <= previous)
      inputError(t, 0,
                 "frame number " + std::to_string(f.number) + " after " + std::to_string(previous) +
                     ": numbers must increase from >= 0");
    previous = f.number;
    const Viseme& v = f.viseme;
    if (f.has(1) && (v.select1 < 0 || v.select1 > 14 || v.select2 < 0 || v.select2 > 14 ||
                     v.blend < 0 || v.blend > 63))
      inputError(t, 1, "viseme_select1/2 must be 0..14 and viseme_blend 0..63");
    const Expression& e = f.expression;
    if (f.has(2) &&
        (e.select1 < 0 || e.select1 > 6 || e.select2 < 0 || e.select2 > 6 || e.intensity1 < 0 ||
         e.intensity1 > 63 || e.intensity2 < 0 || e.intensity2 > 63))
      inputError(t, 2, "expression_select1/2 must be 0..6 and the intensities 0..63");
    for (int fap = 3; fap <= kFapCount; ++fap) {
      if (f.has(fap) && std::abs(std::int64_t{f.value(fap)}) > kDctMaxValue)
        inputError(
            t, fap,
            "value " + std::to_string(f.value(fap)) + " outside +-" + std::to_string(kDctMaxValue));
    }
  }
}

// The 16 samples the encoder transforms for a FAP: the values the segment has, linear
// interpolation between them where a frame lacks it, the nearest value before the first
// and after the last (and in the frames past the end of the stream). The decoder discards
// the reconstruction of those frames, so this is the encoder's free choice; smooth fill keeps
// the AC levels small.
std::array<double, kN> segmentSamples(const std::vector<FapFrame>& frames, std::size_t first,
                                      int length, int fap, std::uint16_t presence) {
  std::array<double, kN> x{};
  int previous = -1;
  for (int n = 0; n < kN; ++n) {
    if (n < length && ((presence >> n) & 1)) {
      x[n] = frames[first + static_cast<std::size_t>(n)].value(fap);
      if (previous < 0) {
        std::fill(x.begin(), x.begin() + n, x[n]);
      } else {
        for (int m = previous + 1; m < n; ++m)
          x[m] = x[previous] + (x[n] - x[previous]) * (m - previous) / (n - previous);
      }
      previous = n;
    }
  }
  std::fill(x.begin() + previous + 1, x.end(), x[previous]);
  return x;
}

// The predictive mode's quantiser: nearest level, halves towards zero.
std::int64_t quantise(double c, double step) {
  const double level = std::ceil(std::abs(c) / step - 0.5);
  return static_cast<std::int64_t>(c < 0 ? -level : level);
}

Segment planSegment(const FapStream& stream, std::size_t first, bool intra,
                    const DctOptions& options) {
  Segment seg;
  seg.length = static_cast<int>(std::min<std::size_t>(kN, stream.frames.size() - first));
  seg.intra = intra;
  for (int n = 0; n < seg.length; ++n) {
    const FapFrame& f = stream.frames[first + static_cast<std::size_t>(n)];
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
    const auto c =
        forwardDct16(segmentSamples(stream.frames, first, seg.length, fap, seg.presence[i]));
    const double acStep = acStepOf(fap, options.fapQuant);
    seg.levels[i][0] = quantise(c[0], acStep / options.dcDivisor);
    for (int k = 1; k < kN; ++k) seg.levels[i][k] = quantise(c[k], acStep);
  }
  return seg;
}

void writeCount(BitWriter& w, std::int64_t count) {
  const int size = sizeClass(count);
  w.writeBits(static_cast<std::uint32_t>(size), kCountBits);
  if (size > 1) w.writeBits(static_cast<std::uint32_t>(count), size - 1);  // below the leading 1
}

void writeVisemeFields(BitWriter& w, const Viseme& v) {
  w.writeBits(static_cast<std::uint32_t>(v.select1), 4);
  w.writeBits(static_cast<std::uint32_t>(v.select2), 4);
  w.writeBits(static_cast<std::uint32_t>(v.blend), 6);
  w.writeBit(v.def);
}

void writeExpressionFields(BitWriter& w, const Expression& e) {
  w.writeBits(static_cast<std::uint32_t>(e.select1), 3);
  w.writeBits(static_cast<std::uint32_t>(e.intensity1), 6);
  w.writeBits(static_cast<std::uint32_t>(e.select2), 3);
  w.writeBits(static_cast<std::uint32_t>(e.intensity2), 6);
  w.writeBit(e.initFace);
  w.writeBit(e.def);
}

// A level: its size class (bit length of |v|, less sizeOffset) in `sizes`, then for v != 0
// the sign and the bits below the leading 1, most significant first.
void encodeLevel(ArithmeticEncoder& enc, Models& models, AdaptiveModel& sizes, int sizeOffset,
                 std::int64_t v) {
  const int size = sizeClass(v);
  enc.encode(size - sizeOffset, sizes);
  if (size == 0) return;
  enc.encode(v < 0, models.sign);
  const std::uint64_t magnitude = static_cast<std::uint64_t>(v < 0 ? -v : v);
  for (int b = size - 2; b >= 0; --b)
    enc.encode(static_cast<int>((magnitude >> b) & 1), models.mantissa);
}

// The plain part of a segment (docs/dct-mode.md "Segment").
void writePlainPart(BitWriter& w, const Segment& seg, CodingState& st) {
  w.writeBit(seg.intra);
  if (seg.intra) st.startIntra();
  // Frame numbers.
  int start = 0;  // the first frame sent as a skip
  if (seg.intra) {
    writeCount(w, seg.numbers[0]);
    st.lastNumber = seg.numbers[0];
    start = 1;
  }
  bool skips = false;
  for (int n = start; n < seg.length; ++n)
    skips |= seg.numbers[n] != (n == 0 ? st.lastNumber : std::int64_t{seg.numbers[n - 1]}) + 1;
  w.writeBit(skips);
  for (int n = start; n < seg.length; ++n) {
    if (skips) writeCount(w, seg.numbers[n] - st.lastNumber - 1);
    st.lastNumber = seg.numbers[n];
  }
  // Segment mask.
  const bool sameMask = st.haveMask && seg.mask == st.mask;
  if (!seg.intra) w.writeBit(sameMask);
  if (!sameMask) {
    for (const FapGroupInfo& g : fapGroupTable()) {
      int count = 0;
      for (int fap = g.firstFap; fap <= g.lastFap; ++fap) count += seg.mask[fap - 1];
      const int type = count == 0 ? 0 : count == g.lastFap - g.firstFap + 1 ? 3 : 1;
      w.writeBits(static_cast<std::uint32_t>(type), 2);
      if (type != 1) continue;
      for (int fap = g.firstFap; fap <= g.lastFap; ++fap) w.writeBit(seg.mask[fap - 1]);
    }
  }
  st.mask = seg.mask;
  st.haveMask = true;
  // Frame masks.
  bool partial = false;
  for (int i = 0; i < kFapCount; ++i) partial |= seg.mask[i] && seg.presence[i] != seg.allFrames();
  w.writeBit(partial);
  for (int i = 0; partial && i < kFapCount; ++i) {
    if (!seg.mask[i]) continue;
    const bool full = seg.presence[i] == seg.allFrames();
    w.writeBit(full);
    for (int n = 0; !full && n < seg.length; ++n) w.writeBit((seg.presence[i] >> n) & 1);
  }
  // FAP 1 and 2.
  for (const Viseme& v : seg.visemes) {
    w.writeBit(v == st.viseme);
    if (v != st.viseme) writeVisemeFields(w, v);
    st.viseme = v;
  }
  for (const Expression& e : seg.expressions) {
    w.writeBit(e == st.expression);
    if (e != st.expression) writeExpressionFields(w, e);
    st.expression = e;
  }
}

// The arithmetic-coded part: the levels of the low-level FAPs, if the segment has any.
void writeCodedPart(BitWriter& w, const Segment& seg, CodingState& st) {
  if ((seg.mask >> 2).none()) return;
  ArithmeticEncoder enc(w);
  Models& m = st.models;
  for (int i = 2; i < kFapCount; ++i) {
    if (!seg.mask[i]) continue;
    const auto& levels = seg.levels[i];
    encodeLevel(enc, m, m.dcSize, 0, levels[0] - st.dc[i]);
    st.dc[i] = levels[0];
    for (int k = 1; k < kN;) {
      int next = k;
      while (next < kN && levels[next] == 0) ++next;
      if (next == kN) {
        enc.encode(kEndOfSegment, m.acRun);
        break;
      }
      enc.encode(next - k, m.acRun);
      encodeLevel(enc, m, m.acSize, 1, levels[next]);
      k = next + 1;
    }
  }
  enc.flush();
}

// ---- Decoder ------------------------------------------------------------------------------------

class Decoder {
 public:
  explicit Decoder(std::span<const std::uint8_t> bytes) : bytes_(bytes), in_(body(bytes)) {}

  FapStream decode() {
    FapStream stream;
    readHeader(stream);
    CodingState st;
    for (std::size_t first = 0; first < frameCount_; first += kN) {
      segment_ = first / kN;
      Segment seg;
      seg.length = static_cast<int>(std::min<std::size_t>(kN, frameCount_ - first));
      try {
        readSegment(seg, st);
      } catch (const Error& e) {
        std::string field = "segment " + std::to_string(segment_);
        if (fap_ > 0) field += " FAP " + std::to_string(fap_);
        throw Error({}, 0, field + " " + e.field(), e.reason());
      }
      appendFrames(seg, fapQuant_, dcDivisor_, stream.frames);
    }
    const std::uint64_t end = (in_.position() + 7) / 8 * 8;
    if (in_.readBits(static_cast<int>(end - in_.position()), "padding") != 0)
      in_.failAt(end - 1, "padding", "the bits up to the byte boundary must be 0");
    if (in_.bitsLeft() > 0) in_.fail("end of stream", "trailing bytes after the last segment");
    const std::uint32_t crc = static_cast<std::uint32_t>(bytes_[end / 8]) << 24 |
                              static_cast<std::uint32_t>(bytes_[end / 8 + 1]) << 16 |
                              static_cast<std::uint32_t>(bytes_[end / 8 + 2]) << 8 |
                              bytes_[end / 8 + 3];
    if (crc != crc32(bytes_.first(end / 8)))
      in_.fail("CRC-32", "checksum mismatch: the stream is corrupted");
    return stream;
  }

 private:
  // All but the CRC-32 (or everything, if the data is too short to have one: the header
  // reader then reports where it ends).
  static std::span<const std::uint8_t> body(std::span<const std::uint8_t> bytes) {
    return bytes.size() >= kHeaderBytes + kCrcBytes ? bytes.first(bytes.size() - kCrcBytes) : bytes;
  }

  void readHeader(FapStream& stream) {
    for (const std::uint8_t b : kMagic) {
      if (in_.readBits(8, "magic") != b) in_.failAt(0, "magic", "not a DCT FAP stream (\"M4FD\")");
    }
    if (const auto v = in_.readBits(8, "version"); v != kVersion)
      in_.failAt(32, "version", "version " + std::to_string(v) + " is not supported (1 is)");
    fapQuant_ = static_cast<int>(in_.readBits(8, "fap_quant"));
    if (fapQuant_ < 1 || fapQuant_ > kMaxFapQuant)
      in_.failAt(40, "fap_quant", std::to_string(fapQuant_) + " is not in 1..31");
    dcDivisor_ = static_cast<int>(in_.readBits(8, "dc_divisor"));
    if (dcDivisor_ < 1 || dcDivisor_ > kMaxDcDivisor)
      in_.failAt(48, "dc_divisor", std::to_string(dcDivisor_) + " is not in 1..15");
    const std::uint64_t high = in_.readBits(32, "frame_rate");
    stream.frameRate = std::bit_cast<double>(high << 32 | in_.readBits(32, "frame_rate"));
    if (!std::isfinite(stream.frameRate) || stream.frameRate <= 0)
      in_.failAt(56, "frame_rate", "not a finite number > 0");
    frameCount_ = in_.readBits(32, "frame_count");
    const std::size_t nameLength = in_.readBits(16, "name_length");
    if (bytes_.size() < kHeaderBytes + nameLength + kCrcBytes)
      in_.fail("name", "the data ends inside the name or before the CRC-32");
    stream.name.assign(reinterpret_cast<const char*>(bytes_.data()) + kHeaderBytes, nameLength);
    in_.seek(8 * (kHeaderBytes + nameLength));
    // Every segment takes at least kMinSegmentBits: a larger count cannot be true, and
    // refusing it here bounds the memory the frames take by the size of the input.
    if ((frameCount_ + kN - 1) / kN > in_.bitsLeft() / kMinSegmentBits)
      in_.failAt(120, "frame_count",
                 std::to_string(frameCount_) + " frames cannot fit in the " +
                     std::to_string(in_.bitsLeft()) + " bits that follow the header");
  }

  std::int64_t readCount(std::string_view element) {
    const int size = static_cast<int>(in_.readBits(kCountBits, element));
    if (size == 0) return 0;
    return (std::int64_t{1} << (size - 1)) | in_.readBits(size - 1, element);
  }

  std::int64_t decodeLevel(ArithmeticDecoder& dec, Models& models, AdaptiveModel& sizes,
                           int sizeOffset) {
    const int size = dec.decode(sizes) + sizeOffset;
    if (size == 0) return 0;
    const bool negative = dec.decode(models.sign) != 0;
    std::int64_t magnitude = 1;
    for (int b = size - 2; b >= 0; --b) magnitude = 2 * magnitude + dec.decode(models.mantissa);
    return negative ? -magnitude : magnitude;
  }

  void readSegment(Segment& seg, CodingState& st) {
    fap_ = 0;
    seg.intra = in_.readBit("is_intra");
    if (segment_ == 0 && !seg.intra) in_.fail("is_intra", "the first segment must be intra");
    if (seg.intra) st.startIntra();
    readNumbers(seg, st);
    readMask(seg, st);
    readPresence(seg);
    readHighLevel(seg, st);
    if ((seg.mask >> 2).none()) return;
    ArithmeticDecoder dec(in_);
    for (fap_ = 3; fap_ <= kFapCount; ++fap_) {
      if (seg.mask[fap_ - 1]) readLevels(dec, seg, st);
    }
    fap_ = 0;
    dec.finish("arithmetic-coded part");
  }

  void readNumbers(Segment& seg, CodingState& st) {
    int n = 0;
    auto next = [&](std::int64_t number, std::string_view element) {
      if (number > std::numeric_limits<int>::max())
        in_.fail(element, "frame number beyond 2^31 - 1");
      seg.numbers[n++] = static_cast<int>(number);
      st.lastNumber = number;
    };
    if (seg.intra) next(readCount("first frame number"), "first frame number");
    const bool skips = in_.readBit("skips");
    while (n < seg.length)
      next(st.lastNumber + 1 + (skips ? readCount("frame skip") : 0), "frame skip");
  }

  void readMask(Segment& seg, CodingState& st) {
    if (!seg.intra && in_.readBit("same_mask")) {
      if (!st.haveMask) in_.fail("same_mask", "no mask to repeat");
      seg.mask = st.mask;
    } else {
      for (const FapGroupInfo& g : fapGroupTable()) {
        const auto type = in_.readBits(2, "fap_mask_type");
        if (type == 2) in_.fail("fap_mask_type", "type 2 is reserved");
        for (int fap = g.firstFap; fap <= g.lastFap; ++fap)
          seg.mask[fap - 1] = type == 3 || (type == 1 && in_.readBit("fap_mask"));
      }
    }
    st.mask = seg.mask;
    st.haveMask = true;
  }

  void readPresence(Segment& seg) {
    const bool partial = in_.readBit("partial");
    for (int i = 0; i < kFapCount; ++i) {
      if (!seg.mask[i]) continue;
      seg.presence[i] = seg.allFrames();
      if (!partial || in_.readBit("full")) continue;
      seg.presence[i] = 0;
      for (int n = 0; n < seg.length; ++n) {
        if (in_.readBit("frame_mask")) seg.presence[i] |= static_cast<std::uint16_t>(1u << n);
      }
      if (seg.presence[i] == 0)
        in_.fail("frame_mask", "FAP " + std::to_string(i + 1) +
                                   " is in the segment mask but in none of its frames");
    }
  }

  void readHighLevel(Segment& seg, CodingState& st) {
    for (int n = 0; n < seg.length; ++n) {
      if (!seg.mask[0] || !((seg.presence[0] >> n) & 1)) continue;
      if (!in_.readBit("viseme repeat")) {
        Viseme& v = st.viseme;
        v.select1 = static_cast<int>(in_.readBits(4, "viseme_select1"));
        v.select2 = static_cast<int>(in_.readBits(4, "viseme_select2"));
        v.blend = static_cast<int>(in_.readBits(6, "viseme_blend"));
        v.def = in_.readBit("viseme_def");
        if (v.select1 > 14 || v.select2 > 14)
          in_.fail("viseme_select", "viseme 15 does not exist (0..14)");
      }
      seg.visemes.push_back(st.viseme);
    }
    for (int n = 0; n < seg.length; ++n) {
      if (!seg.mask[1] || !((seg.presence[1] >> n) & 1)) continue;
      if (!in_.readBit("expression repeat")) {
        Expression& e = st.expression;
        e.select1 = static_cast<int>(in_.readBits(3, "expression_select1"));
        e.intensity1 = static_cast<int>(in_.readBits(6, "expression_intensity1"));
        e.select2 = static_cast<int>(in_.readBits(3, "expression_select2"));
        e.intensity2 = static_cast<int>(in_.readBits(6, "expression_intensity2"));
        e.initFace = in_.readBit("init_face");
        e.def = in_.readBit("expression_def");
        if (e.select1 > 6 || e.select2 > 6)
          in_.fail("expression_select", "expression 7 does not exist (0..6)");
      }
      seg.expressions.push_back(st.expression);
    }
  }

  // The reader is ahead of the arithmetic decoder, which reads 0 bits past the end of the
  // data: an error here gives the reader's position and says when the data had ended.
  [[noreturn]] void levelError(std::string_view element, const std::string& message) const {
    in_.fail(element, message + (in_.position() > in_.size()
                                     ? " (the data ended before this point: truncated?)"
                                     : ""));
  }

  void readLevels(ArithmeticDecoder& dec, Segment& seg, CodingState& st) {
    const int i = fap_ - 1;
    const std::int64_t acStep = acStepOf(fap_, fapQuant_);
    Models& m = st.models;
    auto& levels = seg.levels[i];
    levels[0] = st.dc[i] + decodeLevel(dec, m, m.dcSize, 0);
    if (std::abs(levels[0]) * acStep > kCoefficientLimit * dcDivisor_)
      levelError("DC", "coefficient beyond 2^24");
    st.dc[i] = levels[0];
    for (int k = 1; k < kN;) {
      const int run = dec.decode(m.acRun);
      if (run == kEndOfSegment) break;
      if (k + run >= kN)
        levelError("AC run", "a run of " + std::to_string(run) + " zeros after coefficient " +
                                 std::to_string(k - 1) + " goes past coefficient 15");
      k += run;
      levels[k] = decodeLevel(dec, m, m.acSize, 1);
      if (std::abs(levels[k]) * acStep > kCoefficientLimit)
        levelError("AC level", "coefficient beyond 2^24");
      ++k;
    }
  }

  std::span<const std::uint8_t> bytes_;
  BitReader in_;
  int fapQuant_ = 1;
  int dcDivisor_ = 1;
  std::size_t frameCount_ = 0;
  std::size_t segment_ = 0;
  int fap_ = 0;  // the FAP being read, 0 outside the levels
};

}  // namespace

DctEncoded encodeDct(const FapStream& stream, const DctOptions& options) {
  checkInput(stream, options);
  DctEncoded out;
  out.reconstruction.name = stream.name;
  out.reconstruction.frameRate = stream.frameRate;
  out.reconstruction.frames.reserve(stream.frames.size());
  BitWriter w;
  for (const std::uint8_t b : kMagic) w.writeBits(b, 8);
  w.writeBits(kVersion, 8);
  w.writeBits(static_cast<std::uint32_t>(options.fapQuant), 8);
  w.writeBits(static_cast<std::uint32_t>(options.dcDivisor), 8);
  const auto rate = std::bit_cast<std::uint64_t>(stream.frameRate);
  w.writeBits(static_cast<std::uint32_t>(rate >> 32), 32);
  w.writeBits(static_cast<std::uint32_t>(rate), 32);
  w.writeBits(static_cast<std::uint32_t>(stream.frames.size()), 32);
  w.writeBits(static_cast<std::uint32_t>(stream.name.size()), 16);
  for (const char c : stream.name) w.writeBits(static_cast<std::uint8_t>(c), 8);
  CodingState st;
  for (std::size_t first = 0, index = 0; first < stream.frames.size(); first += kN, ++index) {
    const bool intra =
        index == 0 || (options.intraInterval > 0 && index % options.intraInterval == 0);
    const Segment seg = planSegment(stream, first, intra, options);
    writePlainPart(w, seg, st);
    const std::uint64_t coded = w.bitCount();
    writeCodedPart(w, seg, st);
    out.codedBits += static_cast<std::int64_t>(w.bitCount() - coded);
    appendFrames(seg, options.fapQuant, options.dcDivisor, out.reconstruction.frames);
    for (int i = 2; i < kFapCount; ++i) out.lowLevelSamples += std::popcount(seg.presence[i]);
  }
  std::vector<std::uint8_t> bytes = w.take();  // the last byte padded with 0 bits
  const std::uint32_t crc = crc32(bytes);
  for (int shift = 24; shift >= 0; shift -= 8)
    bytes.push_back(static_cast<std::uint8_t>(crc >> shift));
  out.bytes = std::move(bytes);
  return out;
}

FapStream decodeDct(std::span<const std::uint8_t> bytes) { return Decoder(bytes).decode(); }

}  // namespace mpeg4face
