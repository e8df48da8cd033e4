// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/obj.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/model/mesh_cut.hpp"
#include "mpeg4face/model/mesh_resample.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::cutFaceModel;
using mpeg4face::FaceModel;
using mpeg4face::IndexedFaceSet;
using mpeg4face::test::errorOf;
using mpeg4face::test::kData;

// An n x n grid of unit quads in the z = 0 plane; vertex (i, j) = i + (n + 1) j at (i, j).
IndexedFaceSet grid(const std::string& name, int n) {
  IndexedFaceSet mesh;
  mesh.name = name;
  mesh.coord.resize((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) mesh.coord.row(i + (n + 1) * j) << i, j, 0;
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = i + (n + 1) * j;
      mesh.coordIndex.insert(mesh.coordIndex.end(), {a, a + 1, a + n + 2, a + n + 1, -1});
    }
  }
  return mesh;
}

TEST(Cut, KeepsFacesAboveThePlaneInModelSpace) {
  FaceModel model;
  IndexedFaceSet a = grid("A", 4);
  a.sourceIndex.resize(25);
  for (int v = 0; v < 25; ++v) a.sourceIndex[static_cast<size_t>(v)] = 100 + v;
  a.morphTargets.push_back({"Up", a.coord});
  a.weights = {0.0};
  model.addMeshWithTransform(a);
  const int b = model.addMeshWithTransform(grid("B", 1));
  // B sits at y = -5..-4 in model space: wholly below the plane, so removed.
  model.transforms[1].translation = Eigen::Vector3d(0, -5, 0);
  model.featurePoints["9.3"] = {0, 22, Eigen::Vector3d::Zero()};  // (2, 4): kept
  model.featurePoints["2.1"] = {0, 2, Eigen::Vector3d::Zero()};   // (2, 0): cut away
  model.featurePoints["2.10"] = {b, 3, Eigen::Vector3d::Zero()};  // on B
  model.featurePoints["7.1"] = {-1, -1, Eigen::Vector3d(0, -9, 0)};
  mpeg4face::MorphWeightAnimation animation;
  animation.channels.push_back({0, {}, {0.0}, {1.0}});
  animation.channels.push_back({b, {}, {0.0}, {}});
  model.animations.push_back(animation);
  model.validate();

  // Keep y >= 1.5: rows j = 2..4 of vertices, the 2 upper rows of quads (8 faces).
  const FaceModel out = cutFaceModel(model, {0, 1.5, 0}, {0, 1, 0});
  ASSERT_NO_THROW(out.validate());
  ASSERT_EQ(out.meshes.size(), 1u);
  const IndexedFaceSet& m = out.meshes[0];
  EXPECT_EQ(m.faceCount(), 8);
  ASSERT_EQ(m.vertexCount(), 15);
  for (int v = 0; v < 15; ++v) {
    // Old vertex 10 + v, in order, with its data.
    EXPECT_EQ(Eigen::Vector3d(m.coord.row(v)), Eigen::Vector3d(a.coord.row(10 + v)));
    EXPECT_EQ(m.sourceIndex[static_cast<size_t>(v)], 110 + v);
    EXPECT_EQ(Eigen::Vector3d(m.morphTargets[0].displacements.row(v)),
              Eigen::Vector3d(a.coord.row(10 + v)));
  }
  EXPECT_EQ(out.featurePoints.at("9.3").vertex, 12);
  EXPECT_EQ(*out.featurePointPosition("9.3"), Eigen::Vector3d(2, 4, 0));
  EXPECT_FALSE(out.featurePoints.count("2.1"));
  EXPECT_FALSE(out.featurePoints.count("2.10"));
  EXPECT_EQ(*out.featurePointPosition("7.1"), Eigen::Vector3d(0, -9, 0));  // free: kept
  EXPECT_EQ(out.transforms.size(), 2u);
  EXPECT_TRUE(out.transforms[1].meshes.empty());
  ASSERT_EQ(out.animations[0].channels.size(), 1u);
  EXPECT_EQ(out.animations[0].channels[0].mesh, 0);
}

