// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/obj.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/model/mesh_resample.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::decimateFaceModel;
using mpeg4face::FaceModel;
using mpeg4face::IndexedFaceSet;
using mpeg4face::subdivideFaceModel;
using mpeg4face::test::errorOf;
using mpeg4face::test::kData;

// A closed latitude-longitude sphere: quads, with triangle fans at the poles.
IndexedFaceSet sphere(int rings, int segments) {
  IndexedFaceSet mesh;
  mesh.name = "Sphere";
  const int count = 2 + (rings - 1) * segments;
  mesh.coord.resize(count, 3);
  mesh.coord.row(0) << 0, 1, 0;
  mesh.coord.row(count - 1) << 0, -1, 0;
  const auto ringVertex = [&](int ring, int s) { return 1 + (ring - 1) * segments + s % segments; };
  for (int r = 1; r < rings; ++r) {
    const double theta = M_PI * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2 * M_PI * s / segments;
      mesh.coord.row(ringVertex(r, s)) << std::sin(theta) * std::cos(phi), std::cos(theta),
          std::sin(theta) * std::sin(phi);
    }
  }
  for (int s = 0; s < segments; ++s) {
    mesh.coordIndex.insert(mesh.coordIndex.end(), {0, ringVertex(1, s + 1), ringVertex(1, s), -1});
    for (int r = 1; r + 1 < rings; ++r) {
      mesh.coordIndex.insert(mesh.coordIndex.end(),
                             {ringVertex(r, s), ringVertex(r, s + 1), ringVertex(r + 1, s + 1),
                              ringVertex(r + 1, s), -1});
    }
    mesh.coordIndex.insert(mesh.coordIndex.end(),
                           {count - 1, ringVertex(rings - 1, s), ringVertex(rings - 1, s + 1), -1});
  }
  return mesh;
}

// A sphere with two feature points on vertices, one free, morph data and an animation.
FaceModel sphereModel() {
  FaceModel model;
  IndexedFaceSet mesh = sphere(24, 32);
  mesh.sourceIndex.resize(static_cast<size_t>(mesh.vertexCount()));
  for (int v = 0; v < mesh.vertexCount(); ++v) mesh.sourceIndex[static_cast<size_t>(v)] = 1000 + v;
  mesh.morphTargets.push_back({"Bulge", mesh.coord * 0.1});
  mesh.weights = {0.5};
  mesh.normal = mesh.coord;
  model.addMeshWithTransform(std::move(mesh));
  model.featurePoints["9.3"] = {0, 100, Eigen::Vector3d::Zero()};
  model.featurePoints["2.1"] = {0, 555, Eigen::Vector3d::Zero()};
  model.featurePoints["7.1"] = {-1, -1, Eigen::Vector3d(0.1, 0.2, 0.3)};
  mpeg4face::MorphWeightAnimation animation;
  animation.name = "Anim";
  animation.channels.push_back({0, {}, {0.0, 1.0}, {0.0, 1.0}});
  mpeg4face::TransformChannel spin;
  spin.times = {0.0};
  spin.values = {0, 0, 0, 1};
  animation.transformChannels.push_back(spin);
  model.animations.push_back(animation);
  model.validate();
  return model;
}

