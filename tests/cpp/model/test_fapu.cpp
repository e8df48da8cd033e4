// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <algorithm>

#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/wfm.hpp"
#include "mpeg4face/model/fapu.hpp"

using namespace mpeg4face;

namespace {

// A face whose feature points are free coordinates at simple, known places (Y up, the face's
// left at +X): pupils 60 apart at y = 40, eyelids 12 apart, nose bottom at y = 0, inner
// upper lip at y = -20, outer lip corners 50 apart.
FaceModel syntheticFace() {
  FaceModel m;
  auto put = [&](const char* id, double x, double y, double z) {
    m.featurePoints[id] = FeaturePointBinding{-1, -1, {x, y, z}};
  };
  put("3.5", 30, 40, 10);
  put("3.6", -30, 40, 10);
  put("3.7", 40, 40, 8);
  put("3.11", 20, 40, 8);
  put("3.8", -20, 40, 8);
  put("3.12", -40, 40, 8);
  put("3.1", 30, 46, 10);
  put("3.3", 30, 34, 10);
  put("3.2", -30, 46, 10);
  put("3.4", -30, 34, 10);
  put("9.15", 0, 0, 20);
  put("2.2", 0, -20, 15);
  put("8.3", 25, -22, 12);
  put("8.4", -25, -22, 12);
  put("7.1", 0, -30, -40);
  put("2.1", 0, -60, 10);
  return m;
}

bool mentions(const std::vector<std::string>& list, const std::string& item) {
  return std::find(list.begin(), list.end(), item) != list.end();
}

}  // namespace

TEST(Fapu, MeasuresEveryDistanceFromTheStandardPoints) {
  const FapuMeasurement m = measureFapu(syntheticFace());
  EXPECT_TRUE(m.missing().empty());
  EXPECT_DOUBLE_EQ(m.ES0.value, 60.0);
  EXPECT_DOUBLE_EQ(m.IRISD0.value, 12.0);
  EXPECT_DOUBLE_EQ(m.ENS0.value, 40.0);
  EXPECT_DOUBLE_EQ(m.MNS0.value, 20.0);
  EXPECT_DOUBLE_EQ(m.MW0.value, 50.0);
  EXPECT_EQ(m.ES0.pointsUsed, (std::vector<std::string>{"3.5", "3.6"}));
  EXPECT_EQ(m.MNS0.pointsUsed, (std::vector<std::string>{"9.15", "2.2"}));
  EXPECT_EQ(m.MW0.method, "|8.3 - 8.4|");
  EXPECT_DOUBLE_EQ(m.unit(FapuKind::MNS), 20.0 / 1024.0);
  EXPECT_DOUBLE_EQ(m.unit(FapuKind::AU), 1e-5);
  EXPECT_DOUBLE_EQ(m.unit(FapuKind::None), 0.0);
}

TEST(Fapu, FallsBackToEyeCornersAndInnerLipCorners) {
  FaceModel face = syntheticFace();
  face.featurePoints.erase("3.5");
  face.featurePoints.erase("3.6");
  face.featurePoints.erase("8.3");
  face.featurePoints.erase("8.4");
  face.featurePoints["2.4"] = {-1, -1, {20, -20, 14}};
  face.featurePoints["2.5"] = {-1, -1, {-20, -20, 14}};
  const FapuMeasurement m = measureFapu(face);
  EXPECT_DOUBLE_EQ(m.ES0.value, 60.0);  // (40+20)/2 - (-20-40)/2
  EXPECT_TRUE(mentions(m.ES0.pointsUsed, "3.11") && mentions(m.ES0.pointsUsed, "3.12"));
  EXPECT_EQ(m.ES0.method, "|(3.7+3.11)/2 - (3.8+3.12)/2|");
  EXPECT_DOUBLE_EQ(m.MW0.value, 40.0);
  EXPECT_EQ(m.MW0.pointsUsed, (std::vector<std::string>{"2.4", "2.5"}));
}

TEST(Fapu, OneEyeIsEnoughForIrisdAndEns) {
  FaceModel face = syntheticFace();
  for (const char* id : {"3.2", "3.4", "3.6", "3.8", "3.12"}) face.featurePoints.erase(id);
  const FapuMeasurement m = measureFapu(face);
  EXPECT_DOUBLE_EQ(m.IRISD0.value, 12.0);
  EXPECT_EQ(m.IRISD0.method, "3.1.y - 3.3.y");
  EXPECT_DOUBLE_EQ(m.ENS0.value, 40.0);
  EXPECT_FALSE(m.ES0.measured);
  EXPECT_EQ(m.missing(), (std::vector<std::string>{"ES0"}));
  // An unmeasured distance says which points it needs.
  EXPECT_EQ(m.ES0.method, "needs 3.5 and 3.6, or the eye corners 3.7, 3.11, 3.8 and 3.12");
}

TEST(Fapu, NothingBoundMeansNothingMeasured) {
  const FapuMeasurement m = measureFapu(FaceModel{});
  EXPECT_EQ(m.missing().size(), 5u);
  EXPECT_EQ(m.MNS0.method, "needs 9.15 and 2.2");
  EXPECT_EQ(m.MW0.method, "needs 8.3 and 8.4, or 2.4 and 2.5");
  EXPECT_DOUBLE_EQ(m.unit(FapuKind::MNS), 0.0);
}

