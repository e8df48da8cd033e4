// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face arkit keys`, run as a user runs it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
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

// Feature points given as free positions (a CSV's fp,x,y,z): those on the surface are bound
// to their vertices and the keys are made as with vertex-bound points; points nowhere near the
// head make no key, and a command that makes nothing fails and writes nothing (issue 42).
TEST(CliArkit, KeysFromFreeFeaturePoints) {
  const auto dir = scratchDir();
  const std::string head = (dir / "head.glb").string(), out = (dir / "keys.glb").string();
  const FaceModel model = mpeg4face::test::arkitTestHeadWithShapes();
  writeGltf(model, head);
  const auto csv = [&](const std::string& name, double shift) {
    const std::string path = (dir / name).string();
    std::ofstream f(path);
    f << "fp,x,y,z\n";
    for (const auto& [id, binding] : model.featurePoints) {
      const Eigen::Vector3d p = *model.featurePointPosition(id) + Eigen::Vector3d(0, 0, shift);
      f << id << ',' << p.x() << ',' << p.y() << ',' << p.z() << '\n';
    }
    return path;
  };
  const auto bound = runCli("arkit keys " + head + " --feature-points " +
                            csv("on.csv", 0) + " -o " + out);
  ASSERT_EQ(bound.status, 0) << bound.out;
  EXPECT_TRUE(has(bound.out, "fap3_open_jaw@341")) << bound.out;
  EXPECT_TRUE(has(bound.out, "warning: feature point 2.1 bound to vertex")) << bound.out;
  std::filesystem::remove(out);

  const auto far = runCli("arkit keys " + head + " --feature-points " + csv("off.csv", 5) +
                          " -o " + out);
  EXPECT_EQ(far.status, 1) << far.out;
  EXPECT_TRUE(has(far.out, "feature point 2.1 is left free")) << far.out;
  EXPECT_TRUE(has(far.out, "no FAP key could be made: feature point")) << far.out;
  EXPECT_TRUE(has(far.out, "nothing written")) << far.out;
  EXPECT_FALSE(std::filesystem::exists(out));
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
