// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "fat_test_face.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/fat/generate.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/wfm.hpp"
#include "test_support.hpp"

using namespace mpeg4face;
using mpeg4face::test::errorOf;

using mpeg4face::test::farthest;
using mpeg4face::test::frameFor;
using mpeg4face::test::testFace;

namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

double boundingDiagonal(const FaceModel& model) {
  Eigen::AlignedBox3d box;
  const auto world = model.meshWorldMatrices();
  for (std::size_t m = 0; m < model.meshes.size(); ++m) {
    for (Eigen::Index v = 0; v < model.meshes[m].coord.rows(); ++v) {
      box.extend(world[m] * model.meshes[m].coord.row(v).transpose());
    }
  }
  return box.diagonal().norm();
}

// How a "modeler" sculpts FAP `fap` at `amplitude` on the face mesh: a bump around `centre`,
// not linear in the amplitude (so that each interval has its own displacement).
Eigen::RowVector3d sculptedMotion(const Eigen::RowVector3d& p, int fap, double amplitude) {
  const Eigen::RowVector3d centre(0.01 * (fap % 7) - 0.03, 0.01 * (fap % 5) - 0.02, 0);
  const double r = (p - centre).head<2>().norm();
  if (r > 0.06) return Eigen::RowVector3d::Zero();
  const double a = amplitude * 3e-5;  // about one MNS unit per FAP unit
  return (1 - r / 0.06) * a * (1 + amplitude / 1500.0) *
         Eigen::RowVector3d(0.3, -1, 0.2 * (fap % 3));
}

// The model a modeler saved: the neutral with its face mesh sculpted.
FaceModel sculptedModel(const FaceModel& neutral, int fap, int amplitude, int select = 0) {
  FaceModel model = neutral;
  Points3& c = model.meshes[0].coord;
  for (Eigen::Index v = 0; v < c.rows(); ++v) {
    c.row(v) += sculptedMotion(c.row(v), fap + 10 * select, amplitude);
  }
  return model;
}

// `model` as the copy of FAP `fap` at `amplitude`, named as the shape-key grammar would.
FaceShape shapeOf(const FaceModel& neutral, const FaceModel& model, int fap, int amplitude,
                  int select = 0) {
  FaceShape copy = shapeFromDeformedModel(
      neutral, model,
      (fap <= 2 ? (fap == 1 ? "viseme" : "expression") + std::to_string(select)
                : "fap" + std::to_string(fap)) +
          "@" + std::to_string(amplitude));
  copy.fapID = fap;
  copy.highLevelSelect = select;
  copy.amplitude = amplitude;
  return copy;
}

FaceShape sculpt(const FaceModel& neutral, int fap, int amplitude, int select = 0) {
  return shapeOf(neutral, sculptedModel(neutral, fap, amplitude, select), fap, amplitude, select);
}

void expectReproduced(const FaceModel& neutral, const std::vector<FaceShape>& copies,
                      const GeneratedTables& generated) {
  const FapuMeasurement fapu = measureFapu(neutral);
  const FatEvaluator eval({neutral, generated.faceDefTables}, fapu);
  const double tolerance = 1e-5 * boundingDiagonal(neutral);
  for (const FaceShape& copy : copies) {
    EXPECT_LE(farthest(eval.evaluate(frameFor(copy)), neutral, copy), tolerance) << copy.name;
  }
}

const FaceDefTables& tableOf(const GeneratedTables& g, int fap, int select = 1) {
  for (const FaceDefTables& t : g.faceDefTables) {
    if (t.fapID == fap && (fap > 2 || t.highLevelSelect == select)) return t;
  }
  throw std::runtime_error("no table for FAP " + std::to_string(fap));
}

}  // namespace

