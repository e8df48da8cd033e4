// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face fit`, `encode --fit` and `decode --fit`, run as a user runs them.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "mpeg4face/fit/json.hpp"
#include "mpeg4face/fit/presets.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/vrml.hpp"
#include "test_support.hpp"

namespace {

using namespace mpeg4face;
using mpeg4face::test::runCli;
using mpeg4face::test::scratchDir;

const std::string kJoy = (mpeg4face::test::kData / "xface-fap" / "joy.fap").string();

using mpeg4face::test::has;

TEST(CliFit, PresetWritesTheTableEveryNameAndMerged) {
  for (std::string_view name : fitPresetNames()) {
    const std::string out = (scratchDir() / (std::string(name) + ".json")).string();
    const auto r = runCli("fit preset " + std::string(name) + " -o " + out);
    ASSERT_EQ(r.status, 0) << r.out;
    EXPECT_EQ(readFitJson(out), fitPreset(name)) << name;
  }
  const std::string lip = (scratchDir() / "lip.json").string();
  ASSERT_EQ(runCli("fit preset inner-outer-lip --fmax 500 -o " + lip).status, 0);
  EXPECT_EQ(readFitJson(lip), innerOuterLipFitTable(500));
  const std::string both = (scratchDir() / "both.json").string();
  ASSERT_EQ(runCli("fit preset left-right,eyebrow -o " + both).status, 0);
  EXPECT_EQ(readFitJson(both), mergedFitTables(leftRightFitTable(), eyebrowFitTable()));
  const auto bad = runCli("fit preset smile -o " + both);
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(has(bad.out, "unknown preset 'smile' (presets: left-right")) << bad.out;
}

TEST(CliFit, EncodeLeavesOutDerivedFapsAndDecodeFillsThem) {
  const auto dir = scratchDir();
  const std::string table = (dir / "lr.json").string();
  ASSERT_EQ(runCli("fit preset left-right,inner-outer-lip -o " + table).status, 0);
  const std::string whole = (dir / "whole.fba").string(), part = (dir / "part.fba").string();
  const auto a = runCli("encode " + kJoy + " -o " + whole + " --json");
  const auto b = runCli("encode " + kJoy + " -o " + part + " --fit " + table + " --json");
  ASSERT_EQ(a.status, 0) << a.out;
  ASSERT_EQ(b.status, 0) << b.out;
  const auto ja = nlohmann::json::parse(a.stdoutOnly), jb = nlohmann::json::parse(b.stdoutOnly);
  EXPECT_GT(jb["fit_values_left_out"].get<int>(), 0);
  EXPECT_LT(jb["bits"].get<double>(), 0.6 * ja["bits"].get<double>());
  EXPECT_EQ(std::filesystem::file_size(part) * 8, jb["bits"].get<std::size_t>());

  // Without the table the decoder has only what was sent; with it, every FAP again.
  const std::string bare = (dir / "bare.fap").string(), filled = (dir / "filled.fap").string();
  ASSERT_EQ(runCli("decode " + part + " -o " + bare).status, 0);
  const auto d = runCli("decode " + part + " --fit " + table + " -o " + filled);
  ASSERT_EQ(d.status, 0) << d.out;
  EXPECT_TRUE(has(d.out, "FAP values interpolated")) << d.out;
  const FapStream original = readFapFile(kJoy), sent = readFapFile(bare),
                  full = readFapFile(filled);
  ASSERT_EQ(full.frames.size(), original.frames.size());
  for (std::size_t f = 0; f < original.frames.size(); ++f) {
    EXPECT_LT(sent.frames[f].mask.count(), original.frames[f].mask.count());
    EXPECT_EQ(full.frames[f].mask, original.frames[f].mask) << f;
  }
  // The PSNR encode --fit reports is that of the filled stream against the original.
  const auto psnr = runCli("psnr --json " + kJoy + " " + filled);
  ASSERT_EQ(psnr.status, 0) << psnr.out;
  const auto jp = nlohmann::json::parse(psnr.stdoutOnly)["psnr_db"];
  if (jp.is_number()) {
    EXPECT_NEAR(jb["psnr_db"].get<double>(), jp.get<double>(), 1e-9);
  } else {
    EXPECT_EQ(jb["psnr_db"], jp);
  }
}

TEST(CliFit, LearnAndTryReportWhatTheyDid) {
  const auto dir = scratchDir();
  const std::string learned = (dir / "learned.json").string();
  const auto l = runCli("fit learn " + kJoy + " --degree 2 -o " + learned);
  ASSERT_EQ(l.status, 0) << l.out;
  EXPECT_TRUE(has(l.out, "functions fitted (degree 2")) << l.out;
  const FitTable table = readFitJson(learned);
  EXPECT_EQ(table.nodes.size(),
            (mergedFitTables(mergedFitTables(leftRightFitTable(), innerOuterLipFitTable()),
                             eyebrowFitTable()))
                .nodes.size());
  const auto t = runCli("fit try " + learned + " " + kJoy);
  ASSERT_EQ(t.status, 0) << t.out;
  EXPECT_TRUE(has(t.out, "FAPs derived by the table")) << t.out;
  EXPECT_TRUE(has(t.out, "saved)")) << t.out;
  EXPECT_TRUE(has(t.out, "PSNR of the derived FAPs")) << t.out;

  // Errors name the file and what is wrong.
  const std::string broken = (dir / "broken.json").string();
  std::filesystem::copy_file(learned, broken);
  {
    std::string text = readFile(broken);
    text.replace(text.find("\"parent\": 0"), 11, "\"parent\": -4");
    writeFileAtomically(broken, text);
  }
  const auto e = runCli("decode x.fba --fit " + broken + " -o " + (dir / "o.fap").string());
  EXPECT_EQ(e.status, 1);
  EXPECT_TRUE(has(e.out, broken)) << e.out;
  EXPECT_TRUE(has(e.out, "link 0 joins node -4")) << e.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "o.fap"));
  EXPECT_EQ(runCli("fit learn -o " + learned).status, 2);
  EXPECT_EQ(runCli("fit frobnicate").status, 2);
}

}  // namespace

namespace {
TEST(CliFit, TableFromAFacesFitNode) {
  const auto dir = scratchDir();
  MpegFace face;
  face.fit = leftRightFitTable();
  writeVrml(face, dir / "face.wrl");
  const std::string part = (dir / "part.fba").string();
  const auto r = runCli("encode " + kJoy + " -o " + part + " --fit " + (dir / "face.wrl").string() +
                        " --json");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_GT(nlohmann::json::parse(r.stdoutOnly)["fit_values_left_out"].get<int>(), 0);
  writeVrml(MpegFace{}, dir / "plain.wrl");
  const auto e = runCli("fit try " + (dir / "plain.wrl").string() + " " + kJoy);
  EXPECT_EQ(e.status, 1);
  EXPECT_TRUE(has(e.out, "the face has no FIT node")) << e.out;
}
}  // namespace
