// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mpeg4face/error.hpp"
#include "mpeg4face/model/face_model.hpp"

using namespace mpeg4face;

namespace {

IndexedFaceSet quadAndTriangle() {
  IndexedFaceSet mesh;
  mesh.name = "Face";
  mesh.coord.resize(5, 3);
  mesh.coord << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 2, 0, 0;
  mesh.coordIndex = {0, 1, 2, 3, -1, 1, 4, 2, -1};
  return mesh;
}

}  // namespace

TEST(IndexedFaceSet, FacesAndFanTriangulation) {
  const IndexedFaceSet mesh = quadAndTriangle();
  EXPECT_EQ(mesh.faceCount(), 2);
  EXPECT_EQ(mesh.faceRanges(), (std::vector<std::pair<int, int>>{{0, 4}, {5, 8}}));
  EXPECT_EQ(mesh.triangles(), (std::vector<int>{0, 1, 2, 0, 2, 3, 1, 4, 2}));
}

TEST(IndexedFaceSet, LastFaceWithoutTerminatorCounts) {
  IndexedFaceSet mesh = quadAndTriangle();
  mesh.coordIndex.pop_back();
  EXPECT_EQ(mesh.faceRanges().size(), 2u);
  EXPECT_EQ(mesh.triangles().size(), 9u);
}

TEST(Transform, RotatesAboutItsCentreLikeVrml) {
  Transform t;
  t.center = {1, 0, 0};
  t.rotation = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ());
  t.translation = {0, 0, 5};
  // The centre stays put under rotation and scale; only the translation moves it.
  EXPECT_TRUE((t.localMatrix() * Eigen::Vector3d(1, 0, 0)).isApprox(Eigen::Vector3d(1, 0, 5)));
  // (2,0,0) is one unit right of the centre; a quarter turn about Z puts it one unit above.
  EXPECT_TRUE((t.localMatrix() * Eigen::Vector3d(2, 0, 0)).isApprox(Eigen::Vector3d(1, 1, 5)));
  t.scale = {2, 2, 2};
  EXPECT_TRUE((t.localMatrix() * Eigen::Vector3d(2, 0, 0)).isApprox(Eigen::Vector3d(1, 2, 5)));
}

TEST(FaceModel, WorldMatricesAndFeaturePointsFollowTheHierarchy) {
  FaceModel model;
  const int face = model.addMeshWithTransform(quadAndTriangle());
  IndexedFaceSet eye = quadAndTriangle();
  eye.name = "LeftEye";
  model.meshes.push_back(eye);
  Transform eyeTransform;
  eyeTransform.name = "LeftEye";
  eyeTransform.translation = {10, 0, 0};
  eyeTransform.meshes = {1};
  model.transforms.push_back(eyeTransform);
  model.transforms[0].children = {1};
  model.transforms[0].translation = {0, 100, 0};
  model.validate();

  const auto world = model.meshWorldMatrices();
  ASSERT_EQ(world.size(), 2u);
  EXPECT_TRUE((world[face] * Eigen::Vector3d::Zero()).isApprox(Eigen::Vector3d(0, 100, 0)));
  EXPECT_TRUE((world[1] * Eigen::Vector3d::Zero()).isApprox(Eigen::Vector3d(10, 100, 0)));

  model.featurePoints["3.5"] = {1, 2, Eigen::Vector3d::Zero()};
  model.featurePoints["7.1"] = {-1, -1, {0, -3, -1}};
  EXPECT_TRUE(model.featurePointPosition("3.5")->isApprox(Eigen::Vector3d(11, 101, 0)));
  EXPECT_TRUE(model.featurePointPosition("7.1")->isApprox(Eigen::Vector3d(0, -3, -1)));
  EXPECT_FALSE(model.featurePointPosition("2.1").has_value());
  EXPECT_EQ(model.findMesh("LeftEye"), 1);
  EXPECT_EQ(model.findTransform("Face"), 0);
  EXPECT_FALSE(model.findMesh("Nose").has_value());
}

namespace {

// Expects validate() to throw an Error whose field contains `field`.
void expectInvalid(const FaceModel& model, const std::string& field) {
  try {
    model.validate();
    ADD_FAILURE() << "validate() accepted a model with a broken " << field;
  } catch (const Error& e) {
    EXPECT_NE(e.field().find(field), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(FaceModel, ValidateNamesTheBrokenReference) {
  FaceModel good;
  good.addMeshWithTransform(quadAndTriangle());
  good.validate();

  FaceModel badIndex = good;
  badIndex.meshes[0].coordIndex[2] = 9;
  expectInvalid(badIndex, "coordIndex");

  FaceModel badTarget = good;
  badTarget.meshes[0].morphTargets.push_back({"fap3@512", Points3::Zero(4, 3)});
  expectInvalid(badTarget, "morph target 'fap3@512'");

  FaceModel badWeights = good;
  badWeights.meshes[0].morphTargets.push_back({"t", Points3::Zero(5, 3)});
  badWeights.meshes[0].weights = {0.5, 0.5};
  expectInvalid(badWeights, "weights");

  FaceModel badFp = good;
  badFp.featurePoints["2.1"] = {0, 99, Eigen::Vector3d::Zero()};
  expectInvalid(badFp, "feature point 2.1");

  Transform b;
  b.name = "B";
  b.children = {0};
  FaceModel cycle = good;
  cycle.transforms.push_back(b);
  cycle.transforms[0].children = {1};
  cycle.roots.clear();
  expectInvalid(cycle, "transform");

  FaceModel twoParents = good;
  twoParents.transforms.push_back(b);
  twoParents.roots.push_back(1);
  expectInvalid(twoParents, "");
}

TEST(FaceModel, CycleDoesNotHangWorldMatrices) {
  FaceModel model;
  model.addMeshWithTransform(quadAndTriangle());
  model.transforms[0].children = {0};
  EXPECT_EQ(model.meshWorldMatrices().size(), 1u);
  EXPECT_THROW(model.validate(), Error);
}
