// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face landmarks`: a head without feature points gets them from a template, as CSV
// that reads back or as the head in glTF; bad arguments and faceless heads write nothing.
// `mpeg4face animate`: the same head made animatable in one step.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/fat_gltf.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/gltf.hpp"
#include "mpeg4face/io/obj.hpp"
#include "mpeg4face/model/mesh_cut.hpp"
#include "test_support.hpp"

namespace {

using namespace mpeg4face;
using mpeg4face::test::has;
using mpeg4face::test::kData;
using mpeg4face::test::runCli;
using mpeg4face::test::scratchDir;

// The MakeHuman head with its points (the template) and the same head as an OBJ without
// them (the target), written once for the tests of this file.
struct Files {
  std::string templateGlb, targetObj;
  std::string sourceGlb;  // the template with three FAP shape keys: a source to clone
};

// A smooth bump of `motion` about feature point `fp`, 0 beyond `radius`.
Points3 bump(const FaceModel& head, int mesh, const std::string& fp, double radius,
             const Eigen::Vector3d& motion) {
  const IndexedFaceSet& m = head.meshes[static_cast<std::size_t>(mesh)];
  const Eigen::Vector3d centre = *head.featurePointPosition(fp);
  Points3 d = Points3::Zero(m.vertexCount(), 3);
  for (Eigen::Index v = 0; v < m.coord.rows(); ++v) {
    const double r = (m.coord.row(v).transpose() - centre).norm() / radius;
    if (r < 1) d.row(v) = std::pow(1 - r * r, 3) * motion.transpose();
  }
  return d;
}

Files files() {
  FaceModel model = readObj(kData / "makehuman" / "base.obj");
  model.featurePoints =
      readFeaturePointCsv(kData / "makehuman" / "feature_points.csv", model).featurePoints;
  FaceModel head = cutFaceModel(model, *model.featurePointPosition("7.2"), {0, 1, 0},
                                [](const IndexedFaceSet& m) {
                                  return m.name.starts_with("body") ||
                                         m.name.starts_with("helper-l-eye") ||
                                         m.name.starts_with("helper-r-eye");
                                });
  Files f{(scratchDir() / "template.glb").string(), (scratchDir() / "target.obj").string(),
          (scratchDir() / "source.glb").string()};
  writeGltf(head, f.templateGlb);
  FaceModel source = head;
  const int body = *head.findMesh("body");
  IndexedFaceSet& skin = source.meshes[static_cast<std::size_t>(body)];
  skin.morphTargets = {{"fap3_open_jaw@512", bump(head, body, "2.1", 0.8, {0, -0.15, 0})},
                       {"fap12_raise_l_cornerlip@512", bump(head, body, "8.3", 0.2, {0, 0.05, 0})},
                       {"fap13_raise_r_cornerlip@512", bump(head, body, "8.4", 0.2, {0, 0.05, 0})}};
  skin.weights.assign(3, 0.0);
  writeGltf(source, f.sourceGlb);
  head.featurePoints.clear();
  writeObj(head, f.targetObj);
  return f;
}

TEST(CliLandmarks, WritesTheHeadsPointsAsCsvThatReadsBack) {
  const Files f = files();
  const std::string csv = (scratchDir() / "points.csv").string();
  const auto r = runCli("landmarks " + f.targetObj + " --template " + f.templateGlb +
                        " --pin 9.3=0,6.9,1.68 -o " + csv);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(has(r.out, "feature points placed (1 pins)")) << r.out;
  EXPECT_TRUE(has(r.out, "ES0    = ")) << r.out;
  // The pin, a position on the nose, bound to the vertex there.
  EXPECT_TRUE(has(r.out, "feature point 9.3 bound to vertex")) << r.out;
  const FaceModel target = readObj(f.targetObj);
  const FeaturePointCsv back = readFeaturePointCsv(csv, target);
  EXPECT_TRUE(back.warnings.empty());
  EXPECT_GE(back.featurePoints.size(), 70u);
  EXPECT_GE(back.featurePoints.at("8.3").mesh, 0);
  EXPECT_EQ(back.featurePoints.at("7.1").mesh, -1);  // inside the head: a position
  EXPECT_TRUE(has(mpeg4face::readFile(csv), "fp,mesh,vertex,x,y,z,confidence\n"));

  const std::string glb = (scratchDir() / "head.glb").string();
  ASSERT_EQ(runCli("landmarks " + f.targetObj + " --template " + f.templateGlb + " -o " + glb)
                .status,
            0);
  EXPECT_GE(readGltf(glb).featurePoints.size(), 70u);
}

TEST(CliLandmarks, BadArgumentsAndFacelessHeadsWriteNothing) {
  const Files f = files();
  const std::string out = (scratchDir() / "never.csv").string();
  const auto badPin = runCli("landmarks " + f.targetObj + " --template " + f.templateGlb +
                             " --pin 2.1=nowhere -o " + out);
  EXPECT_EQ(badPin.status, 2);
  EXPECT_TRUE(has(badPin.out, "--pin '2.1=nowhere'")) << badPin.out;
  const auto unknown = runCli("landmarks " + f.targetObj + " --template " + f.templateGlb +
                              " --pin 12.1=3 -o " + out);
  EXPECT_TRUE(has(unknown.out, "not an MPEG-4 feature point")) << unknown.out;
  EXPECT_EQ(runCli("landmarks " + f.targetObj + " -o points.txt").status, 2);
  const std::string cube = test::writeScratchFile(
      "cube.obj",
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
      "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n");
  const auto faceless = runCli("landmarks " + cube + " --template " + f.templateGlb + " -o " + out);
  EXPECT_EQ(faceless.status, 1);
  EXPECT_TRUE(has(faceless.out, "no face found")) << faceless.out;
  EXPECT_FALSE(std::filesystem::exists(out));
}

// One command: points found from the template, the source's three shapes cloned, tables,
// the file, the check of a stream; a line per step. A head with its points keeps them.
TEST(CliAnimate, MakesAHeadWithoutPointsAnimatableInOneStep) {
  const Files f = files();
  const std::string out = (scratchDir() / "animated.glb").string();
  const std::string stream = (kData / "xface-fap" / "test.fap").string();
  const auto r = runCli("animate " + f.targetObj + " --source " + f.sourceGlb + " --template " +
                        f.templateGlb + " --stream " + stream + " -o " + out);
  ASSERT_TRUE(r.status == 0 || r.status == 4) << r.out;
  for (const char* step : {"read:", "feature points: ", "clone:", "write:", "check:"}) {
    EXPECT_TRUE(has(r.out, std::string("\n") + step) || r.out.starts_with(step)) << step << r.out;
  }
  EXPECT_TRUE(has(r.out, "3 copies of")) << r.out;
  EXPECT_TRUE(has(r.out, "test.fap: ")) << r.out;
  const FatGltf written = readFatGltf(out);
  EXPECT_EQ(written.face.faceDefTables.size(), 3u);
  EXPECT_GE(written.face.faceSceneGraph.featurePoints.size(), 70u);

  // The template as the head: its own points, no search.
  const auto own = runCli("animate " + f.templateGlb + " --source " + f.sourceGlb +
                          " --stream " + stream + " -o " + out);
  EXPECT_TRUE(has(own.out, "the head's own")) << own.out;
  EXPECT_EQ(runCli("animate " + f.targetObj + " -o out.fap").status, 2);
}

}  // namespace