TEST(FatGenerate, EvaluatingTheTablesReproducesEveryCopy) {
  const FaceModel neutral = testFace();
  const std::vector<FaceShape> copies = {
      sculpt(neutral, 3, 700),   sculpt(neutral, 3, -200),  sculpt(neutral, 3, 300),
      sculpt(neutral, 6, -300),  sculpt(neutral, 19, 100),  sculpt(neutral, 19, 400),
      sculpt(neutral, 31, -150), sculpt(neutral, 31, -600), sculpt(neutral, 1, 63, 3),
      sculpt(neutral, 2, 30, 1), sculpt(neutral, 2, 63, 1)};
  const GeneratedTables g = generateFaceDefTables(neutral, measureFapu(neutral), copies);
  EXPECT_TRUE(g.warnings.empty());
  ASSERT_EQ(g.faceDefTables.size(), 6u);
  EXPECT_EQ(g.faceDefTables[0].fapID, 1);  // sorted
  EXPECT_EQ(g.faceDefTables[0].highLevelSelect, 3);
  EXPECT_EQ(tableOf(g, 3).faceDefMesh[0].intervalBorders, (std::vector<int>{-200, 0, 300, 700}));
  EXPECT_EQ(tableOf(g, 6).faceDefMesh[0].intervalBorders, (std::vector<int>{-300, 0}));
  EXPECT_EQ(tableOf(g, 19).faceDefMesh[0].intervalBorders, (std::vector<int>{0, 100, 400}));
  EXPECT_EQ(tableOf(g, 31).faceDefMesh[0].intervalBorders, (std::vector<int>{-600, -150, 0}));
  EXPECT_EQ(tableOf(g, 2).faceDefMesh[0].intervalBorders, (std::vector<int>{0, 30, 63}));
  EXPECT_NO_THROW(validateMpegFace({neutral, g.faceDefTables}));
  expectReproduced(neutral, copies, g);
}

TEST(FatGenerate, BetweenAndBeyondTheCopiesTheMotionIsPiecewiseLinear) {
  const FaceModel neutral = testFace();
  const std::vector<FaceShape> copies = {sculpt(neutral, 3, -200), sculpt(neutral, 3, 300),
                                         sculpt(neutral, 3, 700)};
  const GeneratedTables g = generateFaceDefTables(neutral, measureFapu(neutral), copies);
  const FatEvaluator eval({neutral, g.faceDefTables}, measureFapu(neutral));
  const double tolerance = 1e-5 * boundingDiagonal(neutral);
  const Points3& p0 = neutral.meshes[0].coord;
  const auto at = [&](int value) {
    FapFrame f;
    f.set(3, value);
    return eval.evaluate(f).coord[0];
  };
  const auto copy = [&](int i) -> Points3 {
    return deformedModel(neutral, copies[i]).meshes[0].coord;
  };
  // 500 lies halfway between the copies at 300 and 700; 100 a third of the way to 300.
  EXPECT_LE((at(500) - (copy(1) + copy(2)) / 2).cwiseAbs().maxCoeff(), tolerance);
  EXPECT_LE((at(100) - (2 * p0 + copy(1)) / 3).cwiseAbs().maxCoeff(), tolerance);
  EXPECT_LE((at(-100) - (p0 + copy(0)) / 2).cwiseAbs().maxCoeff(), tolerance);
  // Beyond 700 the last interval continues: 1100 = 700 + (700 - 300).
  EXPECT_LE((at(1100) - (2 * copy(2) - copy(1))).cwiseAbs().maxCoeff(), tolerance);
  EXPECT_LE((at(-400) - (2 * copy(0) - p0)).cwiseAbs().maxCoeff(), tolerance);
}

TEST(FatGenerate, DisplacementsArePerFapuAndPerUnitOfAbsFapOnTheNegativeSide) {
  const FaceModel neutral = testFace();
  const FapuMeasurement fapu = measureFapu(neutral);
  const double mns = 0.03 / 1024;
  ASSERT_NEAR(fapu.unit(FapuKind::MNS), mns, 1e-15);
  const std::vector<FaceShape> copies = {sculpt(neutral, 4, -500), sculpt(neutral, 4, -200),
                                         sculpt(neutral, 5, -300)};
  const GeneratedTables g = generateFaceDefTables(neutral, fapu, copies);
  const FaceDefMesh& four = tableOf(g, 4).faceDefMesh[0];
  const FaceDefMesh& five = tableOf(g, 5).faceDefMesh[0];
  const int v = four.coordIndex[0];
  const int n = neutral.meshes[0].vertexCount();
  const Eigen::RowVector3d d200 = denseDisplacement(copies[1], 0, n).row(v);
  const Eigen::RowVector3d d500 = denseDisplacement(copies[0], 0, n).row(v);
  // Borders -500, -200, 0: D0 for [-500, -200], D1 for [-200, 0], per unit of |FAP| outwards.
  EXPECT_TRUE(four.displacements.row(1).isApprox(d200 / (200 * mns)));
  EXPECT_TRUE(four.displacements.row(0).isApprox((d500 - d200) / (300 * mns)));
  // One interval is signed (rule 6): a copy at -300 gives D = d / (-300 FAPU).
  const int w = five.coordIndex[0];
  const Eigen::RowVector3d d = denseDisplacement(copies[2], 0, n).row(w);
  EXPECT_TRUE(five.displacements.row(0).isApprox(d / (-300 * mns)));
  std::vector<double> weights;
  intervalWeights(five.intervalBorders, -300, weights);
  EXPECT_TRUE((weights[0] * mns * five.displacements.row(0)).isApprox(d));
}

