// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face info` on FAP streams (.fap, .fba), and the round trip of a stream that starts
// after frame 0 through encode, decode and psnr; run as a user runs them. Expected values are
// computed from the streams themselves with the library.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/spec.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::FapStream;
using mpeg4face::kFapCount;
using mpeg4face::test::CliResult;
using mpeg4face::test::runCli;
using mpeg4face::test::scratchDir;
using mpeg4face::test::writeScratchFile;

const std::filesystem::path kXface = mpeg4face::test::kData / "xface-fap";

// The JSON `info` must give for `stream`'s frames: count, numbers, duration, each FAP's range,
// visemes and expressions.
void expectFramesMatch(const nlohmann::json& j, const FapStream& s) {
  ASSERT_FALSE(s.frames.empty());
  EXPECT_EQ(j["frames"], s.frames.size());
  EXPECT_DOUBLE_EQ(j["frame_rate"].get<double>(), s.frameRate);
  EXPECT_DOUBLE_EQ(j["duration_s"].get<double>(), mpeg4face::streamDuration(s));
  EXPECT_EQ(j["first_frame"], s.frames.front().number);
  EXPECT_EQ(j["last_frame"], s.frames.back().number);
  size_t row = 0;
  for (int fap = 3; fap <= kFapCount; ++fap) {
    int frames = 0, lo = 0, hi = 0;
    for (const mpeg4face::FapFrame& f : s.frames) {
      if (!f.has(fap)) continue;
      lo = frames == 0 ? f.value(fap) : std::min(lo, f.value(fap));
      hi = frames == 0 ? f.value(fap) : std::max(hi, f.value(fap));
      ++frames;
    }
    if (frames == 0) continue;
    ASSERT_LT(row, j["faps"].size()) << "FAP " << fap;
    const nlohmann::json& r = j["faps"][row++];
    EXPECT_EQ(r["fap"], fap);
    EXPECT_EQ(r["name"], std::string(mpeg4face::fapInfo(fap).name));
    EXPECT_EQ(r["frames"], frames) << "FAP " << fap;
    EXPECT_EQ(r["min"], lo) << "FAP " << fap;
    EXPECT_EQ(r["max"], hi) << "FAP " << fap;
  }
  EXPECT_EQ(row, j["faps"].size());
  const auto visemeFrames = std::count_if(s.frames.begin(), s.frames.end(),
                                          [](const mpeg4face::FapFrame& f) { return f.has(1); });
  EXPECT_EQ(j["viseme"]["frames"], visemeFrames);
}

}  // namespace

TEST(CliInfoStream, FapText) {
  const std::string file = (kXface / "joy.fap").string();
  const FapStream s = mpeg4face::readFapFile(file);
  const CliResult r = runCli("info " + file);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("format: FAP file version " + s.version), std::string::npos) << r.out;
  char frames[128];
  std::snprintf(frames, sizeof frames, "frames: %zu at %g Hz, %.3f s, numbers %d..%d",
                s.frames.size(), s.frameRate, mpeg4face::streamDuration(s),
                s.frames.front().number, s.frames.back().number);
  EXPECT_NE(r.out.find(frames), std::string::npos) << r.out;
  // open_jaw's row: frames, min, max as the stream has them.
  int lo = s.frames.front().value(3), hi = lo;
  for (const auto& f : s.frames) {
    lo = std::min(lo, f.value(3));
    hi = std::max(hi, f.value(3));
  }
  const size_t at = r.out.find("3 open_jaw");
  ASSERT_NE(at, std::string::npos) << r.out;
  const std::string row = r.out.substr(at, r.out.find('\n', at) - at);
  EXPECT_NE(row.find(" " + std::to_string(s.frames.size()) + " "), std::string::npos) << row;
  EXPECT_NE(row.find(" " + std::to_string(lo) + " "), std::string::npos) << row;
  EXPECT_TRUE(row.ends_with(" " + std::to_string(hi))) << row;
}