// Undirected edges of the fan-triangulated faces, counted independently of OpenMesh.
std::set<std::pair<int, int>> triangleEdges(const IndexedFaceSet& mesh) {
  std::set<std::pair<int, int>> edges;
  const std::vector<int> t = mesh.triangles();
  for (size_t i = 0; i < t.size(); i += 3) {
    for (int k = 0; k < 3; ++k) {
      const int a = t[i + static_cast<size_t>(k)], b = t[i + static_cast<size_t>((k + 1) % 3)];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  }
  return edges;
}

void expectFeaturePointsKept(const FaceModel& before, const FaceModel& after) {
  ASSERT_EQ(before.featurePoints.size(), after.featurePoints.size());
  for (const auto& [id, fp] : before.featurePoints) {
    ASSERT_TRUE(after.featurePoints.count(id)) << id;
    EXPECT_EQ(after.featurePoints.at(id).mesh, fp.mesh) << id;
    // Exactly: kept vertices are neither moved nor rounded.
    EXPECT_EQ(*after.featurePointPosition(id), *before.featurePointPosition(id)) << id;
  }
}

TEST(Decimate, SphereToAQuarterKeepsFeaturePointsAndSurvivors) {
  const FaceModel model = sphereModel();
  const IndexedFaceSet& in = model.meshes[0];
  const FaceModel out = decimateFaceModel(model, 0.25);
  ASSERT_NO_THROW(out.validate());
  const IndexedFaceSet& mesh = out.meshes[0];
  const int target = static_cast<int>(std::lround(0.25 * in.vertexCount()));
  EXPECT_EQ(mesh.vertexCount(), target);
  // A closed genus-0 triangle mesh: F = 2V - 4.
  EXPECT_EQ(mesh.faceCount(), 2 * mesh.vertexCount() - 4);
  expectFeaturePointsKept(model, out);
  // Every survivor is an original vertex at its exact place, in the original order, and
  // its sourceIndex says which.
  ASSERT_EQ(mesh.sourceIndex.size(), static_cast<size_t>(mesh.vertexCount()));
  int previous = -1;
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    const int original = mesh.sourceIndex[static_cast<size_t>(v)] - 1000;
    ASSERT_GT(original, previous);
    EXPECT_EQ(Eigen::Vector3d(mesh.coord.row(v)), Eigen::Vector3d(in.coord.row(original)));
    previous = original;
  }
  EXPECT_TRUE(mesh.morphTargets.empty());
  EXPECT_TRUE(mesh.weights.empty());
  EXPECT_EQ(mesh.normal.rows(), 0);
  EXPECT_TRUE(out.animations[0].channels.empty());
  EXPECT_EQ(out.animations[0].transformChannels.size(), 1u);
  EXPECT_EQ(out.transforms.size(), model.transforms.size());
}

TEST(Decimate, FractionOneOnlyTriangulates) {
  const FaceModel model = sphereModel();
  const FaceModel out = decimateFaceModel(model, 1.0);
  EXPECT_EQ(out.meshes[0].coord, model.meshes[0].coord);
  EXPECT_EQ(out.meshes[0].faceCount(), static_cast<int>(model.meshes[0].triangles().size() / 3));
}