TEST(FatGenerate, TheThresholdIsRelativeToTheFapu) {
  const FaceModel neutral = testFace();
  const FapuMeasurement fapu = measureFapu(neutral);
  const double mw = fapu.unit(FapuKind::MW);
  FaceModel model = neutral;
  model.meshes[0].coord(10, 0) += 0.02 * mw;   // above 0.01 MW
  model.meshes[0].coord(11, 1) += 0.005 * mw;  // below
  const FaceShape copy = shapeOf(neutral, model, 6, 100);
  GeneratedTables g = generateFaceDefTables(neutral, fapu, std::span(&copy, 1));
  EXPECT_EQ(tableOf(g, 6).faceDefMesh[0].coordIndex, std::vector<int>{10});
  g = generateFaceDefTables(neutral, fapu, std::span(&copy, 1), {0.001, std::nullopt});
  EXPECT_EQ(tableOf(g, 6).faceDefMesh[0].coordIndex, (std::vector<int>{10, 11}));
  g = generateFaceDefTables(neutral, fapu, std::span(&copy, 1), {0.01, 0.1 * mw});
  EXPECT_TRUE(g.faceDefTables.empty());
  ASSERT_EQ(g.warnings.size(), 1u);
  EXPECT_TRUE(contains(g.warnings[0], "copy 'fap6@100'")) << g.warnings[0];
}

TEST(FatGenerate, TransformChangesBecomeFaceDefTransforms) {
  const FaceModel neutral = testFace();
  const Transform& eye0 = neutral.transforms[1];
  // FAP 23 (yaw_l_eyeball, AU) sculpted at 20000: the eye turned by 0.2 rad about -y.
  FaceModel turned = neutral;
  turned.transforms[1].rotation = eye0.rotation * Eigen::AngleAxisd(0.2, -Eigen::Vector3d::UnitY());
  const FaceShape yaw = shapeOf(neutral, turned, 23, 20000);
  // FAP 27 (thrust_l_eyeball, ES) at 500: the eye moved forward and grew a little.
  FaceModel thrusted = neutral;
  thrusted.transforms[1].translation += Eigen::Vector3d(0, 0, 0.004);
  thrusted.transforms[1].scale = {1.1, 1.1, 1.1};
  const FaceShape thrust = shapeOf(neutral, thrusted, 27, 500);
  const std::vector<FaceShape> copies = {yaw, thrust};
  const FapuMeasurement fapu = measureFapu(neutral);
  const GeneratedTables g = generateFaceDefTables(neutral, fapu, copies);
  EXPECT_TRUE(g.warnings.empty());
  const FaceDefTables& t23 = tableOf(g, 23);
  EXPECT_TRUE(t23.faceDefMesh.empty());
  ASSERT_EQ(t23.faceDefTransform.size(), 1u);
  const FaceDefTransform& r = t23.faceDefTransform[0];
  EXPECT_EQ(r.transform, 1);
  EXPECT_EQ(r.fieldId, FaceDefTransform::Field::Rotation);
  // R0^-1 * R is 0.2 rad about -y: per AU 0.2 / (20000 * 1e-5) = 1 rad per radian of FAP.
  EXPECT_NEAR((r.rotationDef.head<3>() * r.rotationDef[3]).dot(Eigen::Vector3d(0, -1, 0)), 1.0,
              1e-9);
  const FaceDefTables& t27 = tableOf(g, 27);
  ASSERT_EQ(t27.faceDefTransform.size(), 2u);
  const double es = fapu.unit(FapuKind::ES);
  EXPECT_EQ(t27.faceDefTransform[0].fieldId, FaceDefTransform::Field::Scale);
  EXPECT_TRUE(
      t27.faceDefTransform[0].scaleDef.isApprox(Eigen::Vector3d::Constant(0.1 / (500 * es))));
  EXPECT_EQ(t27.faceDefTransform[1].fieldId, FaceDefTransform::Field::Translation);
  EXPECT_TRUE(
      t27.faceDefTransform[1].translationDef.isApprox(Eigen::Vector3d(0, 0, 0.004 / (500 * es))));
  expectReproduced(neutral, copies, g);
}

