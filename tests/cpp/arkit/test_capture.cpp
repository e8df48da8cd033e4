// SPDX-License-Identifier: GPL-3.0-or-later
// ARKit captures to FAP streams and back on a synthetic ARKit head: a flat grid face with a
// few ARKit shapes (bumps and a jaw), feature points giving every FAPU, and FAP keys that are
// multiples of those shapes, so that the right answers are known exactly.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "mpeg4face/arkit/capture.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/livelink.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::ArkitCaptureFace;
using mpeg4face::FaceModel;
using mpeg4face::FapStream;
using mpeg4face::LiveLinkCapture;
using mpeg4face::MorphTarget;
using mpeg4face::Points3;

constexpr int kSide = 21;  // grid vertices per row, 0.5 apart, x in -5..5, y in -6..4

Eigen::Vector3d gridPoint(int i) { return {-5 + 0.5 * (i % kSide), -6 + 0.5 * (i / kSide), 0}; }

int vertexAt(double x, double y) {
  return static_cast<int>(std::lround((y + 6) / 0.5)) * kSide +
         static_cast<int>(std::lround((x + 5) / 0.5));
}

// A bump of `motion` around (cx, cy), 1 at the centre, 0 from `radius` on.
Points3 bump(double cx, double cy, double radius, const Eigen::Vector3d& motion) {
  Points3 d = Points3::Zero(kSide * kSide, 3);
  for (int i = 0; i < d.rows(); ++i) {
    const double r = (gridPoint(i).head<2>() - Eigen::Vector2d(cx, cy)).norm() / radius;
    if (r < 1) d.row(i) = (1 - r * r) * motion.transpose();
  }
  return d;
}

Points3 jaw() {
  Points3 d = Points3::Zero(kSide * kSide, 3);
  for (int i = 0; i < d.rows(); ++i)
    d(i, 1) = -0.5 * std::clamp(-2.25 - gridPoint(i).y(), 0.0, 1.0);
  return d;
}

// The head's ARKit shapes; the FAP keys are kKeyScale times one of them.
constexpr double kKeyScale = 0.5;
std::vector<MorphTarget> arkitShapes() {
  return {{"jawOpen", jaw()},
          {"eyeBlink_L", bump(1.5, 1.5, 0.8, {0, -0.4, 0})},
          {"EyeBlinkRight", bump(-1.5, 1.5, 0.8, {0, -0.4, 0})},
          {"blendShape1.mouthSmileLeft", bump(1.5, -2, 0.8, {0.2, 0.3, 0})},
          {"browInnerUp_L", bump(0.5, 2.5, 0.9, {0, 0.3, 0})},
          {"browInnerUp_R", bump(-0.5, 2.5, 0.9, {0, 0.3, 0})}};
}

// `lidsFollowPitch`: a key fap25@10000 (the left eye looking down) that moves the left upper
// lid as EyeBlinkLeft at weight kKeyScale does.
FaceModel syntheticHead(bool withKeys, bool withShapes = true, bool lidsFollowPitch = false) {
  mpeg4face::IndexedFaceSet mesh;
  mesh.name = "skin";
  mesh.coord.resize(kSide * kSide, 3);
  for (int i = 0; i < kSide * kSide; ++i) mesh.coord.row(i) = gridPoint(i).transpose();
  for (int r = 0; r + 1 < kSide; ++r) {
    for (int c = 0; c + 1 < kSide; ++c) {
      const int v = r * kSide + c;
      mesh.coordIndex.insert(mesh.coordIndex.end(), {v, v + 1, v + kSide + 1, v + kSide, -1});
    }
  }
  const std::vector<MorphTarget> shapes = arkitShapes();
  if (withShapes) mesh.morphTargets = shapes;
  if (withKeys) {
    const auto key = [&](const char* name, int shape) {
      mesh.morphTargets.push_back(
          {name, kKeyScale * shapes[static_cast<std::size_t>(shape)].displacements});
    };
    key("fap3_open_jaw@400", 0);
    key("fap19@300", 1);
    key("fap20@300", 2);
    key("fap12@200", 3);
    key("fap31@200", 4);
    key("fap32@200", 5);
    if (lidsFollowPitch) key("fap25@10000", 1);
  }
  FaceModel head;
  head.addMeshWithTransform(std::move(mesh));
  // ES0 3, IRISD0 1, ENS0 2, MNS0 1, MW0 3.
  const std::vector<std::tuple<const char*, double, double>> points{
      {"3.5", 1.5, 1},    {"3.6", -1.5, 1},    {"3.1", 1.5, 1.5}, {"3.2", -1.5, 1.5},
      {"3.3", 1.5, 0.5},  {"3.4", -1.5, 0.5},  {"9.15", 0, -1},   {"2.2", 0, -2},
      {"2.3", 0, -2.5},   {"8.3", 1.5, -2},    {"8.4", -1.5, -2}, {"2.1", 0, -4.5},
      {"2.4", 1.5, -2.5}, {"2.5", -1.5, -2.5}, {"4.1", 0.5, 2.5}, {"4.2", -0.5, 2.5}};
  for (const auto& [id, x, y] : points) {
    mpeg4face::FeaturePointBinding& b = head.featurePoints[id];
    b.mesh = 0;
    b.vertex = vertexAt(x, y);
  }
  return head;
}

