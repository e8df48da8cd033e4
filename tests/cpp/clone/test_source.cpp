// SPDX-License-Identifier: GPL-3.0-or-later
// shapesFromFaceDefTables: a source given by tables as deformed copies. Checked by
// hand on a small table set, and by a round trip: the generator (fat/generate.hpp) makes
// tables from the copies that the evaluator animates like the original at random FAPs.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "fat_test_face.hpp"
#include "mpeg4face/clone/clone.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/fat/generate.hpp"
#include "test_support.hpp"

using namespace mpeg4face;

using mpeg4face::test::testFace;

namespace {

FaceDefMesh meshTable(int mesh, std::vector<int> borders, std::vector<int> coordIndex,
                      Points3 displacements) {
  FaceDefMesh m;
  m.mesh = mesh;
  m.intervalBorders = std::move(borders);
  m.coordIndex = std::move(coordIndex);
  m.displacements = std::move(displacements);
  return m;
}

const FaceShape* findCopy(const std::vector<FaceShape>& copies, const std::string& name) {
  for (const FaceShape& c : copies) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

double rowDistance(const Points3& a, const Points3& b) {
  return (a - b).rowwise().norm().maxCoeff();
}

}  // namespace

TEST(CloneSource, HandMadeTables) {
  MpegFace face{testFace(), {}};
  const double mns = 0.03 / 1024, mw = 0.05 / 1024;
  Points3 d3(6, 3);  // two vertices x three intervals [-100, 0], [0, 200], [200, 600]
  d3 << 1, 0, 0, 0, -1, 0, 0, -2, 0,  //
      0, 0, 1, 0, 0, -1, 1, 1, 1;
  face.faceDefTables.push_back({3, 0, {meshTable(0, {-100, 0, 200, 600}, {5, 6}, d3)}, {}});
  // One interval: linear and signed, sampled at its widest border (-300; 400 on a tie).
  face.faceDefTables.push_back({6, 0, {meshTable(0, {-300, 0}, {7}, Points3{{0.5, 0.25, 0}})}, {}});
  face.faceDefTables.push_back({7, 0, {meshTable(0, {-400, 400}, {8}, Points3{{-0.5, 0, 0}})}, {}});
  // Transforms only: sampled at the FAP's default range (1200 for yaw_l_eyeball).
  FaceDefTransform yaw;
  yaw.transform = 1;
  yaw.fieldId = FaceDefTransform::Field::Rotation;
  yaw.rotationDef = {0, 1, 0, 1};
  face.faceDefTables.push_back({23, 0, {}, {yaw}});
  // A viseme is shown at 63 only; an expression at its inner borders and at 63.
  Points3 dv(2, 3);
  dv << 0, 0.001, 0, 0, 0.002, 0;
  face.faceDefTables.push_back({1, 3, {meshTable(0, {0, 20, 63}, {9}, dv)}, {}});
  Points3 de(3, 3);
  de << 0.001, 0, 0, 0.003, 0, 0, 0.1, 0, 0;
  face.faceDefTables.push_back({2, 1, {meshTable(0, {0, 30, 63, 100}, {10}, de)}, {}});

  const FapuMeasurement fapu = measureFapu(face.faceSceneGraph);
  const std::vector<FaceShape> copies = shapesFromFaceDefTables(face, fapu);
  std::vector<std::string> names;
  for (const FaceShape& c : copies) names.push_back(c.name);
  EXPECT_EQ(names,
            (std::vector<std::string>{"fap3_open_jaw@-100", "fap3_open_jaw@200",
                                      "fap3_open_jaw@600", "fap6_stretch_l_cornerlip@-300",
                                      "fap7_stretch_r_cornerlip@400", "fap23_yaw_l_eyeball@1200",
                                      "viseme3", "expression1_joy@30", "expression1_joy"}));

  const Points3& p = face.faceSceneGraph.meshes[0].coord;
  // The evaluator sums motion in float: 1e-8 is a few float steps of these 0.03-unit motions.
  const auto expectMoved = [&](const std::string& name, int fapID, int select, int amplitude,
                               const std::vector<std::pair<int, Eigen::RowVector3d>>& motion) {
    const FaceShape* c = findCopy(copies, name);
    ASSERT_NE(c, nullptr) << name;
    EXPECT_EQ(c->fapID, fapID) << name;
    EXPECT_EQ(c->highLevelSelect, select) << name;
    EXPECT_EQ(c->amplitude, amplitude) << name;
    Points3 expected = p;
    for (const auto& [vertex, m] : motion) expected.row(vertex) += m;
    const FaceModel moved = deformedModel(face.faceSceneGraph, *c);
    EXPECT_LE(rowDistance(moved.meshes[0].coord, expected), 1e-8) << name;
    EXPECT_EQ(moved.meshes[1].coord, face.faceSceneGraph.meshes[1].coord) << name;
  };
  using V = Eigen::RowVector3d;
  // Negative side: per unit of |FAP|, 100 * D0; positive: 200 * D1 (+ 400 * D2).
  expectMoved("fap3_open_jaw@-100", 3, 0, -100,
              {{5, mns * 100 * V(1, 0, 0)}, {6, mns * 100 * V(0, 0, 1)}});
  expectMoved("fap3_open_jaw@200", 3, 0, 200,
              {{5, mns * 200 * V(0, -1, 0)}, {6, mns * 200 * V(0, 0, -1)}});
  expectMoved("fap3_open_jaw@600", 3, 0, 600,
              {{5, mns * (200 * V(0, -1, 0) + 400 * V(0, -2, 0))},
               {6, mns * (200 * V(0, 0, -1) + 400 * V(1, 1, 1))}});
  expectMoved("fap6_stretch_l_cornerlip@-300", 6, 0, -300, {{7, mw * -300 * V(0.5, 0.25, 0)}});
  expectMoved("fap7_stretch_r_cornerlip@400", 7, 0, 400, {{8, mw * 400 * V(-0.5, 0, 0)}});
  expectMoved("viseme3", 1, 3, 63, {{9, 20 * dv.row(0) + 43 * dv.row(1)}});
  expectMoved("expression1_joy@30", 2, 1, 30, {{10, 30 * de.row(0)}});
  expectMoved("expression1_joy", 2, 1, 63, {{10, 30 * de.row(0) + 33 * de.row(1)}});

  // The eye copy: its Transform turned by 1200 AU (1e-5 rad each) about y, nothing else.
  const FaceShape* eye = findCopy(copies, "fap23_yaw_l_eyeball@1200");
  ASSERT_NE(eye, nullptr);
  EXPECT_TRUE(eye->meshes.empty());
  const Eigen::Quaterniond expected =
      face.faceSceneGraph.transforms[1].rotation *
      Eigen::Quaterniond(Eigen::AngleAxisd(1200 * 1e-5, Eigen::Vector3d::UnitY()));
  EXPECT_LE(shapeTransforms(face.faceSceneGraph, *eye)[1].rotation.angularDistance(expected),
            1e-12);
  for (const FaceShape& c : copies) {
    if (c.fapID != 23) {
      EXPECT_LE(shapeTransforms(face.faceSceneGraph, c)[1].rotation.angularDistance(
                    face.faceSceneGraph.transforms[1].rotation),
                1e-15)
          << c.name;
    }
  }
}

TEST(CloneSource, RoundTripThroughTheGenerator) {
  MpegFace face{testFace(), {}};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  const int faceVertices = face.faceSceneGraph.meshes[0].vertexCount();
  const auto randomMesh = [&](int mesh, std::vector<int> borders, int vertexCount, int stride,
                              double size) {
    FaceDefMesh m;
    m.mesh = mesh;
    m.intervalBorders = std::move(borders);
    for (int v = 0; v < vertexCount; ++v) m.coordIndex.push_back((7 + v * stride) % faceVertices);
    m.displacements.resize(static_cast<Eigen::Index>(m.coordIndex.size()) * m.intervalCount(), 3);
    for (Eigen::Index r = 0; r < m.displacements.rows(); ++r) {
      m.displacements.row(r) << size * unit(rng), size * unit(rng), size * unit(rng);
    }
    return m;
  };
  // Meshes of one table with different borders, one-interval tables, Transform fields.
  FaceDefTables jaw{3, 0, {randomMesh(0, {-200, 0, 300, 900}, 30, 5, 1)}, {}};
  FaceDefMesh eyeMesh = randomMesh(1, {0, 100, 500}, 4, 1, 1);
  eyeMesh.coordIndex = {0, 1, 2, 3};
  jaw.faceDefMesh.push_back(eyeMesh);
  FaceDefTransform shift;
  shift.transform = 1;
  shift.fieldId = FaceDefTransform::Field::Translation;
  shift.translationDef = {0.1, -0.3, 0.2};
  jaw.faceDefTransform.push_back(shift);
  face.faceDefTables.push_back(jaw);
  face.faceDefTables.push_back({4, 0, {randomMesh(0, {-300, 0, 300}, 20, 3, 1)}, {}});
  face.faceDefTables.push_back({6, 0, {randomMesh(0, {0, 500}, 15, 11, 1)}, {}});
  face.faceDefTables.push_back({19, 0, {randomMesh(0, {-1000, -200}, 12, 13, 1)}, {}});
  FaceDefTransform yaw;
  yaw.transform = 1;
  yaw.rotationDef = {0.2, 1, 0, 0.8};
  face.faceDefTables.push_back({23, 0, {}, {yaw}});
  face.faceDefTables.push_back({1, 2, {randomMesh(0, {0, 63}, 25, 7, 0.001)}, {}});
  face.faceDefTables.push_back({2, 4, {randomMesh(0, {0, 21, 63}, 25, 9, 0.001)}, {}});

  const FapuMeasurement fapu = measureFapu(face.faceSceneGraph);
  const std::vector<FaceShape> copies = shapesFromFaceDefTables(face, fapu);
  const GeneratedTables generated =
      generateFaceDefTables(face.faceSceneGraph, fapu, copies, GeneratorOptions{});
  EXPECT_TRUE(generated.warnings.empty());
  ASSERT_EQ(generated.faceDefTables.size(), face.faceDefTables.size());
  const MpegFace regenerated{face.faceSceneGraph, generated.faceDefTables};

  const FatEvaluator original(face, fapu), again(regenerated, fapu);
  const double tolerance = 1e-6;  // the evaluator sums float motion of a 0.3-unit face
  std::uniform_int_distribution<int> value(-1500, 1500), amount(0, 63), coin(0, 1);
  for (int trial = 0; trial < 200; ++trial) {
    FapFrame frame;
    if (trial % 4 == 3) {  // a viseme and an expression
      frame.set(1, 0);
      frame.viseme = {2, 0, amount(rng), false};
      frame.set(2, 0);
      frame.expression.select1 = 4;
      frame.expression.intensity1 = amount(rng);
    } else {
      for (int fap : {3, 4, 6, 19, 23}) {
        if (trial < 20 ? fap == face.faceDefTables[static_cast<size_t>(trial % 5)].fapID
                       : coin(rng)) {
          frame.set(fap, value(rng));
        }
      }
    }
    const FatState a = original.evaluate(frame), b = again.evaluate(frame);
    for (size_t m = 0; m < a.coord.size(); ++m) {
      EXPECT_LE(rowDistance(a.coord[m], b.coord[m]), tolerance) << "trial " << trial;
    }
    for (size_t t = 0; t < a.transforms.size(); ++t) {
      EXPECT_LE((a.transforms[t].translation - b.transforms[t].translation).norm(), tolerance);
      EXPECT_LE(a.transforms[t].rotation.angularDistance(b.transforms[t].rotation), 1e-9);
    }
  }
}

TEST(CloneSource, NeedsTheFapuOfEveryTable) {
  MpegFace face{testFace(), {}};
  face.faceSceneGraph.featurePoints.erase("2.2");  // no MNS0
  face.faceDefTables.push_back({3, 0, {meshTable(0, {0, 100}, {5}, Points3{{0, -1, 0}})}, {}});
  const Error e = mpeg4face::test::errorOf(
      [&] { shapesFromFaceDefTables(face, measureFapu(face.faceSceneGraph)); });
  EXPECT_NE(std::string(e.what()).find("2.2"), std::string::npos) << e.what();
}
