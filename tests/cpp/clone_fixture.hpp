// SPDX-License-Identifier: GPL-3.0-or-later
// Heads and FAP shapes for measuring Facial Motion Cloning, shared by
// tests/cpp/clone/test_smoothness.cpp and bench/bench_clone.cpp: CANDIDE-3 with its feature
// points at any density (model/mesh_resample.hpp), 68 synthetic FAP, viseme and expression shapes
// on it, and a
// roughness measure of a motion field. Header-only, no GoogleTest.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "mpeg4face/fat/generate.hpp"
#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/wfm.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/model/mesh_resample.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face::clone_fixture {

// Turns triangles so that neighbours run through their common edge in opposite directions
// (breadth first from each unvisited triangle): CANDIDE-3 mixes both windings, which
// OpenMesh (model/mesh_resample.hpp) refuses as non-manifold.
inline void orientConsistently(IndexedFaceSet& mesh) {
  std::vector<int> t = mesh.triangles();
  const size_t n = t.size() / 3;
  std::map<std::pair<int, int>, std::vector<size_t>> byEdge;
  for (size_t f = 0; f < n; ++f) {
    for (size_t k = 0; k < 3; ++k) {
      byEdge[std::minmax(t[3 * f + k], t[3 * f + (k + 1) % 3])].push_back(f);
    }
  }
  const auto runs = [&](size_t f, int a, int b) {  // does triangle f go a -> b?
    for (size_t k = 0; k < 3; ++k) {
      if (t[3 * f + k] == a && t[3 * f + (k + 1) % 3] == b) return true;
    }
    return false;
  };
  std::vector<bool> done(n, false);
  for (size_t seed = 0; seed < n; ++seed) {
    if (done[seed]) continue;
    done[seed] = true;
    std::vector<size_t> queue{seed};
    while (!queue.empty()) {
      const size_t f = queue.back();
      queue.pop_back();
      for (size_t k = 0; k < 3; ++k) {
        const int a = t[3 * f + k], b = t[3 * f + (k + 1) % 3];
        for (size_t g : byEdge[std::minmax(a, b)]) {
          if (done[g]) continue;
          done[g] = true;
          if (runs(g, a, b)) std::swap(t[3 * g + 1], t[3 * g + 2]);
          queue.push_back(g);
        }
      }
    }
  }
  mesh.coordIndex.clear();
  for (size_t f = 0; f < n; ++f) {
    mesh.coordIndex.insert(mesh.coordIndex.end(), {t[3 * f], t[3 * f + 1], t[3 * f + 2], -1});
  }
}

// CANDIDE-3 (one mesh of 113 vertices, consistently oriented) with the feature points of
// its CSV, from tests/data.
inline FaceModel candide(const std::filesystem::path& dataDir) {
  FaceModel model = readWfm(dataDir / "candide3" / "candide3.wfm").model;
  orientConsistently(model.meshes[0]);
  model.featurePoints =
      readFeaturePointCsv(dataDir / "candide3" / "feature_points.csv", model).featurePoints;
  return model;
}

// One-mesh `model` with about `vertices` vertices: subdivided (modified butterfly, which keeps
// the feature-point vertices) until it has at least that many, then decimated (quadric, the
// feature points locked) down to them: an irregular mesh, as a modeled or scanned head is.
inline FaceModel resampled(const FaceModel& model, int vertices) {
  FaceModel out = model;
  while (out.meshes[0].vertexCount() < vertices) out = subdivideFaceModel(out, 1);
  const double fraction = static_cast<double>(vertices) / out.meshes[0].vertexCount();
  return fraction < 1 ? decimateFaceModel(out, fraction) : out;
}

// A hash of (shape, vertex) to [-1, 1]: per-vertex detail that does not depend on the order
// in which vertices are visited.
inline double detailNoise(int shape, int vertex) {
  std::uint64_t x = static_cast<std::uint64_t>(shape) * 0x9E3779B97F4A7C15ull ^
                    static_cast<std::uint64_t>(vertex) * 0xC2B2AE3D27D4EB4Full;
  x ^= x >> 31;
  x *= 0xBF58476D1CE4E5B9ull;
  x ^= x >> 29;
  return static_cast<double>(x >> 11) / static_cast<double>(1ull << 52) - 1.0;
}

