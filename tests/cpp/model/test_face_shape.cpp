// SPDX-License-Identifier: GPL-3.0-or-later
// model/face_shape.hpp: a shape as what moves, and the conversions at the edges that have whole
// models.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "fat_test_face.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/model/face_shape.hpp"
#include "test_support.hpp"

using namespace mpeg4face;
using mpeg4face::test::errorOf;
using mpeg4face::test::testFace;

TEST(FaceShape, SparseAndDenseDisplacementsRoundTrip) {
  Points3 dense = Points3::Zero(5, 3);
  dense.row(1) << 0, -1, 0;
  dense.row(4) << 0.5, 0, 2;
  const MeshDisplacement d = sparseDisplacement(2, dense);
  EXPECT_EQ(d.mesh, 2);
  EXPECT_EQ(d.vertices, (std::vector<int>{1, 4}));
  EXPECT_EQ(d.displacement.row(0), dense.row(1));
  EXPECT_EQ(d.displacement.row(1), dense.row(4));
  FaceShape shape;
  shape.meshes = {d};
  EXPECT_EQ(denseDisplacement(shape, 2, 5), dense);
  EXPECT_EQ(denseDisplacement(shape, 0, 3), Points3::Zero(3, 3));  // a mesh it does not move
}

TEST(FaceShape, FromADeformedModelAndBack) {
  const FaceModel neutral = testFace();
  FaceModel deformed = neutral;
  deformed.meshes[0].coord.row(3) += Eigen::RowVector3d(0, 0.01, 0);
  deformed.meshes[0].coord.row(7) += Eigen::RowVector3d(0.02, 0, 0);
  FaceShape shape = shapeFromDeformedModel(neutral, deformed, "lift");
  EXPECT_EQ(shape.name, "lift");
  ASSERT_EQ(shape.meshes.size(), 1u);
  EXPECT_EQ(shape.meshes[0].mesh, 0);
  EXPECT_EQ(shape.meshes[0].vertices, (std::vector<int>{3, 7}));
  EXPECT_TRUE(shape.transforms.empty());  // no Transform changes: the neutral's
  EXPECT_EQ(&shapeTransforms(neutral, shape), &neutral.transforms);
  EXPECT_EQ(deformedModel(neutral, shape).meshes[0].coord, deformed.meshes[0].coord);
  EXPECT_EQ(deformedModel(neutral, shape).meshes[1].coord, neutral.meshes[1].coord);

  deformed.transforms[1].translation += Eigen::Vector3d(0, 0, 0.003);
  shape = shapeFromDeformedModel(neutral, deformed, "lift and thrust");
  ASSERT_EQ(shape.transforms.size(), neutral.transforms.size());
  EXPECT_EQ(shapeTransforms(neutral, shape)[1].translation, deformed.transforms[1].translation);
  EXPECT_EQ(deformedModel(neutral, shape).transforms[1].translation,
            deformed.transforms[1].translation);

  // The neutral itself moves nothing.
  shape = shapeFromDeformedModel(neutral, neutral, "neutral");
  EXPECT_TRUE(shape.meshes.empty());
  EXPECT_TRUE(shape.transforms.empty());
}

TEST(FaceShape, MeshDisplacementsOfEvaluatedPositions) {
  const FaceModel neutral = testFace();
  std::vector<Points3> coord;
  for (const IndexedFaceSet& mesh : neutral.meshes) coord.push_back(mesh.coord);
  coord[1].row(2) += Eigen::RowVector3d(1, 2, 3);
  const std::vector<MeshDisplacement> d = meshDisplacements(neutral, coord);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].mesh, 1);
  EXPECT_EQ(d[0].vertices, std::vector<int>{2});
  EXPECT_EQ(d[0].displacement.row(0), Eigen::RowVector3d(1, 2, 3));
}

TEST(FaceShape, ACheckNamesTheCopyAndTheMesh) {
  const FaceModel neutral = testFace();
  const auto fieldOf = [&](FaceShape shape) {
    shape.name = "bad";
    return errorOf([&] { checkFaceShape(neutral, shape); }).field();
  };
  const auto one = [](int mesh, std::vector<int> vertices) {
    FaceShape s;
    s.meshes.push_back(
        {mesh, vertices, Points3::Zero(static_cast<Eigen::Index>(vertices.size()), 3)});
    return s;
  };
  EXPECT_NO_THROW(checkFaceShape(neutral, one(0, {1, 5})));
  EXPECT_EQ(fieldOf(one(0, {5, 1})), "copy 'bad' mesh 'Face'");  // not ascending
  EXPECT_EQ(fieldOf(one(0, {neutral.meshes[0].vertexCount()})), "copy 'bad' mesh 'Face'");
  EXPECT_EQ(fieldOf(one(9, {0})), "copy 'bad'");
  FaceShape twice = one(1, {0});
  twice.meshes.push_back(twice.meshes[0]);
  EXPECT_EQ(fieldOf(twice), "copy 'bad'");  // meshes ascending, once each
  FaceShape rows = one(0, {1, 2});
  rows.meshes[0].displacement.conservativeResize(1, 3);
  EXPECT_EQ(fieldOf(rows), "copy 'bad' mesh 'Face'");
  FaceShape nan = one(0, {1});
  nan.meshes[0].displacement(0, 2) = NAN;
  const Error e = errorOf([&] { checkFaceShape(neutral, nan); });
  EXPECT_NE(std::string(e.what()).find("vertex 1 is not a finite number"), std::string::npos)
      << e.what();
  FaceShape transforms;
  transforms.transforms = neutral.transforms;
  transforms.transforms.pop_back();
  EXPECT_EQ(fieldOf(transforms), "copy 'bad'");
  transforms.transforms = neutral.transforms;
  transforms.transforms[1].center.x() += 1;
  EXPECT_EQ(fieldOf(transforms), "copy 'bad' transform 'LeftEyeX'");
}
