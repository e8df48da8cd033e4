// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face encode` and `mpeg4face decode`, run as a user runs them.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "mpeg4face/io/fap_file.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::test::runCli;
using mpeg4face::test::scratchDir;

const std::string kJoy = (mpeg4face::test::kData / "xface-fap" / "joy.fap").string();

using mpeg4face::test::has;

TEST(CliCodec, EncodePrintsBitsRateAndPsnr) {
  const std::string fba = (scratchDir() / "joy.fba").string();
  const auto r = runCli("encode " + kJoy + " -o " + fba + " --fap-quant 4");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(has(r.out, "108 frames at 25 Hz")) << r.out;
  EXPECT_TRUE(has(r.out, "bits/s")) << r.out;
  EXPECT_TRUE(has(r.out, "PSNR ")) << r.out;
  EXPECT_TRUE(std::filesystem::exists(fba));
}

TEST(CliCodec, JsonAgreesWithTheFileAndThePsnrCommand) {
  const std::string fba = (scratchDir() / "joy.fba").string();
  const std::string fap = (scratchDir() / "joy_decoded.fap").string();
  const auto r =
      runCli("encode " + kJoy + " -o " + fba + " --fap-quant 8 --intra-period 25 --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.stdoutOnly);
  const auto bits = j["bits"].get<double>();
  EXPECT_EQ(bits, 8.0 * static_cast<double>(std::filesystem::file_size(fba)));
  EXPECT_DOUBLE_EQ(j["bits_per_second"].get<double>(), bits / (108.0 / 25.0));
  EXPECT_EQ(j["intra_frames"], 5);  // frames 0, 25, 50, 75, 100
  EXPECT_EQ(j["mode"], "predictive");

  ASSERT_EQ(runCli("decode " + fba + " -o " + fap).status, 0);
  const auto psnr = runCli("psnr --json " + kJoy + " " + fap);
  ASSERT_EQ(psnr.status, 0) << psnr.out;
  EXPECT_DOUBLE_EQ(j["psnr_db"].get<double>(),
                   nlohmann::json::parse(psnr.stdoutOnly)["psnr_db"].get<double>());
}

TEST(CliCodec, LosslessRoundTripThroughFiles) {
  const std::string fba = (scratchDir() / "joy.fba").string();
  const std::string fap = (scratchDir() / "back.fap").string();
  const auto r = runCli("encode " + kJoy + " -o " + fba + " --fap-quant 0");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(has(r.out, "lossless")) << r.out;
  ASSERT_EQ(runCli("decode " + fba + " -o " + fap).status, 0);
  const mpeg4face::FapStream original = mpeg4face::readFapFile(kJoy);
  const mpeg4face::FapStream back = mpeg4face::readFapFile(fap);
  EXPECT_EQ(back.name, "joy");
  EXPECT_EQ(back.frameRate, original.frameRate);
  EXPECT_EQ(back.frames, original.frames);
}

// decode --strict reads as a standard decoder (FbaDecodeLimits::strict), and the encoder's
// streams read the same that way (test_fba_start_codes.cpp has what it refuses).
TEST(CliCodec, DecodeStrictReadsTheSame) {
  const std::string fba = (scratchDir() / "joy.fba").string();
  const std::string plain = (scratchDir() / "plain.fap").string();
  const std::string strict = (scratchDir() / "strict.fap").string();
  ASSERT_EQ(runCli("encode " + kJoy + " -o " + fba + " --fap-quant 0 --rdo-lambda 0.005 " +
                   "--intra-period 7").status, 0);
  ASSERT_EQ(runCli("decode " + fba + " -o " + plain).status, 0);
  const auto r = runCli("decode " + fba + " --strict -o " + strict);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(mpeg4face::readFapFile(strict).frames, mpeg4face::readFapFile(plain).frames);
}

TEST(CliCodec, BadArgumentsAndStreams) {
  const std::string fba = (scratchDir() / "x.fba").string();
  auto r = runCli("encode " + kJoy + " -o " + fba + " --fap-quant 32");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_TRUE(has(r.out, "--fap-quant takes a whole number in 0..31")) << r.out;
  r = runCli("encode " + kJoy + " -o " + fba + " --mode wavelet");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_TRUE(has(r.out, "unknown mode 'wavelet'")) << r.out;
  r = runCli("encode " + kJoy);
  EXPECT_EQ(r.status, 2) << r.out;
  r = runCli("decode " + (mpeg4face::test::kData / "malformed" / "fba_truncated.fba").string() +
             " -o " + (scratchDir() / "x.fap").string());
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_TRUE(has(r.out, "fba_truncated.fba: low-level FAP data: the stream is damaged at bit "))
      << r.out;
  EXPECT_FALSE(std::filesystem::exists(scratchDir() / "x.fap"));
}

}  // namespace
