// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face psnr`, run as a user runs it.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "test_support.hpp"

namespace {

const std::string kXface = (mpeg4face::test::kData / "xface-fap").string();

using mpeg4face::test::CliResult;
using mpeg4face::test::runCli;
using mpeg4face::test::writeScratchFile;

// Four frames sending FAPs 3 and 4 with the given values.
std::string stream(const std::array<int, 4>& fap3, const std::array<int, 4>& fap4, int rate = 25) {
  std::string mask = "0 0 1 1";
  for (int i = 4; i < 68; ++i) mask += " 0";
  std::string text = "2.1 hand " + std::to_string(rate) + " 4\n";
  for (int i = 0; i < 4; ++i) {
    text += mask + "\n" + std::to_string(i) + " " + std::to_string(fap3[i]) + " " +
            std::to_string(fap4[i]) + "\n";
  }
  return text;
}

// The hand example of codec/test_measure.cpp: eq. (8) gives 10 log10(250) = 23.98 dB.
const std::string kOriginal = stream({0, 10, 20, 30}, {0, 100, 0, 100});
const std::string kDecoded = stream({0, 10, 20, 33}, {10, 90, 10, 90});

}  // namespace

TEST(CliPsnr, PrintsPsnrAndPerFapErrors) {
  const std::string a = writeScratchFile("a.fap", kOriginal);
  const std::string b = writeScratchFile("b.fap", kDecoded);
  const CliResult r = runCli("psnr " + a + " " + b);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("PSNR 23.98 dB over 2 FAPs"), std::string::npos) << r.out;
  // The robust PSNR, 10 log10(2 / (2.25/900 + 100/10000)) = 22.04 dB, first by default.
  EXPECT_LT(r.out.find("robust PSNR 22.04 dB over 2 FAPs"), r.out.find("\nPSNR 23.98")) << r.out;
  const CliResult tao = runCli("psnr " + a + " " + b + " --quality tao");
  ASSERT_EQ(tao.status, 0) << tao.out;
  EXPECT_LT(tao.out.find("PSNR 23.98 dB"), tao.out.find("robust PSNR 22.04 dB")) << tao.out;
  // FAP 3: 4 frames, range 30, max error 3, RMS 1.5, 10 log10(400) = 26.02 dB.
  EXPECT_NE(r.out.find("   3 open_jaw"), std::string::npos) << r.out;
  const std::string row3 = r.out.substr(r.out.find("   3 open_jaw"), 80);
  EXPECT_NE(row3.find("      4     30         3     1.500    26.02"), std::string::npos) << row3;
  EXPECT_NE(r.out.find("   4 lower_t_midlip"), std::string::npos) << r.out;
}

TEST(CliPsnr, Json) {
  const std::string a = writeScratchFile("a.fap", kOriginal);
  const std::string b = writeScratchFile("b.fap", kDecoded);
  CliResult r = runCli("psnr --json " + a + " " + b);
  ASSERT_EQ(r.status, 0) << r.out;
  auto j = nlohmann::json::parse(r.stdoutOnly);
  EXPECT_NEAR(j["psnr_db"].get<double>(), 23.9794, 1e-4);
  EXPECT_NEAR(j["robust_psnr_db"].get<double>(), 10 * std::log10(160.0), 1e-9);
  EXPECT_EQ(j["quality"], "robust");
  EXPECT_EQ(j["quality_db"], j["robust_psnr_db"]);
  EXPECT_EQ(j["psnr_faps"], 2);
  EXPECT_EQ(j["frames"], 4);
  ASSERT_EQ(j["faps"].size(), 2u);
  EXPECT_EQ(j["faps"][0]["fap"], 3);
  EXPECT_EQ(j["faps"][0]["name"], "open_jaw");
  EXPECT_EQ(j["faps"][0]["max_abs_error"], 3);
  EXPECT_DOUBLE_EQ(j["faps"][0]["rms_error"].get<double>(), 1.5);
  EXPECT_EQ(j["faps"][1]["range"], 100);

  r = runCli("psnr " + kXface + "/anger.fap " + kXface + "/anger.fap --json");
  ASSERT_EQ(r.status, 0) << r.out;
  j = nlohmann::json::parse(r.stdoutOnly);
  EXPECT_EQ(j["psnr_db"], "inf");
  EXPECT_EQ(j["frames"], 108);
  EXPECT_EQ(j["faps"].size(), 48u);
}

TEST(CliPsnr, SaysWhenPsnrIsUndefined) {
  // One frame: no FAP has a range.
  std::string mask = "0 0 1";
  for (int i = 3; i < 68; ++i) mask += " 0";
  const std::string one = writeScratchFile("one.fap", "2.1 x 25 1\n" + mask + "\n0 5\n");
  const CliResult r = runCli("psnr " + one + " " + one);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("PSNR undefined"), std::string::npos) << r.out;
  EXPECT_EQ(nlohmann::json::parse(runCli("psnr --json " + one + " " + one).stdoutOnly)["psnr_db"],
            nullptr);
}

TEST(CliPsnr, BadFilesFailNamingFileAndLine) {
  const std::string a = writeScratchFile("a.fap", kOriginal);
  const std::string bad = writeScratchFile("bad.fap", "2.1 x 25 1\n0 0 1 x\n");
  CliResult r = runCli("psnr " + a + " " + bad);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find(bad + ":2: mask:"), std::string::npos) << r.out;

  r = runCli("psnr /nonexistent/a.fap " + a);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("/nonexistent/a.fap"), std::string::npos) << r.out;

  const std::string other = writeScratchFile("30hz.fap", stream({0, 1, 2, 3}, {0, 1, 2, 3}, 30));
  r = runCli("psnr " + a + " " + other);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find(other + ": frame rate:"), std::string::npos) << r.out;

  r = runCli("psnr " + kXface + "/anger.fap " + kXface + "/test.fap");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("the original has 108 frames, the decoded stream 43"), std::string::npos)
      << r.out;
}

TEST(CliPsnr, UsageErrorsExitWithStatus2) {
  CliResult r = runCli("psnr");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("usage: mpeg4face psnr"), std::string::npos) << r.out;
  EXPECT_EQ(runCli("psnr a.fap").status, 2);
  EXPECT_EQ(runCli("psnr a.fap b.fap c.fap").status, 2);
  EXPECT_EQ(runCli("psnr a.fap b.fap --bogus").status, 2);
  EXPECT_EQ(runCli("psnr a.fap b.fap --quality").status, 2);
  EXPECT_EQ(runCli("psnr a.fap b.fap --quality tao8").status, 2);
  r = runCli("--help");
  EXPECT_NE(r.out.find("psnr"), std::string::npos) << r.out;
}
