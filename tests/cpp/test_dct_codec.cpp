// SPDX-License-Identifier: GPL-3.0-or-later
// Tests of the DCT coding mode (dct_codec.hpp, docs/dct-mode.md): the transform against its
// definition, the decoder reproducing the encoder's reconstruction bit for bit, quantisation
// error bounds derived from the steps, rate against distortion (PSNR as Tao et al. eq. 8),
// and bad input of every kind.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include "mpeg4face/dct_codec.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/file_io.hpp"
#include "mpeg4face/spec.hpp"
#include "test_support.hpp"

namespace mpeg4face {
namespace {

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

// ---- Measures ----------------------------------------------------------------------------------

// PSNR of Tao et al. eq. (8): 10 log10((1/N) sum_i R_i^2 / MSE_i^2) over the N active
// low-level FAPs, R_i the range of FAP i in the original. "MSE_i^2" is read as the mean
// square error (MSE_i the RMS error), which makes the ratio dimensionless. FAPs with R_i = 0
// are left out (they have no range to compare with).
double psnr(const FapStream& original, const FapStream& decoded) {
  double sum = 0;
  int n = 0;
  for (int fap = 3; fap <= kFapCount; ++fap) {
    double lo = INFINITY, hi = -INFINITY, squares = 0;
    int samples = 0;
    for (std::size_t t = 0; t < original.frames.size(); ++t) {
      if (!original.frames[t].has(fap)) continue;
      const double x = original.frames[t].value(fap);
      const double e = x - decoded.frames[t].value(fap);
      lo = std::min(lo, x);
      hi = std::max(hi, x);
      squares += e * e;
      ++samples;
    }
    if (samples == 0 || hi == lo) continue;
    sum += (hi - lo) * (hi - lo) / std::max(squares / samples, 1e-12);
    ++n;
  }
  return 10 * std::log10(sum / n);
}

// A second CRC-32 (bit by bit, without a table) to re-seal streams the tests corrupt.
std::uint32_t crc32(const std::uint8_t* data, std::size_t size) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) {
    c ^= data[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}

void reseal(Bytes& b) {
  const std::uint32_t c = crc32(b.data(), b.size() - 4);
  for (int i = 0; i < 4; ++i) b[b.size() - 4 + i] = static_cast<std::uint8_t>(c >> (24 - 8 * i));
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

// The decoder returns exactly the encoder's reconstruction, and everything but the low-level
// values exactly as given; the values are off by no more than the quantisers allow: at most
// dcStep / 2 in DC and acStep / 2 in each AC coefficient, i.e. per sample
// dcStep / 8 + 15 acStep / 2 sqrt(2 / 16), plus 1/2 for the final rounding.
void expectRoundTrip(const FapStream& in, const DctOptions& options = {}) {
  const DctEncoded enc = encodeDct(in, options);
  const FapStream out = decodeDct(enc.bytes);
  ASSERT_EQ(out, enc.reconstruction);
  EXPECT_EQ(out.name, in.name);
  EXPECT_EQ(out.frameRate, in.frameRate);
  ASSERT_EQ(out.frames.size(), in.frames.size());
  for (std::size_t t = 0; t < in.frames.size(); ++t) {
    const FapFrame& a = in.frames[t];
    const FapFrame& b = out.frames[t];
    ASSERT_EQ(b.number, a.number) << "frame " << t;
    ASSERT_EQ(b.mask, a.mask) << "frame " << t;
    ASSERT_EQ(b.viseme, a.viseme) << "frame " << t;
    ASSERT_EQ(b.expression, a.expression) << "frame " << t;
    for (int fap = 3; fap <= kFapCount; ++fap) {
      if (!a.has(fap)) continue;
      const double acStep = fapInfo(fap).quantStep * options.fapQuant;
      const double bound =
          acStep / options.dcDivisor / 8 + 15 * acStep / 2 * std::sqrt(2.0 / 16) + 0.5;
      ASSERT_LE(std::abs(a.value(fap) - b.value(fap)), bound) << "frame " << t << " FAP " << fap;
    }
  }
}

TEST(DctCodec, SmoothStreamRoundTrips) {
  expectRoundTrip(smoothStream(300));
  expectRoundTrip(smoothStream(300), {.fapQuant = 8, .dcDivisor = 3});
}

TEST(DctCodec, KeyFramedStreamRoundTrips) {
  expectRoundTrip(keyFramedStream(300));
  expectRoundTrip(keyFramedStream(300), {.fapQuant = 31, .dcDivisor = 1});
}

TEST(DctCodec, MasksSkipsVisemesAndExpressionsRoundTrip) {
  expectRoundTrip(irregularStream(250));
  expectRoundTrip(irregularStream(250), {.fapQuant = 2, .intraInterval = 3});
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
  FapStream s = streamOf(
      20, [](int i, int t) { return ((i + t) % 2 ? 1 : -1) * static_cast<double>(kDctMaxValue); });
  expectRoundTrip(s);
  expectRoundTrip(s, {.fapQuant = 31, .dcDivisor = 15});
}

TEST(DctCodec, ReconstructionOfAConstantFollowsTheQuantiser) {
  // FAP 48 (QP 170): dcStep = 170 / 4 = 42.5; a constant 1000 has DC 4000, level
  // round(4000 / 42.5 = 94.1) = 94, reconstruction 94 * 42.5 / 4 = 998.75 -> 999.
  FapStream s;
  for (int t = 0; t < 40; ++t) {
    s.frames.push_back(numbered(t));
    s.frames.back().set(48, 1000);
  }
  const DctEncoded enc = encodeDct(s);
  for (const FapFrame& f : decodeDct(enc.bytes).frames) EXPECT_EQ(f.value(48), 999);
}

TEST(DctCodec, DcIsPredictedFromThePreviousSegment) {
  // After the first segment a constant FAP costs a zero DC difference and end_of_segment:
  // each further segment adds no more than its few flag bits and one FAP's two symbols.
  auto constant = [](int frames) {
    FapStream s;
    for (int t = 0; t < frames; ++t) {
      s.frames.push_back(numbered(t));
      s.frames.back().set(3, 777);
    }
    return encodeDct(s).bytes.size();
  };
  EXPECT_LE(constant(16 * 11) - constant(16), 10u * 2);
}

TEST(DctCodec, FinerStepsGiveHigherPsnrForMoreBits) {
  for (const auto& [name, stream] :
       {std::pair{"smooth", smoothStream(600)}, std::pair{"key-framed", keyFramedStream(600)}}) {
    std::printf("%s stream, %zu frames at 30 Hz, %zu FAPs\n", name, stream.frames.size(),
                kFapsAndAmplitudes.size());
    std::printf("  fapQuant  bits/sample  bit/s   PSNR dB\n");
    double lastPsnr = INFINITY;
    std::int64_t lastBits = std::numeric_limits<std::int64_t>::max();
    for (int q : {1, 2, 4, 8, 15, 31}) {
      const DctEncoded enc = encodeDct(stream, {.fapQuant = q});
      const double p = psnr(stream, decodeDct(enc.bytes));
      const double perSample =
          static_cast<double>(enc.bits()) / static_cast<double>(enc.lowLevelSamples);
      std::printf("  %8d  %11.3f  %6.0f  %7.2f\n", q, perSample,
                  static_cast<double>(enc.bits()) * stream.frameRate /
                      static_cast<double>(stream.frames.size()),
                  p);
      EXPECT_LT(p, lastPsnr) << name << " fapQuant " << q;
      EXPECT_LT(enc.bits(), lastBits) << name << " fapQuant " << q;
      lastPsnr = p;
      lastBits = enc.bits();
    }
  }
}

// ---- Bad input ---------------------------------------------------------------------------------

TEST(DctCodec, EncoderRefusesWhatTheFormatCannotCarry) {
  FapStream s = smoothStream(20);
  s.frames[5].number = s.frames[4].number;
  EXPECT_TRUE(contains(errorOf([&] { encodeDct(s); }), "frame 5"));
  s = smoothStream(20);
  s.frames[0].number = -1;
  EXPECT_TRUE(contains(errorOf([&] { encodeDct(s); }), "frame 0"));
  s = smoothStream(20);
  s.frames[7].set(12, kDctMaxValue + 1);
  EXPECT_TRUE(contains(errorOf([&] { encodeDct(s); }), "frame 7 FAP 12"));
  s = smoothStream(20);
  s.frames[3].mask.set(0);
  s.frames[3].viseme.select2 = 15;
  EXPECT_TRUE(contains(errorOf([&] { encodeDct(s); }), "frame 3 FAP 1"));
  s = smoothStream(20);
  s.frames[3].mask.set(1);
  s.frames[3].expression.intensity1 = 64;
  EXPECT_TRUE(contains(errorOf([&] { encodeDct(s); }), "frame 3 FAP 2"));
  s = smoothStream(20);
  s.frameRate = NAN;
  EXPECT_TRUE(contains(errorOf([&] { encodeDct(s); }), "frameRate"));
  EXPECT_TRUE(contains(errorOf([&] { encodeDct(smoothStream(2), {.fapQuant = 0}); }), "fapQuant"));
  EXPECT_TRUE(
      contains(errorOf([&] { encodeDct(smoothStream(2), {.dcDivisor = 16}); }), "dcDivisor"));
}

TEST(DctCodec, EveryTruncationIsAnError) {
  const Bytes full = encodeDct(irregularStream(40)).bytes;
  for (std::size_t size = 0; size < full.size(); ++size) {
    const Error e = errorOf([&] { decodeDct(std::span(full.data(), size)); });
    EXPECT_TRUE(contains(e, "byte ")) << e.what();
  }
}

TEST(DctCodec, EveryBitFlipIsAnError) {
  const Bytes full = encodeDct(irregularStream(40)).bytes;
  for (std::size_t bit = 0; bit < 8 * full.size(); ++bit) {
    Bytes b = full;
    b[bit / 8] ^= static_cast<std::uint8_t>(0x80 >> (bit % 8));
    const Error e = errorOf([&] { decodeDct(b); });
    EXPECT_TRUE(contains(e, "byte ")) << e.what();
  }
}

TEST(DctCodec, CorruptSegmentsBehindAValidChecksumAreErrorsOrStreams) {
  // With the CRC recomputed the decoder sees what a buggy encoder could write: each flip
  // gives an Error naming a segment element, or a well-formed stream; never a crash.
  const DctEncoded enc = encodeDct(irregularStream(40), {.intraInterval = 2});
  const std::size_t header = 21 + std::string("synthetic").size();
  int errors = 0, named = 0;
  for (std::size_t bit = 8 * header; bit < 8 * (enc.bytes.size() - 4); ++bit) {
    Bytes b = enc.bytes;
    b[bit / 8] ^= static_cast<std::uint8_t>(0x80 >> (bit % 8));
    reseal(b);
    try {
      const FapStream s = decodeDct(b);
      EXPECT_EQ(s.frames.size(), enc.reconstruction.frames.size());
    } catch (const Error& e) {
      ++errors;
      named += contains(e, "segment ");
    }
  }
  EXPECT_GT(errors, 0);
  EXPECT_GT(named, 0);
}

Error malformed(const std::string& name) {
  const std::string data = readFile(kData / "malformed" / name);
  return errorOf([&] {
    decodeDct(std::span(reinterpret_cast<const std::uint8_t*>(data.data()), data.size()));
  });
}

TEST(DctCodec, MalformedFiles) {
  for (const auto& [file, element, text] :
       std::vector<std::tuple<std::string, std::string, std::string>>{
           {"dct_empty.m4fd", "magic", "(byte 0,"},
           {"dct_garbage.m4fd", "magic", "(byte 0,"},
           {"dct_bad_version.m4fd", "version", "(byte 4,"},
           {"dct_bad_fap_quant.m4fd", "fap_quant", "(byte 5,"},
           {"dct_nan_frame_rate.m4fd", "frame_rate", "(byte 7,"},
           {"dct_huge_frame_count.m4fd", "frame_count", "(byte 15,"},
           {"dct_name_past_end.m4fd", "name", "the data ends inside the name"},
           {"dct_truncated.m4fd", "segment 2 FAP 32 AC run", "the data ended before this point"},
           {"dct_trailing_bytes.m4fd", "end of stream", "trailing bytes"},
           {"dct_bit_flipped.m4fd", "CRC-32", "checksum mismatch"},
           {"dct_bad_crc.m4fd", "CRC-32", "checksum mismatch"}}) {
    const Error e = malformed(file);
    EXPECT_EQ(e.field(), element) << file << ": " << e.what();
    EXPECT_TRUE(contains(e, text)) << file << ": " << e.what();
  }
}

TEST(DctCodec, TheSampleStreamDecodes) {
  // tests/data/dct/irregular.m4fd is irregularStream(70) as version 1 encoded it; the
  // malformed files are made from it (tests/data/malformed/dct_generate.py).
  const std::string data = readFile(kData / "dct" / "irregular.m4fd");
  const FapStream s =
      decodeDct(std::span(reinterpret_cast<const std::uint8_t*>(data.data()), data.size()));
  EXPECT_EQ(s, encodeDct(irregularStream(70)).reconstruction);
}

}  // namespace
}  // namespace mpeg4face