const ArkitCaptureFace& keyedFace() {
  static const ArkitCaptureFace face = mpeg4face::prepareArkitCaptureFace(syntheticHead(true));
  return face;
}

int channel(const char* name) {
  const auto names = mpeg4face::liveLinkChannelNames();
  return static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin());
}

// `frames` frames at 60 fps from t = 10 s; JawOpen ramps 0..1, EyeBlinkLeft 1..0, the others
// as `fill` says.
LiveLinkCapture capture(int frames) {
  LiveLinkCapture c;
  c.channels.assign(mpeg4face::liveLinkChannelNames().begin(),
                    mpeg4face::liveLinkChannelNames().end());
  c.frameRate = 60;
  c.values = Eigen::MatrixXd::Zero(frames, mpeg4face::kLiveLinkChannelCount);
  for (int f = 0; f < frames; ++f) {
    const double s = frames > 1 ? f / (frames - 1.0) : 0;
    c.times.push_back(10 + f / 60.0);
    c.values(f, channel("JawOpen")) = s;
    c.values(f, channel("EyeBlinkLeft")) = 1 - s;
    c.values(f, channel("EyeBlinkRight")) = 0.5 * s;
    c.values(f, channel("MouthSmileLeft")) = s * s;
    c.values(f, channel("BrowInnerUp")) = 0.25;
    c.values(f, channel("CheekPuff")) = 0.7;  // the head lacks it
  }
  return c;
}

TEST(ArkitCapture, PreparesTheFace) {
  const ArkitCaptureFace& face = keyedFace();
  EXPECT_TRUE(face.fromTables);
  int shapes = 0;
  for (bool has : face.hasShape) shapes += has;
  EXPECT_EQ(shapes, 5);  // the brow's halves are one ARKit shape
  EXPECT_TRUE(face.hasShape[static_cast<std::size_t>(channel("BrowInnerUp"))]);
  ASSERT_EQ(face.warnings.size(), 1u);
  EXPECT_NE(face.warnings[0].find("lacks 47 of the 52 ARKit shapes"), std::string::npos);
  EXPECT_NE(face.warnings[0].find("CheekPuff"), std::string::npos);
  // FAP 3 is unidirectional: one column; the others have both sides.
  EXPECT_EQ(face.columnFap.size(), 11u);
}

