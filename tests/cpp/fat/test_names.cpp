// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <string>
#include <tuple>

#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/fat/names.hpp"
#include "test_support.hpp"

using namespace mpeg4face;
using mpeg4face::test::errorOf;

namespace {

ShapeKeyName parsed(const std::string& name) {
  const std::optional<ShapeKeyName> key = parseShapeKeyName(name);
  if (!key) throw std::runtime_error(name + " was not read as ours");
  return *key;
}

void expectKey(const std::string& name, int fap, int select, int amplitude,
               const std::string& label) {
  const ShapeKeyName k = parsed(name);
  EXPECT_EQ(k.fapID, fap) << name;
  EXPECT_EQ(k.highLevelSelect, select) << name;
  EXPECT_EQ(k.amplitude, amplitude) << name;
  EXPECT_EQ(k.label, label) << name;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST(ShapeKeyNames, TheGrammarsExamples) {
  expectKey("fap3_open_jaw@512", 3, 0, 512, "open_jaw");
  expectKey("fap6@-300", 6, 0, -300, "");
  expectKey("fap68@+7", 68, 0, 7, "");
  expectKey("FAP19_Close_T_L_Eyelid@200", 19, 0, 200, "Close_T_L_Eyelid");
  expectKey("fap19_blink-left@200", 19, 0, 200, "blink-left");
  expectKey("viseme1_p_b_m", 1, 1, 63, "p_b_m");
  expectKey("viseme14", 1, 14, 63, "");
  expectKey("expression1_joy@40", 2, 1, 40, "joy");
  expectKey("expression6", 2, 6, 63, "");
  expectKey("Expression3_angry@1", 2, 3, 1, "angry");
}

TEST(ShapeKeyNames, StandardNamesMustMatchTheNumber) {
  // "stretch_l_cornerlip" names FAP 6 and is the BIFS field name of FAP 53: both fit.
  expectKey("fap6_stretch_l_cornerlip@100", 6, 0, 100, "stretch_l_cornerlip");
  expectKey("fap53_stretch_l_cornerlip@100", 53, 0, 100, "stretch_l_cornerlip");
  expectKey("fap6_stretch_l_corner@100", 6, 0, 100, "stretch_l_corner");
  expectKey("fap53_stretch_l_cornerlip_o@100", 53, 0, 100, "stretch_l_cornerlip_o");
  const Error e = errorOf([] { parseShapeKeyName("fap3_stretch_l_cornerlip@100"); });
  EXPECT_TRUE(
      contains(e.reason(), "'stretch_l_cornerlip' is the name of FAP 6, not FAP 3 (open_jaw)"))
      << e.what();
  EXPECT_TRUE(contains(errorOf([] { parseShapeKeyName("fap4_Open_Jaw@100"); }).reason(), "FAP 3"));
  EXPECT_TRUE(contains(errorOf([] { parseShapeKeyName("expression1_anger"); }).reason(),
                       "'anger' is expression 3, not expression 1"));
}

TEST(ShapeKeyNames, OtherNamesAreNotOurs) {
  for (const char* name : {"Basis", "smile", "fapulous", "visemes", "expressionless", "Key 1",
                           "open_jaw", "xfap3@10", ""}) {
    EXPECT_FALSE(parseShapeKeyName(name)) << name;
  }
}

TEST(ShapeKeyNames, MalformedNamesAreRejectedWithTheGrammar) {
  const std::pair<const char*, const char*> cases[] = {
      {"fap99", "FAP 99 is not 3..68"},
      {"fap3@", "'@' must be followed by an integer"},
      {"fap3_x@1.5e", "'1.5e' after '@' is not an integer"},
      {"viseme15", "viseme 15 is not 1..14"},
      {"viseme0", "viseme 0 is not 1..14"},
      {"expression7", "expression 7 is not 1..6"},
      {"fap6@0", "amplitude 0 is the neutral face"},
      {"fap3", "the amplitude '@<value>' is missing"},
      {"fap3_open_jaw", "the amplitude '@<value>' is missing"},
      {"fap1@5", "FAP 1 and 2 are named viseme<N> and expression<N>"},
      {"fap_open_jaw@5", "the number after 'fap' is missing"},
      {"fap@5", "the number after 'fap' is missing"},
      {"viseme", "the number after 'viseme' is missing"},
      {"viseme3@20", "a viseme takes no '@'"},
      {"expression2@64", "intensity 64 is not 1..63"},
      {"expression2@0", "intensity 0 is not 1..63"},
      {"fap3_@5", "'_' must be followed by a name"},
      {"fap3_open jaw@5", "unexpected ' ' after 'fap3_open'"},
      {"fap3@512.001", "'512.001' after '@' is not an integer"},
      {"fap3x@5", "unexpected 'x' after 'fap3'"},
      {"fap99999999999@1", "the number '99999999999' is too large"},
      {"fap3@99999999999", "after '@' is not an integer"},
  };
  for (const auto& [name, why] : cases) {
    const Error e = errorOf([name = name] { parseShapeKeyName(name); });
    EXPECT_EQ(e.field(), "shape key '" + std::string(name) + "'");
    EXPECT_TRUE(contains(e.reason(), why)) << e.what();
    EXPECT_TRUE(contains(e.reason(), "fap<N>[_<name>]@<amplitude>")) << e.what();
    EXPECT_TRUE(contains(e.reason(), "expression<N>[_<label>][@<intensity>]")) << e.what();
  }
}

TEST(ShapeKeyNames, FormatWritesWhatParseReads) {
  EXPECT_EQ(formatShapeKeyName({3, 0, 512, "open_jaw"}), "fap3_open_jaw@512");
  EXPECT_EQ(formatShapeKeyName({6, 0, -300, ""}), "fap6@-300");
  EXPECT_EQ(formatShapeKeyName({1, 4, 63, ""}), "viseme4");
  EXPECT_EQ(formatShapeKeyName({2, 1, 63, "joy"}), "expression1_joy");
  EXPECT_EQ(formatShapeKeyName({2, 1, 20, ""}), "expression1@20");
  for (const ShapeKeyName& k : std::vector<ShapeKeyName>{
           {3, 0, 512, "open_jaw"}, {68, 0, -1, ""}, {1, 14, 63, "U"}, {2, 6, 5, "surprise"}}) {
    const ShapeKeyName back = parsed(formatShapeKeyName(k));
    EXPECT_EQ(std::tie(back.fapID, back.highLevelSelect, back.amplitude, back.label),
              std::tie(k.fapID, k.highLevelSelect, k.amplitude, k.label));
  }
}

namespace {

// Two meshes, four vertices each; morph targets named as a Blender user would.
FaceModel keyedModel() {
  FaceModel model;
  for (const char* name : {"Face", "Teeth"}) {
    IndexedFaceSet mesh;
    mesh.name = name;
    mesh.coord = Points3::Random(4, 3);
    mesh.coordIndex = {0, 1, 2, -1, 0, 2, 3, -1};
    model.addMeshWithTransform(mesh);
  }
  const auto target = [](const char* name, Eigen::RowVector3d d) {
    MorphTarget t;
    t.name = name;
    t.displacements = Points3::Zero(4, 3);
    t.displacements.row(1) = d;
    return t;
  };
  model.meshes[0].morphTargets = {target("fap3_open_jaw@512", {0, -0.05, 0}),
                                  target("smile", {1, 0, 0}), target("viseme2", {0, 0, 0.01}),
                                  target("expression1_joy@40", {0.02, 0, 0})};
  model.meshes[0].weights = {0, 0, 0, 0};
  model.meshes[1].morphTargets = {target("fap3_open_jaw@512", {0, -0.04, 0}),
                                  target("smile", {1, 0, 0}), target("Basis.001", {1, 0, 0})};
  model.featurePoints["9.15"] = {-1, -1, {0, 0, 0}};
  model.featurePoints["2.2"] = {-1, -1, {0, -0.0512, 0}};  // MNS = 5e-5
  return model;
}

}  // namespace

TEST(ShapeKeyCopies, OneCopyPerNameAcrossMeshesOthersIgnored) {
  const FaceModel model = keyedModel();
  const ShapeKeyCopies out = shapesFromShapeKeys(model);
  ASSERT_EQ(out.copies.size(), 3u);
  EXPECT_EQ(out.ignored, (std::vector<std::string>{"smile", "Basis.001"}));
  const FaceModel basis = neutralFaceModel(model);
  const FaceShape& jaw = out.copies[0];
  EXPECT_EQ(jaw.name, "fap3_open_jaw@512");
  EXPECT_EQ(std::make_pair(jaw.fapID, jaw.amplitude), std::make_pair(3, 512));
  const FaceModel jawModel = deformedModel(basis, jaw);
  EXPECT_EQ(jawModel.meshes[0].coord.row(1),
            model.meshes[0].coord.row(1) + Eigen::RowVector3d(0, -0.05, 0));
  EXPECT_EQ(jawModel.meshes[1].coord.row(1),
            model.meshes[1].coord.row(1) + Eigen::RowVector3d(0, -0.04, 0));
  EXPECT_EQ(jawModel.meshes[0].coord.row(0), model.meshes[0].coord.row(0));
  // Sparse: the vertices the morph targets move, on each mesh they move; no Transforms.
  ASSERT_EQ(jaw.meshes.size(), 2u);
  EXPECT_EQ(jaw.meshes[0].mesh, 0);
  EXPECT_EQ(jaw.meshes[0].vertices, std::vector<int>{1});
  EXPECT_EQ(jaw.meshes[1].mesh, 1);
  EXPECT_EQ(jaw.meshes[1].vertices, std::vector<int>{1});
  EXPECT_TRUE(jaw.transforms.empty());
  EXPECT_EQ(std::tie(out.copies[1].fapID, out.copies[1].highLevelSelect, out.copies[1].amplitude),
            std::make_tuple(1, 2, 63));
  ASSERT_EQ(out.copies[1].meshes.size(), 1u);  // no viseme2 on the teeth
  EXPECT_EQ(out.copies[1].meshes[0].mesh, 0);
  EXPECT_EQ(std::tie(out.copies[2].fapID, out.copies[2].highLevelSelect, out.copies[2].amplitude),
            std::make_tuple(2, 1, 40));
}

TEST(ShapeKeyCopies, MalformedNamesNameTheMesh) {
  FaceModel model = keyedModel();
  model.meshes[1].morphTargets[2].name = "fap3@";
  const Error e = errorOf([&] { shapesFromShapeKeys(model); });
  EXPECT_EQ(e.field(), "mesh 'Teeth' morph target 'fap3@'");
  EXPECT_TRUE(contains(e.reason(), "fap<N>[_<name>]@<amplitude>"));
  model = keyedModel();
  model.meshes[1].morphTargets[1].name = "fap3_open_jaw@512";
  EXPECT_TRUE(contains(errorOf([&] { shapesFromShapeKeys(model); }).reason(), "twice"));
}

TEST(ShapeKeyCopies, FeedTheGenerator) {
  const FaceModel model = keyedModel();
  const ShapeKeyCopies out = shapesFromShapeKeys(model);
  const FapuMeasurement fapu = measureFapu(model);
  const GeneratedTables g = generateFaceDefTables(model, fapu, out.copies, {0.01, 1e-6});
  ASSERT_EQ(g.faceDefTables.size(), 3u);
  const FatEvaluator eval({model, g.faceDefTables}, fapu);
  FapFrame f;
  f.set(3, 256);  // half of the sculpted 512
  const FatState s = eval.evaluate(f);
  EXPECT_LE(
      (s.coord[0].row(1) - model.meshes[0].coord.row(1) - Eigen::RowVector3d(0, -0.025, 0)).norm(),
      1e-8);
  EXPECT_LE(
      (s.coord[1].row(1) - model.meshes[1].coord.row(1) - Eigen::RowVector3d(0, -0.02, 0)).norm(),
      1e-8);
}

namespace {

// A one-key pose of transform `t`: its rotation about Y by `angle` (radians), or its
// translation.
TransformChannel rotationAboutY(int t, double angle) {
  TransformChannel c;
  c.transform = t;
  c.path = TransformChannel::Path::Rotation;
  c.times = {0};
  const Eigen::Quaterniond q(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()));
  c.values = {q.x(), q.y(), q.z(), q.w()};
  return c;
}

TransformChannel translation(int t, Eigen::Vector3d to) {
  TransformChannel c;
  c.transform = t;
  c.path = TransformChannel::Path::Translation;
  c.times = {0, 1};  // the pose is the last key
  c.values = {9, 9, 9, to.x(), to.y(), to.z()};
  return c;
}

}  // namespace

TEST(ShapeKeyCopies, AnimationsOfOurNamesArePosesOfTheTransforms) {
  FaceModel model = keyedModel();
  // Teeth follow the jaw: the pose joins the morph targets of the same name.
  model.animations.push_back({"fap3_open_jaw@512", {}, {translation(1, {0, -0.03, 0})}});
  // The whole head turns: a copy of its own (no morph target has that name).
  model.animations.push_back({"fap49_head_yaw@20000", {}, {rotationAboutY(0, 0.2)}});
  model.animations.push_back({"idle", {}, {rotationAboutY(0, 1)}});
  model.animations.push_back({"talk", {}, {}});  // weights only (none here): not a pose
  const ShapeKeyCopies out = shapesFromShapeKeys(model);
  ASSERT_EQ(out.copies.size(), 4u);
  EXPECT_EQ(out.ignored, (std::vector<std::string>{"smile", "Basis.001", "idle"}));
  const FaceShape& jaw = out.copies[0];
  EXPECT_EQ(deformedModel(neutralFaceModel(model), jaw).meshes[0].coord.row(1),
            model.meshes[0].coord.row(1) + Eigen::RowVector3d(0, -0.05, 0));
  ASSERT_EQ(jaw.transforms.size(), model.transforms.size());
  EXPECT_EQ(jaw.transforms[1].translation, Eigen::Vector3d(0, -0.03, 0));
  EXPECT_EQ(jaw.transforms[0].translation, Eigen::Vector3d::Zero());
  const FaceShape& yaw = out.copies[3];
  EXPECT_EQ(std::make_pair(yaw.fapID, yaw.amplitude), std::make_pair(49, 20000));
  EXPECT_TRUE(yaw.meshes.empty());
  ASSERT_EQ(yaw.transforms.size(), model.transforms.size());
  EXPECT_NEAR(Eigen::AngleAxisd(yaw.transforms[0].rotation).angle(), 0.2, 1e-12);

  // The generator turns the poses into FaceDefTransforms the evaluator follows linearly.
  const FapuMeasurement fapu = measureFapu(model);
  const GeneratedTables g =
      generateFaceDefTables(neutralFaceModel(model), fapu, out.copies, {0.01, 1e-6});
  const FatEvaluator eval({neutralFaceModel(model), g.faceDefTables}, fapu);
  FapFrame f;
  f.set(3, 256);
  f.set(49, 10000);
  const FatState s = eval.evaluate(f);
  EXPECT_LE((s.transforms[1].translation - Eigen::Vector3d(0, -0.015, 0)).norm(), 1e-9);
  const Eigen::AngleAxisd turn(s.transforms[0].rotation);
  EXPECT_NEAR(turn.angle(), 0.1, 1e-9);
  EXPECT_NEAR(std::abs(turn.axis().y()), 1, 1e-9);
}

TEST(ShapeKeyCopies, PosesThatDoNotFitTheModelAreNamed) {
  FaceModel model = keyedModel();
  model.animations.push_back({"fap23@1000", {}, {rotationAboutY(7, 0.1)}});
  Error e = errorOf([&] { shapesFromShapeKeys(model); });
  EXPECT_EQ(e.field(), "animation 'fap23@1000'");
  EXPECT_TRUE(contains(e.reason(), "transform 7 out of range (the model has 2)")) << e.reason();
  model.animations.back().transformChannels[0] = rotationAboutY(0, 0.1);
  model.animations.back().transformChannels[0].values.pop_back();
  EXPECT_TRUE(contains(errorOf([&] { shapesFromShapeKeys(model); }).reason(),
                       "3 values for 1 keys (expected 4 a key)"));
  model.animations.back().name = "fap23@";
  e = errorOf([&] { shapesFromShapeKeys(model); });
  EXPECT_EQ(e.field(), "animation 'fap23@'");
  EXPECT_TRUE(contains(e.reason(), "fap<N>[_<name>]@<amplitude>"));
}
