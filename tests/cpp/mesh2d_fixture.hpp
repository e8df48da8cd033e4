// SPDX-License-Identifier: GPL-3.0-or-later
// Synthetic 2D mesh sequences for the mesh2d tests: uniform grids, Delaunay meshes with a
// convex or a concave (star) boundary and jittered interior nodes, smooth motion.
#pragma once

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "mpeg4face/mesh2d/mesh2d.hpp"
#include "mpeg4face/mesh2d/warp.hpp"

namespace mpeg4face::test {

// Crossing-number test (points exactly on an edge do not occur in the fixtures).
inline bool insidePolygon(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p) {
  bool inside = false;
  for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

inline double segmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                              const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

// A Delaunay intra plane of `count` nodes: the boundary `polygon`, the rest on a jittered grid
// inside it, kept 1/3 of the grid spacing from the boundary.
inline Mesh2dSequence delaunayFixture(int count, const std::vector<Eigen::Vector2d>& polygon,
                                      int width, int height, unsigned seed = 1) {
  Mesh2dSequence s;
  s.type = Mesh2dType::Delaunay;
  s.width = width;
  s.height = height;
  Eigen::Vector2d low = polygon[0], high = polygon[0];
  for (const Eigen::Vector2d& p : polygon) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  const auto boundary = static_cast<int>(polygon.size());
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> jitter(-0.25, 0.25);
  // Shrink the grid until enough interior nodes fit.
  std::vector<Eigen::Vector2d> interior;
  for (double spacing = 1.5 * std::sqrt((high - low).prod() / count);
       interior.size() < size_t(count - boundary); spacing *= 0.9) {
    interior.clear();
    for (double y = low.y() + spacing / 2; y < high.y(); y += spacing) {
      for (double x = low.x() + spacing / 2; x < high.x(); x += spacing) {
        const Eigen::Vector2d p(x + jitter(random) * spacing, y + jitter(random) * spacing);
        if (!insidePolygon(polygon, p)) continue;
        bool clear = true;
        for (size_t i = 0; i < polygon.size() && clear; ++i) {
          clear = segmentDistance(p, polygon[i], polygon[(i + 1) % polygon.size()]) > spacing / 3;
        }
        if (clear) interior.push_back(p);
      }
    }
  }
  std::shuffle(interior.begin(), interior.end(), random);
  Mesh2dNodes nodes(count, 2);
  for (int i = 0; i < boundary; ++i) nodes.row(i) = polygon[static_cast<size_t>(i)].transpose();
  for (int i = boundary; i < count; ++i) {
    nodes.row(i) = interior[static_cast<size_t>(i - boundary)].transpose();
  }
  s.boundary = boundary;
  s.frames.push_back(nodes);
  return s;
}

// The same around (r + 20, r + 20): a circle (convex) or a star (concave) of `boundary` nodes.
inline Mesh2dSequence delaunayFixture(int count, int boundary, bool concave, double radius,
                                      unsigned seed = 1) {
  const double c = radius + 20;
  std::vector<Eigen::Vector2d> polygon;
  for (int i = 0; i < boundary; ++i) {
    const double a = 2 * std::numbers::pi * i / boundary;
    const double r = concave ? radius * (i % 2 == 0 ? 1.0 : 0.55) : radius;
    polygon.emplace_back(c + r * std::cos(a), c + r * std::sin(a));
  }
  const int size = static_cast<int>(std::ceil(2 * c));
  return delaunayFixture(count, polygon, size, size, seed);
}

// The same over a whole width x height image, the boundary its frame (every `side` pixels).
inline Mesh2dSequence delaunayImageFixture(int count, int width, int height, double side) {
  std::vector<Eigen::Vector2d> polygon;
  const double w = width - 1, h = height - 1;
  for (double x = 0; x < w; x += side) polygon.emplace_back(x, 0);
  for (double y = 0; y < h; y += side) polygon.emplace_back(w, y);
  for (double x = w; x > 0; x -= side) polygon.emplace_back(x, h);
  for (double y = h; y > 0; y -= side) polygon.emplace_back(0, y);
  return delaunayFixture(count, polygon, width, height);
}

inline Mesh2dSequence uniformFixture(int nodesX, int nodesY, int topology) {
  Mesh2dSequence s;
  s.type = Mesh2dType::Uniform;
  s.uniform = {nodesX, nodesY, 10, 12.5, 20, 17.5, topology};
  s.width = static_cast<int>(20 + (nodesX - 1) * 20);
  s.height = static_cast<int>(25 + (nodesY - 1) * 17.5);
  s.frames.push_back(uniformMeshNodes(s.uniform));
  return s;
}

// A smooth motion field: a slow drift plus a travelling wave, a few pixels at most.
inline Eigen::Vector2d smoothMotion(const Eigen::Vector2d& p, int frame) {
  const double t = frame / 10.0;
  return {3 * t + 2.5 * std::sin(0.02 * p.y() + t), -1.5 * t + 2 * std::cos(0.015 * p.x() - t)};
}

// Appends `frames` - 1 inter planes moved by smoothMotion from the intra plane.
inline void addSmoothFrames(Mesh2dSequence& s, int frames) {
  const Mesh2dNodes intra = s.frames[0];
  for (int f = 1; f < frames; ++f) {
    Mesh2dNodes next = intra;
    for (Eigen::Index n = 0; n < next.rows(); ++n) {
      next.row(n) += smoothMotion(intra.row(n).transpose(), f).transpose();
    }
    s.frames.push_back(next);
  }
}

// A colour texture with detail at several scales.
inline Image testTexture(int w, int h) {
  Image image(w, h, 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) {
        const double v = 128 + 60 * std::sin(x / (7.0 + c) + c) * std::cos(y / 9.0) +
                         40 * std::sin((x + 2 * y) / 23.0 - c);
        image.row(y)[x * 3 + c] = static_cast<uint8_t>(std::clamp(std::lround(v), 0L, 255L));
      }
    }
  }
  return image;
}

// Bilinear sample of one channel, in double precision.
inline double bilinear(const Image& image, double x, double y, int c) {
  const int ix = std::clamp(static_cast<int>(std::floor(x)), 0, image.width - 2);
  const int iy = std::clamp(static_cast<int>(std::floor(y)), 0, image.height - 2);
  const double fx = x - ix, fy = y - iy;
  auto at = [&](int u, int v) { return double(image.row(v)[u * image.channels + c]); };
  return (1 - fy) * ((1 - fx) * at(ix, iy) + fx * at(ix + 1, iy)) +
         fy * ((1 - fx) * at(ix, iy + 1) + fx * at(ix + 1, iy + 1));
}

}  // namespace mpeg4face::test