TEST(ArkitCapture, ValuesStopWhereAKeysTableIsHeld) {
  // FAP 19's table held flat past its key (a copy at twice the amplitude with the same
  // motion, as arkitFapKeys writes them): its column reaches 300, the others' have no end.
  FaceModel head = syntheticHead(true);
  std::vector<MorphTarget>& targets = head.meshes[0].morphTargets;
  const auto key = std::find_if(targets.begin(), targets.end(),
                                [](const MorphTarget& t) { return t.name == "fap19@300"; });
  ASSERT_NE(key, targets.end());
  targets.push_back({"fap19_held@600", key->displacements});
  const ArkitCaptureFace face = mpeg4face::prepareArkitCaptureFace(head);
  ASSERT_EQ(face.columnReach.size(), face.columnFap.size());
  for (std::size_t c = 0; c < face.columnFap.size(); ++c) {
    if (face.columnFap[c] == 19 && face.columnSign[c] > 0) {
      EXPECT_EQ(face.columnReach[c], 300);
    } else {
      EXPECT_TRUE(std::isinf(face.columnReach[c])) << face.columnFap[c];
    }
  }
  // The capture's blink at 1 asks for 600 (the key is half the shape); the solver stops at
  // the reach, where the table does.
  const FapStream s = mpeg4face::arkitCaptureToFaps(capture(61), face, {25, {}});
  EXPECT_EQ(s.frames.front().value(19), 300);
  EXPECT_NEAR(s.frames.back().value(19), 0, 1.0);
  EXPECT_NEAR(s.frames[20].value(3), 400 * 0.8 / kKeyScale, 1.0);  // the others as before
}

TEST(ArkitCapture, HeadWithoutArkitShapes) {
  const mpeg4face::Error e = mpeg4face::test::errorOf(
      [] { mpeg4face::prepareArkitCaptureFace(syntheticHead(false, false)); });
  EXPECT_NE(e.reason().find("no ARKit blendshape"), std::string::npos) << e.what();
  EXPECT_NE(e.reason().find("EyeBlinkLeft"), std::string::npos);
  EXPECT_NE(e.reason().find("TongueOut"), std::string::npos);
}

TEST(ArkitCapture, ToFapsReproducesTheWeightsThroughTheKeys) {
  const LiveLinkCapture c = capture(61);  // 1 s at 60 fps
  std::vector<std::pair<int, int>> progress;
  const FapStream s = mpeg4face::arkitCaptureToFaps(
      c, keyedFace(), {25, [&](int done, int total) { progress.emplace_back(done, total); }});
  EXPECT_EQ(s.frameRate, 25);
  ASSERT_EQ(s.frames.size(), 26u);  // 0 .. 1 s at 25 fps
  ASSERT_FALSE(progress.empty());
  EXPECT_EQ(progress.back(), std::make_pair(26, 26));
  for (std::size_t f = 0; f < s.frames.size(); ++f) {
    const double t = static_cast<double>(f) / 25;  // the ramp's parameter
    const auto& frame = s.frames[f];
    EXPECT_EQ(frame.number, static_cast<int>(f));
    // A key at amplitude A is kKeyScale times its shape: FAP = A * w / kKeyScale.
    EXPECT_NEAR(frame.value(3), 400 * t / kKeyScale, 1.0) << f;
    EXPECT_NEAR(frame.value(19), 300 * (1 - t) / kKeyScale, 1.0) << f;
    EXPECT_NEAR(frame.value(20), 300 * 0.5 * t / kKeyScale, 1.0) << f;
    // Linear interpolation of the weights between the capture's frames.
    const double f60 = t * 60, lo = std::floor(f60 + 1e-9) / 60, hi = std::min(1.0, lo + 1.0 / 60);
    const double smile = lo * lo + (t - lo) * 60 * (hi * hi - lo * lo);
    EXPECT_NEAR(frame.value(12), 200 * smile / kKeyScale, 1.0) << f;
    EXPECT_NEAR(frame.value(31), 200 * 0.25 / kKeyScale, 1.0) << f;
    EXPECT_NEAR(frame.value(32), 200 * 0.25 / kKeyScale, 1.0) << f;
    for (int fap : {23, 24, 25, 26, 48, 49, 50}) EXPECT_TRUE(frame.has(fap));
  }
}

