// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face check` end to end: the summary, --json, the limit options and exit status, and
// the errors for bad input.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "motion_check_fixture.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/fat_gltf.hpp"
#include "mpeg4face/io/gltf.hpp"
#include "mpeg4face/io/vrml.hpp"
#include "test_support.hpp"

namespace {

using namespace mpeg4face;
using mpeg4face::test::runCli;
using mpeg4face::test::scratchDir;

// A head with a stretching key and a jaw that leaves the lower lip behind, and one whose
// keys are within the limits; written once per test (each test is a process of its own).
std::string writeHead(bool bad) {
  test::MotionHead h = test::motionHead();
  if (bad) {
    h.key("expression1_stretch", h.stretchSheet, {-2, 0, 0});
    h.key("fap3@1024", h.chin, {0, -1, 0});
    h.key("fap3@1024", h.lowerLip, {0, -0.3, 0});
  } else {  // the whole sheet: no stretch, no spike
    for (int v = h.stretchSheet; v < h.stretchSheet + 9; ++v) {
      h.key("expression2_ok", v, {0.1, 0, 0});
    }
  }
  const std::string path = (scratchDir() / (bad ? "bad.glb" : "good.glb")).string();
  writeGltf(h.model, path);
  return path;
}

std::string writeStream() {
  FapStream s;
  for (int n = 0; n < 4; ++n) {
    FapFrame f;
    f.number = n;
    f.set(3, 100 * n);
    s.frames.push_back(f);
  }
  const std::string path = (scratchDir() / "jaw.fap").string();
  writeFapFile(path, s);
  return path;
}

TEST(CliCheck, SummaryNamesTheWorstKeyAndTheLimit) {
  const std::string head = writeHead(true);
  const auto r = runCli("check " + head + " --stream " + writeStream());
  EXPECT_EQ(r.status, 4) << r.out;
  EXPECT_NE(r.stdoutOnly.find("FAIL - 1 of 2 keys, 0 of 4 frames past the limits"),
            std::string::npos)
      << r.out;
  // p99 of the 8 edges the key moves: the second longest, 1 -> sqrt(5).
  EXPECT_NE(r.stdoutOnly.find("edge ratio p99 2.24 > 2"), std::string::npos) << r.out;
  EXPECT_NE(r.stdoutOnly.find("lips never part"), std::string::npos);
  EXPECT_NE(r.stdoutOnly.find("expression1_stretch"), std::string::npos);
  // The corner the key moves alone is a spike: its row in the table, and in the key's line.
  EXPECT_NE(r.stdoutOnly.find("1 spike vertex (bump 1.00 x the local motion > 0.75)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.stdoutOnly.find("  spike vertices             <= 0      1            1       0"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.stdoutOnly.find("  bump / local motion        <= 0.75   1.00         1       0"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.stdoutOnly.find("the lower lip 8.2 moves 30% of the chin 2.1"), std::string::npos);
  EXPECT_NE(r.stdoutOnly.find("jaw.fap"), std::string::npos);
  EXPECT_NE(r.out.find("check: 6/6 poses"), std::string::npos);  // progress, on stderr
  EXPECT_EQ(r.stdoutOnly.find("poses"), std::string::npos);
  // Within the other limits the spike alone fails the head.
  const auto spike = runCli("check " + head + " --max-edge-ratio 3.5 --min-lower-lip 25");
  EXPECT_EQ(spike.status, 4) << spike.out;
  EXPECT_NE(spike.stdoutOnly.find("FAIL - 1 of 2 keys"), std::string::npos) << spike.out;
}

TEST(CliCheck, JsonAndLimitOptions) {
  const std::string head = writeHead(true);
  const auto r = runCli("check " + head + " --json");
  EXPECT_EQ(r.status, 4) << r.out;
  const auto j = nlohmann::json::parse(r.stdoutOnly);
  EXPECT_FALSE(j["passed"]);
  ASSERT_EQ(j["keys"].size(), 2u);
  const auto& key = j["keys"][0];
  EXPECT_EQ(key["name"], "expression1_stretch");
  EXPECT_NEAR(key["edge_ratio_max"].get<double>(), 3.0, 1e-5);
  EXPECT_EQ(key["meshes"][0]["mesh"], "skin");
  EXPECT_FALSE(key["meshes"][0]["offending_vertices"].empty());
  EXPECT_EQ(key["spikes"], 1);
  EXPECT_NEAR(key["bump_ratio_max"].get<double>(), 1.0, 1e-9);
  EXPECT_EQ(key["meshes"][0]["spike_vertices"], nlohmann::json::array({0}));  // stretchSheet
  EXPECT_EQ(j["limits"]["spike_vertices"], 0);
  EXPECT_NEAR(j["limits"]["bump_of_local_motion"].get<double>(), 0.75, 1e-12);
  EXPECT_NEAR(j["limits"]["bump_of_peak"].get<double>(), 0.05, 1e-12);
  EXPECT_NEAR(j["lower_lip_share"].get<double>(), 0.3, 1e-5);
  // Looser limits pass the same head.
  const auto loose =
      runCli("check " + head + " --max-edge-ratio 3.5 --min-lower-lip 25 --max-spikes 1");
  EXPECT_EQ(loose.status, 0) << loose.out;
  EXPECT_NE(loose.stdoutOnly.find("PASS"), std::string::npos);
  // A ratio limit above 1 lets the spike pass.
  EXPECT_EQ(
      runCli("check " + head + " --max-edge-ratio 3.5 --min-lower-lip 25 --spike-ratio 1.5").status,
      0);
  EXPECT_EQ(runCli("check " + writeHead(false)).status, 0);
}

TEST(CliCheck, FaceWithTables) {
  const std::string head = writeHead(true);
  const std::string wrl = (scratchDir() / "bad.wrl").string();
  writeVrml(faceFromShapeKeys(readGltf(head)).face, wrl);
  const auto r = runCli("check " + wrl + " --json");
  EXPECT_EQ(r.status, 4) << r.out;
  const auto j = nlohmann::json::parse(r.stdoutOnly);
  std::vector<std::string> names;
  for (const auto& k : j["keys"]) names.push_back(k["name"]);
  EXPECT_EQ(names, (std::vector<std::string>{"expression1", "fap3_open_jaw@1024"}));
  EXPECT_NEAR(j["keys"][0]["edge_ratio_max"].get<double>(), 3.0, 1e-5);

  // A glTF file with tables (what fat generate, clone and animate write) is checked through
  // them as the .wrl is: its interval targets ("expression1_stretch[0,63]") are no shape keys.
  const MpegFace generated = faceFromShapeKeys(readGltf(head)).face;
  const std::string glb = (scratchDir() / "bad_tables.glb").string();
  writeFatGltf(generated, measureFapu(generated.faceSceneGraph), {}, glb);
  const auto g = runCli("check " + glb + " --json");
  EXPECT_EQ(g.status, 4) << g.out;
  const auto k = nlohmann::json::parse(g.stdoutOnly);
  EXPECT_EQ(k["keys"].size(), 2u);
  EXPECT_EQ(k["keys"][1]["name"], "fap3_open_jaw@1024");
  EXPECT_NEAR(k["keys"][0]["edge_ratio_max"].get<double>(), 3.0, 1e-5);
}

TEST(CliCheck, BadInput) {
  const auto missing = runCli("check " + (scratchDir() / "none.glb").string());
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.out.find("none.glb"), std::string::npos) << missing.out;
  const std::string broken = test::writeScratchFile("broken.fap", "not a fap file\n1 2 3\n");
  const auto stream = runCli("check " + writeHead(false) + " --stream " + broken);
  EXPECT_EQ(stream.status, 1);
  EXPECT_NE(stream.out.find("broken.fap"), std::string::npos) << stream.out;
  EXPECT_EQ(stream.stdoutOnly, "");  // nothing checked, nothing printed
  EXPECT_EQ(runCli("check head.obj").status, 2);
  test::MotionHead still = test::motionHead();
  const std::string none = (scratchDir() / "none_named.glb").string();
  writeGltf(still.model, none);
  const auto nothing = runCli("check " + none);
  EXPECT_EQ(nothing.status, 1);
  EXPECT_NE(nothing.out.find("nothing to check"), std::string::npos) << nothing.out;
  const auto option = runCli("check " + writeHead(false) + " --max-edge-ratio x");
  EXPECT_EQ(option.status, 2);
  EXPECT_NE(option.out.find("--max-edge-ratio takes a number"), std::string::npos);
}

}  // namespace