TEST(CliInfoStream, FapJson) {
  for (const char* name : {"joy.fap", "test.fap", "anger.fap"}) {
    const std::string file = (kXface / name).string();
    const FapStream s = mpeg4face::readFapFile(file);
    const CliResult r = runCli("info --json " + file);
    ASSERT_EQ(r.status, 0) << r.out;
    const auto j = nlohmann::json::parse(r.stdoutOnly);
    EXPECT_EQ(j["format"], "fap");
    EXPECT_EQ(j["version"], s.version);
    EXPECT_EQ(j["name"], s.name);
    EXPECT_FALSE(j.contains("coding"));
    expectFramesMatch(j, s);
  }
}

TEST(CliInfoStream, FbaTextAndJson) {
  const std::string in = (kXface / "joy.fap").string();
  const std::string fba = (scratchDir() / "info_joy.fba").string();
  ASSERT_EQ(runCli("encode " + in + " -o " + fba + " --fap-quant 2 --intra-period 10").status, 0);
  mpeg4face::FbaStreamInfo info;
  const FapStream s = mpeg4face::readFbaFile(fba, info);
  const auto bits = std::filesystem::file_size(fba) * 8;

  CliResult r = runCli("info --json " + fba);
  ASSERT_EQ(r.status, 0) << r.out;
  auto j = nlohmann::json::parse(r.stdoutOnly);
  EXPECT_EQ(j["format"], "fba");
  EXPECT_EQ(j["coding"]["mode"], "predictive");
  EXPECT_EQ(j["coding"]["fap_quant"], nlohmann::json::array({2}));
  EXPECT_EQ(j["coding"]["intra_period"], 10);
  EXPECT_EQ(j["coding"]["intra_planes"], info.intraFrameIndices.size());
  EXPECT_EQ(j["coding"]["planes"], s.frames.size());  // a predictive plane is one frame
  EXPECT_EQ(j["coding"]["bits"], bits);
  EXPECT_NEAR(j["coding"]["bits_per_second"].get<double>(),
              static_cast<double>(bits) / mpeg4face::streamDuration(s), 1e-9);
  expectFramesMatch(j, s);

  r = runCli("info " + fba);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("predictive coding"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("fap_quant: 2\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("at most 10 frames"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("bits: " + std::to_string(bits) + ","), std::string::npos) << r.out;

  // The DCT and PCA modes are named as such.
  const std::string dct = (scratchDir() / "info_joy_dct.fba").string();
  ASSERT_EQ(runCli("encode " + in + " -o " + dct + " --mode dct").status, 0);
  r = runCli("info --json " + dct);
  ASSERT_EQ(r.status, 0) << r.out;
  j = nlohmann::json::parse(r.stdoutOnly);
  EXPECT_EQ(j["coding"]["mode"], "dct");
  EXPECT_TRUE(j["coding"]["intra_period"].is_null());
  expectFramesMatch(j, mpeg4face::readFbaFile(dct));
  const std::string pca = (scratchDir() / "info_joy_pca.fba").string();
  ASSERT_EQ(runCli("encode " + in + " -o " + pca + " --mode pca").status, 0);
  r = runCli("info --json " + pca);
  ASSERT_EQ(r.status, 0) << r.out;
  j = nlohmann::json::parse(r.stdoutOnly);
  EXPECT_EQ(j["coding"]["mode"], "pca (predictive components)");
  EXPECT_GT(j["coding"]["pca_components"].get<int>(), 0);
}

TEST(CliInfoStream, BadStreamsAreRefusedClearly) {
  const std::string garbage = writeScratchFile("info_garbage.fba", "not a bitstream\n");
  CliResult r = runCli("info " + garbage);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find(garbage + ": fba_object_start_code"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("unknown model format"), std::string::npos) << r.out;

  const std::string truncated = (mpeg4face::test::kData / "malformed/dct_truncated.fba").string();
  r = runCli("info " + truncated);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find(truncated + ":"), std::string::npos) << r.out;

  const std::string fap = (mpeg4face::test::kData / "malformed/fap_truncated.fap").string();
  r = runCli("info " + fap);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find(fap + ":9: frame count"), std::string::npos) << r.out;

  // --feature-points binds a model's points; a stream has none.
  EXPECT_EQ(runCli("info " + (kXface / "joy.fap").string() + " --feature-points x.csv").status,
            2);
}

