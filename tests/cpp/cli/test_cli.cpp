// SPDX-License-Identifier: GPL-3.0-or-later
// The mpeg4face command-line tool, run as a user runs it.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "test_support.hpp"

namespace {

const std::string kData = mpeg4face::test::kData.string();

using mpeg4face::test::CliResult;
using mpeg4face::test::runCli;
using mpeg4face::test::writeScratchFile;

const std::string kCandide = kData + "/candide3/candide3.wfm";
const std::string kCandideFp = kData + "/candide3/feature_points.csv";

}  // namespace

TEST(CliInfo, Candide3PrintsAllFiveFapu) {
  const CliResult r = runCli("info " + kCandide + " --feature-points " + kCandideFp);
  ASSERT_EQ(r.status, 0) << r.out;
  for (const char* name : {"ES0", "IRISD0", "ENS0", "MNS0", "MW0"}) {
    const auto line = r.out.find(std::string("  ") + name + " ");
    ASSERT_NE(line, std::string::npos) << name << "\n" << r.out;
    const std::string text = r.out.substr(line, r.out.find('\n', line) - line);
    EXPECT_NE(text.find("= "), std::string::npos) << text;
    EXPECT_EQ(text.find("not measured"), std::string::npos) << text;
  }
  EXPECT_NE(r.out.find("candide3"), std::string::npos);
  EXPECT_NE(r.out.find("113 vertices"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("FAP 3 open_jaw"), std::string::npos) << r.out;
}

TEST(CliInfo, JsonHasTheDocumentedKeys) {
  const CliResult r = runCli("info " + kCandide + " --feature-points " + kCandideFp + " --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.stdoutOnly);
  for (const char* key : {"meshes", "feature_points", "fapu", "warnings"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  ASSERT_EQ(j["meshes"].size(), 1u);
  EXPECT_EQ(j["meshes"][0]["vertices"], 113);
  EXPECT_EQ(j["meshes"][0]["faces"], 184);
  for (const char* name : {"ES0", "IRISD0", "ENS0", "MNS0", "MW0"}) {
    ASSERT_TRUE(j["fapu"][name].is_number()) << name;
    EXPECT_GT(j["fapu"][name].get<double>(), 0.0) << name;
  }
  const auto& present = j["feature_points"]["present"];
  EXPECT_NE(std::find(present.begin(), present.end(), "2.1"), present.end());
  const auto& missing = j["feature_points"]["missing"];
  EXPECT_NE(std::find(missing.begin(), missing.end(), "3.5"), missing.end());
  EXPECT_EQ(present.size() + missing.size(), 85u);
  // CANDIDE's CSV binds 11.1 twice: the warning names the later row.
  bool duplicate = false;
  for (const auto& w : j["warnings"])
    duplicate |= w.get<std::string>().find("11.1") != std::string::npos;
  EXPECT_TRUE(duplicate) << j["warnings"].dump();
}

TEST(CliInfo, WithoutFeaturePointsFapuAreMissingNotInvented) {
  const CliResult r = runCli("info " + kCandide + " --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.stdoutOnly);
  EXPECT_TRUE(j["fapu"]["ES0"].is_null());
  EXPECT_EQ(j["feature_points"]["present"].size(), 0u);
}

TEST(CliInfo, MissingFileFailsWithItsName) {
  const CliResult r = runCli("info /nonexistent/head.glb");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("/nonexistent/head.glb"), std::string::npos) << r.out;
}

TEST(CliInfo, AFolderIsNotAModel) {
  const CliResult r = runCli("info " + kData);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find(kData + ": is a folder"), std::string::npos) << r.out;
}

TEST(CliInfo, UnmeasuredFapuSayWhatTheyNeed) {
  const CliResult r = runCli("info " + kCandide);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("not measured (needs 9.15 and 2.2)"), std::string::npos) << r.out;
}

TEST(CliInfo, MalformedFilesFailNamingFileAndLine) {
  const std::string obj = writeScratchFile("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
  CliResult r = runCli("info " + obj);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find(obj + ":4"), std::string::npos) << r.out;

  const std::string csv = writeScratchFile("bad.csv", "fp,vertex\n2.1,10\n99.9,3\n");
  r = runCli("info " + kCandide + " --feature-points " + csv);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find(csv + ":3"), std::string::npos) << r.out;

  const std::string glb = writeScratchFile("bad.glb", std::string("glTF\x02\0\0\0", 8));
  r = runCli("info " + glb);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find(glb), std::string::npos) << r.out;

  const std::string wfm = writeScratchFile("bad.wfm", "# VERTEX LIST:\n3\n0 0 0\n1 0\n");
  r = runCli("info " + wfm);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find(wfm + ":4"), std::string::npos) << r.out;
}

TEST(Cli, UsageErrorsExitWithStatus2) {
  EXPECT_EQ(runCli("").status, 2);
  EXPECT_EQ(runCli("frobnicate").status, 2);
  const CliResult r = runCli("info");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("usage: mpeg4face info"), std::string::npos) << r.out;
  EXPECT_EQ(runCli("info a.glb --bogus").status, 2);
  EXPECT_EQ(runCli("info a.glb --feature-points").status, 2);
  EXPECT_EQ(runCli("info a.obj b.obj").status, 2);
}

TEST(Cli, HelpAndVersion) {
  CliResult r = runCli("--help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("info"), std::string::npos);
  r = runCli("info --help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("--feature-points"), std::string::npos);
  r = runCli("--version");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("mpeg4face "), std::string::npos);
}
