// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <random>

#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/tables.hpp"
#include "test_support.hpp"

using namespace mpeg4face;
using mpeg4face::test::errorOf;

namespace {

std::vector<double> weightsOf(std::vector<int> borders, double value) {
  std::vector<double> w;
  intervalWeights(borders, value, w);
  return w;
}

}  // namespace

// Tekalp-Ostermann Table 5: borders -1000, 0, 500, 1000; FAP 6 = 600 -> 500 * D1 + 100 * D2.
TEST(IntervalWeights, PaperWorkedExamplePositive) {
  EXPECT_EQ(weightsOf({-1000, 0, 500, 1000}, 600), (std::vector<double>{0, 500, 100}));
}

// The negative side multiplies by positive lengths: FAP 6 = -500 -> (0 - (-500)) * D0.
TEST(IntervalWeights, PaperWorkedExampleNegative) {
  EXPECT_EQ(weightsOf({-1000, 0, 500, 1000}, -500), (std::vector<double>{500, 0, 0}));
  EXPECT_EQ(weightsOf({-1000, -400, 0, 1000}, -600), (std::vector<double>{200, 400, 0}));
}

TEST(IntervalWeights, BeyondTheOutermostBordersTheOutermostIntervalContinues) {
  EXPECT_EQ(weightsOf({-1000, 0, 500, 1000}, 1500), (std::vector<double>{0, 500, 1000}));
  EXPECT_EQ(weightsOf({-1000, 0, 500, 1000}, -1300), (std::vector<double>{1300, 0, 0}));
  EXPECT_EQ(weightsOf({0, 500, 1000}, -200), (std::vector<double>{-200, 0}));
  EXPECT_EQ(weightsOf({-1000, -500, 0}, 300), (std::vector<double>{0, -300}));
  EXPECT_EQ(weightsOf({-1000, 0, 500, 1000}, 0), (std::vector<double>{0, 0, 0}));
}

TEST(IntervalWeights, OneIntervalIsLinearAndSigned) {
  EXPECT_EQ(weightsOf({0, 1000}, -250), (std::vector<double>{-250}));
  EXPECT_EQ(weightsOf({-1000, 1000}, 700), (std::vector<double>{700}));
}

// The border weights give the same motion as the interval weights: with D_k per interval and
// motion(b) = sum_k intervalWeights(b)_k D_k, sum_i borderWeights(v)_i motion(b_i) equals
// sum_k intervalWeights(v)_k D_k, for random borders (one interval, 0 first or last, 0
// inside), values inside, on and beyond the borders.
TEST(BorderWeights, GiveTheMotionOfTheIntervalWeights) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> width(1, 500), count(1, 5), value(-3000, 3000);
  std::uniform_real_distribution<double> d(-1, 1);
  for (int round = 0; round < 500; ++round) {
    const int n = count(rng);
    std::vector<int> borders{0};
    const int below = n == 1 && round % 3 == 0 ? 0 : std::uniform_int_distribution<int>(0, n)(rng);
    for (int k = 0; k < below; ++k) borders.insert(borders.begin(), borders.front() - width(rng));
    while (static_cast<int>(borders.size()) < n + 1) borders.push_back(borders.back() + width(rng));
    if (n == 1 && round % 3 == 1) borders = {-width(rng), width(rng)};  // 0 inside
    std::vector<double> D(static_cast<std::size_t>(n));
    for (double& x : D) x = d(rng);
    const auto motion = [&](double v) {
      std::vector<double> w;
      intervalWeights(borders, v, w);
      double sum = 0;
      for (int k = 0; k < n; ++k) sum += w[k] * D[k];
      return sum;
    };
    for (const double v : {double(value(rng)), double(borders[rng() % borders.size()]), 0.0,
                           borders.front() - 100.0, borders.back() + 100.0}) {
      std::vector<double> w;
      borderWeights(borders, v, w);
      ASSERT_EQ(w.size(), borders.size());
      double sum = 0;
      for (std::size_t i = 0; i < borders.size(); ++i) sum += w[i] * motion(borders[i]);
      EXPECT_NEAR(sum, motion(v), 1e-9 * (1 + std::abs(motion(v))))
          << "round " << round << " value " << v;
    }
  }
  std::vector<double> w;
  borderWeights(std::vector<int>{-1000, 0, 500, 1000}, 600, w);
  EXPECT_EQ(w, (std::vector<double>{0, 0, 0.8, 0.2}));
  borderWeights(std::vector<int>{0, 500}, -250, w);  // one interval continues through 0
  EXPECT_EQ(w, (std::vector<double>{1.5, -0.5}));
}

TEST(IntervalWeights, BordersAreChecked) {
  EXPECT_THROW(checkIntervalBorders(std::vector<int>{0}), Error);
  EXPECT_THROW(checkIntervalBorders(std::vector<int>{0, 0}), Error);
  EXPECT_THROW(checkIntervalBorders(std::vector<int>{-5, 5, 10}), Error);
  EXPECT_EQ(errorOf([] {
              checkIntervalBorders(std::vector<int>{0, 10, 5});
            }).field(),
            "intervalBorders");
  EXPECT_NO_THROW(checkIntervalBorders(std::vector<int>{-1000, 1000}));
  EXPECT_NO_THROW(checkIntervalBorders(std::vector<int>{-1000, 0, 500, 1000}));
}

TEST(FaceDefTransform, RotationTranslationAndScaleFollowTheScaledValue) {
  Transform t;
  t.translation = {1, 2, 3};
  FaceDefTransform yaw;  // Tekalp-Ostermann Table 5: LeftEyeX, axis (0, -1, 0), angle 1
  yaw.rotationDef = {0, -1, 0, 1};
  applyFaceDefTransform(yaw, 20000 * kAngleUnitRadians, t);
  EXPECT_NEAR(Eigen::AngleAxisd(t.rotation).angle(), 0.2, 1e-12);
  EXPECT_TRUE(Eigen::AngleAxisd(t.rotation).axis().isApprox(Eigen::Vector3d(0, -1, 0)));
  FaceDefTransform move;
  move.fieldId = FaceDefTransform::Field::Translation;
  move.translationDef = {0, -0.5, 0};
  applyFaceDefTransform(move, 4.0, t);
  EXPECT_TRUE(t.translation.isApprox(Eigen::Vector3d(1, 0, 3)));
  FaceDefTransform grow;
  grow.fieldId = FaceDefTransform::Field::Scale;
  grow.scaleDef = {0.1, 0, 0};
  applyFaceDefTransform(grow, 2.0, t);
  EXPECT_TRUE(t.scale.isApprox(Eigen::Vector3d(1.2, 1, 1)));
  yaw.rotationDef = {0, 0, 0, 1};
  EXPECT_EQ(errorOf([&] { applyFaceDefTransform(yaw, 1.0, t); }).field(), "rotationDef");
}

TEST(FapScale, LinearFapuAngleUnitAndHighLevel) {
  FapuMeasurement fapu;
  fapu.MNS0 = {true, 2048.0, {"9.15", "2.2"}, "9.15.y - 2.2.y"};
  EXPECT_EQ(fapScale(fapu, 3), 2.0);  // open_jaw: MNS
  EXPECT_EQ(fapScale(fapu, 23), kAngleUnitRadians);
  EXPECT_EQ(fapScale(fapu, 1), 1.0);
  EXPECT_EQ(fapScale(fapu, 19), 0.0);  // IRISD not measured
}