// A stream whose first frame is 1 decodes with the bitstream's empty frame 0 in front
// (docs/bitstream.md, "Frame numbers"); psnr compares from the original's first frame.
TEST(CliInfoStream, RoundTripOfStreamStartingAtFrameOne) {
  FapStream s = mpeg4face::readFapFile(kXface / "joy.fap");
  ASSERT_EQ(s.frames.front().number, 0);
  for (mpeg4face::FapFrame& f : s.frames) ++f.number;
  const std::string original = (scratchDir() / "from1.fap").string();
  mpeg4face::writeFapFile(original, s);
  const std::string fba = (scratchDir() / "from1.fba").string();
  const std::string decoded = (scratchDir() / "from1_decoded.fap").string();
  ASSERT_EQ(runCli("encode " + original + " -o " + fba + " --fap-quant 0").status, 0);
  CliResult r = runCli("decode " + fba + " -o " + decoded);
  ASSERT_EQ(r.status, 0) << r.out;
  const FapStream back = mpeg4face::readFapFile(decoded);
  ASSERT_EQ(back.frames.size(), s.frames.size() + 1);
  EXPECT_EQ(back.frames.front().number, 0);
  EXPECT_TRUE(back.frames.front().mask.none());

  r = runCli("psnr " + original + " " + decoded);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("robust PSNR inf dB"), std::string::npos) << r.out;  // fap_quant 0
  r = runCli("psnr --json " + original + " " + decoded);
  ASSERT_EQ(r.status, 0) << r.out;
  auto j = nlohmann::json::parse(r.stdoutOnly);
  EXPECT_EQ(j["frames"], s.frames.size());
  EXPECT_EQ(j["robust_psnr_db"], "inf");

  // Lossy: a finite figure.
  ASSERT_EQ(runCli("encode " + original + " -o " + fba + " --fap-quant 4").status, 0);
  ASSERT_EQ(runCli("decode " + fba + " -o " + decoded).status, 0);
  r = runCli("psnr --json " + original + " " + decoded);
  ASSERT_EQ(r.status, 0) << r.out;
  j = nlohmann::json::parse(r.stdoutOnly);
  ASSERT_TRUE(j["robust_psnr_db"].is_number()) << r.out;
  EXPECT_GT(j["robust_psnr_db"].get<double>(), 20.0);

  // info shows the decoded stream's empty frame 0.
  r = runCli("info --json " + fba);
  ASSERT_EQ(r.status, 0) << r.out;
  j = nlohmann::json::parse(r.stdoutOnly);
  EXPECT_EQ(j["first_frame"], 0);
  EXPECT_EQ(j["empty_frames"], 1);
}

// Only empty frames before the original's first are skipped: a decoded frame 0 that sends
// something is a real difference and psnr says so.
TEST(CliInfoStream, PsnrStillRefusesAnExtraFrameThatSendsSomething) {
  std::string mask = "0 0 1";
  for (int i = 3; i < 68; ++i) mask += " 0";
  const std::string a = writeScratchFile("extra_a.fap", "2.1 a 25 2\n" + mask + "\n1 5\n" + mask +
                                                            "\n2 7\n");
  const std::string b = writeScratchFile(
      "extra_b.fap", "2.1 b 25 3\n" + mask + "\n0 1\n" + mask + "\n1 5\n" + mask + "\n2 7\n");
  const CliResult r = runCli("psnr " + a + " " + b);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("frame number"), std::string::npos) << r.out;
}
