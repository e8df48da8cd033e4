// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/fat/motion_check.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <optional>

#include "fat/pose_intersections.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/fit/fit.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/model/surface_bump.hpp"
#include "mpeg4face/spec.hpp"
#include "percentile.hpp"

namespace mpeg4face {
namespace {

std::string format(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

std::vector<std::string> pointIds(int group, int last) {
  std::vector<std::string> ids;
  for (int i = 1; i <= last; ++i) ids.push_back(std::to_string(group) + "." + std::to_string(i));
  return ids;
}

// One mesh's neutral, prepared once: its edges, normals, one-rings, its self-intersection
// test (which knows the pairs the neutral already has), and which vertices lie where lips or
// lids may touch.
struct MeshCheck {
  int mesh = 0;
  std::vector<int> triangles;             // three per triangle, degenerate ones left out
  std::vector<std::array<int, 2>> edges;  // unique
  std::vector<double> edgeLength;         // neutral
  std::vector<Eigen::Vector3d> normal;    // neutral, unnormalised
  WeldedRings rings;                      // for the bumps
  double moveTolerance = 0;               // a vertex moved when it moved more than this
  std::optional<fat::PoseIntersections> intersections;  // of `triangles`
  std::vector<bool> lip, lid;                           // per mesh vertex
  // The triangles the head's own shapes turn over or make intersect, and their spike
  // vertices (sorted): a flip of such a triangle, a new pair with one, such a spike is the
  // head's, not counted.
  std::vector<int> ownTriangles, ownSpikes;

  bool ownTriangle(int t) const {
    return std::binary_search(ownTriangles.begin(), ownTriangles.end(), t);
  }

  // All `n` vertices in the lip region, or all in the lid region: where lips or lids meet,
  // skin may touch skin and fold (docs/motion-check.md, "Lips and lids meeting").
  bool inContactRegion(const int* vertices, int n) const {
    const auto all = [&](const std::vector<bool>& region) {
      return std::all_of(vertices, vertices + n, [&](int v) { return region[v]; });
    };
    return all(lip) || all(lid);
  }

  Eigen::Vector3d triangleNormal(const Points3& coord, std::size_t t) const {
    const Eigen::Vector3d a = coord.row(triangles[3 * t]).transpose();
    const Eigen::Vector3d b = coord.row(triangles[3 * t + 1]).transpose();
    const Eigen::Vector3d c = coord.row(triangles[3 * t + 2]).transpose();
    return (b - a).cross(c - a);
  }
};

MeshCheck prepareMesh(const FaceModel& model, int m, const std::vector<Eigen::Vector3d>& lipPoints,
                      double lipRadius, const std::vector<Eigen::Vector3d>& lidPoints,
                      double lidRadius) {
  const IndexedFaceSet& mesh = model.meshes[m];
  MeshCheck c;
  c.mesh = m;
  c.triangles = fat::checkedTriangles(mesh);
  const Points3& coord = mesh.coord;
  const std::size_t triangleCount = c.triangles.size() / 3;
  for (std::size_t t = 0; t < triangleCount; ++t) {
    for (int k = 0; k < 3; ++k) {
      int a = c.triangles[3 * t + k], b = c.triangles[3 * t + (k + 1) % 3];
      if (a > b) std::swap(a, b);
      c.edges.push_back({a, b});
    }
    c.normal.push_back(c.triangleNormal(coord, t));
  }
  std::sort(c.edges.begin(), c.edges.end());
  c.edges.erase(std::unique(c.edges.begin(), c.edges.end()), c.edges.end());
  for (const auto& [a, b] : c.edges) c.edgeLength.push_back((coord.row(a) - coord.row(b)).norm());
  c.rings = weldedRings(coord, c.triangles);
  const double size =
      coord.rows() ? (coord.colwise().maxCoeff() - coord.colwise().minCoeff()).norm() : 0.0;
  c.moveTolerance = 1e-7 * size;

  c.intersections.emplace(coord, c.triangles);

  const Eigen::Affine3d world = model.meshWorldMatrices()[m];
  const auto near = [&](const std::vector<Eigen::Vector3d>& points, double radius, int v) {
    const Eigen::Vector3d p = world * Eigen::Vector3d(coord.row(v).transpose());
    return std::any_of(points.begin(), points.end(),
                       [&](const Eigen::Vector3d& q) { return (p - q).norm() <= radius; });
  };
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    c.lip.push_back(near(lipPoints, lipRadius, v));
    c.lid.push_back(near(lidPoints, lidRadius, v));
  }
  return c;
}

class Checker {
 public:
  Checker(const FaceModel& neutral, const MotionLimits& limits)
      : neutral_(neutral),
        limits_(limits),
        fapu_(measureFapu(neutral)),
        world_(neutral.meshWorldMatrices()) {
    result_.limits = limits;
    const auto bound = [&](const std::vector<std::string>& ids) {
      std::vector<Eigen::Vector3d> points;
      for (const std::string& id : ids) {
        if (auto p = neutral.featurePointPosition(id)) points.push_back(*p);
      }
      return points;
    };
    std::vector<std::string> lipIds = pointIds(2, 9);
    lipIds.erase(lipIds.begin());  // 2.1 is the chin
    for (const std::string& id : pointIds(8, 10)) lipIds.push_back(id);
    const std::vector<Eigen::Vector3d> lips = bound(lipIds), lids = bound(pointIds(3, 14));
    const double lipRadius = limits.lipRegion * fapu_.MW0.value * (fapu_.MW0.measured ? 1 : 0);
    const double lidRadius = limits.lidRegion * fapu_.ES0.value * (fapu_.ES0.measured ? 1 : 0);
    if (!fapu_.MW0.measured) result_.notes.push_back("MW0 not measured: no lip region");
    if (!fapu_.ES0.measured) result_.notes.push_back("ES0 not measured: no lid region");
    for (int m = 0; m < static_cast<int>(neutral.meshes.size()); ++m) {
      meshes_.push_back(prepareMesh(neutral, m, lips, lipRadius, lids, lidRadius));
      result_.neutralIntersections +=
          static_cast<int>(meshes_.back().intersections->neutralPairs().size());
    }
    const bool corners = neutral.featurePointPosition("2.4") &&
                         neutral.featurePointPosition("2.5") &&
                         neutral.featurePointPosition("8.3") && neutral.featurePointPosition("8.4");
    if (corners && fapu_.MW0.measured) {
      outwards_ = (*neutral.featurePointPosition("8.3") - *neutral.featurePointPosition("8.4"))
                      .normalized();
    } else {
      result_.notes.push_back("lip corners not checked: needs 2.4, 2.5, 8.3, 8.4 and MW0");
    }
    hasGap_ = neutral.featurePointPosition("2.2") && neutral.featurePointPosition("2.3") &&
              fapu_.MNS0.measured;
    if (!hasGap_) result_.notes.push_back("inner-lip gap not measured: needs 2.2, 2.3 and MNS0");
    if (hasGap_) result_.neutralLipGap = lipGap(neutralCoord());
  }

