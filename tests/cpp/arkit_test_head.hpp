// SPDX-License-Identifier: GPL-3.0-or-later
// A small head whose ARKit-like shapes are made here, so that the mapping's answer is known:
// shared by the ARKit tests and the mapping's benchmark.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face::test {

// Feature points of the test head (x = the face's left), metres. FAPU: ES0 0.06 (3.5 - 3.6),
// IRISD0 0.012, ENS0 0.05, MNS0 0.03, MW0 0.054 (8.3 - 8.4).
struct TestPoint {
  const char* id;
  double x, y, z;
};
inline const std::vector<TestPoint>& arkitTestPoints() {
  static const std::vector<TestPoint> points{
      {"3.5", 0.03, 0.03, 0.08},     {"3.6", -0.03, 0.03, 0.08},     {"3.1", 0.03, 0.036, 0.085},
      {"3.2", -0.03, 0.036, 0.085},  {"3.3", 0.03, 0.024, 0.085},    {"3.4", -0.03, 0.024, 0.085},
      {"9.15", 0, -0.02, 0.1},       {"2.2", 0, -0.05, 0.09},        {"2.3", 0, -0.052, 0.09},
      {"2.1", 0, -0.09, 0.08},       {"2.4", 0.025, -0.051, 0.088},  {"2.5", -0.025, -0.051, 0.088},
      {"8.3", 0.027, -0.051, 0.087}, {"8.4", -0.027, -0.051, 0.087}, {"4.1", 0.01, 0.05, 0.085},
      {"4.2", -0.01, 0.05, 0.085},   {"9.3", 0, -0.005, 0.11},       {"5.1", 0.05, -0.03, 0.06},
      {"5.2", -0.05, -0.03, 0.06}};
  return points;
}

// The head: mesh "skin" with one vertex per test point (then `padding` more, on a sphere
// behind the face), triangles fanned over them, the feature points bound to their vertices.
inline FaceModel arkitTestHead(int padding = 0) {
  const std::vector<TestPoint>& points = arkitTestPoints();
  IndexedFaceSet skin;
  skin.name = "skin";
  const int n = static_cast<int>(points.size()) + padding;
  skin.coord.resize(n, 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    skin.coord.row(static_cast<Eigen::Index>(i)) << points[i].x, points[i].y, points[i].z;
  }
  for (int i = static_cast<int>(points.size()); i < n; ++i) {
    const double a = 2.399963 * i, z = 1 - 2.0 * (i + 0.5) / n;  // a Fibonacci sphere
    const double r = std::sqrt(1 - z * z);
    skin.coord.row(i) << 0.09 * r * std::cos(a), 0.12 * z, 0.09 * r * std::sin(a) - 0.02;
  }
  for (int i = 1; i + 1 < n; ++i) skin.coordIndex.insert(skin.coordIndex.end(), {0, i, i + 1, -1});
  FaceModel head;
  head.addMeshWithTransform(std::move(skin));
  for (std::size_t i = 0; i < points.size(); ++i) {
    head.featurePoints[points[i].id] = {0, static_cast<int>(i), Eigen::Vector3d::Zero()};
  }
  return head;
}

// A morph target `name` on the skin moving the test points listed by (id, motion).
inline void addTestShape(FaceModel& head, const std::string& name,
                         const std::vector<std::pair<std::string, Eigen::Vector3d>>& motion) {
  IndexedFaceSet& skin = head.meshes[0];
  MorphTarget target{name, Points3::Zero(skin.vertexCount(), 3)};
  for (const auto& [id, d] : motion) {
    target.displacements.row(head.featurePoints.at(id).vertex) = d.transpose();
  }
  skin.morphTargets.push_back(std::move(target));
}

// The shapes whose FAPs the tests know (docs in arkit/test_shapes.cpp):
//   jawOpen      2.1 and 2.3 down 10 mm                       -> FAP 3 at 341 MNS units
//   mouthSmile_L 2.4 up 4 mm and left 2 mm;  mouthPress_L 2.4 right 2 mm
//                                                             -> FAP 12 = both, 136 MNS units
//   mouthSmile_R, mouthPress_R mirrored (mouthPress_R also drags 2.4 right 1 mm)
//   eyeBlink_L   3.1 down 10 mm                               -> FAP 19 at 853 IRISD units
//   browInnerUp_L / _R: 4.1 / 4.2 up 5 mm                     -> FAP 31 / 32 at 102 ENS units
inline FaceModel arkitTestHeadWithShapes(int padding = 0) {
  FaceModel head = arkitTestHead(padding);
  using V = Eigen::Vector3d;
  addTestShape(head, "jawOpen", {{"2.1", V(0, -0.01, 0)}, {"2.3", V(0, -0.01, 0)}});
  addTestShape(head, "mouthSmile_L", {{"2.4", V(0.002, 0.004, 0)}});
  addTestShape(head, "mouthPress_L", {{"2.4", V(-0.002, 0, 0)}});
  addTestShape(head, "mouthSmile_R", {{"2.5", V(-0.002, 0.004, 0)}});
  addTestShape(head, "mouthPress_R", {{"2.5", V(0.002, 0, 0)}, {"2.4", V(-0.001, 0, 0)}});
  addTestShape(head, "eyeBlink_L", {{"3.1", V(0, -0.01, 0)}});
  addTestShape(head, "browInnerUp_L", {{"4.1", V(0, 0.005, 0)}});
  addTestShape(head, "browInnerUp_R", {{"4.2", V(0, 0.005, 0)}});
  return head;
}

}  // namespace mpeg4face::test
