// SPDX-License-Identifier: GPL-3.0-or-later
// The small face the FaceDefTables generator's and the clone source's tests share, and what
// checks tables against deformed copies.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>

#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/fat/generate.hpp"
#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face::test {

// A 13 x 13 grid face (transform "Face") with an eye mesh under its child transform
// "LeftEyeX", and feature points giving ES0 0.06, IRISD0 0.012, ENS0 0.05, MNS0 0.03, MW0 0.05.
inline FaceModel testFace() {
  FaceModel model;
  IndexedFaceSet face;
  face.name = "Face";
  constexpr int kSide = 13;
  face.coord.resize(kSide * kSide, 3);
  for (int i = 0; i < kSide; ++i) {
    for (int j = 0; j < kSide; ++j) {
      const double x = -0.1 + 0.2 * j / (kSide - 1), y = -0.12 + 0.24 * i / (kSide - 1);
      face.coord.row(i * kSide + j) << x, y, 0.1 - 2 * (x * x + y * y);
      if (i + 1 < kSide && j + 1 < kSide) {
        const int v = i * kSide + j;
        face.coordIndex.insert(face.coordIndex.end(), {v, v + 1, v + kSide + 1, v + kSide, -1});
      }
    }
  }
  model.addMeshWithTransform(face);
  IndexedFaceSet eye;
  eye.name = "LeftEye";
  eye.coord.resize(4, 3);
  eye.coord << 0, 0, 0.012, 0.01, 0, 0, -0.01, 0, 0, 0, 0.01, 0;
  eye.coordIndex = {0, 1, 2, -1, 0, 2, 3, -1};
  model.meshes.push_back(eye);
  Transform eyeX;
  eyeX.name = "LeftEyeX";
  eyeX.translation = {0.03, 0.03, 0.07};
  eyeX.rotation = Eigen::AngleAxisd(0.2, Eigen::Vector3d(1, 2, 0).normalized());
  eyeX.meshes = {1};
  model.transforms.push_back(eyeX);
  model.transforms[0].children = {1};
  const auto bind = [&](const char* id, double x, double y, double z) {
    model.featurePoints[id] = {-1, -1, {x, y, z}};
  };
  bind("3.5", 0.03, 0.03, 0.08);
  bind("3.6", -0.03, 0.03, 0.08);
  bind("3.1", 0.03, 0.036, 0.08);
  bind("3.3", 0.03, 0.024, 0.08);
  bind("9.15", 0, -0.02, 0.1);
  bind("2.2", 0, -0.05, 0.09);
  bind("8.3", 0.025, -0.05, 0.09);
  bind("8.4", -0.025, -0.05, 0.09);
  return model;
}

// The frame that drives `copy`'s shape at its amplitude (a viseme, expression or FAP).
inline FapFrame frameFor(const FaceShape& copy) {
  FapFrame f;
  if (copy.fapID == 1) {
    f.mask.set(0);
    f.viseme = {copy.highLevelSelect, 0, copy.amplitude, false};
  } else if (copy.fapID == 2) {
    f.mask.set(1);
    f.expression = {copy.highLevelSelect, copy.amplitude, 0, 0, false, false};
  } else {
    f.set(copy.fapID, copy.amplitude);
  }
  return f;
}

// The largest distance between the evaluated state and the copy, over all meshes (in model
// space, so that Transform changes count too).
inline double farthest(const FatState& state, const FaceModel& neutral, const FaceShape& shape) {
  const FaceModel copy = deformedModel(neutral, shape);
  FaceModel animated = neutral;
  animated.transforms = state.transforms;
  for (std::size_t m = 0; m < neutral.meshes.size(); ++m) animated.meshes[m].coord = state.coord[m];
  const auto a = animated.meshWorldMatrices();
  const auto b = copy.meshWorldMatrices();
  double worst = 0;
  for (std::size_t m = 0; m < neutral.meshes.size(); ++m) {
    for (Eigen::Index v = 0; v < copy.meshes[m].coord.rows(); ++v) {
      const Eigen::Vector3d p = a[m] * animated.meshes[m].coord.row(v).transpose();
      const Eigen::Vector3d q = b[m] * copy.meshes[m].coord.row(v).transpose();
      worst = std::max(worst, (p - q).norm());
    }
  }
  return worst;
}

}  // namespace mpeg4face::test
