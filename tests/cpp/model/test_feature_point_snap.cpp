// SPDX-License-Identifier: GPL-3.0-or-later
// model/feature_point_snap.hpp: free feature points bound to the vertex they lie on.
#include "mpeg4face/model/feature_point_snap.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <string>

#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/obj.hpp"
#include "test_support.hpp"

namespace {

using namespace mpeg4face;
using mpeg4face::test::kData;

FaceModel makeHuman() {
  FaceModel model = readObj(kData / "makehuman" / "base.obj");
  model.featurePoints =
      readFeaturePointCsv(kData / "makehuman" / "feature_points.csv", model).featurePoints;
  return model;
}

// The extent of the model's feature points: the face's size the tolerance is a fraction of.
double faceSize(const FaceModel& model) {
  Points3 p(static_cast<Eigen::Index>(model.featurePoints.size()), 3);
  Eigen::Index row = 0;
  for (const auto& [id, binding] : model.featurePoints) {
    p.row(row++) = model.featurePointPosition(id)->transpose();
  }
  return (p.colwise().maxCoeff() - p.colwise().minCoeff()).norm();
}

// Each vertex-bound point, made free at its vertex's position (as another tool's landmarks or
// a CSV's fp,x,y,z give it), is bound again to that vertex or one at the same place (a seam's
// copy), and said so. 7.1 and 7.2, free inside the head, stay free.
TEST(FeaturePointSnap, FreePointsOnTheSurfaceGoBackToTheirVertices) {
  const FaceModel truth = makeHuman();
  FaceModel model = truth;
  std::size_t onVertices = 0;
  for (auto& [id, binding] : model.featurePoints) {
    if (binding.mesh < 0) continue;
    binding = {-1, -1, *truth.featurePointPosition(id)};
    ++onVertices;
  }
  ASSERT_GT(onVertices, 80U);
  const FeaturePointSnap snap = snapFeaturePointsToVertices(model);
  EXPECT_TRUE(snap.unbound.empty()) << snap.unbound.front();
  ASSERT_EQ(snap.notes.size(), onVertices);
  EXPECT_NE(snap.notes.front().find("bound to vertex"), std::string::npos) << snap.notes.front();
  for (const auto& [id, binding] : model.featurePoints) {
    EXPECT_EQ(binding.mesh, truth.featurePoints.at(id).mesh) << id;
    EXPECT_LT((*model.featurePointPosition(id) - *truth.featurePointPosition(id)).norm(), 1e-9)
        << id;
  }
  EXPECT_EQ(model.featurePoints.at("7.1").mesh, -1);
}

// A point a little off the surface is bound to the nearest vertex; one farther than the
// tolerance stays free and is reported with its distance; points on vertices are untouched.
TEST(FeaturePointSnap, OnlyPointsWithinTheToleranceAreBound) {
  FaceModel model = makeHuman();
  const double size = faceSize(model);
  const FeaturePointBinding nose = model.featurePoints.at("9.3");
  const Eigen::Vector3d tip = *model.featurePointPosition("9.3");
  const Eigen::Vector3d forward(0, 0, 1);  // MakeHuman faces +Z
  model.featurePoints["9.3"] = {-1, -1, tip + 0.008 * size * forward};
  model.featurePoints["2.1"] = {-1, -1, *model.featurePointPosition("2.1") + 0.05 * size * forward};
  const FeaturePointBinding kept = model.featurePoints.at("3.5");
  const FeaturePointSnap snap = snapFeaturePointsToVertices(model);
  ASSERT_EQ(snap.notes.size(), 1U);
  EXPECT_NE(snap.notes[0].find("feature point 9.3 bound to vertex"), std::string::npos);
  EXPECT_EQ(model.featurePoints.at("9.3").mesh, 0);
  EXPECT_LT((*model.featurePointPosition("9.3") - tip).norm(), 0.02 * size);
  EXPECT_EQ(model.featurePoints.at("9.3").vertex, nose.vertex);  // the nose tip sticks out
  ASSERT_EQ(snap.unbound.size(), 1U);
  EXPECT_TRUE(snap.unbound[0].starts_with("feature point 2.1 is left free: ")) << snap.unbound[0];
  EXPECT_TRUE(snap.unbound[0].ends_with("of the face's size off the nearest surface (2.00% "
                                        "allowed)"))
      << snap.unbound[0];
  EXPECT_EQ(model.featurePoints.at("2.1").mesh, -1);
  EXPECT_EQ(model.featurePoints.at("3.5").vertex, kept.vertex);
}

// Positions are in model space: a mesh under a moved and scaled Transform is searched where
// the Transform puts it.
TEST(FeaturePointSnap, MeshesAreSearchedWhereTheirTransformsPutThem) {
  IndexedFaceSet quad;
  quad.name = "quad";
  quad.coord.resize(4, 3);
  quad.coord << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  quad.coordIndex = {0, 1, 2, 3, -1};
  FaceModel model;
  const int mesh = model.addMeshWithTransform(quad);
  Transform& t = model.transforms[static_cast<std::size_t>(model.roots[0])];
  t.translation = Eigen::Vector3d(10, 0, 0);
  t.scale = Eigen::Vector3d::Constant(2);
  model.featurePoints["9.3"] = {-1, -1, Eigen::Vector3d(12, 1.9, 0)};  // near vertex 2 at (12, 2)
  model.featurePoints["2.1"] = {-1, -1, Eigen::Vector3d(1, 1, 0)};     // where it was unmoved
  const FeaturePointSnap snap = snapFeaturePointsToVertices(model);
  EXPECT_EQ(model.featurePoints.at("9.3").mesh, mesh);
  EXPECT_EQ(model.featurePoints.at("9.3").vertex, 2);
  EXPECT_EQ(model.featurePoints.at("2.1").mesh, -1);
  EXPECT_EQ(snap.unbound.size(), 1U);
}

TEST(FeaturePointSnap, AModelWithoutTrianglesLeavesEveryPointFree) {
  FaceModel model;
  model.featurePoints["2.1"] = {-1, -1, Eigen::Vector3d(0, 0, 0)};
  const FeaturePointSnap snap = snapFeaturePointsToVertices(model);
  ASSERT_EQ(snap.unbound.size(), 1U);
  EXPECT_NE(snap.unbound[0].find("the model has no triangles"), std::string::npos);
}

}  // namespace