TEST(Decimate, BadFraction) {
  const FaceModel model = sphereModel();
  for (const double f : {0.0, -0.5, 1.5, std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_EQ(errorOf([&] { decimateFaceModel(model, f); }).field(), "vertexFraction") << f;
  }
}

TEST(Subdivide, OneRoundSplitsEveryEdgeAndInterpolates) {
  const FaceModel model = sphereModel();
  const IndexedFaceSet& in = model.meshes[0];
  const FaceModel out = subdivideFaceModel(model, 1);
  ASSERT_NO_THROW(out.validate());
  const IndexedFaceSet& mesh = out.meshes[0];
  const auto edges = triangleEdges(in);
  EXPECT_EQ(mesh.vertexCount(), in.vertexCount() + static_cast<int>(edges.size()));
  EXPECT_EQ(mesh.faceCount(), 4 * static_cast<int>(in.triangles().size() / 3));
  for (int v = 0; v < in.vertexCount(); ++v) {
    ASSERT_EQ(Eigen::Vector3d(mesh.coord.row(v)), Eigen::Vector3d(in.coord.row(v))) << v;
  }
  expectFeaturePointsKept(model, out);
  for (const auto& [id, fp] : model.featurePoints) {
    EXPECT_EQ(out.featurePoints.at(id).vertex, fp.vertex) << id;
  }
  EXPECT_TRUE(mesh.sourceIndex.empty());
  // The new vertices lie near the unit sphere (butterfly is smooth; the sphere is fine).
  for (int v = in.vertexCount(); v < mesh.vertexCount(); ++v) {
    EXPECT_NEAR(mesh.coord.row(v).norm(), 1.0, 0.02) << v;
  }
}

TEST(Subdivide, TwoRounds) {
  const FaceModel model = sphereModel();
  const int v0 = model.meshes[0].vertexCount();
  const int e0 = static_cast<int>(triangleEdges(model.meshes[0]).size());
  const int f0 = static_cast<int>(model.meshes[0].triangles().size() / 3);
  const FaceModel out = subdivideFaceModel(model, 2);
  // Each round: V += E, E = 2E + 3F, F = 4F.
  const int v1 = v0 + e0, e1 = 2 * e0 + 3 * f0, f1 = 4 * f0;
  EXPECT_EQ(out.meshes[0].vertexCount(), v1 + e1);
  EXPECT_EQ(out.meshes[0].faceCount(), 4 * f1);
  expectFeaturePointsKept(model, out);
}

TEST(Subdivide, BadIterations) {
  const FaceModel model = sphereModel();
  for (const int n : {-1, 5}) {
    EXPECT_EQ(errorOf([&] { subdivideFaceModel(model, n); }).field(), "iterations") << n;
  }
  const FaceModel same = subdivideFaceModel(model, 0);
  EXPECT_EQ(same.meshes[0].coord, model.meshes[0].coord);
}

TEST(Resample, NonManifoldMeshNamesMeshAndFace) {
  // Three triangles on one edge (0, 1).
  FaceModel model;
  IndexedFaceSet mesh;
  mesh.name = "Fin";
  mesh.coord.resize(5, 3);
  mesh.coord << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1;
  mesh.coordIndex = {0, 1, 2, -1, 1, 0, 3, -1, 0, 1, 4, -1};
  model.addMeshWithTransform(mesh);
  for (const auto& run : {+[](const FaceModel& m) { decimateFaceModel(m, 0.5); },
                          +[](const FaceModel& m) { subdivideFaceModel(m, 1); }}) {
    const mpeg4face::Error e = errorOf([&] { run(model); });
    EXPECT_NE(e.field().find("'Fin'"), std::string::npos) << e.what();
    EXPECT_NE(e.field().find("face 2"), std::string::npos) << e.what();
  }
}

TEST(Resample, DegenerateFacesAreDropped) {
  FaceModel model;
  IndexedFaceSet mesh;
  mesh.name = "Tri";
  mesh.coord.resize(3, 3);
  mesh.coord << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  mesh.coordIndex = {0, 1, 2, -1, 0, 0, 1, -1};
  model.addMeshWithTransform(mesh);
  EXPECT_EQ(subdivideFaceModel(model, 0).meshes[0].faceCount(), 1);
}

// The MakeHuman base mesh with its feature points: the sizes the clone benchmarks use.
FaceModel makeHuman() {
  FaceModel model = mpeg4face::readObj(kData / "makehuman" / "base.obj");
  model.featurePoints =
      mpeg4face::readFeaturePointCsv(kData / "makehuman" / "feature_points.csv", model)
          .featurePoints;
  return model;
}

void expectSameFapu(const FaceModel& a, const FaceModel& b) {
  const auto fa = mpeg4face::measureFapu(a), fb = mpeg4face::measureFapu(b);
  for (size_t i = 0; i < fa.distances().size(); ++i) {
    EXPECT_TRUE(fb.distances()[i].distance->measured) << fa.distances()[i].name;
    EXPECT_EQ(fa.distances()[i].distance->value, fb.distances()[i].distance->value)
        << fa.distances()[i].name;
  }
}

TEST(MakeHuman, DecimatedToAQuarter) {
  const FaceModel model = makeHuman();
  const int body = *model.findMesh("body");
  const FaceModel out = decimateFaceModel(model, 0.25);
  ASSERT_NO_THROW(out.validate());
  EXPECT_EQ(out.meshes.size(), model.meshes.size());
  EXPECT_EQ(out.meshes[static_cast<size_t>(body)].vertexCount(),
            std::lround(0.25 * model.meshes[static_cast<size_t>(body)].vertexCount()));
  expectFeaturePointsKept(model, out);
  expectSameFapu(model, out);
  // Still bound through the OBJ's numbering: the CSV reads on the decimated model's body.
  const auto& bodyIndex = out.meshes[static_cast<size_t>(body)].sourceIndex;
  const auto& fp = out.featurePoints.at("9.3");
  EXPECT_EQ(bodyIndex[static_cast<size_t>(fp.vertex)],
            model.meshes[static_cast<size_t>(body)]
                .sourceIndex[static_cast<size_t>(model.featurePoints.at("9.3").vertex)]);
}

TEST(MakeHuman, SubdividedOnce) {
  const FaceModel model = makeHuman();
  const int body = *model.findMesh("body");
  const FaceModel out = subdivideFaceModel(model, 1);
  ASSERT_NO_THROW(out.validate());
  const IndexedFaceSet& in = model.meshes[static_cast<size_t>(body)];
  EXPECT_EQ(out.meshes[static_cast<size_t>(body)].vertexCount(),
            in.vertexCount() + static_cast<int>(triangleEdges(in).size()));
  expectFeaturePointsKept(model, out);
  expectSameFapu(model, out);
}

}  // namespace