  std::vector<Points3> neutralCoord() const {
    std::vector<Points3> coord;
    for (const IndexedFaceSet& mesh : neutral_.meshes) coord.push_back(mesh.coord);
    return coord;
  }

  Eigen::Vector3d point(const std::vector<Points3>& coord, const std::string& id) const {
    const FeaturePointBinding& fp = neutral_.featurePoints.at(id);
    if (fp.mesh < 0) return fp.position;
    return world_[fp.mesh] * Eigen::Vector3d(coord[fp.mesh].row(fp.vertex).transpose());
  }

  double lipGap(const std::vector<Points3>& coord) const {
    return (point(coord, "2.2").y() - point(coord, "2.3").y()) / fapu_.MNS0.value;
  }

  PoseMotion check(const std::vector<Points3>& coord, std::string name) {
    PoseMotion pose;
    pose.name = std::move(name);
    // Each mesh's largest motion in model space (and in its own), and the pose's: a mesh that
    // moves a mere fraction of the pose (a lip FAP's rounding on the teeth) is not measured
    // for spikes, and a mesh's bumps count against the pose's motion, not the mesh's: a lash
    // that moves 0.75 mm while the mouth moves a centimetre has no spike of 0.04 mm.
    std::vector<double> peak(meshes_.size(), 0.0), ownPeak(meshes_.size(), 0.0);
    for (std::size_t i = 0; i < meshes_.size(); ++i) {
      const int m = meshes_[i].mesh;
      if (meshes_[i].triangles.empty() || coord[m].rows() == 0) continue;
      const Points3 d = coord[m] - neutral_.meshes[m].coord;
      ownPeak[i] = d.rowwise().norm().maxCoeff();
      peak[i] = (d * world_[m].linear().transpose()).rowwise().norm().maxCoeff();
    }
    const double posePeak = peak.empty() ? 0.0 : *std::max_element(peak.begin(), peak.end());
    for (std::size_t i = 0; i < meshes_.size(); ++i) {
      MeshCheck& c = meshes_[i];
      if (c.triangles.empty()) continue;
      // The pose's peak in the mesh's own units; 0: no spikes looked for.
      const double spikePeak = peak[i] > 0 && peak[i] >= limits_.bumpMeshShare * posePeak
                                   ? posePeak * ownPeak[i] / peak[i]
                                   : 0.0;
      if (auto motion = checkMesh(c, coord[c.mesh], spikePeak)) {
        pose.meshes.push_back(std::move(*motion));
      }
    }
    for (const MeshMotion& m : pose.meshes) {
      pose.edgeRatioMax = std::max(pose.edgeRatioMax, m.edgeRatioMax);
      pose.edgeRatioP99 = std::max(pose.edgeRatioP99, m.edgeRatioP99);
      pose.normalFlips += static_cast<int>(m.flippedTriangles.size());
      pose.contactFolds += m.contactFolds;
      pose.newIntersections += static_cast<int>(m.newIntersections.size());
      pose.touchingIntersections += m.touchingIntersections;
      pose.spikes += static_cast<int>(m.spikeVertices.size());
      pose.ownShapeFaults += m.ownShapeFaults;
      pose.bumpP99 = std::max(pose.bumpP99, m.bumpP99);
      pose.bumpRatioMax = std::max(pose.bumpRatioMax, m.bumpRatioMax);
    }
    if (outwards_) {
      const double mw0 = fapu_.MW0.value;
      const double left = (point(coord, "2.4") - point(coord, "8.3")).dot(*outwards_) / mw0;
      const double right = (point(coord, "8.4") - point(coord, "2.5")).dot(*outwards_) / mw0;
      pose.lipCornerOutside = std::max(left, right);
    }
    if (hasGap_) pose.innerLipGap = lipGap(coord);

    if (pose.edgeRatioP99 > limits_.edgeRatioP99) {
      pose.failures.push_back(format("edge ratio p99 %.2f", pose.edgeRatioP99) +
                              format(" > %g", limits_.edgeRatioP99));
    }
    if (pose.normalFlips > limits_.normalFlips) {
      pose.failures.push_back(std::to_string(pose.normalFlips) + " triangles flipped" +
                              format(" (> %g degrees)", limits_.flipDegrees));
    }
    if (pose.newIntersections > limits_.newIntersections) {
      pose.failures.push_back(std::to_string(pose.newIntersections) +
                              " new self-intersections (not lips or lids touching)");
    }
    if (pose.spikes > limits_.spikeVertices) {
      pose.failures.push_back(std::to_string(pose.spikes) +
                              (pose.spikes == 1 ? " spike vertex" : " spike vertices") +
                              format(" (bump %.2f x the local motion", pose.bumpRatioMax) +
                              format(" > %g)", limits_.bumpOfLocalMotion));
    }
    if (pose.lipCornerOutside && *pose.lipCornerOutside > limits_.lipCornerOutside) {
      pose.failures.push_back(
          format("inner lip corner %.1f%% of MW0", 100 * *pose.lipCornerOutside) +
          format(" outside the outer one > %g%%", 100 * limits_.lipCornerOutside));
    }
    return pose;
  }