TEST(FatGenerate, ATransformThatIsNotLinearInTheFapIsReported) {
  const FaceModel neutral = testFace();
  std::vector<FaceShape> copies = {sculpt(neutral, 48, 10000), sculpt(neutral, 48, 30000)};
  for (FaceShape& c : copies) c.transforms = neutral.transforms;
  copies[0].transforms[1].rotation =
      neutral.transforms[1].rotation * Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX());
  copies[1].transforms[1].rotation =
      neutral.transforms[1].rotation * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX());
  GeneratedTables g = generateFaceDefTables(neutral, measureFapu(neutral), copies);
  ASSERT_EQ(g.warnings.size(), 1u);
  EXPECT_TRUE(contains(g.warnings[0], "copy 'fap48@10000': transform 'LeftEyeX'")) << g.warnings[0];
  // The copy of largest |amplitude| defines the rotation.
  EXPECT_NEAR(tableOf(g, 48).faceDefTransform[0].rotationDef[3], 0.2 / 0.3, 1e-9);
  copies[0].transforms[1].rotation =
      neutral.transforms[1].rotation * Eigen::AngleAxisd(0.2 / 3, Eigen::Vector3d::UnitX());
  g = generateFaceDefTables(neutral, measureFapu(neutral), copies);
  EXPECT_TRUE(g.warnings.empty());
}

TEST(FatGenerate, TopologyMismatchNamesTheCopyAndTheMesh) {
  const FaceModel neutral = testFace();
  const FapuMeasurement fapu = measureFapu(neutral);
  // A whole model is checked where it becomes a shape (shapeFromDeformedModel)...
  const auto modelFieldOf = [&](const std::function<void(FaceModel&)>& breakIt) {
    FaceModel model = sculptedModel(neutral, 4, 100);
    breakIt(model);
    return errorOf([&] {
             const std::vector<FaceShape> copies = {sculpt(neutral, 3, 100),
                                                    shapeOf(neutral, model, 4, 100)};
             generateFaceDefTables(neutral, fapu, copies);
           })
        .field();
  };
  EXPECT_EQ(modelFieldOf([](FaceModel& m) { m.meshes[1].coord.conservativeResize(3, 3); }),
            "copy 'fap4@100' mesh 'LeftEye'");
  EXPECT_EQ(modelFieldOf([](FaceModel& m) { m.meshes[0].coordIndex[0] = 1; }),
            "copy 'fap4@100' mesh 'Face'");
  EXPECT_EQ(modelFieldOf([](FaceModel& m) { m.meshes.pop_back(); }), "copy 'fap4@100'");
  EXPECT_EQ(modelFieldOf([](FaceModel& m) { m.transforms[1].center.x() = 1; }),
            "copy 'fap4@100' transform 'LeftEyeX'");
  EXPECT_EQ(modelFieldOf([](FaceModel& m) { m.transforms[0].children.clear(); }),
            "copy 'fap4@100' transform 'Face'");
  EXPECT_EQ(modelFieldOf([](FaceModel& m) { m.meshes[0].coord(3, 1) = NAN; }),
            "copy 'fap4@100' mesh 'Face'");
  // ... a shape by the generator.
  const auto fieldOf = [&](const std::function<void(FaceShape&)>& breakIt) {
    std::vector<FaceShape> copies = {sculpt(neutral, 3, 100), sculpt(neutral, 4, 100)};
    breakIt(copies[1]);
    return errorOf([&] { generateFaceDefTables(neutral, fapu, copies); }).field();
  };
  EXPECT_EQ(fieldOf([](FaceShape& c) { c.meshes[0].displacement(0, 1) = NAN; }),
            "copy 'fap4@100' mesh 'Face'");
  EXPECT_EQ(
      fieldOf([](FaceShape& c) { std::swap(c.meshes[0].vertices[0], c.meshes[0].vertices[1]); }),
      "copy 'fap4@100' mesh 'Face'");
  EXPECT_EQ(fieldOf([](FaceShape& c) { c.meshes[0].vertices.pop_back(); }),
            "copy 'fap4@100' mesh 'Face'");
  EXPECT_EQ(fieldOf([](FaceShape& c) { c.meshes[0].mesh = 7; }), "copy 'fap4@100'");
  EXPECT_EQ(fieldOf([&](FaceShape& c) { c.transforms.assign(1, neutral.transforms[0]); }),
            "copy 'fap4@100'");
  EXPECT_EQ(fieldOf([](FaceShape& c) { c.amplitude = 0; }), "copy 'fap4@100' amplitude");
  EXPECT_EQ(fieldOf([](FaceShape& c) { c.fapID = 69; }), "copy 'fap4@100' fapID");
  EXPECT_EQ(fieldOf([](FaceShape& c) { c.fapID = 1, c.highLevelSelect = 15; }),
            "copy 'fap4@100' highLevelSelect");
  EXPECT_EQ(fieldOf([](FaceShape& c) { c.fapID = 2, c.highLevelSelect = 1, c.amplitude = 64; }),
            "copy 'fap4@100' amplitude");
  const Error e = errorOf([&] {
    std::vector<FaceShape> copies = {sculpt(neutral, 3, 100), sculpt(neutral, 3, 100)};
    copies[1].name = "again";
    generateFaceDefTables(neutral, fapu, copies);
  });
  EXPECT_TRUE(contains(e.what(), "copy 'again'") && contains(e.what(), "copy 'fap3@100'"))
      << e.what();
}

