// SPDX-License-Identifier: GPL-3.0-or-later
// Tests of the PCA coding mode (codec/pca.hpp, FapCodingMode::Pca, docs/pca-mode.md): the KLT and
// Tao's energy rule on hand-made data, a stream in a known subspace reconstructed within the
// quantiser's bound, FAPs not sent in every frame, the decoder reproducing the encoder's
// reconstruction bit for bit on the Xface streams, `encode --mode pca|auto`, bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include "codec/fba_pca.hpp"
#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/codec/measure.hpp"
#include "mpeg4face/codec/pca.hpp"
#include "mpeg4face/codec/rd.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/spec.hpp"
#include "fba_strict.hpp"
#include "test_support.hpp"

namespace mpeg4face {
namespace {

using test::decodeBothWays;
using test::errorOf;
using test::kData;
using test::runCli;
using test::scratchDir;

const std::vector<std::string> kXface = {"anger", "beg", "disgust", "fear", "happy-for",
                                         "hate",  "joy", "pride",   "test"};

std::string xfacePath(const std::string& name) {
  return (kData / "xface-fap" / (name + ".fap")).string();
}

FbaEncodeOptions pca(int fapQuant, FapCodingMode temporal = FapCodingMode::Predictive,
                     double energy = 0.98, int basisBits = FbaEncodeOptions{}.pcaBasisBits) {
  return {.mode = FapCodingMode::Pca,
          .fapQuant = fapQuant,
          .pcaTemporal = temporal,
          .pcaEnergy = energy,
          .pcaBasisBits = basisBits};
}

int quantStep(int fap) { return fapTable()[static_cast<size_t>(fap - 1)].quantStep; }

bool contains(const Error& e, const std::string& text) {
  return std::string(e.what()).find(text) != std::string::npos;
}

// Group 2's FAPs 3..10 moving in the plane spanned by two integer directions (integer
// coordinates, so the stream lies exactly in that 2-D subspace), 30 Hz.
const std::vector<int> kPlaneFaps = {3, 4, 5, 6, 7, 8, 9, 10};
FapStream planeStream(int frames) {
  const std::vector<int> p = {3, -1, 2, 0, 1, 4, -2, 1};
  const std::vector<int> q = {-1, 2, 1, 3, -2, 0, 1, 2};
  FapStream s;
  s.frameRate = 30;
  for (int t = 0; t < frames; ++t) {
    FapFrame& f = s.frames.emplace_back();
    f.number = t;
    const auto a = static_cast<int>(std::lround(40 * std::sin(2 * std::numbers::pi * t / 37)));
    const auto b = static_cast<int>(std::lround(30 * std::cos(2 * std::numbers::pi * t / 23)));
    for (size_t i = 0; i < kPlaneFaps.size(); ++i) f.set(kPlaneFaps[i], a * p[i] + b * q[i]);
  }
  return s;
}

// ---- KLT and the energy rule ------------------------------------------------------------------

TEST(PcaKlt, EigenvaluesOfAHandMadeCovariance) {
  // Samples (+-1, 0) and (0, +-2): mean 0, covariance (eq. 4, 1/(n-1)) diag(2/3, 8/3).
  Eigen::MatrixXd samples(4, 2);
  samples << 1, 0, -1, 0, 0, 2, 0, -2;
  const Klt klt = computeKlt(samples);
  EXPECT_NEAR(klt.mean.norm(), 0.0, 1e-12);
  ASSERT_EQ(klt.eigenvalues.size(), 2);
  EXPECT_NEAR(klt.eigenvalues(0), 8.0 / 3.0, 1e-12);  // descending, as Tao numbers them
  EXPECT_NEAR(klt.eigenvalues(1), 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(std::abs(klt.axes(1, 0)), 1.0, 1e-12);  // the y axis first
  EXPECT_NEAR(std::abs(klt.axes(0, 1)), 1.0, 1e-12);
  // One sample: no variance.
  EXPECT_NEAR(computeKlt(samples.topRows(1)).eigenvalues.norm(), 0.0, 1e-12);
}

TEST(PcaKlt, EnergyRuleOnAHandMadeSpectrum) {
  const std::vector<double> spectrum = {50, 30, 15, 4, 1};  // total 100
  // Cumulative 50, 80, 95, 99, 100.
  EXPECT_EQ(componentsForEnergy(spectrum, 0.98), 4);
  EXPECT_EQ(componentsForEnergy(spectrum, 0.95), 3);
  EXPECT_EQ(componentsForEnergy(spectrum, 0.951), 4);
  EXPECT_EQ(componentsForEnergy(spectrum, 0.5), 1);
  EXPECT_EQ(componentsForEnergy(spectrum, 1.0), 5);
  EXPECT_EQ(componentsForEnergy(std::vector<double>{0, 0, 0}, 0.98), 0);
  EXPECT_EQ(componentsForEnergy(std::vector<double>{}, 0.98), 0);
}

TEST(PcaCodec, AStreamInATwoDimensionalSubspaceKeepsTwoComponents) {
  const FapStream s = planeStream(120);
  const std::vector<PcaGroup> groups = pcaGroups(s, pca(1));
  ASSERT_EQ(groups.size(), 1u);
  EXPECT_EQ(groups[0].group, 2);
  EXPECT_EQ(groups[0].faps, kPlaneFaps);
  EXPECT_EQ(groups[0].components, 2);
  const double total = groups[0].eigenvalues.sum();
  for (Eigen::Index i = 2; i < groups[0].eigenvalues.size(); ++i) {
    EXPECT_LT(groups[0].eigenvalues(i), 1e-9 * total);
  }
  // Even keeping all energy, two components suffice.
  EXPECT_EQ(pcaGroups(s, pca(1, FapCodingMode::Predictive, 1.0))[0].components, 2);

  for (const int q : {1, 2, 5}) {
    const FbaEncoding enc = encodeFba(s, pca(q, FapCodingMode::Predictive, 0.98, 12));
    EXPECT_EQ(decodeBothWays(enc.bytes), enc.reconstruction);
    EXPECT_EQ(enc.stats.clippedValues, 0);
    // Each component is off by at most half its step (QP of its slot times q, closed-loop
    // prediction) plus half a unit for its rounding to an integer; in FAP i that is at most
    // QP_i (q + 1) / 2 per unit of sum_j |u_ij| <= sqrt(2) (two orthonormal axes), plus the
    // mean's and the output's rounding (1/2 each) and the basis rounding (2^-12 relative).
    ASSERT_EQ(enc.reconstruction.frames.size(), s.frames.size());
    for (size_t t = 0; t < s.frames.size(); ++t) {
      for (const int fap : kPlaneFaps) {
        const double bound = quantStep(fap) * (q + 1) / 2.0 * std::numbers::sqrt2 + 1.5;
        EXPECT_LE(std::abs(enc.reconstruction.frames[t].value(fap) - s.frames[t].value(fap)), bound)
            << "q " << q << " frame " << t << " FAP " << fap;
      }
    }
  }
}

TEST(PcaCodec, FapsNotSentInEveryFrameHoldTheirLastValue) {
  // FAP 5 starts at frame 10, FAP 6 is sent in even frames only: PCA runs on the resolved
  // values (held; 0 before the first sending) and the decoder sends every FAP in every frame.
  FapStream s = planeStream(60);
  std::vector<int> held(kFapCount + 1, 0);
  for (FapFrame& f : s.frames) {
    if (f.number < 10) f.mask.reset(4);
    if (f.number % 2 == 1) f.mask.reset(5);
  }
  const FbaEncoding enc = encodeFba(s, pca(1, FapCodingMode::Predictive, 1.0, 12));
  EXPECT_EQ(decodeBothWays(enc.bytes), enc.reconstruction);
  for (size_t t = 0; t < s.frames.size(); ++t) {
    const FapFrame& in = s.frames[t];
    const FapFrame& out = enc.reconstruction.frames[t];
    for (const int fap : kPlaneFaps) {
      if (in.has(fap)) held[static_cast<size_t>(fap)] = in.value(fap);
      ASSERT_TRUE(out.has(fap)) << "frame " << t << " FAP " << fap;
      // All components kept: only the quantiser's and rounding's error (as above, with
      // sum_j |u_ij| <= sqrt(8) for up to 8 axes).
      const double bound = quantStep(fap) * 1.0 * std::sqrt(8.0) + 1.5;
      EXPECT_LE(std::abs(out.value(fap) - held[static_cast<size_t>(fap)]), bound)
          << "frame " << t << " FAP " << fap;
    }
  }
}

TEST(PcaCodec, FapOneAndTwoPassThrough) {
  FapStream s = planeStream(20);
  for (FapFrame& f : s.frames) {
    if (f.number % 3 == 0) {
      f.mask.set(0);
      f.viseme = {f.number % 15, 3, 40, false};
    }
    if (f.number % 4 == 0) {
      f.mask.set(1);
      f.expression = {2, 50, 5, 10, f.number == 0, false};
    }
  }
  const FbaEncoding enc = encodeFba(s, pca(4, FapCodingMode::Dct));
  EXPECT_EQ(decodeBothWays(enc.bytes), enc.reconstruction);
  for (size_t t = 0; t < s.frames.size(); ++t) {
    const FapFrame& out = enc.reconstruction.frames[t];
    EXPECT_EQ(out.has(1), s.frames[t].has(1));
    EXPECT_EQ(out.has(2), s.frames[t].has(2));
    if (out.has(1)) {
      EXPECT_EQ(out.viseme, s.frames[t].viseme);
    }
    if (out.has(2)) {
      EXPECT_EQ(out.expression, s.frames[t].expression);
    }
    EXPECT_EQ(out.number, s.frames[t].number);
  }
}

// ---- The Xface streams -------------------------------------------------------------------------

TEST(PcaCodec, DecoderReproducesTheEncoderOnEveryXfaceStream) {
  for (const std::string& name : kXface) {
    const FapStream s = readFapFile(xfacePath(name));
    for (const FapCodingMode temporal : {FapCodingMode::Predictive, FapCodingMode::Dct}) {
      for (const int q : {1, 6, 31}) {
        const FbaEncoding enc = encodeFba(s, pca(q, temporal));
        EXPECT_EQ(decodeBothWays(enc.bytes), enc.reconstruction)
            << name << " " << codingModeName(temporal) << " q" << q;
        EXPECT_EQ(enc.stats.bits, 8 * enc.bytes.size());
        uint64_t frameBits = 0;
        for (const uint64_t b : enc.stats.frameBits) frameBits += b;
        EXPECT_LT(frameBits, enc.stats.bits);  // start and end codes are no frame's
      }
    }
  }
}

// The cheapest (mode, component coder, fap_quant) reaching `db` of the robust PSNR (what
// --mode auto judges by), by a loop of its own.
uint64_t cheapestBitsByHand(const FapStream& s, double db) {
  uint64_t best = std::numeric_limits<uint64_t>::max();
  const auto tryOptions = [&](const FbaEncodeOptions& o) {
    const FbaEncoding enc = encodeFba(s, o);
    FapStream rec = enc.reconstruction;
    if (rec.frames.size() == s.frames.size() + 1) rec.frames.erase(rec.frames.begin());
    rec.frameRate = s.frameRate;
    const std::optional<double> psnr = compareFapStreams(s, rec).robustPsnr;
    if (psnr && *psnr >= db && enc.stats.bits < best) best = enc.stats.bits;
  };
  for (int q = 0; q <= 31; ++q) {
    tryOptions({.mode = FapCodingMode::Predictive, .fapQuant = q});
    if (q == 0) continue;
    tryOptions({.mode = FapCodingMode::Dct, .fapQuant = q});
    tryOptions(pca(q, FapCodingMode::Predictive));
    tryOptions(pca(q, FapCodingMode::Dct));
  }
  return best;
}

TEST(PcaCodec, AutoIsNeverWorseThanTheBestSingleModeIncludingPca) {
  for (const std::string& name : {std::string("joy"), std::string("test"), std::string("beg")}) {
    const FapStream s = readFapFile(xfacePath(name));
    for (const double db : {25.0, 35.0}) {
      const uint64_t byHand = cheapestBitsByHand(s, db);
      const std::optional<RdPoint> best = cheapestEncoding(s, db, allCodingModes());
      ASSERT_TRUE(best.has_value()) << name;
      EXPECT_EQ(best->bits, byHand) << name << " " << db << " dB";

      const std::string fba = (scratchDir() / (name + ".fba")).string();
      const auto r = runCli("encode " + xfacePath(name) + " -o " + fba + " --mode auto --psnr " +
                            std::to_string(db) + " --json");
      ASSERT_EQ(r.status, 0) << r.out;
      const auto j = nlohmann::json::parse(r.stdoutOnly);
      EXPECT_EQ(j["bits"].get<uint64_t>(), byHand) << name << " " << db << " dB";
      EXPECT_GE(j["robust_psnr_db"].get<double>(), db);
      if (j["mode"] == "pca") {
        EXPECT_EQ(j["pca_temporal"], codingModeName(best->pcaTemporal));
      }
    }
  }
}

TEST(PcaCodec, KeepsEnoughComponentsForTheRobustTarget) {
  // By energy alone (0.98) PCA drops the components of the least-moving FAPs, which the robust
  // PSNR weighs most; with the residual rule finer fap_quant keeps more components and joy
  // reaches 25 dB robust.
  const FapStream s = readFapFile(xfacePath("joy"));
  int kept31 = 0, kept1 = 0;
  for (const PcaGroup& g : pcaGroups(s, pca(31))) kept31 += g.components;
  for (const PcaGroup& g : pcaGroups(s, pca(1))) kept1 += g.components;
  EXPECT_GT(kept1, kept31);
  double best = 0;
  for (const int q : {1, 4, 8}) {
    const RdPoint p = measureEncoding(s, pca(q, FapCodingMode::Dct));
    best = std::max(best, p.robustPsnr.value_or(0));
  }
  EXPECT_GE(best, 25.0);
}

TEST(PcaCodec, SweepsCoverBothComponentCoders) {
  const FapStream s = readFapFile(xfacePath("joy"));
  const std::array modes{FapCodingMode::Pca};
  const std::vector<RdPoint> points = sweepRateDistortion(s, modes);
  ASSERT_EQ(points.size(), 62u);  // fap_quant 1..31, predictive then dct components
  EXPECT_EQ(rdModeName(points.front()), "pca+predictive");
  EXPECT_EQ(points.front().fapQuant, 1);
  EXPECT_EQ(rdModeName(points.back()), "pca+dct");
  EXPECT_EQ(points.back().fapQuant, 31);
  EXPECT_EQ(fapQuantRange(FapCodingMode::Pca).front(), 1);
}

// ---- CLI ---------------------------------------------------------------------------------------

TEST(PcaCodec, CliEncodesWithPcaAndEitherComponentCoder) {
  for (const std::string temporal : {"predictive", "dct"}) {
    const std::string fba = (scratchDir() / ("joy_" + temporal + ".fba")).string();
    const std::string fap = (scratchDir() / ("joy_" + temporal + ".fap")).string();
    const auto r = runCli("encode " + xfacePath("joy") + " -o " + fba +
                          " --mode pca --pca-temporal " + temporal + " --fap-quant 6 --json");
    ASSERT_EQ(r.status, 0) << r.out;
    const auto j = nlohmann::json::parse(r.stdoutOnly);
    EXPECT_EQ(j["mode"], "pca");
    EXPECT_EQ(j["pca_temporal"], temporal);
    const FbaEncoding enc =
        encodeFba(readFapFile(xfacePath("joy")),
                  pca(6, temporal == "dct" ? FapCodingMode::Dct : FapCodingMode::Predictive));
    EXPECT_EQ(j["bits"].get<uint64_t>(), enc.stats.bits);
    ASSERT_EQ(runCli("decode " + fba + " -o " + fap).status, 0);
    const auto psnr = runCli("psnr --json " + xfacePath("joy") + " " + fap);
    ASSERT_EQ(psnr.status, 0) << psnr.out;
    EXPECT_DOUBLE_EQ(j["psnr_db"].get<double>(),
                     nlohmann::json::parse(psnr.stdoutOnly)["psnr_db"].get<double>());
  }
  const std::string fba = (scratchDir() / "x.fba").string();
  auto r = runCli("encode " + xfacePath("joy") + " -o " + fba + " --mode pca --pca-temporal pca");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("--pca-temporal takes predictive or dct, not 'pca'"), std::string::npos)
      << r.out;
  r = runCli("encode " + xfacePath("joy") + " -o " + fba + " --pca-temporal dct");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("--pca-temporal goes with --mode pca"), std::string::npos) << r.out;
}

// ---- Bad input ---------------------------------------------------------------------------------

TEST(PcaCodec, BadOptions) {
  const FapStream s = planeStream(5);
  Error e = errorOf([&] { encodeFba(s, pca(1, FapCodingMode::Pca)); });
  EXPECT_EQ(e.field(), "pcaTemporal");
  e = errorOf([&] { encodeFba(s, pca(1, FapCodingMode::Predictive, 0.0)); });
  EXPECT_EQ(e.field(), "pcaEnergy");
  e = errorOf([&] { encodeFba(s, pca(1, FapCodingMode::Predictive, 1.5)); });
  EXPECT_EQ(e.field(), "pcaEnergy");
  for (const int bits : {0, 16}) {
    FbaEncodeOptions o = pca(1);
    o.pcaBasisBits = bits;
    e = errorOf([&] { encodeFba(s, o); });
    EXPECT_EQ(e.field(), "pcaBasisBits");
  }
  e = errorOf([&] { encodeFba(s, pca(0, FapCodingMode::Dct)); });  // the DCT coder's own check
  EXPECT_EQ(e.field(), "fapQuant") << e.what();
}

std::string readBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

TEST(PcaCodec, MalformedFiles) {
  // Made by tests/data/malformed/pca_generate.py from tests/data/pca/legacy_joy_q8.fba.
  for (const auto& [file, element, text] :
       std::vector<std::tuple<std::string, std::string, std::string>>{
           {"pca_zero_basis_bits.fba", "pca_basis_bits", "is 0 (1..15)"},
           {"pca_too_many_components.fba", "pca_components (FAP group 2)", "components of 16 FAPs"},
           {"pca_huge_basis_entry.fba", "pca_basis (FAP group 2)", "exceeds 16777216"},
           {"pca_long_code.fba", "pca_mean (FAP group 2)", "longer than 40 leading zeros"},
           {"pca_missing_component.fba", "FAP ", "carries a PCA component and is not sent"},
           {"pca_truncated.fba", "pca_basis (FAP group 8)", "truncated"},
           {"pca_stuffing_bit_zero.fba", "pca_stuffing_bit", "is 0 after 16 zeros"}}) {
    const std::string data = readBytes(kData / "malformed" / file);
    ASSERT_FALSE(data.empty()) << file;
    const Error e = errorOf([&, file = file] {
      decodeFba(std::span(reinterpret_cast<const std::uint8_t*>(data.data()), data.size()), file);
    });
    EXPECT_EQ(e.file(), file);
    EXPECT_TRUE(e.field().starts_with(element)) << file << ": " << e.what();
    EXPECT_TRUE(contains(e, text)) << file << ": " << e.what();
  }
}

// The longest run of zero bits in bytes [from, to).
int longestZeroRun(std::span<const std::uint8_t> bytes, size_t from, size_t to) {
  int run = 0, longest = 0;
  for (size_t i = from * 8; i < to * 8; ++i) {
    run = (bytes[i / 8] >> (7 - i % 8)) & 1 ? 0 : run + 1;
    longest = std::max(longest, run);
  }
  return longest;
}

// A header's pca_fap_mask is all zeros for every group before the only one that moves (62 in
// a row for group 10), and its Exp-Golomb codes hold long runs of zeros too: unstuffed, the
// header emulated a start code (fuzz_pca found a seed where it did, issue 44). Stuffed, no run
// in it is longer than the stuffing allows, and every encoding reads the same strictly.
TEST(PcaCodec, TheHeaderEmulatesNoStartCode) {
  const std::vector<std::uint8_t> objectAndHeaderCodes = {0, 0, 1, 0xB9, 0x7F, 0, 0, 1, 0xB2};
  const std::vector<std::uint8_t> planeCode = {0, 0, 1, 0xBB};
  for (const FapGroupInfo& g : fapGroupTable()) {
    if (g.number < 2) continue;
    FapStream s;
    for (int t = 0; t < 12; ++t) {
      FapFrame& f = s.frames.emplace_back();
      f.number = t;
      for (int fap = g.firstFap; fap <= g.lastFap; ++fap) f.set(fap, (fap * 37 + t * t * 11) % 300);
    }
    for (int basisBits = 1; basisBits <= 15; ++basisBits) {
      SCOPED_TRACE("FAP group " + std::to_string(g.number) + ", pca_basis_bits " +
                   std::to_string(basisBits));
      const FbaEncoding enc = encodeFba(s, pca(4, FapCodingMode::Predictive, 0.98, basisBits));
      ASSERT_TRUE(std::equal(objectAndHeaderCodes.begin(), objectAndHeaderCodes.end(),
                             enc.bytes.begin()));
      const auto planes =
          std::search(enc.bytes.begin(), enc.bytes.end(), planeCode.begin(), planeCode.end());
      ASSERT_NE(planes, enc.bytes.end());
      // From the header start code's last byte to the first plane start code's stuffing: its
      // last 0 before the header and the stuffing's 0 after it add one each to a run.
      EXPECT_LE(longestZeroRun(enc.bytes, objectAndHeaderCodes.size() - 1,
                               static_cast<size_t>(planes - enc.bytes.begin())),
                fba::kPcaStuffingRun + 1);
      EXPECT_EQ(decodeBothWays(enc.bytes), enc.reconstruction);
    }
  }
}

// Streams written before issue 44 have an unstuffed header, told apart by its first 4 bits
// (pca_basis_bits 1..15 where pca_header_format is 0 now): the decoder still reads them, to
// what the decoder of then read (legacy_joy_q8.fap, decoded by it; tests/data/pca/README.md).
TEST(PcaCodec, ReadsTheHeaderWrittenBeforeStuffing) {
  const std::string legacy = readBytes(kData / "pca" / "legacy_joy_q8.fba");
  ASSERT_FALSE(legacy.empty());
  const FapStream decoded =
      decodeFba(std::span(reinterpret_cast<const std::uint8_t*>(legacy.data()), legacy.size()));
  const FapStream then = readFapFile((kData / "pca" / "legacy_joy_q8.fap").string());
  ASSERT_EQ(decoded.frames.size(), 108U);
  EXPECT_EQ(decoded.frames, then.frames);
}

TEST(PcaCodec, EveryTruncationIsAnError) {
  const FbaEncoding enc = encodeFba(readFapFile(xfacePath("anger")), pca(8));
  for (size_t size = 0; size + 1 < enc.bytes.size(); size += 7) {
    errorOf([&] { decodeFba(std::span(enc.bytes.data(), size)); });
  }
}

}  // namespace
}  // namespace mpeg4face