  // `spikePeak` > 0: the spikes too, their bumps relative to it (the pose's peak, in the
  // mesh's units).
  std::optional<MeshMotion> checkMesh(MeshCheck& c, const Points3& coord,
                                      double spikePeak) const {
    const Points3& rest = neutral_.meshes[c.mesh].coord;
    std::vector<bool> moved(rest.rows(), false);
    bool any = false;
    for (Eigen::Index v = 0; v < rest.rows(); ++v) {
      moved[v] = (coord.row(v) - rest.row(v)).norm() > c.moveTolerance;
      any = any || moved[v];
    }
    if (!any) return std::nullopt;
    MeshMotion out;
    out.mesh = c.mesh;
    std::vector<int> offending;

    std::vector<double> ratios;
    for (std::size_t e = 0; e < c.edges.size(); ++e) {
      const auto [a, b] = c.edges[e];
      if (!moved[a] && !moved[b]) continue;
      const double l0 = c.edgeLength[e], l = (coord.row(a) - coord.row(b)).norm();
      const double ratio = std::max(l / std::max(l0, 1e-300), l0 / std::max(l, 1e-300));
      ratios.push_back(ratio);
      if (ratio > limits_.edgeRatioP99)
        out.stretchedVertices.insert(out.stretchedVertices.end(), {a, b});
    }
    out.movedEdges = static_cast<int>(ratios.size());
    if (!ratios.empty()) {
      out.edgeRatioMax = *std::max_element(ratios.begin(), ratios.end());
      out.edgeRatioP99 = percentile(ratios, 0.99);
    }
    std::sort(out.stretchedVertices.begin(), out.stretchedVertices.end());
    out.stretchedVertices.erase(
        std::unique(out.stretchedVertices.begin(), out.stretchedVertices.end()),
        out.stretchedVertices.end());
    offending = out.stretchedVertices;

    // Spikes: a mesh moved by rounding alone has none.
    const SurfaceBump bump = spikePeak > 0 ? surfaceBump(c.rings, coord - rest) : SurfaceBump{};
    if (bump.peak > c.moveTolerance) {
      SurfaceSpikes spikes = surfaceSpikes(bump, std::max(bump.peak, spikePeak),
                                           limits_.bumpOfPeak, limits_.bumpOfLocalMotion);
      out.bumpP99 = spikes.bumpP99;
      out.bumpRatioMax = spikes.localRatioMax;
      for (int v : spikes.vertices) {
        if (std::binary_search(c.ownSpikes.begin(), c.ownSpikes.end(), v)) {
          ++out.ownShapeFaults;
        } else {
          out.spikeVertices.push_back(v);
        }
      }
      offending.insert(offending.end(), out.spikeVertices.begin(), out.spikeVertices.end());
    }

    // Triangles with a moved corner: flips.
    const double cosFlip = std::cos(limits_.flipDegrees * std::numbers::pi / 180);
    const std::size_t triangleCount = c.triangles.size() / 3;
    bool anyTriangle = false;
    for (std::size_t t = 0; t < triangleCount; ++t) {
      const int* tri = &c.triangles[3 * t];
      if (!moved[tri[0]] && !moved[tri[1]] && !moved[tri[2]]) continue;
      anyTriangle = true;
      const Eigen::Vector3d n = c.triangleNormal(coord, t);
      const double norms = n.norm() * c.normal[t].norm();
      if (norms > 0 && n.dot(c.normal[t]) < cosFlip * norms) {
        if (c.inContactRegion(tri, 3)) {
          ++out.contactFolds;
          continue;
        }
        if (c.ownTriangle(static_cast<int>(t))) {
          ++out.ownShapeFaults;
          continue;
        }
        out.flippedTriangles.push_back(static_cast<int>(t));
        offending.insert(offending.end(), tri, tri + 3);
      }
    }

    // New self-intersections.
    if (anyTriangle) {
      for (std::uint64_t key : c.intersections->newPairs(coord)) {
        const std::array<int, 2> pair{static_cast<int>(key >> 32),
                                      static_cast<int>(key & 0xffffffffu)};
        const std::array<int, 6> corners{
            c.triangles[3 * pair[0]],     c.triangles[3 * pair[0] + 1],
            c.triangles[3 * pair[0] + 2], c.triangles[3 * pair[1]],
            c.triangles[3 * pair[1] + 1], c.triangles[3 * pair[1] + 2]};
        if (c.inContactRegion(corners.data(), 6)) {
          ++out.touchingIntersections;
          continue;
        }
        if (c.ownTriangle(pair[0]) || c.ownTriangle(pair[1])) {
          ++out.ownShapeFaults;
          continue;
        }
        out.newIntersections.push_back(pair);
        for (int t : pair)
          offending.insert(offending.end(), &c.triangles[3 * t], &c.triangles[3 * t + 3]);
      }
    }
    std::sort(offending.begin(), offending.end());
    offending.erase(std::unique(offending.begin(), offending.end()), offending.end());
    out.offendingVertices = std::move(offending);
    return out;
  }