TEST(FatGenerate, AnUnmeasuredFapuNamesTheFeaturePointsItNeeds) {
  FaceModel neutral = testFace();
  neutral.featurePoints.erase("3.1");
  const FaceShape copy = sculpt(neutral, 19, 100);  // close_t_l_eyelid: IRISD
  const Error e =
      errorOf([&] { generateFaceDefTables(neutral, measureFapu(neutral), std::span(&copy, 1)); });
  EXPECT_EQ(e.field(), "copy 'fap19@100'");
  EXPECT_TRUE(contains(e.what(), "IRISD0 is not measured: needs 3.1 and 3.3, or 3.2 and 3.4"))
      << e.what();
}

// CANDIDE-3's MPEG-4 animation units are a FAP-to-vertex-motion table made by someone else.
// Convention (docs/fat.md): a unit's displacement is in its FAPU (the unit's "# MNS" line, or
// the standard's FAPU where the file has none: AU for FAP 23-26, ES for 27-28, IRISD for
// 29-30), so FAP value a moves each of its vertices by a * FAPU * d.
namespace {

// CANDIDE-3 with its feature points, and the motion of a unit straight from the file.
struct Candide3 {
  CandideModel candide = readWfm(mpeg4face::test::kData / "candide3" / "candide3.wfm");
  FaceModel neutral = withFeaturePoints(candide.model);
  FapuMeasurement fapu = measureFapu(neutral);

  static FaceModel withFeaturePoints(FaceModel model) {
    model.featurePoints =
        readFeaturePointCsv(mpeg4face::test::kData / "candide3" / "feature_points.csv", model)
            .featurePoints;
    return model;
  }
  double unitOf(const CandideUnit& u) const {
    if (u.fapu.empty()) return fapu.unit(fapInfo(u.fap).fapu);
    for (const FapuInfo& info : fapuTable()) {
      if (info.name == u.fapu) return fapu.unit(info.kind);
    }
    throw std::runtime_error("unknown FAPU " + u.fapu);
  }
  // Unit u at FAP value a added to coord.
  void motion(const CandideUnit& u, double a, Points3& coord) const {
    for (std::size_t i = 0; i < u.vertices.size(); ++i) {
      coord.row(u.vertices[i]) += a * unitOf(u) * u.displacements.row(static_cast<Eigen::Index>(i));
    }
  }
};

}  // namespace