TEST(ArkitCapture, AnglesToFapsAndBack) {
  LiveLinkCapture c = capture(2);
  c.values(0, mpeg4face::kLeftEyeYaw) = 0.1;  // towards the face's right: FAP 23 < 0
  c.values(0, mpeg4face::kRightEyeYaw) = 0.05;
  c.values(0, mpeg4face::kLeftEyePitch) = 0.2;  // down: FAP 25 > 0
  c.values(0, mpeg4face::kRightEyePitch) = -0.1;
  c.values(0, mpeg4face::kHeadPitch) = 0.03;
  c.values(0, mpeg4face::kHeadYaw) = -0.04;
  c.values(0, mpeg4face::kHeadRoll) = 0.02;
  const FapStream s = mpeg4face::arkitCaptureToFaps(c, keyedFace(), {60, {}});
  const auto& f = s.frames[0];
  EXPECT_EQ(f.value(23), -10000);
  EXPECT_EQ(f.value(24), -5000);
  EXPECT_EQ(f.value(25), 20000);
  EXPECT_EQ(f.value(26), -10000);
  EXPECT_EQ(f.value(48), 3000);
  EXPECT_EQ(f.value(49), 4000);
  EXPECT_EQ(f.value(50), 2000);
  const LiveLinkCapture back = mpeg4face::fapsToArkit(s, keyedFace());
  for (int k = mpeg4face::kHeadYaw; k <= mpeg4face::kRightEyeRoll; ++k) {
    EXPECT_NEAR(back.values(0, k), c.values(0, k), 1e-9) << c.channels[static_cast<std::size_t>(k)];
  }
}

TEST(ArkitCapture, WhatTheAngleFapsMoveIsNotAskedOfTheOthers) {
  const ArkitCaptureFace face = mpeg4face::prepareArkitCaptureFace(syntheticHead(true, true, true));
  ASSERT_EQ(face.angleColumnFap.size(), 2u);  // FAP 25, both sides
  LiveLinkCapture c = capture(2);
  c.values.col(channel("EyeBlinkLeft")).setConstant(kKeyScale);
  c.values.col(mpeg4face::kLeftEyePitch).setConstant(0.1);  // FAP 25 = 10000: the lid's motion
  const FapStream s = mpeg4face::arkitCaptureToFaps(c, face, {60, {}});
  EXPECT_EQ(s.frames[0].value(25), 10000);
  EXPECT_NEAR(s.frames[0].value(19), 0, 1);
  // Without the eye's turn the lid's motion is FAP 19's.
  c.values.col(mpeg4face::kLeftEyePitch).setZero();
  EXPECT_NEAR(mpeg4face::arkitCaptureToFaps(c, face, {60, {}}).frames[0].value(19), 300, 1);
}