TEST(Cut, KeepMeshFilterAndOtherSide) {
  FaceModel model;
  model.addMeshWithTransform(grid("A", 2));
  model.addMeshWithTransform(grid("B", 2));
  const FaceModel out = cutFaceModel(model, {0, 1, 0}, {0, -1, 0},
                                     [](const IndexedFaceSet& m) { return m.name == "B"; });
  ASSERT_EQ(out.meshes.size(), 1u);
  EXPECT_EQ(out.meshes[0].name, "B");
  EXPECT_EQ(out.meshes[0].faceCount(), 2);  // y <= 1: the lower row
  EXPECT_TRUE(out.transforms[0].meshes.empty());
  EXPECT_EQ(out.transforms[1].meshes, std::vector<int>{0});
}

TEST(Cut, BadPlane) {
  FaceModel model;
  model.addMeshWithTransform(grid("A", 1));
  EXPECT_EQ(errorOf([&] { cutFaceModel(model, {0, 0, 0}, {0, 0, 0}); }).field(), "plane");
  EXPECT_EQ(errorOf([&] { cutFaceModel(model, {0, 0, 0}, {0, NAN, 0}); }).field(), "plane");
}

// The MakeHuman head: body, eyes, teeth, tongue and eyelashes above the neck base (7.2).
TEST(Cut, MakeHumanHead) {
  FaceModel model = mpeg4face::readObj(kData / "makehuman" / "base.obj");
  const auto csvPath = kData / "makehuman" / "feature_points.csv";
  model.featurePoints = mpeg4face::readFeaturePointCsv(csvPath, model).featurePoints;
  const auto isHead = [](const IndexedFaceSet& m) {
    for (const char* prefix : {"body", "helper-l-eye", "helper-r-eye", "helper-upper-teeth",
                               "helper-lower-teeth", "helper-tongue"}) {
      if (m.name.starts_with(prefix)) return true;
    }
    return false;
  };
  const Eigen::Vector3d neck = *model.featurePointPosition("7.2");
  const FaceModel head = cutFaceModel(model, neck, {0, 1, 0}, isHead);
  ASSERT_NO_THROW(head.validate());
  int vertices = 0;
  for (const IndexedFaceSet& m : head.meshes) {
    EXPECT_TRUE(isHead(m)) << m.name;
    vertices += m.vertexCount();
    for (int v = 0; v < m.vertexCount(); ++v) ASSERT_GE(m.coord(v, 1), neck.y()) << m.name;
  }
  // Eyes, teeth, tongue, eyelashes (4 meshes) and the body's head and neck.
  EXPECT_EQ(head.meshes.size(), 10u);
  const int body = *head.findMesh("body");
  EXPECT_LT(head.meshes[static_cast<size_t>(body)].vertexCount(), 13380 / 2);
  EXPECT_GT(head.meshes[static_cast<size_t>(body)].vertexCount(), 13380 / 5);
  // Every feature point survives (all are above the neck base) at the same place ...
  ASSERT_EQ(head.featurePoints.size(), model.featurePoints.size());
  for (const auto& [id, fp] : model.featurePoints) {
    EXPECT_EQ(*head.featurePointPosition(id), *model.featurePointPosition(id)) << id;
  }
  const auto a = mpeg4face::measureFapu(model), b = mpeg4face::measureFapu(head);
  EXPECT_EQ(a.ES0.value, b.ES0.value);
  EXPECT_EQ(a.MW0.value, b.MW0.value);
  // ... and the CSV, in the whole OBJ's numbering, reads on the head alone the same way.
  const auto again = mpeg4face::readFeaturePointCsv(csvPath, head).featurePoints;
  for (const auto& [id, fp] : head.featurePoints) {
    EXPECT_EQ(again.at(id).mesh, fp.mesh) << id;
    EXPECT_EQ(again.at(id).vertex, fp.vertex) << id;
  }
  std::printf("MakeHuman head: %d vertices in %zu meshes\n", vertices, head.meshes.size());
  // The head resampled for denser and sparser clone targets (model/mesh_resample.hpp) stays valid
  // with every feature point.
  for (const FaceModel& resampled :
       {mpeg4face::subdivideFaceModel(head, 1), mpeg4face::decimateFaceModel(head, 0.5)}) {
    ASSERT_NO_THROW(resampled.validate());
    EXPECT_EQ(resampled.featurePoints.size(), head.featurePoints.size());
    int count = 0;
    for (const IndexedFaceSet& m : resampled.meshes) count += m.vertexCount();
    std::printf("  resampled: %d vertices\n", count);
  }
}

}  // namespace