// Where shape `fapID` acts: its feature point (the first listed), else the mouth (visemes,
// FAPs whose point the face lacks), the left brow (expressions).
inline Eigen::Vector3d shapeCentre(const FaceModel& model, int fapID) {
  std::string id = fapID == 2 ? "4.3" : "2.2";
  if (fapID >= 3) {
    const std::string_view fp = fapInfo(fapID).featurePoint;
    const std::string first(fp.substr(0, fp.find(',')));
    if (model.featurePoints.contains(first)) id = first;
  }
  return *model.featurePointPosition(id);
}

// 68 shapes (FAP 3..68 at 512, viseme 1 and expression 1 at 63) of one-mesh `model`: each a
// smooth bump of motion around the shape's centre (peak 0.1 ES0, a direction of its own),
// local as a sculpted shape is: (1 - r^2 / R^2)^3 within R = 0.9 ES0 of the centre, 0
// beyond; times (1 + detail * noise): `detail` > 0 adds per-vertex
// irregularity, the high-frequency motion that aliases when a dense source is sampled by a
// coarse target.
inline std::vector<FaceShape> syntheticCopies(const FaceModel& model, double detail) {
  const double es = measureFapu(model).ES0.value;
  const double reach = 0.9 * es, peak = 0.1 * es;
  std::vector<std::pair<int, int>> shapes{{1, 1}, {2, 1}};
  for (int fap = 3; fap <= kFapCount; ++fap) shapes.emplace_back(fap, 0);
  std::vector<FaceShape> copies;
  for (const auto& [fapID, select] : shapes) {
    FaceShape& copy = copies.emplace_back();
    copy.fapID = fapID;
    copy.highLevelSelect = select;
    copy.amplitude = fapID <= 2 ? 63 : 512;
    copy.name = "shape" + std::to_string(fapID);
    const Eigen::RowVector3d centre = shapeCentre(model, fapID).transpose();
    const Eigen::RowVector3d direction =
        Eigen::RowVector3d(std::sin(fapID), std::cos(1.7 * fapID), 0.5 * std::sin(2.3 * fapID))
            .normalized();
    const Points3& coord = model.meshes[0].coord;
    Points3 motion = Points3::Zero(coord.rows(), 3);
    for (int v = 0; v < coord.rows(); ++v) {
      const double r2 = (coord.row(v) - centre).squaredNorm();
      const double q = 1 - r2 / (reach * reach);
      if (q <= 0) continue;
      motion.row(v) = peak * q * q * q * (1 + detail * detailNoise(fapID, v)) * direction;
    }
    copy.meshes.push_back(sparseDisplacement(0, motion));
  }
  return copies;
}

// Roughness of a motion field on a mesh: mean |uniform Laplacian of the motion| (a vertex's
// motion minus the mean of its neighbours') over mean |motion|, over the vertices that move.
// 0 for a motion that is locally linear on a regular mesh; about 1 or more for noise.
inline double roughness(const IndexedFaceSet& mesh, const Points3& motion) {
  std::vector<std::vector<int>> neighbours(static_cast<size_t>(mesh.vertexCount()));
  const std::vector<int> triangles = mesh.triangles();
  for (size_t t = 0; t < triangles.size(); t += 3) {
    for (int k = 0; k < 3; ++k) {
      const int a = triangles[t + static_cast<size_t>(k)];
      const int b = triangles[t + static_cast<size_t>((k + 1) % 3)];
      neighbours[static_cast<size_t>(a)].push_back(b);
      neighbours[static_cast<size_t>(b)].push_back(a);
    }
  }
  for (auto& n : neighbours) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  double laplacian = 0, magnitude = 0;
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    const auto& n = neighbours[static_cast<size_t>(v)];
    if (n.empty() || motion.row(v).isZero(0)) continue;
    Eigen::RowVector3d mean = Eigen::RowVector3d::Zero();
    for (int w : n) mean += motion.row(w);
    mean /= static_cast<double>(n.size());
    laplacian += (motion.row(v) - mean).norm();
    magnitude += motion.row(v).norm();
  }
  return magnitude > 0 ? laplacian / magnitude : 0;
}

}  // namespace mpeg4face::clone_fixture
