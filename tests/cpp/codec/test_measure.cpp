// SPDX-License-Identifier: GPL-3.0-or-later
// PSNR (Tao et al. eq. 8), the robust PSNR, per-FAP errors and bit rates, against hand
// computations, the paper's own figures and a second, naive implementation.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <vector>

#include "mpeg4face/codec/measure.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::compareFapStreams;
using mpeg4face::FapComparison;
using mpeg4face::FapStream;
using mpeg4face::test::errorOf;

constexpr double kInf = std::numeric_limits<double>::infinity();

// A stream of n frames numbered 0..n-1 sending the given FAP series.
FapStream streamOf(const std::map<int, std::vector<int>>& series) {
  FapStream s;
  const size_t n = series.begin()->second.size();
  s.frames.resize(n);
  for (size_t i = 0; i < n; ++i) {
    s.frames[i].number = static_cast<int>(i);
    for (const auto& [fap, values] : series) s.frames[i].set(fap, values[i]);
  }
  return s;
}

TEST(FapMeasure, PsnrAveragesTheRatiosInsideTheLogarithm) {
  // FAP 3: range 30, errors 0 0 0 3 -> mse 2.25, R^2/mse = 400.
  // FAP 4: range 100, errors 10 each -> mse 100, R^2/mse = 100.
  // Eq. (8): 10 log10((400 + 100) / 2) = 10 log10(250) = 23.979 dB (the mean of the two
  // FAPs' dB values would be 23.01; R^2/mse^2 read literally would give 19.5).
  const FapStream a = streamOf({{3, {0, 10, 20, 30}}, {4, {0, 100, 0, 100}}});
  const FapStream b = streamOf({{3, {0, 10, 20, 33}}, {4, {10, 90, 10, 90}}});
  const FapComparison c = compareFapStreams(a, b);
  EXPECT_EQ(c.frames, 4);
  EXPECT_EQ(c.psnrFaps, 2);
  ASSERT_TRUE(c.psnr);
  EXPECT_NEAR(*c.psnr, 23.9794, 1e-4);
  ASSERT_EQ(c.faps.size(), 2u);
  EXPECT_EQ(c.faps[0].fap, 3);
  EXPECT_EQ(c.faps[0].range, 30);
  EXPECT_EQ(c.faps[0].maxAbs, 3);
  EXPECT_DOUBLE_EQ(c.faps[0].rms, 1.5);
  EXPECT_NEAR(*c.faps[0].psnr, 26.0206, 1e-4);
  EXPECT_EQ(c.faps[1].range, 100);
  EXPECT_EQ(c.faps[1].maxAbs, 10);
  EXPECT_DOUBLE_EQ(c.faps[1].rms, 10.0);
  EXPECT_NEAR(*c.faps[1].psnr, 20.0, 1e-12);
  // Robust: 10 log10(1 / mean(2.25/900, 100/10000)) = 10 log10(2 / 0.0125) = 22.04 dB, closer
  // to the worse FAP 4 (20 dB) than eq. (8) is.
  ASSERT_TRUE(c.robustPsnr);
  EXPECT_NEAR(*c.robustPsnr, 10 * std::log10(160.0), 1e-9);
  EXPECT_EQ(mpeg4face::psnrBy(c, mpeg4face::FapQuality::Robust), c.robustPsnr);
  EXPECT_EQ(mpeg4face::psnrBy(c, mpeg4face::FapQuality::Tao), c.psnr);
}

TEST(FapMeasure, OneExactFapMakesTaoInfiniteButNotTheRobustPsnr) {
  // FAP 3 exact, FAP 4 10 dB off: eq. (8) says +inf whatever FAP 4 does; the robust PSNR is
  // 10 log10(2 / 0.1) = 13.01 dB, and falls as FAP 4 gets worse.
  const FapStream a = streamOf({{3, {0, 10, 20, 30}}, {4, {0, 100, 0, 100}}});
  FapStream b = streamOf({{3, {0, 10, 20, 30}}, {4, {0, 100, 0, 100}}});
  double previous = kInf;
  for (const int error : {10, 20, 40}) {
    for (auto& frame : b.frames)
      frame.set(4, a.frames[static_cast<size_t>(frame.number)].value(4) + error);
    const FapComparison c = compareFapStreams(a, b);
    EXPECT_EQ(c.psnr, kInf) << error;
    ASSERT_TRUE(c.robustPsnr) << error;
    EXPECT_NEAR(*c.robustPsnr, 10 * std::log10(2.0 / (error * error / 10000.0)), 1e-9) << error;
    EXPECT_LT(*c.robustPsnr, previous) << error;
    previous = *c.robustPsnr;
  }
  EXPECT_EQ(compareFapStreams(a, a).robustPsnr, kInf);
  EXPECT_FALSE(compareFapStreams(streamOf({{5, {7, 7}}}), streamOf({{5, {7, 8}}})).robustPsnr);
}

