// SPDX-License-Identifier: GPL-3.0-or-later
// The motion error at a face's feature points (issue 20 part 1) on the motion-check test head:
// its FAP 3 table moves the chin (2.1) by one model unit at 1024, and ES0 is 2 model units.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "motion_check_fixture.hpp"
#include "mpeg4face/codec/motion_error.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/vrml.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::FapStream;

FapStream fap3(const std::vector<int>& values) {
  FapStream s;
  for (size_t n = 0; n < values.size(); ++n) {
    mpeg4face::FapFrame f;
    f.number = static_cast<int>(n);
    f.set(3, values[n]);
    s.frames.push_back(f);
  }
  return s;
}

TEST(FapMotionError, ChinErrorInPercentOfEs0) {
  mpeg4face::test::MotionHead h = mpeg4face::test::motionHead();
  h.key("fap3@1024", h.chin, {0, -1, 0});
  const mpeg4face::MpegFace face = mpeg4face::faceFromShapeKeys(h.model).face;
  // Frame 1 decoded at 512 instead of 1024: the chin is 0.5 units off = 25 % of ES0 = 2;
  // frames 0 and 2 are exact.
  const auto e =
      mpeg4face::featurePointMotionError(face, fap3({0, 1024, 256}), fap3({0, 512, 256}));
  EXPECT_EQ(e.frames, 3);
  EXPECT_GT(e.points, 0);
  EXPECT_NEAR(e.maxPercentEs0, 25.0, 1e-6);
  EXPECT_EQ(e.worstPoint, "2.1");
  EXPECT_EQ(e.worstFrame, 1);
  // Only one point in one frame moves wrongly.
  EXPECT_NEAR(e.rmsPercentEs0, std::sqrt(25.0 * 25.0 / (3.0 * e.points)), 1e-6);
  EXPECT_EQ(
      mpeg4face::featurePointMotionError(face, fap3({0, 1024}), fap3({0, 1024})).maxPercentEs0,
      0.0);
  EXPECT_THROW(mpeg4face::featurePointMotionError(face, fap3({0, 1}), fap3({0})), mpeg4face::Error);
}

// `psnr --face`, run as a user runs it: the same figures, the face written as .wrl and read
// back.
TEST(FapMotionError, PsnrFace) {
  mpeg4face::test::MotionHead h = mpeg4face::test::motionHead();
  h.key("fap3@1024", h.chin, {0, -1, 0});
  const auto dir = mpeg4face::test::scratchDir();
  mpeg4face::writeVrml(mpeg4face::faceFromShapeKeys(h.model).face, dir / "face.wrl");
  mpeg4face::writeFapFile(dir / "a.fap", fap3({0, 1024, 256}));
  mpeg4face::writeFapFile(dir / "b.fap", fap3({0, 512, 256}));
  const std::string files = (dir / "a.fap").string() + " " + (dir / "b.fap").string() + " --face " +
                            (dir / "face.wrl").string();
  auto r = mpeg4face::test::runCli("psnr " + files + " --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.stdoutOnly)["motion_error"];
  EXPECT_NEAR(j["max_percent_es0"].get<double>(), 25.0, 1e-6) << j;
  EXPECT_EQ(j["worst_point"], "2.1");
  EXPECT_EQ(j["worst_frame"], 1);
  r = mpeg4face::test::runCli("psnr " + files);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("largest 25.000 % (point 2.1, frame 1)"), std::string::npos) << r.out;
}

}  // namespace
