// SPDX-License-Identifier: GPL-3.0-or-later
// model/landmarks.hpp: feature points found by registering a template head. Here the
// MakeHuman head is its own template, so every point has a true place to be found at
// whatever the copy's axes, size, position and meshing; the cross-head figures (the ICT and
// MakeHuman samples, each with the other as template) are tests/python/test_landmarks.py's.
#include "mpeg4face/model/landmarks.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/obj.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/model/mesh_cut.hpp"
#include "mpeg4face/model/mesh_resample.hpp"
#include "clone_fixture.hpp"
#include "test_support.hpp"

namespace {

using namespace mpeg4face;
using mpeg4face::test::errorOf;
using mpeg4face::test::kData;

// The MakeHuman head as the sample cuts it from base.obj: the body above the neck base, with
// eyes, teeth, tongue and every feature point.
const FaceModel& makeHumanHead() {
  static const FaceModel head = [] {
    FaceModel model = readObj(kData / "makehuman" / "base.obj");
    model.featurePoints =
        readFeaturePointCsv(kData / "makehuman" / "feature_points.csv", model).featurePoints;
    const auto isHead = [](const IndexedFaceSet& m) {
      for (const char* prefix : {"body", "helper-l-eye", "helper-r-eye", "helper-upper-teeth",
                                 "helper-lower-teeth", "helper-tongue"}) {
        if (m.name.starts_with(prefix)) return true;
      }
      return false;
    };
    return cutFaceModel(model, *model.featurePointPosition("7.2"), {0, 1, 0}, isHead);
  }();
  return head;
}

// `model`'s meshes moved by `motion` into model space, each under a root of its own, without
// feature points: a head as another file would give it.
FaceModel placed(const FaceModel& model, const Eigen::Affine3d& motion) {
  FaceModel out;
  const std::vector<Eigen::Affine3d> world = model.meshWorldMatrices();
  for (std::size_t m = 0; m < model.meshes.size(); ++m) {
    IndexedFaceSet mesh = model.meshes[m];
    for (Eigen::Index v = 0; v < mesh.coord.rows(); ++v) {
      mesh.coord.row(v) = (motion * world[m] * Eigen::Vector3d(mesh.coord.row(v).transpose()))
                              .transpose();
    }
    mesh.morphTargets.clear();
    mesh.weights.clear();
    out.addMeshWithTransform(std::move(mesh));
  }
  return out;
}

// Z up, the face looking along +x, 100 times larger (centimetres for metres), moved onto a
// body's height away from the origin.
Eigen::Affine3d turnedScaledMoved() {
  Eigen::Matrix3d axes;
  axes << 0, 0, 1, 1, 0, 0, 0, 1, 0;  // x <- z, y <- x, z <- y
  Eigen::Affine3d motion = Eigen::Affine3d::Identity();
  motion.translate(Eigen::Vector3d(30, -20, 170));
  motion.linear() = 100 * axes;
  return motion;
}

struct Errors {
  std::vector<double> all;  // per point, in ES0 of the true points
  double median() const {
    std::vector<double> v = all;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  }
  double max() const { return *std::max_element(all.begin(), all.end()); }
};

// The distance of each found point on the skin from the truth moved the same way.
Errors errorsOnTheSkin(const LandmarkResult& found, const FaceModel& truth,
                       const Eigen::Affine3d& motion, double es0) {
  Errors e;
  for (const auto& [id, binding] : truth.featurePoints) {
    if (binding.mesh != *truth.findMesh("body")) continue;
    const auto p = found.points.find(id);
    if (p == found.points.end()) continue;
    e.all.push_back((p->second.binding.position - motion * *truth.featurePointPosition(id)).norm() /
                    es0);
  }
  return e;
}

TEST(Landmarks, FindsAHeadsOwnPointsWhateverItsAxesSizeAndPlace) {
  const FaceModel& head = makeHumanHead();
  const Eigen::Affine3d motion = turnedScaledMoved();
  const FaceModel target = placed(head, motion);
  const LandmarkResult found = findFeaturePoints(target, head);
  EXPECT_EQ(target.meshes[static_cast<std::size_t>(found.faceMesh)].name, "body");
  EXPECT_NEAR(found.scale, 100, 1);
  const double es0 = 100 * measureFapu(head).ES0.value;
  const Errors e = errorsOnTheSkin(found, head, motion, es0);
  EXPECT_GT(e.all.size(), 60u);
  std::printf("own points, turned, scaled and moved: median %.2f%%, max %.2f%% of ES0\n",
              100 * e.median(), 100 * e.max());
  EXPECT_LT(e.median(), 0.005);
  EXPECT_LT(e.max(), 0.05);
  // Every point of the template is placed: the eyes', teeth's and tongue's on those meshes.
  EXPECT_EQ(found.points.size(), head.featurePoints.size());
  EXPECT_TRUE(found.notPlaced.empty());
  for (const char* id : {"3.5", "3.6", "9.10", "9.11", "6.1"}) {
    const int mesh = found.points.at(id).binding.mesh;
    ASSERT_GE(mesh, 0) << id;
    EXPECT_EQ(target.meshes[static_cast<std::size_t>(mesh)].name,
              head.meshes[static_cast<std::size_t>(head.featurePoints.at(id).mesh)].name)
        << id;
  }
}

// Another meshing of the same head: the points land within a few edges of the truth.
TEST(Landmarks, FindsThePointsOnAnotherMeshingOfTheHead) {
  const FaceModel& head = makeHumanHead();
  const FaceModel target = decimateFaceModel(placed(head, Eigen::Affine3d::Identity()), 0.4);
  const LandmarkResult found = findFeaturePoints(target, head);
  const double es0 = measureFapu(head).ES0.value;
  const Errors e = errorsOnTheSkin(found, head, Eigen::Affine3d::Identity(), es0);
  std::printf("own points on 40%% of the vertices: median %.2f%%, max %.2f%% of ES0\n",
              100 * e.median(), 100 * e.max());
  for (const auto& [id, p] : found.points) {
    if (head.featurePoints.at(id).mesh != *head.findMesh("body")) continue;
    const double d = (p.binding.position - *head.featurePointPosition(id)).norm() / es0;
    if (d > 0.05) std::printf("  %s %.1f%% (%s)\n", id.c_str(), 100 * d, p.rule.c_str());
  }
  EXPECT_LT(e.median(), 0.04);
  EXPECT_LT(e.max(), 0.15);
}

// Pins stay exactly where the user put them and pull the fit: pinned a vertex away from the
// truth, the mouth corners are found there, and the rest of the face is found as before.
TEST(Landmarks, PinsAreKeptExactly) {
  const FaceModel& head = makeHumanHead();
  const FaceModel target = placed(head, Eigen::Affine3d::Identity());
  const int body = *target.findMesh("body");
  LandmarkOptions options;
  // The vertex nearest the true mouth corner.
  const Points3& coord = target.meshes[static_cast<std::size_t>(body)].coord;
  const Eigen::RowVector3d corner = coord.row(head.featurePoints.at("8.3").vertex);
  int beside = -1;
  for (Eigen::Index v = 0; v < coord.rows(); ++v) {
    const double d = (coord.row(v) - corner).norm();
    if (d > 0 && (beside < 0 || d < (coord.row(beside) - corner).norm())) {
      beside = static_cast<int>(v);
    }
  }
  FeaturePointBinding mouth;
  mouth.mesh = body;
  mouth.vertex = beside;
  options.pins["8.3"] = mouth;
  FeaturePointBinding pupil;
  pupil.position = *head.featurePointPosition("3.5") + Eigen::Vector3d(0, 0.01, 0);
  options.pins["3.5"] = pupil;
  std::vector<std::string> steps;
  options.progress = [&](double f, std::string_view step) {
    EXPECT_GE(f, 0);
    EXPECT_LE(f, 1);
    steps.emplace_back(step);
  };
  const LandmarkResult found = findFeaturePoints(target, head, options);
  EXPECT_EQ(found.points.at("8.3").binding.vertex, beside);
  EXPECT_EQ(found.points.at("8.3").rule, "pin");
  EXPECT_DOUBLE_EQ(found.points.at("8.3").confidence, 1);
  EXPECT_EQ(found.points.at("3.5").binding.mesh, -1);
  EXPECT_EQ(found.points.at("3.5").binding.position, options.pins["3.5"].position);
  EXPECT_EQ(found.points.at("8.4").binding.vertex, head.featurePoints.at("8.4").vertex);
  EXPECT_FALSE(steps.empty());
  EXPECT_EQ(steps.back(), "done");
}

// A head on which the alignment alone finds no face: CANDIDE-3, a mask of 113 vertices with
// no back, eyes or mouth inside, turned, scaled and moved. Five pins (the lip and outer eye
// corners, the nose tip) align the template and pull its fit (docs/landmarks.md, Pins).
TEST(Landmarks, FivePinsPlaceTheTemplateOnAMaskTheAlignmentAloneMisses) {
  const FaceModel mask = clone_fixture::candide(kData);
  const Eigen::Affine3d motion = turnedScaledMoved();
  const FaceModel target = placed(mask, motion);
  EXPECT_TRUE(test::has(errorOf([&] { findFeaturePoints(target, makeHumanHead()); }).what(),
                        "no face found"));
  LandmarkOptions options;
  for (const char* id : {"8.3", "8.4", "3.7", "3.12", "9.3"}) {
    FeaturePointBinding pin;
    pin.mesh = 0;
    pin.vertex = mask.featurePoints.at(id).vertex;
    options.pins[id] = pin;
  }
  const LandmarkResult found = findFeaturePoints(target, makeHumanHead(), options);
  // The other named points whose place the geometry defines (the brows are CANDIDE's own
  // reading), in ES0 of the mask's own points.
  const double es0 = 100 * measureFapu(mask).ES0.value;
  Errors e;
  for (const char* id : {"2.2", "2.3", "8.1", "8.2", "3.11", "3.8", "9.15"}) {
    e.all.push_back((found.points.at(id).binding.position - motion * *mask.featurePointPosition(id))
                        .norm() / es0);
  }
  std::printf("CANDIDE-3 from five pins: median %.1f%%, max %.1f%% of ES0\n", 100 * e.median(),
              100 * e.max());
  EXPECT_LT(e.median(), 0.04);
  EXPECT_LT(e.max(), 0.2);
}

TEST(Landmarks, ASphereIsNoFace) {
  IndexedFaceSet sphere;
  sphere.name = "sphere";
  const int rings = 30, segments = 40;
  sphere.coord.resize((rings + 1) * segments, 3);
  for (int i = 0; i <= rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      const double theta = M_PI * i / rings, phi = 2 * M_PI * j / segments;
      sphere.coord.row(i * segments + j) << std::sin(theta) * std::cos(phi), std::cos(theta),
          std::sin(theta) * std::sin(phi);
    }
  }
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      const int a = i * segments + j, b = i * segments + (j + 1) % segments;
      sphere.coordIndex.insert(sphere.coordIndex.end(), {a, a + segments, b, -1});
      sphere.coordIndex.insert(sphere.coordIndex.end(), {b, a + segments, b + segments, -1});
    }
  }
  FaceModel ball;
  ball.addMeshWithTransform(sphere);
  const Error e = errorOf([&] { findFeaturePoints(ball, makeHumanHead()); });
  EXPECT_TRUE(test::has(e.what(), "no face found")) << e.what();
}

TEST(Landmarks, AHeadWithoutFacesOrATemplateWithoutPointsIsAnError) {
  FaceModel empty;
  EXPECT_TRUE(test::has(errorOf([&] { findFeaturePoints(empty, makeHumanHead()); }).what(),
                        "no faces"));
  FaceModel bare = makeHumanHead();
  bare.featurePoints.clear();
  EXPECT_TRUE(test::has(errorOf([&] { findFeaturePoints(makeHumanHead(), bare); }).what(),
                        "template"));
}

}  // namespace