TEST(ArkitCapture, FromFapsGivesTheWeightsBack) {
  const LiveLinkCapture c = capture(61);
  const FapStream s = mpeg4face::arkitCaptureToFaps(c, keyedFace(), {60, {}});
  ASSERT_EQ(s.frames.size(), 61u);
  const LiveLinkCapture back = mpeg4face::fapsToArkit(s, keyedFace());
  ASSERT_EQ(back.frameCount(), 61);
  EXPECT_EQ(back.frameRate, 60);
  EXPECT_NEAR(back.times[60], 1.0, 1e-12);
  EXPECT_GE(back.values.leftCols(52).minCoeff(), 0);
  EXPECT_LE(back.values.leftCols(52).maxCoeff(), 1);
  for (const char* name :
       {"JawOpen", "EyeBlinkLeft", "EyeBlinkRight", "MouthSmileLeft", "BrowInnerUp"}) {
    const int k = channel(name);
    // The FAPs are whole numbers: 1 FAPU is 1/800 .. 1/400 of a unit weight here.
    EXPECT_LT((back.values.col(k) - c.values.col(k)).cwiseAbs().maxCoeff(), 5e-3) << name;
  }
  EXPECT_EQ(back.values.col(channel("CheekPuff")).cwiseAbs().maxCoeff(), 0);  // the head lacks it
  // Written and read back as a Live Link Face CSV.
  const auto path = mpeg4face::test::scratchDir() / "back.csv";
  mpeg4face::writeLiveLinkCsv(path, back);
  const LiveLinkCapture read = mpeg4face::readLiveLinkCsv(path);
  EXPECT_EQ(read.frameCount(), 61);
  EXPECT_LT((read.values - back.values).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(ArkitCapture, WeightsAreBoundedWhenTheMotionAsksForMore) {
  // Twice the jaw's full motion: JawOpen stops at 1.
  FapStream s;
  s.frameRate = 25;
  s.frames.resize(1);
  s.frames[0].set(3, static_cast<int>(2 * 400 / kKeyScale));
  s.frames[0].set(19, -300);  // the eyelid up: no ARKit shape does that, EyeBlinkLeft stays 0
  const LiveLinkCapture back = mpeg4face::fapsToArkit(s, keyedFace());
  EXPECT_DOUBLE_EQ(back.values(0, channel("JawOpen")), 1);
  EXPECT_DOUBLE_EQ(back.values(0, channel("EyeBlinkLeft")), 0);
}

TEST(ArkitCapture, WithoutKeysEachFapMovesItsFeaturePoint) {
  const ArkitCaptureFace face = mpeg4face::prepareArkitCaptureFace(syntheticHead(false));
  EXPECT_FALSE(face.fromTables);
  const FapStream s = mpeg4face::arkitCaptureToFaps(capture(61), face, {60, {}});
  // FAP 3: 2.1 moves down by 0.5 w model units; MNS = MNS0 / 1024 = 1 / 1024.
  // FAP 19: 3.1 down by 0.4 w, IRISD = 1 / 1024.
  for (std::size_t f = 0; f < s.frames.size(); ++f) {
    const double t = static_cast<double>(f) / 60;
    EXPECT_NEAR(s.frames[f].value(3), 0.5 * t * 1024, 1.0);
    EXPECT_NEAR(s.frames[f].value(19), 0.4 * (1 - t) * 1024, 1.0);
  }
  // And back: the feature points' motion gives the weights.
  const LiveLinkCapture back = mpeg4face::fapsToArkit(s, face);
  EXPECT_LT((back.values.col(channel("JawOpen")) - capture(61).values.col(channel("JawOpen")))
                .cwiseAbs()
                .maxCoeff(),
            5e-3);
}

TEST(ArkitCapture, BoundedLeastSquaresMeetsKuhnTucker) {
  std::mt19937 random(7);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 12;
    Eigen::MatrixXd A(30, n);
    for (int i = 0; i < A.size(); ++i) A.data()[i] = normal(random);
    Eigen::VectorXd y(30);
    for (int i = 0; i < y.size(); ++i) y[i] = 3 * normal(random);
    const Eigen::MatrixXd G = A.transpose() * A;
    const Eigen::VectorXd b = A.transpose() * y;
    const Eigen::VectorXd lower = Eigen::VectorXd::Zero(n);
    const Eigen::VectorXd upper = Eigen::VectorXd::Constant(n, trial % 2 ? 1.0 : INFINITY);
    Eigen::VectorXd x = Eigen::VectorXd::Constant(n, 0.5);  // a warm start that is not the answer
    mpeg4face::boundedLeastSquares(G, b, lower, upper, x);
    const Eigen::VectorXd gradient = G * x - b;
    for (int i = 0; i < n; ++i) {
      ASSERT_GE(x[i], lower[i]);
      ASSERT_LE(x[i], upper[i]);
      if (x[i] > lower[i] && x[i] < upper[i]) {
        EXPECT_NEAR(gradient[i], 0, 1e-8);
      } else if (x[i] == lower[i]) {
        EXPECT_GE(gradient[i], -1e-8);
      } else {
        EXPECT_LE(gradient[i], 1e-8);
      }
    }
  }
}

TEST(ArkitCapture, BadArguments) {
  LiveLinkCapture empty;
  empty.values.resize(0, 61);
  EXPECT_NE(mpeg4face::test::errorOf([&] { mpeg4face::arkitCaptureToFaps(empty, keyedFace()); })
                .reason()
                .find("no frames"),
            std::string::npos);
  EXPECT_NE(mpeg4face::test::errorOf([&] {
              mpeg4face::arkitCaptureToFaps(capture(3), keyedFace(), {0, {}});
            })
                .reason()
                .find("frame rate"),
            std::string::npos);
}

}  // namespace