  // 8.2's share of 2.1's displacement in `coord` (the face at FAP 3 = 1024).
  void lowerLipShare(const std::vector<Points3>& coord) {
    if (!neutral_.featurePointPosition("2.1") || !neutral_.featurePointPosition("8.2")) {
      result_.notes.push_back("lower-lip share not measured: needs 2.1 and 8.2");
      return;
    }
    const std::vector<Points3> rest = neutralCoord();
    const Eigen::Vector3d chin = point(coord, "2.1") - point(rest, "2.1");
    const Eigen::Vector3d lip = point(coord, "8.2") - point(rest, "8.2");
    if (chin.squaredNorm() == 0) {
      result_.notes.push_back("lower-lip share not measured: FAP 3 does not move the chin 2.1");
      return;
    }
    result_.lowerLipShare = lip.dot(chin) / chin.squaredNorm();
    if (*result_.lowerLipShare < limits_.lowerLipShare) {
      result_.failures.push_back(
          format("under FAP 3 the lower lip 8.2 moves %.0f%% of the chin 2.1",
                 100 * *result_.lowerLipShare) +
          format(" < %g%%", 100 * limits_.lowerLipShare));
    }
  }

  // Every frame of each stream through `evaluator`; identical consecutive frames are
  // measured once.
  void streams(std::span<const FapStream> streams, const MpegFace& face,
               const FatEvaluator& evaluator, const MotionProgress& progress) {
    std::size_t total = 0, done = 0;
    for (const FapStream& s : streams) total += s.frames.size();
    FatState state = evaluator.neutralState();
    for (std::size_t k = 0; k < streams.size(); ++k) {
      FapStream stream = streams[k];
      if (face.fit) interpolateFitStream(*face.fit, stream);
      StreamMotion summary{stream.name.empty() ? "stream " + std::to_string(k + 1) : stream.name,
                           static_cast<int>(stream.frames.size())};
      std::optional<FapFrame> previous;
      bool first = true;
      for (const FapState& fapState : resolveFapStream(stream)) {
        const FapFrame& frame = fapState;
        const std::string name = summary.name + " frame " + std::to_string(fapState.number);
        PoseMotion pose;
        if (previous && *previous == frame) {
          pose = result_.frames.back();
          pose.name = name;
        } else {
          evaluator.evaluate(frame, state);
          pose = check(state.coord, name);
          previous = frame;
        }
        pose.stream = static_cast<int>(k);
        pose.frame = fapState.number;
        if (pose.innerLipGap) {
          summary.innerLipGapMin =
              first ? *pose.innerLipGap : std::min(summary.innerLipGapMin, *pose.innerLipGap);
          summary.innerLipGapMax =
              first ? *pose.innerLipGap : std::max(summary.innerLipGapMax, *pose.innerLipGap);
          first = false;
        }
        result_.frames.push_back(std::move(pose));
        if (progress) progress(++done, total);
      }
      result_.streams.push_back(std::move(summary));
    }
  }