TEST(FapMeasure, QualityNames) {
  using mpeg4face::FapQuality;
  for (const FapQuality q : {FapQuality::Robust, FapQuality::Tao}) {
    EXPECT_EQ(mpeg4face::parseFapQuality(mpeg4face::fapQualityName(q)), q);
  }
  EXPECT_FALSE(mpeg4face::parseFapQuality("Robust"));
  EXPECT_FALSE(mpeg4face::parseFapQuality(""));
}

TEST(FapMeasure, IdenticalStreamsAreInfinite) {
  const FapStream a = streamOf({{3, {0, 10, 20, 30}}, {48, {-5, 5, -5, 5}}});
  const FapComparison c = compareFapStreams(a, a);
  EXPECT_EQ(c.psnr, kInf);
  for (const auto& e : c.faps) {
    EXPECT_EQ(e.psnr, kInf);
    EXPECT_EQ(e.maxAbs, 0);
    EXPECT_EQ(e.rms, 0.0);
  }
  EXPECT_EQ(c.visemeMismatches, 0);
}

TEST(FapMeasure, ConstantFapsAreReportedButNotInN) {
  const FapStream a = streamOf({{3, {0, 10, 20, 30}}, {5, {7, 7, 7, 7}}});
  const FapStream b = streamOf({{3, {0, 10, 20, 33}}, {5, {9, 9, 9, 9}}});
  const FapComparison c = compareFapStreams(a, b);
  EXPECT_EQ(c.psnrFaps, 1);
  EXPECT_NEAR(*c.psnr, 10 * std::log10(400.0), 1e-9);
  ASSERT_EQ(c.faps.size(), 2u);
  EXPECT_EQ(c.faps[1].fap, 5);
  EXPECT_EQ(c.faps[1].range, 0);
  EXPECT_FALSE(c.faps[1].psnr);
  EXPECT_EQ(c.faps[1].maxAbs, 2);
  EXPECT_DOUBLE_EQ(c.faps[1].rms, 2.0);

  // Nothing varies: no PSNR.
  EXPECT_FALSE(compareFapStreams(streamOf({{5, {7, 7}}}), streamOf({{5, {7, 8}}})).psnr);
}

TEST(FapMeasure, HeldMirroredMissingAndExtraFaps) {
  // Original: FAP 3 sent in frames 0 and 2 only (held in 1), FAP 19 and 20 equal, FAP 6.
  FapStream a = streamOf({{19, {50, 60, 70}}, {20, {50, 60, 70}}, {6, {0, 40, 0}}});
  a.frames[0].set(3, 10);
  a.frames[2].set(3, 30);
  // Decoded: FAP 3 sent every frame, only the left eyelid (20 mirrors it), no FAP 6, and a
  // FAP 50 the original never has.
  FapStream b = streamOf({{3, {10, 10, 30}}, {19, {50, 60, 70}}, {50, {1, 1, 1}}});
  const FapComparison c = compareFapStreams(a, b);
  ASSERT_EQ(c.faps.size(), 4u);  // 3, 6, 19, 20
  EXPECT_EQ(c.faps[0].fap, 3);
  EXPECT_EQ(c.faps[0].frames, 3);
  EXPECT_EQ(c.faps[0].maxAbs, 0);
  EXPECT_EQ(c.faps[1].fap, 6);
  EXPECT_EQ(c.faps[1].missing, 3);
  EXPECT_EQ(c.faps[1].maxAbs, 40);  // missing counts as 0
  EXPECT_EQ(c.faps[3].fap, 20);
  EXPECT_EQ(c.faps[3].maxAbs, 0);
  EXPECT_EQ(c.faps[3].missing, 0);
  EXPECT_EQ(c.extraFaps, std::vector<int>{50});
  // Only FAP 6 has an error: every other term is infinite.
  EXPECT_EQ(c.psnr, kInf);
}

TEST(FapMeasure, HighLevelFapsAreComparedAsWholeFields) {
  FapStream a = streamOf({{3, {0, 1, 2}}});
  FapStream b = a;
  for (FapStream* s : {&a, &b}) {
    s->frames[0].mask.set(0);
    s->frames[0].viseme = {1, 2, 30, false};
  }
  b.frames[2].mask.set(0);
  b.frames[2].viseme = {1, 2, 31, false};
  a.frames[1].mask.set(1);
  a.frames[1].expression = {1, 63, 0, 0, false, false};
  const FapComparison c = compareFapStreams(a, b);
  EXPECT_EQ(c.visemeMismatches, 1);
  EXPECT_EQ(c.expressionMismatches, 2);  // frames 1 and 2: missing in b
}

