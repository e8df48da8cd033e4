// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh design on a still image and tracking through a synthetic sequence of known motion.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mesh2d_fixture.hpp"
#include "mpeg4face/mesh2d/design.hpp"
#include "mpeg4face/mesh2d/track.hpp"
#include "test_support.hpp"

namespace mpeg4face {
namespace {

constexpr int kWidth = 320, kHeight = 240;

// The known smooth warp of frame t: a drift, a shear and a bulge, about 8 pixels at most.
Eigen::Vector2d displacement(const Eigen::Vector2d& p, int t) {
  const double s = t / 8.0;
  return s * Eigen::Vector2d(3 + 2 * std::sin(p.y() / 45.0) + 0.01 * (p.y() - 120),
                             -2 + 2.5 * std::cos(p.x() / 60.0));
}

// A texture with blobs at random places and sizes over the periodic one, so that the
// optical flow has unambiguous features.
Image blobTexture() {
  Image image = test::testTexture(kWidth, kHeight);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> x(0, kWidth), y(0, kHeight), r(3, 12), v(-90, 90);
  std::vector<std::array<double, 4>> blobs;
  for (int i = 0; i < 150; ++i) blobs.push_back({x(random), y(random), r(random), v(random)});
  for (int py = 0; py < kHeight; ++py) {
    for (int px = 0; px < kWidth; ++px) {
      double add = 0;
      for (const auto& b : blobs) {
        const double d2 = (px - b[0]) * (px - b[0]) + (py - b[1]) * (py - b[1]);
        if (d2 < 9 * b[2] * b[2]) add += b[3] * std::exp(-d2 / (2 * b[2] * b[2]));
      }
      for (int c = 0; c < 3; ++c) {
        uint8_t& p = image.row(py)[px * 3 + c];
        p = static_cast<uint8_t>(std::clamp(std::lround(0.5 * p + add + 64), 0L, 255L));
      }
    }
  }
  return image;
}

// Frame t: the texture moved by displacement(., t), I_t(q) = I_0(p) where q = p + D(p).
Image movedFrame(const Image& texture, int t) {
  Image out(kWidth, kHeight, 3);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const Eigen::Vector2d q(x, y);
      Eigen::Vector2d p = q;
      for (int i = 0; i < 20; ++i) p = q - displacement(p, t);  // contraction: D is smooth
      for (int c = 0; c < 3; ++c) {
        out.row(y)[x * 3 + c] =
            static_cast<uint8_t>(std::lround(test::bilinear(texture, p.x(), p.y(), c)));
      }
    }
  }
  return out;
}

TEST(Mesh2dTrack, DesignsUniformAndContentBasedMeshes) {
  const Mesh2dSequence u = designUniformMesh2d(kWidth, kHeight, 8, 6, 1);
  EXPECT_EQ(u.uniform.nodesX, 9);
  EXPECT_LE(u.frames[0].col(0).maxCoeff(), kWidth - 1);
  EXPECT_GT(u.frames[0].col(0).maxCoeff(), kWidth - 1 - 8 * 0.5 - 1e-9);
  const Image texture = blobTexture();
  const Mesh2dSequence d = designDelaunayMesh2d(texture, 200);
  EXPECT_NEAR(static_cast<double>(d.frames[0].rows()), 200, 10);
  EXPECT_EQ(d.boundary, 20);
  EXPECT_GT(d.triangles.rows(), 300);
  // With a mask, the nodes stay inside it.
  Image mask(kWidth, kHeight, 3);
  for (int y = 60; y < 180; ++y) std::fill_n(mask.row(y) + 80 * 3, 160 * 3, uint8_t{255});
  const Mesh2dSequence m = designDelaunayMesh2d(texture, 100, &mask);
  EXPECT_GE(m.frames[0].col(0).minCoeff(), 79);
  EXPECT_LE(m.frames[0].col(0).maxCoeff(), 240);
  EXPECT_GE(m.frames[0].col(1).minCoeff(), 59);
  EXPECT_LE(m.frames[0].col(1).maxCoeff(), 180);
  const Image empty(kWidth, kHeight, 3);
  EXPECT_EQ(test::errorOf([&] { designDelaunayMesh2d(texture, 100, &empty); }).field(), "mask");
}

TEST(Mesh2dTrack, SyntheticSmoothWarpIsTrackedWithinHalfAPixel) {
  const Image texture = blobTexture();
  std::vector<Image> frames{texture};
  constexpr int kFrames = 9;
  for (int t = 1; t < kFrames; ++t) frames.push_back(movedFrame(texture, t));
  // Inside a margin, so that every node's window sees the moved texture, not the border.
  Image mask(kWidth, kHeight, 3);
  for (int y = 25; y < kHeight - 25; ++y)
    std::fill_n(mask.row(y) + 25 * 3, (kWidth - 50) * 3, uint8_t{255});
  const Mesh2dSequence mesh = designDelaunayMesh2d(texture, 150, &mask);
  const Mesh2dSequence tracked = trackMesh2d(frames, mesh);
  ASSERT_EQ(tracked.frames.size(), size_t{kFrames});
  double sum = 0, worst = 0;
  long count = 0;
  for (int t = 1; t < kFrames; ++t) {
    for (Eigen::Index n = 0; n < mesh.frames[0].rows(); ++n) {
      const Eigen::Vector2d p = mesh.frames[0].row(n).transpose();
      const double e =
          (p + displacement(p, t) - tracked.frames[size_t(t)].row(n).transpose()).norm();
      sum += e;
      worst = std::max(worst, e);
      ++count;
    }
  }
  std::printf("[ track ] %ld nodes x frames: mean error %.3f px, worst %.3f px\n", count,
              sum / static_cast<double>(count), worst);
  EXPECT_LE(sum / static_cast<double>(count), 0.5);
}

TEST(Mesh2dTrack, NoFoldOversAndBadFramesAreNamed) {
  // A frame of noise: the flow finds nothing sensible, the mesh must still not fold.
  const Image texture = blobTexture();
  Image noise(kWidth, kHeight, 3);
  std::mt19937 random(3);
  for (uint8_t& p : noise.pixels) p = static_cast<uint8_t>(random() & 255);
  const Mesh2dSequence mesh = designDelaunayMesh2d(texture, 120);
  const Mesh2dSequence tracked = trackMesh2d({texture, noise, movedFrame(texture, 2)}, mesh);
  for (const Mesh2dNodes& plane : tracked.frames) {
    for (Eigen::Index t = 0; t < tracked.triangles.rows(); ++t) {
      const Eigen::Vector2d a = plane.row(tracked.triangles(t, 0)),
                            b = plane.row(tracked.triangles(t, 1)),
                            c = plane.row(tracked.triangles(t, 2));
      const Eigen::Vector2d u = b - a, v = c - a;
      EXPECT_GT(u.x() * v.y() - u.y() * v.x(), 0) << "triangle " << t << " folds over";
    }
  }
  const Image small(10, 10, 3);
  EXPECT_EQ(test::errorOf([&] { trackMesh2d({texture, small}, mesh); }).field(), "frames[1]");
  EXPECT_EQ(test::errorOf([] { readFrames("/nonexistent/video.mp4"); }).field(), "video");
}

}  // namespace
}  // namespace mpeg4face