  // One of the head's own shapes: the triangles it turns over or makes intersect and its
  // spikes join what is not counted.
  void learnOwnShape(const std::vector<Points3>& coord, const std::string& name) {
    const auto merge = [](auto& into, const auto& more) {
      into.insert(into.end(), more.begin(), more.end());
      std::sort(into.begin(), into.end());
      into.erase(std::unique(into.begin(), into.end()), into.end());
    };
    for (const MeshMotion& m : check(coord, name).meshes) {
      MeshCheck& c = meshes_[static_cast<std::size_t>(m.mesh)];
      std::vector<int> triangles = m.flippedTriangles;
      for (const auto& [a, b] : m.newIntersections) triangles.insert(triangles.end(), {a, b});
      merge(c.ownTriangles, triangles);
      merge(c.ownSpikes, m.spikeVertices);
    }
    result_.ownShapes.push_back(name);
  }

  void addKey(PoseMotion pose, std::size_t total, const MotionProgress& progress) {
    result_.keys.push_back(std::move(pose));
    if (progress) progress(result_.keys.size(), total);
  }

  MotionCheck take() { return std::move(result_); }

 private:
  const FaceModel& neutral_;
  MotionLimits limits_;
  FapuMeasurement fapu_;
  std::vector<Eigen::Affine3d> world_;
  std::vector<MeshCheck> meshes_;
  std::optional<Eigen::Vector3d> outwards_;  // from 8.4 to 8.3
  bool hasGap_ = false;
  MotionCheck result_;
};

std::size_t frameCount(std::span<const FapStream> streams) {
  std::size_t n = 0;
  for (const FapStream& s : streams) n += s.frames.size();
  return n;
}

// The tables' part of the check: the lower lip under FAP 3, then the streams.
MotionCheck finish(Checker& checker, const MpegFace& face, const FatEvaluator& evaluator,
                   std::span<const FapStream> streams, const MotionProgress& progress) {
  const bool jaw = std::any_of(face.faceDefTables.begin(), face.faceDefTables.end(),
                               [](const FaceDefTables& t) { return t.fapID == 3; });
  if (jaw) {
    FapFrame open;
    open.set(3, 1024);
    checker.lowerLipShare(evaluator.evaluate(open).coord);
  }
  checker.streams(streams, face, evaluator, progress);
  MotionCheck result = checker.take();
  if (!jaw) result.notes.push_back("lower-lip share not measured: no table for FAP 3");
  return result;
}

}  // namespace

bool MotionCheck::passed() const {
  const auto ok = [](const PoseMotion& p) { return p.failures.empty(); };
  return failures.empty() && std::all_of(keys.begin(), keys.end(), ok) &&
         std::all_of(frames.begin(), frames.end(), ok);
}

MotionCheck checkMotion(const FaceModel& head, std::span<const FapStream> streams,
                        const MotionLimits& limits, const MotionProgress& progress) {
  const ShapeKeyCopies copies = shapesFromShapeKeys(head);
  const ShapeKeyFace generated = faceFromShapeKeys(head);
  const FaceModel& neutral = generated.face.faceSceneGraph;
  Checker checker(neutral, limits);
  if (limits.ownShapes) {
    // The head's morph targets outside the grammar, by name (one name may move several
    // meshes), each alone at 1 on the neutral.
    for (const std::string& name : copies.ignored) {
      std::vector<Points3> coord;
      bool moves = false;
      for (std::size_t m = 0; m < neutral.meshes.size(); ++m) {
        coord.push_back(neutral.meshes[m].coord);
        for (const MorphTarget& t : head.meshes[m].morphTargets) {
          if (t.name != name) continue;
          coord.back() += t.displacements;
          moves = true;
        }
      }
      if (moves) checker.learnOwnShape(coord, name);
    }
  }
  const std::size_t total = copies.copies.size() + frameCount(streams);
  for (const FaceShape& copy : copies.copies) {
    // The whole pose: what the check measures (edges, triangles) spans the meshes.
    std::vector<Points3> coord;
    for (IndexedFaceSet& mesh : deformedModel(neutral, copy).meshes) {
      coord.push_back(std::move(mesh.coord));
    }
    checker.addKey(checker.check(coord, copy.name), total, progress);
  }
  const FatEvaluator evaluator(generated.face, measureFapu(neutral));
  MotionCheck result = finish(checker, generated.face, evaluator, streams,
                              progress ? MotionProgress([&](std::size_t done, std::size_t) {
                                progress(copies.copies.size() + done, total);
                              })
                                       : MotionProgress{});
  if (copies.copies.empty()) {
    result.notes.push_back("no shape key named as a FAP, viseme or expression (docs/fat.md)");
  }
  return result;
}

MotionCheck checkMotion(const MpegFace& face, std::span<const FapStream> streams,
                        const MotionLimits& limits, const MotionProgress& progress) {
  const FaceModel& neutral = face.faceSceneGraph;
  const FatEvaluator evaluator(face, measureFapu(neutral));
  Checker checker(neutral, limits);
  // Each table at its outermost borders: the largest motion it was made for.
  std::vector<std::pair<FapFrame, std::string>> keys;
  for (const FaceDefTables& t : face.faceDefTables) {
    ShapeKeyName key{t.fapID, t.fapID <= 2 ? t.highLevelSelect : 0, 63, ""};
    FapFrame frame;
    if (t.fapID == 1) {
      frame.mask.set(0);
      frame.viseme = {t.highLevelSelect, 0, 63, false};
      keys.emplace_back(frame, formatShapeKeyName(key));
      continue;
    }
    if (t.fapID == 2) {
      frame.mask.set(1);
      frame.expression = {t.highLevelSelect, 63, 0, 0, false, false};
      keys.emplace_back(frame, formatShapeKeyName(key));
      continue;
    }
    if (t.faceDefMesh.empty()) continue;
    key.label = std::string(fapInfo(t.fapID).name);
    const std::vector<int>& borders = t.faceDefMesh.front().intervalBorders;
    for (int value : {borders.front(), borders.back()}) {
      if (value == 0 || (value > 0 && value != borders.back()) ||
          (value < 0 && value != borders.front())) {
        continue;
      }
      key.amplitude = value;
      FapFrame one;
      one.set(t.fapID, value);
      keys.emplace_back(one, formatShapeKeyName(key));
    }
  }
  const std::size_t total = keys.size() + frameCount(streams);
  FatState state = evaluator.neutralState();
  for (const auto& [frame, name] : keys) {
    evaluator.evaluate(frame, state);
    checker.addKey(checker.check(state.coord, name), total, progress);
  }
  return finish(checker, face, evaluator, streams,
                progress ? MotionProgress([&](std::size_t done, std::size_t) {
                  progress(keys.size() + done, total);
                })
                         : MotionProgress{});
}

}  // namespace mpeg4face