TEST(FapMeasure, StreamsMustShareFrameRateAndNumbers) {
  const FapStream a = streamOf({{3, {0, 1, 2}}});
  FapStream b = a;
  b.frameRate = 30;
  EXPECT_EQ(errorOf([&] { compareFapStreams(a, b); }).field(), "frame rate");
  b = a;
  b.frames[1].number = 5;
  b.frames[2].number = 6;
  const auto e = errorOf([&] { compareFapStreams(a, b); });
  EXPECT_EQ(e.field(), "frame number");
  EXPECT_NE(std::string(e.what()).find("frame 1 is number 1 in the original but 5"),
            std::string::npos)
      << e.what();
  b = a;
  b.frames.pop_back();
  EXPECT_EQ(errorOf([&] { compareFapStreams(a, b); }).field(), "frame number");
}

TEST(FapMeasure, AgreesWithANaiveImplementationOnXfaceStreams) {
  // Quantise every value of an Xface stream to a step of 8; Xface frames all send the same
  // FAPs, so a per-column computation is the whole definition.
  for (const char* name : {"anger", "fear", "test"}) {
    const FapStream a =
        mpeg4face::readFapFile(mpeg4face::test::kData / "xface-fap" / (std::string(name) + ".fap"));
    FapStream b = a;
    for (auto& f : b.frames) {
      for (int fap = 3; fap <= 68; ++fap) {
        if (f.has(fap)) f.set(fap, 8 * static_cast<int>(std::lround(f.value(fap) / 8.0)));
      }
    }
    double sum = 0, sumOfErrors = 0;
    int n = 0;
    for (int fap = 3; fap <= 68; ++fap) {
      if (!a.frames[0].has(fap)) continue;
      double lo = 1e9, hi = -1e9, se = 0;
      for (size_t i = 0; i < a.frames.size(); ++i) {
        const double x = a.frames[i].value(fap), y = b.frames[i].value(fap);
        lo = std::min(lo, x);
        hi = std::max(hi, x);
        se += (x - y) * (x - y);
      }
      if (hi > lo) {
        sum += (hi - lo) * (hi - lo) / (se / static_cast<double>(a.frames.size()));
        sumOfErrors += (se / static_cast<double>(a.frames.size())) / ((hi - lo) * (hi - lo));
        ++n;
      }
    }
    const FapComparison c = compareFapStreams(a, b);
    EXPECT_EQ(c.psnrFaps, n) << name;
    ASSERT_TRUE(c.psnr) << name;
    EXPECT_NEAR(*c.psnr, 10 * std::log10(sum / n), 1e-9) << name;
    ASSERT_TRUE(c.robustPsnr) << name;
    EXPECT_NEAR(*c.robustPsnr, 10 * std::log10(n / sumOfErrors), 1e-9) << name;
    EXPECT_LE(*c.robustPsnr, *c.psnr) << name;  // the mean of ratios >= the harmonic mean
    EXPECT_GT(*c.psnr, 10.0) << name;
    EXPECT_LT(*c.psnr, 80.0) << name;
  }
}

TEST(FapMeasure, BitRatesMatchThePapersFigures) {
  // Tao et al.: Marco30 (1542 frames, 30 Hz) in 20,000 bits is "0.4 kbit/s"; Emotions (1050
  // frames) in 8500 bits is "0.24 kbit/s"; 68 FAPs of 10 bits at 30 Hz "reach 20 kbit/s".
  EXPECT_NEAR(mpeg4face::bitsPerSecond(20000, 1542, 30), 389.1, 0.05);
  EXPECT_NEAR(mpeg4face::bitsPerSecond(8500, 1050, 30), 242.86, 0.005);
  EXPECT_DOUBLE_EQ(mpeg4face::bitsPerSecond(68 * 10 * 300, 300, 30), 20400);
  EXPECT_DOUBLE_EQ(mpeg4face::bitsPerFrame(1000, 8), 125);
  // Over a stream, skipped frame numbers are time: frames 0, 5, 24 at 25 Hz span 1 s.
  FapStream s = streamOf({{3, {0, 0, 0}}});
  s.frames[1].number = 5;
  s.frames[2].number = 24;
  EXPECT_DOUBLE_EQ(mpeg4face::bitsPerSecond(500, s), 500);
  EXPECT_EQ(errorOf([] { mpeg4face::bitsPerFrame(1, 0); }).field(), "frame count");
  EXPECT_EQ(errorOf([] { mpeg4face::bitsPerSecond(1, FapStream{}); }).field(), "frame count");
}

}  // namespace
