// SPDX-License-Identifier: GPL-3.0-or-later
// Texture warping and rendering of the 2D mesh object.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <fstream>

#include "mesh2d_fixture.hpp"
#include "mpeg4face/mesh2d/codec.hpp"
#include "mpeg4face/mesh2d/render.hpp"
#include "mpeg4face/mesh2d/warp.hpp"
#include "test_support.hpp"

namespace mpeg4face {
namespace {

// The affine motion of the test: about the image centre, with a shift.
struct Affine {
  Eigen::Matrix2d a{{1.05, 0.08}, {-0.06, 0.97}};
  Eigen::Vector2d centre{160, 120}, shift{6, -4};
  Eigen::Vector2d operator()(const Eigen::Vector2d& p) const {
    return centre + a * (p - centre) + shift;
  }
  Eigen::Vector2d inverse(const Eigen::Vector2d& q) const {
    return centre + a.inverse() * (q - centre - shift);
  }
};

double psnrAgainstDirectWarp(const Image& texture, const Image& warped, const Affine& affine,
                             double x0, double y0, double x1, double y1) {
  double sum = 0;
  long count = 0;
  for (int y = 0; y < warped.height; ++y) {
    for (int x = 0; x < warped.width; ++x) {
      const Eigen::Vector2d s = affine.inverse({x, y});
      // Interior: 2 pixels inside the mesh.
      if (s.x() < x0 + 2 || s.x() > x1 - 2 || s.y() < y0 + 2 || s.y() > y1 - 2) continue;
      for (int c = 0; c < 3; ++c) {
        const double d = warped.row(y)[x * 3 + c] - test::bilinear(texture, s.x(), s.y(), c);
        sum += d * d;
        ++count;
      }
    }
  }
  EXPECT_GT(count, 100000);
  return 10 * std::log10(255.0 * 255.0 / (sum / static_cast<double>(count)));
}

TEST(Mesh2dWarp, GlobalAffineMotionMatchesTheDirectWarp) {
  const Image texture = test::testTexture(320, 240);
  Mesh2dSequence s;
  s.width = 320;
  s.height = 240;
  s.uniform = {9, 7, 16, 16, 36, 34.5, 2};
  s.frames.push_back(uniformMeshNodes(s.uniform));
  const Affine affine;
  Mesh2dNodes moved = s.frames[0];
  for (Eigen::Index n = 0; n < moved.rows(); ++n) {
    moved.row(n) = affine(moved.row(n).transpose()).transpose();
  }
  s.frames.push_back(moved);
  const double x1 = 16 + 8 * 36, y1 = 16 + 6 * 34.5;
  const double exact =
      psnrAgainstDirectWarp(texture, renderMesh2dFrame(texture, s, 1), affine, 16, 16, x1, y1);
  Mesh2dSequence decoded = decodeMesh2d(encodeMesh2d(s, 0.5));
  const double coded = psnrAgainstDirectWarp(texture, renderMesh2dFrame(texture, decoded, 1),
                                             affine, 16, 16, x1, y1);
  std::printf(
      "[ warp ] PSNR against the direct affine warp: %.1f dB (exact nodes), %.1f dB "
      "(coded, step 0.5)\n",
      exact, coded);
  EXPECT_GE(exact, 35);
  EXPECT_GE(coded, 35);
}

TEST(Mesh2dWarp, ExactAtTheNodes) {
  const Image texture = test::testTexture(64, 48);
  const UniformMesh2d u{5, 4, 2, 3, 15, 14, 1};
  const Mesh2dNodes intra = uniformMeshNodes(u);
  Mesh2dNodes current = intra;
  for (Eigen::Index n = 0; n < current.rows(); ++n)
    current.row(n) += Eigen::RowVector2d(n % 3 - 1, n % 2);
  Image out(64, 48, 3);
  warpMesh2d(texture, intra, current, uniformMeshTriangles(u), out);
  for (Eigen::Index n = 0; n < current.rows(); ++n) {
    const int x = static_cast<int>(current(n, 0)), y = static_cast<int>(current(n, 1));
    const int sx = static_cast<int>(intra(n, 0)), sy = static_cast<int>(intra(n, 1));
    for (int c = 0; c < 3; ++c) EXPECT_EQ(out.row(y)[x * 3 + c], texture.row(sy)[sx * 3 + c]) << n;
  }
}

TEST(Mesh2dWarp, ImagesRoundTripAndBadImagesAreNamed) {
  const auto dir = test::scratchDir();
  const Image texture = test::testTexture(40, 30);
  writeImage(dir / "t.png", texture);
  const Image back = readImage(dir / "t.png");
  EXPECT_EQ(back.pixels, texture.pixels);
  std::ofstream(dir / "bad.png") << "not an image";
  Error e = test::errorOf([&] { readImage(dir / "bad.png"); });
  EXPECT_EQ(e.file(), (dir / "bad.png").string());
  EXPECT_NE(e.reason().find("does not load"), std::string::npos);
  e = test::errorOf([&] { readImage(dir / "missing.png"); });
  EXPECT_NE(e.reason().find("no such file"), std::string::npos);
  // Frames to a folder; a texture of the wrong size is named.
  Mesh2dSequence s = test::uniformFixture(3, 3, 0);
  test::addSmoothFrames(s, 3);
  e = test::errorOf([&] { renderMesh2d(texture, s, dir / "frames"); });
  EXPECT_EQ(e.field(), "image");
  const Image fitting = test::testTexture(s.width, s.height);
  renderMesh2d(fitting, s, dir / "frames");
  EXPECT_TRUE(std::filesystem::exists(dir / "frames" / "frame_00002.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "frames.part"));
}

}  // namespace
}  // namespace mpeg4face