TEST(Fapu, UpsideDownFaceIsNotMeasuredAndSaysWhy) {
  FaceModel face = syntheticFace();
  for (auto& [id, fp] : face.featurePoints) fp.position.y() = -fp.position.y();
  const FapuMeasurement m = measureFapu(face);
  EXPECT_FALSE(m.MNS0.measured);
  EXPECT_NE(m.MNS0.method.find("not positive"), std::string::npos);
  EXPECT_TRUE(m.ES0.measured);  // a distance, not a signed difference
}

TEST(Fapu, FeaturePointsOnMeshesUseTheirTransforms) {
  FaceModel face;
  IndexedFaceSet mesh;
  mesh.name = "Face";
  mesh.coord.resize(3, 3);
  mesh.coord << 0, 0, 0, 0, -1, 0, 1, 0, 0;
  mesh.coordIndex = {0, 1, 2, -1};
  face.addMeshWithTransform(mesh);
  face.transforms[0].scale = {10, 10, 10};
  face.featurePoints["9.15"] = {0, 0, Eigen::Vector3d::Zero()};
  face.featurePoints["2.2"] = {0, 1, Eigen::Vector3d::Zero()};
  EXPECT_DOUBLE_EQ(measureFapu(face).MNS0.value, 10.0);
}

TEST(LocationConstraints, SatisfiedConstraintsGiveNoWarning) {
  const FaceModel face = syntheticFace();
  EXPECT_TRUE(checkLocationConstraints(face, measureFapu(face)).empty());
}

TEST(LocationConstraints, EqualityViolationIsMeasuredInEs0) {
  FaceModel face = syntheticFace();
  face.featurePoints["2.1"].position.x() = 0.042 * 60.0;  // 4.2% of ES0 off the 7.1 plane
  const auto warnings = checkLocationConstraints(face, measureFapu(face));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].featurePoint, "2.1");
  EXPECT_EQ(warnings[0].axis, 'x');
  EXPECT_EQ(warnings[0].message, "2.1.x differs from 7.1.x by 4.2% of ES0");
  EXPECT_FALSE(warnings[0].advisory);
}

TEST(LocationConstraints, InequalityAndMidpointViolations) {
  FaceModel face = syntheticFace();
  // 2.11 (chin left corner) must lie between 8.7.x and 8.3.x; put it outside 8.3.
  face.featurePoints["8.7"] = {-1, -1, {12, -26, 12}};
  face.featurePoints["2.11"] = {-1, -1, {40, -50, 10}};
  // 2.6 must sit at (2.2.x + 2.4.x)/2 = 10.
  face.featurePoints["2.4"] = {-1, -1, {20, -20, 14}};
  face.featurePoints["2.6"] = {-1, -1, {10, -19, 15}};
  auto warnings = checkLocationConstraints(face, measureFapu(face));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].message, "2.11.x should be < 8.3.x but exceeds it by 25.0% of ES0");

  face.featurePoints["2.6"].position.x() = 16;
  warnings = checkLocationConstraints(face, measureFapu(face));
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_EQ(warnings[0].message, "2.6.x differs from (2.2.x+2.4.x)/2 by 10.0% of ES0");
}

TEST(LocationConstraints, AlternativesInTable6AreAdvisory) {
  FaceModel face = syntheticFace();
  face.featurePoints["4.1"] = {-1, -1, {10, 60, 10}};
  face.featurePoints["4.5"] = {-1, -1, {50, 60, 10}};
  face.featurePoints["4.3"] = {-1, -1, {20, 65, 10}};  // not the midpoint (30)
  const auto warnings = checkLocationConstraints(face, measureFapu(face));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(warnings[0].advisory);
  EXPECT_NE(warnings[0].message.find("may instead be"), std::string::npos) << warnings[0].message;
}

TEST(Fapu, Candide3WithItsFeaturePointCsvHasAllFiveFapu) {
  const std::string dir = MPEG4FACE_TEST_DATA "/candide3/";
  const CandideModel candide = readWfm(dir + "candide3.wfm");
  FaceModel model = candideToFaceModel(candide);
  model.featurePoints = readFeaturePointCsv(dir + "feature_points.csv", model).featurePoints;
  const FapuMeasurement m = measureFapu(model);
  EXPECT_TRUE(m.missing().empty());
  // Expected values straight from the vertex list (vertex numbers from the CSV): CANDIDE has
  // no pupil points, so the eye-corner midpoints stand in for them.
  const Points3& v = model.meshes[0].coord;
  const Eigen::Vector3d leftPupil = (v.row(20) + v.row(23)).transpose() / 2;   // 3.7, 3.11
  const Eigen::Vector3d rightPupil = (v.row(53) + v.row(56)).transpose() / 2;  // 3.12, 3.8
  EXPECT_NEAR(m.ES0.value, (leftPupil - rightPupil).norm(), 1e-12);
  EXPECT_NEAR(m.IRISD0.value, ((v(21, 1) - v(22, 1)) + (v(54, 1) - v(55, 1))) / 2, 1e-12);
  EXPECT_NEAR(m.ENS0.value, (leftPupil.y() + rightPupil.y()) / 2 - v(6, 1), 1e-12);
  EXPECT_NEAR(m.MNS0.value, v(6, 1) - v(87, 1), 1e-12);
  EXPECT_NEAR(m.MW0.value, (v.row(31) - v.row(64)).norm(), 1e-12);
  // CANDIDE is about 2 units tall: the distances must be in that scale and positive.
  for (const FapuDistance* d : {&m.ES0, &m.IRISD0, &m.ENS0, &m.MNS0, &m.MW0}) {
    EXPECT_GT(d->value, 0.01);
    EXPECT_LT(d->value, 1.0);
  }
}