TEST(FatCandide3, TablesFromSculptedCopiesReproduceTheUnitsMotion) {
  const Candide3 c3;
  const FaceModel& neutral = c3.neutral;
  const FapuMeasurement& fapu = c3.fapu;
  ASSERT_TRUE(fapu.missing().empty());
  const auto motion = [&](const CandideUnit& u, double a, Points3& coord) {
    c3.motion(u, a, coord);
  };
  const CandideModel& candide = c3.candide;
  std::vector<FaceShape> copies;
  int units = 0;
  for (const CandideUnit& u : candide.animationUnits) {
    if (u.fap == 0) continue;
    ++units;
    for (int amplitude : {-400, 300, 700}) {
      FaceShape& c = copies.emplace_back();
      c.name = u.name + " @" + std::to_string(amplitude);
      c.fapID = u.fap;
      c.amplitude = amplitude;
      Points3 d = Points3::Zero(neutral.meshes[0].coord.rows(), 3);
      motion(u, amplitude, d);
      c.meshes.push_back(sparseDisplacement(0, d));
    }
  }
  ASSERT_EQ(units, 54);
  const GeneratedTables g = generateFaceDefTables(neutral, fapu, copies);
  EXPECT_TRUE(g.warnings.empty());
  EXPECT_EQ(g.faceDefTables.size(), 54u);
  const FatEvaluator eval({neutral, g.faceDefTables}, fapu);
  const double tolerance = 1e-5 * boundingDiagonal(neutral);
  FapFrame all;
  Points3 expectedAll = neutral.meshes[0].coord;
  int index = 0;
  for (const CandideUnit& u : candide.animationUnits) {
    if (u.fap == 0) continue;
    for (int a : {-1000, -400, -150, 1, 300, 500, 700, 1200}) {
      FapFrame f;
      f.set(u.fap, a);
      Points3 expected = neutral.meshes[0].coord;
      motion(u, a, expected);
      EXPECT_LE((eval.evaluate(f).coord[0] - expected).cwiseAbs().maxCoeff(), tolerance)
          << u.name << " at " << a;
    }
    const int a = 100 * (index++ % 9) - 400;  // every FAP at once; units sharing vertices add
    all.set(u.fap, a);
    motion(u, a, expectedAll);
  }
  EXPECT_LE((eval.evaluate(all).coord[0] - expectedAll).cwiseAbs().maxCoeff(), tolerance);
}

// The same convention through the shape-key grammar: nameCandideFapUnits makes the units
// targets that faceFromShapeKeys turns into tables reproducing the file's motion.
TEST(FatCandide3, UnitsNamedInTheGrammarGiveTablesOfTheUnitsMotion) {
  const Candide3 c3;
  FaceModel model = Candide3::withFeaturePoints(candideToFaceModel(c3.candide));
  nameCandideFapUnits(model, c3.candide);
  const std::vector<MorphTarget>& targets = model.meshes[0].morphTargets;
  EXPECT_EQ(targets[0].name, c3.candide.animationUnits[0].name);  // not an MPEG-4 unit: kept
  EXPECT_TRUE(std::ranges::any_of(targets, [](const MorphTarget& t) {
    return t.name == "fap3_open_jaw@1000";  // unidirectional: no @-1000
  }));
  EXPECT_TRUE(std::ranges::none_of(
      targets, [](const MorphTarget& t) { return t.name == "fap3_open_jaw@-1000"; }));
  EXPECT_TRUE(std::ranges::any_of(
      targets, [](const MorphTarget& t) { return t.name == "fap6_stretch_l_cornerlip@-1000"; }));
  const ShapeKeyFace generated = faceFromShapeKeys(model);
  EXPECT_TRUE(generated.warnings.empty()) << generated.warnings[0];
  EXPECT_EQ(generated.face.faceDefTables.size(), 54u);
  const FatEvaluator eval(generated.face, c3.fapu);
  const double tolerance = 1e-5 * boundingDiagonal(c3.neutral);
  for (const CandideUnit& u : c3.candide.animationUnits) {
    if (u.fap == 0) continue;
    for (int a : {-700, 250, 1500}) {
      if (a < 0 && !fapInfo(u.fap).bidirectional) continue;
      FapFrame f;
      f.set(u.fap, a);
      Points3 expected = c3.neutral.meshes[0].coord;
      c3.motion(u, a, expected);
      EXPECT_LE((eval.evaluate(f).coord[0] - expected).cwiseAbs().maxCoeff(), tolerance)
          << u.name << " at " << a;
    }
  }
  // Without the feature points the FAPU is not measured: the unit is named.
  FaceModel bare = candideToFaceModel(c3.candide);
  const Error e = errorOf([&] { nameCandideFapUnits(bare, c3.candide); });
  EXPECT_TRUE(e.field().starts_with("animation unit 'FAP")) << e.field();
  EXPECT_TRUE(e.reason().find("is not measured") != std::string::npos) << e.reason();
}
