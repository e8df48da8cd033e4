// SPDX-License-Identifier: GPL-3.0-or-later
// Tests of the DCT coding mode of the FBA bitstream (codec/dct_transform.hpp, FapCodingMode::Dct,
// docs/dct-mode.md): the transform against its definition, the decoder reproducing the
// encoder's reconstruction bit for bit, quantisation error bounds derived from the steps,
// rate against distortion (PSNR of Tao et al. eq. 8) next to the predictive mode, and bad
// input of every kind.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include "codec/bit_io.hpp"
#include "codec/dct_transform.hpp"
#include "codec/fba_dct.hpp"
#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/codec/measure.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/spec.hpp"
#include "fba_strict.hpp"
#include "test_support.hpp"

namespace mpeg4face {
namespace {

using test::decodeBothWays;
using test::errorOf;
using test::kData;
using Bytes = std::vector<std::uint8_t>;
constexpr int kN = kDctSegmentLength;

// ---- Synthetic streams -------------------------------------------------------------------------

// A deterministic pseudo-random sequence (64-bit LCG), so that streams are the same everywhere.
struct Random {
  std::uint64_t state;
  double uniform() {  // [0, 1)
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) / 9007199254740992.0;
  }
};

// Low-level FAPs of a talking head: jaw, lips, eyelids, brows, head rotation (AU).
const std::vector<std::pair<int, double>> kFapsAndAmplitudes = {
    {3, 400},  {4, 150},  {5, 150},  {12, 120},   {13, 120},   {19, 300},
    {20, 300}, {31, 200}, {32, 200}, {48, 15000}, {49, 20000}, {50, 8000}};

FapStream streamOf(int frames, const std::function<double(int fapIndex, int t)>& value) {
  FapStream s;
  s.name = "synthetic";
  s.frameRate = 30;
  s.frames.resize(static_cast<std::size_t>(frames));
  for (int t = 0; t < frames; ++t) {
    FapFrame& f = s.frames[static_cast<std::size_t>(t)];
    f.number = t;
    for (std::size_t i = 0; i < kFapsAndAmplitudes.size(); ++i)
      f.set(kFapsAndAmplitudes[i].first,
            static_cast<int>(std::lround(value(static_cast<int>(i), t))));
  }
  return s;
}

// Smooth motion at 30 Hz: two sinusoids of 0.2-2 Hz per FAP plus low-pass filtered noise,
// as facial motion is band-limited (Tao et al. V-B: "FAP data have relatively low frequencies").
FapStream smoothStream(int frames) {
  Random random{42};
  struct Track {
    double f1, f2, p1, p2, amplitude, noise = 0;
  };
  std::vector<Track> tracks;
  for (const auto& [fap, amplitude] : kFapsAndAmplitudes)
    tracks.push_back({0.2 + 1.8 * random.uniform(), 0.2 + 1.8 * random.uniform(),
                      6.3 * random.uniform(), 6.3 * random.uniform(), amplitude});
  std::vector<std::vector<double>> v(tracks.size(), std::vector<double>(frames));
  for (int t = 0; t < frames; ++t) {
    for (std::size_t i = 0; i < tracks.size(); ++i) {
      Track& k = tracks[i];
      k.noise = 0.85 * k.noise + 0.15 * (random.uniform() - 0.5);
      const double s = t / 30.0;
      v[i][t] = k.amplitude * (0.6 * std::sin(2 * std::numbers::pi * k.f1 * s + k.p1) +
                               0.3 * std::sin(2 * std::numbers::pi * k.f2 * s + k.p2) + k.noise);
    }
  }
  return streamOf(frames, [&](int i, int t) { return v[i][t]; });
}

// Key-framed animation: per FAP, keys every 6-30 frames; FAPs of even index hold each key
// (piecewise constant), the others move linearly between keys (piecewise linear).
FapStream keyFramedStream(int frames) {
  Random random{7};
  std::vector<std::vector<double>> v(kFapsAndAmplitudes.size(), std::vector<double>(frames));
  for (std::size_t i = 0; i < kFapsAndAmplitudes.size(); ++i) {
    const double amplitude = kFapsAndAmplitudes[i].second;
    int key = 0;
    double keyValue = 0;
    while (key < frames) {
      const int next = key + 6 + static_cast<int>(24 * random.uniform());
      const double nextValue = amplitude * (2 * random.uniform() - 1);
      for (int t = key; t < std::min(next, frames); ++t)
        v[i][t] =
            i % 2 == 0 ? keyValue : keyValue + (nextValue - keyValue) * (t - key) / (next - key);
      key = next;
      keyValue = nextValue;
    }
  }
  return streamOf(frames, [&](int i, int t) { return v[i][t]; });
}

FapFrame numbered(int number) {
  FapFrame f;
  f.number = number;
  return f;
}

// FAPs that come and go within segments, skipped frame numbers, visemes and expressions.
FapStream irregularStream(int frames) {
  FapStream s = smoothStream(frames);
  Random random{99};
  int number = 3;
  for (int t = 0; t < frames; ++t) {
    FapFrame& f = s.frames[static_cast<std::size_t>(t)];
    f.number = number;
    number += 1 + (random.uniform() < 0.1 ? 1 + static_cast<int>(40 * random.uniform()) : 0);
    if (random.uniform() < 0.3) f.mask.reset(2);  // FAP 3 missing in some frames
    if (t % 50 >= 30) f.mask.reset(18);           // FAP 19 absent for whole stretches
    if (t % 7 != 0) f.mask.reset(47);             // FAP 48 in one frame in seven
    if (t % 3 != 2) {
      f.mask.set(0);
      f.viseme = {(t / 9) % 15, (t / 13) % 15, (t * 5) % 64, t % 40 == 0};
    }
    if (t % 4 == 0) {
      f.mask.set(1);
      f.expression = {(t / 40) % 7, (t / 8) % 64, 6, 63 - (t / 8) % 64, t == 0, t % 80 == 0};
    }
  }
  return s;
}

// ---- Helpers -----------------------------------------------------------------------------------

FbaEncodeOptions dct(int fapQuant = 1, int dcDivisor = 4, int intraPeriod = 0) {
  return {.mode = FapCodingMode::Dct,
          .fapQuant = fapQuant,
          .intraPeriod = intraPeriod,
          .dcDivisor = dcDivisor};
}

// The decoded frames that match the input's: the bitstream puts an empty frame 0 in front of
// a stream that starts later.
std::span<const FapFrame> matching(const FapStream& in, const FapStream& out) {
  return std::span(out.frames).subspan(out.frames.size() - in.frames.size());
}

// The decoded stream as compareFapStreams wants it: the input's frames and exact rate.
FapStream comparable(const FapStream& in, const FapStream& out) {
  FapStream s = in;
  const auto frames = matching(in, out);
  s.frames.assign(frames.begin(), frames.end());
  return s;
}

std::int64_t lowLevelSamples(const FapStream& s) {
  std::int64_t n = 0;
  for (const FapFrame& f : s.frames) n += static_cast<std::int64_t>((f.mask >> 2).count());
  return n;
}

bool contains(const Error& e, const std::string& text) {
  return std::string(e.what()).find(text) != std::string::npos;
}

// ---- Transform ---------------------------------------------------------------------------------

TEST(DctTransform, BasisIsTheRoundedOrthonormalCosine) {
  for (int k = 0; k < kN; ++k) {
    const long double c = k == 0 ? std::sqrt(1.0L / kN) : std::sqrt(2.0L / kN);
    for (int n = 0; n < kN; ++n) {
      const long double exact =
          268435456.0L * c * std::cos(std::numbers::pi_v<long double> * (2 * n + 1) * k / 32);
      EXPECT_EQ(dctBasis()[k][n], std::llround(exact)) << "k " << k << " n " << n;
    }
  }
}

TEST(DctTransform, ForwardIsOrthonormal) {
  Random random{1};
  std::array<double, kN> x{};
  for (double& v : x) v = 1000 * random.uniform() - 500;
  const auto c = forwardDct16(x);
  // Parseval, and the transpose undoes it.
  double ex = 0, ec = 0;
  for (int i = 0; i < kN; ++i) ex += x[i] * x[i], ec += c[i] * c[i];
  EXPECT_NEAR(ec, ex, 1e-9 * ex);
  for (int n = 0; n < kN; ++n) {
    double back = c[0] / 4;
    for (int k = 1; k < kN; ++k)
      back += c[k] * std::sqrt(2.0 / kN) * std::cos(std::numbers::pi * (2 * n + 1) * k / 32);
    EXPECT_NEAR(back, x[n], 1e-9);
  }
  // A constant is all DC: X[0] = 16 v / sqrt(16) = 4 v.
  std::array<double, kN> flat{};
  flat.fill(25);
  const auto cf = forwardDct16(flat);
  EXPECT_NEAR(cf[0], 100, 1e-12);
  for (int k = 1; k < kN; ++k) EXPECT_NEAR(cf[k], 0, 1e-12);
}

TEST(DctTransform, IntegerReconstructionIsTheInverseRounded) {
  Random random{2};
  for (int trial = 0; trial < 200; ++trial) {
    std::array<std::int64_t, kN> levels{};
    for (auto& l : levels)
      l = random.uniform() < 0.5 ? 0 : static_cast<std::int64_t>(200 * random.uniform()) - 100;
    const int acStep = 1 + static_cast<int>(20 * random.uniform());
    const int divisor = 1 + static_cast<int>(15 * random.uniform());
    const auto x = reconstructDctSegment(levels, acStep, divisor);
    for (int n = 0; n < kN; ++n) {
      long double v = levels[0] * static_cast<long double>(acStep) / divisor / 4;
      for (int k = 1; k < kN; ++k)
        v += levels[k] * static_cast<long double>(acStep) * std::sqrt(2.0L / kN) *
             std::cos(std::numbers::pi_v<long double> * (2 * n + 1) * k / 32);
      if (std::abs(std::abs(v - std::trunc(v)) - 0.5L) < 1e-6L) continue;  // a tie: see below
      EXPECT_EQ(x[n], std::lround(v)) << "trial " << trial << " n " << n;
    }
  }
}

TEST(DctTransform, HalvesRoundAwayFromZero) {
  // DC only: x = level * acStep / (4 dcDivisor).
  std::array<std::int64_t, kN> levels{};
  levels[0] = 2;  // 2 / 16 = 0.125
  EXPECT_EQ(reconstructDctSegment(levels, 1, 4)[0], 0);
  levels[0] = 8;  // 0.5
  EXPECT_EQ(reconstructDctSegment(levels, 1, 4)[5], 1);
  levels[0] = -8;
  EXPECT_EQ(reconstructDctSegment(levels, 1, 4)[5], -1);
  levels[0] = 24;  // 1.5
  EXPECT_EQ(reconstructDctSegment(levels, 1, 4)[15], 2);
}

// ---- Round trips -------------------------------------------------------------------------------

// The AC step the encoder gives `fap` in `in`: from its range over the stream
// (docs/dct-mode.md, "Steps").
double acStepOf(const FapStream& in, int fap, int fapQuant) {
  int lo = std::numeric_limits<int>::max(), hi = std::numeric_limits<int>::min();
  for (const FapFrame& f : in.frames) {
    if (f.has(fap)) lo = std::min(lo, f.value(fap)), hi = std::max(hi, f.value(fap));
  }
  const std::int64_t range = hi >= lo ? std::int64_t{hi} - lo : 0;
  return static_cast<double>(
             fba::dctStep256(fba::dctStepIndex(range, fapInfo(fap).quantStep, fapQuant))) /
         256;
}

// The decoder returns exactly the encoder's reconstruction, and the input's frame numbers,
// masks, visemes and expressions; the values are off by no more than the quantisers allow:
// at most dcStep / 2 in DC, i.e. dcStep / 8 per sample, plus 1/2 for the final rounding, and
// what RDOQ leaves of the AC coefficients: the nearest levels' error is at most 15 acStep / 2
// sqrt(2 / 16) per sample (2.65 acStep); RDOQ may lower levels or drop a block where that saves
// bits (docs/dct-mode.md), which these streams keep within 5 acStep.
void expectRoundTrip(const FapStream& in, const FbaEncodeOptions& options = dct()) {
  const FbaEncoding enc = encodeFba(in, options);
  const FapStream out = decodeBothWays(enc.bytes);
  ASSERT_EQ(out, enc.reconstruction);
  if (!in.frames.empty()) {
    EXPECT_EQ(out.frameRate, in.frameRate);
  }
  ASSERT_GE(out.frames.size(), in.frames.size());
  EXPECT_EQ(enc.stats.frameBits.size(), out.frames.size());
  const auto frames = matching(in, out);
  for (std::size_t t = 0; t < in.frames.size(); ++t) {
    const FapFrame& a = in.frames[t];
    const FapFrame& b = frames[t];
    ASSERT_EQ(b.number, a.number) << "frame " << t;
    ASSERT_EQ(b.mask, a.mask) << "frame " << t;
    ASSERT_EQ(b.viseme, a.viseme) << "frame " << t;
    ASSERT_EQ(b.expression, a.expression) << "frame " << t;
    for (int fap = 3; fap <= kFapCount; ++fap) {
      if (!a.has(fap)) continue;
      const double acStep = acStepOf(in, fap, options.fapQuant);
      const double bound = acStep / options.dcDivisor / 8 + 5 * acStep + 0.5;
      ASSERT_LE(std::abs(a.value(fap) - b.value(fap)), bound) << "frame " << t << " FAP " << fap;
    }
  }
}

TEST(DctCodec, SmoothStreamRoundTrips) {
  expectRoundTrip(smoothStream(300));
  expectRoundTrip(smoothStream(300), dct(8, 3));
}

TEST(DctCodec, KeyFramedStreamRoundTrips) {
  expectRoundTrip(keyFramedStream(300));
  expectRoundTrip(keyFramedStream(300), dct(31, 1));
}

TEST(DctCodec, MasksSkipsVisemesAndExpressionsRoundTrip) {
  expectRoundTrip(irregularStream(250));
  expectRoundTrip(irregularStream(250), dct(2, 4, 40));
}

TEST(DctCodec, IntraPeriodStartsIntraSegments) {
  // Intra segments begin at frames 0, 48 (>= 40 frames after 0), 96, 144: 4 of 10 segments.
  const FbaEncoding enc = encodeFba(smoothStream(160), dct(1, 4, 40));
  EXPECT_EQ(enc.stats.intraFrames, 4);
  EXPECT_EQ(encodeFba(smoothStream(160), dct()).stats.intraFrames, 1);
  EXPECT_EQ(decodeBothWays(enc.bytes), enc.reconstruction);
}

TEST(DctCodec, EveryLengthOfTheLastSegment) {
  for (int frames : {0, 1, 2, 15, 16, 17, 31, 32, 33}) {
    SCOPED_TRACE(frames);
    expectRoundTrip(smoothStream(frames));
    expectRoundTrip(irregularStream(frames));
  }
}

TEST(DctCodec, FramesWithoutAnyFap) {
  FapStream s = irregularStream(40);
  for (std::size_t t = 10; t < 30; ++t) s.frames[t] = numbered(s.frames[t].number);
  expectRoundTrip(s);
}

TEST(DctCodec, ExtremeValues) {
  const FapStream s = streamOf(
      20, [](int i, int t) { return ((i + t) % 2 ? 1 : -1) * static_cast<double>(kDctMaxValue); });
  expectRoundTrip(s);
  expectRoundTrip(s, dct(31, 15));
}

// The planes of an FBA object after the first plane's start code (the object start code, a
// stuffing byte and the plane start code: 72 bits), up to the next_start_code() stuffing (a 0,
// then 1s to the byte boundary) of its end code.
std::vector<bool> planeBits(const Bytes& object) {
  std::size_t end = 8 * (object.size() - 4);
  do --end;
  while ((object[end / 8] >> (7 - end % 8)) & 1);
  std::vector<bool> bits;
  for (std::size_t i = 72; i < end; ++i) bits.push_back((object[i / 8] >> (7 - i % 8)) & 1);
  return bits;
}

TEST(DctCodec, StreamsMayMixModes) {
  // coding_type belongs to each intra plane: predictive planes for frames 0..19, then DCT
  // planes, then predictive again; each mode's decoder keeps its own state.
  const FapStream first = smoothStream(20), second = keyFramedStream(40);
  const FbaEncoding a = encodeFba(first, {.fapQuant = 2});
  const FbaEncoding b = encodeFba(second, dct(2));
  BitWriter w;
  w.writeBits(kFbaObjectStartCode, 32);
  for (const auto& part : {a, b, a}) {
    w.writeStartCode(kFbaObjectPlaneStartCode);  // byte-aligns, as the part's start code was
    for (const bool bit : planeBits(part.bytes)) w.writeBit(bit);
  }
  w.writeStartCode(kFbaObjectEndCode);
  const FapStream out = decodeFba(w.bytes());
  std::vector<FapFrame> expected;
  for (const auto& part : {a, b, a}) {
    const int offset = expected.empty() ? 0 : expected.back().number + 1;
    for (FapFrame f : part.reconstruction.frames) {
      f.number += offset;
      expected.push_back(f);
    }
  }
  EXPECT_EQ(out.frames, expected);
}

TEST(DctCodec, ReconstructionOfAConstantFollowsTheQuantiser) {
  // FAP 48 (QP 170) does not move, so its step is QP * fap_quant = 170, sent as the step index
  // round(8 log2(170 * 4)) = 75: 83 * 2^9 / 256 = 166. dcStep = 166 / 4 = 41.5; a constant 1000
  // has DC 4000, level round(4000 / 41.5 = 96.4) = 96, reconstruction 96 * 41.5 / 4 = 996.
  FapStream s;
  for (int t = 0; t < 40; ++t) {
    s.frames.push_back(numbered(t));
    s.frames.back().set(48, 1000);
  }
  for (const FapFrame& f : decodeBothWays(encodeFba(s, dct()).bytes).frames) {
    EXPECT_EQ(f.value(48), 996);
  }
}

TEST(DctCodec, DcIsPredictedFromThePreviousSegment) {
  // A constant FAP costs its DC level once: each later segment is a plane header (4 bits),
  // segment_length (4 bits), the adapted flags skips, same_mask and partial, a zero DC
  // difference and coded_block 0 (well under a bit each once adapted) and the coder's flush
  // (2-3 bits): about 14 bits, and surely under 20.
  auto bits = [](int frames) {
    FapStream s;
    for (int t = 0; t < frames; ++t) {
      s.frames.push_back(numbered(t));
      s.frames.back().set(3, 777);
    }
    return encodeFba(s, dct()).stats.bits;
  };
  EXPECT_LT(bits(16 * 21) - bits(16), 20u * 20);
}

TEST(DctCodec, StepsFollowEachFapsRange) {
  // The smooth stream's FAPs span 150 to 20000 FAPU; each gets a step in proportion to its
  // range, so each comes back with about the same PSNR of its own (the robust PSNR's optimum).
  const FapStream s = smoothStream(300);
  for (const int q : {4, 16, 28}) {
    const FapComparison c =
        compareFapStreams(s, comparable(s, encodeFba(s, dct(q)).reconstruction));
    double lo = INFINITY, hi = -INFINITY;
    for (const FapError& e : c.faps) {
      ASSERT_TRUE(e.psnr.has_value());
      lo = std::min(lo, *e.psnr), hi = std::max(hi, *e.psnr);
    }
    EXPECT_LT(hi - lo, 6.0) << "fap_quant " << q << ": " << lo << ".." << hi << " dB";
  }
}

TEST(DctCodec, FinerStepsGiveHigherPsnrForMoreBits) {
  for (const auto& [name, stream] :
       {std::pair{"smooth", smoothStream(600)}, std::pair{"key-framed", keyFramedStream(600)}}) {
    std::printf("%s stream: %zu frames at 30 Hz, %zu FAPs, %lld samples\n", name,
                stream.frames.size(), kFapsAndAmplitudes.size(),
                static_cast<long long>(lowLevelSamples(stream)));
    std::printf(
        "  fap_quant | DCT: bits/sample  bit/s  PSNR dB | predictive: bits/sample  "
        "bit/s  PSNR dB\n");
    double lastPsnr = INFINITY;
    std::uint64_t lastBits = std::numeric_limits<std::uint64_t>::max();
    for (int q : {1, 2, 4, 8, 15, 31}) {
      double row[2][3];
      for (const FapCodingMode mode : {FapCodingMode::Dct, FapCodingMode::Predictive}) {
        const FbaEncoding enc = encodeFba(stream, {.mode = mode, .fapQuant = q});
        const FapStream decoded = decodeBothWays(enc.bytes);
        const double p = *compareFapStreams(stream, comparable(stream, decoded)).psnr;
        const auto bits = static_cast<double>(enc.stats.bits);
        const int m = mode == FapCodingMode::Dct ? 0 : 1;
        row[m][0] = bits / static_cast<double>(lowLevelSamples(stream));
        row[m][1] = bitsPerSecond(bits, stream);
        row[m][2] = p;
        if (mode != FapCodingMode::Dct) continue;
        EXPECT_LT(p, lastPsnr) << name << " fap_quant " << q;
        EXPECT_LT(enc.stats.bits, lastBits) << name << " fap_quant " << q;
        lastPsnr = p;
        lastBits = enc.stats.bits;
      }
      std::printf("  %9d | %16.3f %6.0f %8.2f | %23.3f %6.0f %8.2f\n", q, row[0][0], row[0][1],
                  row[0][2], row[1][0], row[1][1], row[1][2]);
    }
  }
}

// ---- Bad input ---------------------------------------------------------------------------------

TEST(DctCodec, EncoderRefusesWhatTheModeCannotCarry) {
  FapStream s = smoothStream(20);
  s.frames[7].set(12, kDctMaxValue + 1);
  Error e = errorOf([&] { encodeFba(s, dct()); });
  EXPECT_EQ(e.field(), "FAP 12");
  EXPECT_TRUE(contains(e, "frame 7")) << e.what();
  e = errorOf([&] { encodeFba(smoothStream(2), dct(0)); });
  EXPECT_EQ(e.field(), "fapQuant");
  e = errorOf([&] { encodeFba(smoothStream(2), dct(1, 16)); });
  EXPECT_EQ(e.field(), "dcDivisor");
  e = errorOf([&] { encodeFba(smoothStream(2), dct(1, 0)); });
  EXPECT_EQ(e.field(), "dcDivisor");
}

TEST(DctCodec, EveryTruncationIsAnError) {
  const Bytes full = encodeFba(irregularStream(40), dct()).bytes;
  for (std::size_t size = 0; size < full.size(); ++size) {
    const Error e = errorOf([&] { decodeFba(std::span(full.data(), size)); });
    EXPECT_TRUE(contains(e, "(byte ")) << e.what();
  }
}

TEST(DctCodec, BitFlipsGiveErrorsOrStreamsNeverCrashes) {
  // The FBA syntax has no checksum: a flip in coded data may decode to other values. Every
  // flip must end in an Error naming where, or in a well-formed stream.
  const FbaEncoding enc = encodeFba(irregularStream(40), dct(1, 4, 20));
  int errors = 0, inSegments = 0;
  for (std::size_t bit = 0; bit < 8 * enc.bytes.size(); ++bit) {
    Bytes b = enc.bytes;
    b[bit / 8] ^= static_cast<std::uint8_t>(0x80 >> (bit % 8));
    try {
      const FapStream s = decodeFba(b);
      for (std::size_t t = 1; t < s.frames.size(); ++t)
        ASSERT_GT(s.frames[t].number, s.frames[t - 1].number);
    } catch (const Error& e) {
      ++errors;
      EXPECT_TRUE(contains(e, "(byte ")) << e.what();
      inSegments += contains(e, "FAP ") || contains(e, "DCT segment");
    }
  }
  EXPECT_GT(errors, 0);
  EXPECT_GT(inSegments, 0);
}

TEST(DctCodec, DecodeLimits) {
  const FbaEncoding enc = encodeFba(smoothStream(50), dct());
  EXPECT_NO_THROW(decodeFba(enc.bytes, {}, {.maxFrames = 50}));
  const Error e = errorOf([&] { decodeFba(enc.bytes, {}, {.maxFrames = 40}); });
  EXPECT_EQ(e.field(), "segment_length");
  FapStream skips = irregularStream(40);
  const FbaEncoding withSkips = encodeFba(skips, dct());
  const int last = withSkips.reconstruction.frames.back().number;
  EXPECT_NO_THROW(decodeFba(withSkips.bytes, {}, {.maxFrameNumber = last + 1}));
  EXPECT_THROW(decodeFba(withSkips.bytes, {}, {.maxFrameNumber = last - 1}), Error);
}

Error malformed(const std::string& name) {
  const std::string data = readFile(kData / "malformed" / name);
  return errorOf([&] {
    decodeFba(std::span(reinterpret_cast<const std::uint8_t*>(data.data()), data.size()), name);
  });
}

TEST(DctCodec, MalformedFiles) {
  for (const auto& [file, element, text] :
       std::vector<std::tuple<std::string, std::string, std::string>>{
           {"dct_truncated.fba", "DCT segment", "runs past the end of the data"},
           {"dct_zero_dc_divisor.fba", "dc_divisor", "is 0"},
           {"dct_zero_fap_quant.fba", "fap_quant", "not a DCT mode step"},
           {"dct_flipped_bit.fba", "step_index",
            "FAP 3: -61 is outside 0..175 (segment from frame 0)"}}) {
    const Error e = malformed(file);
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.field(), element) << e.what();
    EXPECT_TRUE(contains(e, text)) << e.what();
  }
}

TEST(DctCodec, TheSampleStreamDecodes) {
  // tests/data/dct/irregular.fba is irregularStream(70) as the DCT mode
  // encoded it (dct(): fap_quant 1, dc_divisor 4); the malformed dct_* files are made from it
  // (tests/data/malformed/dct_generate.py).
  const std::string data = readFile(kData / "dct" / "irregular.fba");
  const FapStream s =
      decodeFba(std::span(reinterpret_cast<const std::uint8_t*>(data.data()), data.size()));
  EXPECT_EQ(s, encodeFba(irregularStream(70), dct()).reconstruction);
}

}  // namespace
}  // namespace mpeg4face
