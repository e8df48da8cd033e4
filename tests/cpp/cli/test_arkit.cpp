// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face arkit keys`, run as a user runs it.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "arkit_test_head.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/io/gltf.hpp"
#include "test_support.hpp"

namespace {

using namespace mpeg4face;
using mpeg4face::test::runCli;
using mpeg4face::test::scratchDir;

using mpeg4face::test::has;

TEST(CliArkit, KeysReportsTheFapsMadeAndMissedAndFeedsFatGenerate) {
  const auto dir = scratchDir();
  const std::string head = (dir / "head.glb").string(), out = (dir / "keys.glb").string();
  writeGltf(mpeg4face::test::arkitTestHeadWithShapes(), head);
  const auto r = runCli("arkit keys " + head + " -o " + out);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(has(r.out, "8 ARKit shapes")) << r.out;
  EXPECT_TRUE(has(r.out, "fap3_open_jaw@341")) << r.out;
  EXPECT_TRUE(has(r.out, "jawOpen 1.00")) << r.out;
  EXPECT_TRUE(has(r.out, "FAP 27 thrust_l_eyeball: no ARKit shape thrusts the eyeball")) << r.out;
  EXPECT_TRUE(has(r.out, "13 viseme and 5 expression keys"))
      << r.out;  // the rest move nothing here
  const FaceModel keys = readGltf(out);
  const ShapeKeyFace face = faceFromShapeKeys(keys);
  EXPECT_GT(face.copies, 20u);
  const auto fat = runCli("fat generate " + out + " -o " + (dir / "face.wrl").string());
  EXPECT_EQ(fat.status, 0) << fat.out;

  const auto lean = runCli("arkit keys " + head + " --no-visemes --no-expressions -o " + out);
  ASSERT_EQ(lean.status, 0) << lean.out;
  EXPECT_TRUE(has(lean.out, "0 viseme and 0 expression keys")) << lean.out;
}

TEST(CliArkit, ErrorsNameTheFileAndWriteNothing) {
  const auto dir = scratchDir();
  const std::string plain = (dir / "plain.glb").string(), out = (dir / "out.glb").string();
  writeGltf(mpeg4face::test::arkitTestHead(), plain);
  const auto none = runCli("arkit keys " + plain + " -o " + out);
  EXPECT_EQ(none.status, 1);
  EXPECT_TRUE(has(none.out, plain)) << none.out;
  EXPECT_TRUE(has(none.out, "no morph target is an ARKit blendshape; looked for eyeBlinkLeft"))
      << none.out;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out + ".part"));

  EXPECT_EQ(runCli("arkit keys " + plain).status, 2);
  EXPECT_EQ(runCli("arkit keys head.obj -o " + out).status, 2);
  EXPECT_EQ(runCli("arkit fly " + plain).status, 2);
  const auto missing = runCli("arkit keys " + (dir / "missing.glb").string() + " -o " + out);
  EXPECT_EQ(missing.status, 1);
  EXPECT_TRUE(has(missing.out, "missing.glb")) << missing.out;
}

}  // namespace
