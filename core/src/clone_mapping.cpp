// SPDX-License-Identifier: GPL-3.0-or-later
// The vertex mapping of Facial Motion Cloning (Pandzic 2003): normalisation, projection,
// alignment on the feature-point triangulation, interpolation from the source's own
// triangles with the low-pass filter and the lip rule, all folded once into sparse weights
// per target vertex so that each copy costs one sparse product. docs/clone.md.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "clone_internal.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/triangle_interpolation.hpp"

namespace mpeg4face::clone {
namespace {

constexpr std::uint8_t kUpperTag = 1, kLowerTag = 2;

struct Projected {
  Points2 uv;
  std::vector<double> depth;
  std::vector<int> triangles;  // without those that cross the seam behind the head
};

Projected projectSurface(const Surface& s, const FaceFrame& frame) {
  Projected p;
  const Eigen::Index n = s.positions.rows();
  p.uv.resize(n, 2);
  p.depth.resize(static_cast<std::size_t>(n));
  for (Eigen::Index r = 0; r < n; ++r) {
    p.uv.row(r) =
        project(frame, s.positions.row(r).transpose(), &p.depth[static_cast<std::size_t>(r)]);
  }
  // A triangle whose corners lie on both sides of the angle +-pi spans the whole projection.
  const double seam = std::numbers::pi * frame.radius;
  for (std::size_t t = 0; t + 2 < s.triangles.size(); t += 3) {
    double lo = p.uv(s.triangles[t], 0), hi = lo;
    for (int k = 1; k < 3; ++k) {
      lo = std::min(lo, p.uv(s.triangles[t + k], 0));
      hi = std::max(hi, p.uv(s.triangles[t + k], 0));
    }
    if (hi - lo < seam) p.triangles.insert(p.triangles.end(), &s.triangles[t], &s.triangles[t] + 3);
  }
  return p;
}

Eigen::Vector2d projectedPoint(const FaceModel& model, const FaceFrame& frame,
                               std::string_view id) {
  return project(frame, *model.featurePointPosition(std::string(id)));
}

// Crossing-number test.
bool insidePolygon(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& p) {
  bool inside = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Eigen::Vector2d& a = poly[i];
    const Eigen::Vector2d& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

// The lip contour along the mouth (by u, so that a face's left / right labels do not
// matter), then the two closing points back the other way.
std::vector<Eigen::Vector2d> lipPolygon(const FaceModel& model, const FaceFrame& frame,
                                        std::span<const std::string_view> contour,
                                        std::span<const std::string_view> sides) {
  std::vector<Eigen::Vector2d> poly, back;
  for (std::string_view id : contour) poly.push_back(projectedPoint(model, frame, id));
  for (std::string_view id : sides) back.push_back(projectedPoint(model, frame, id));
  const auto byU = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() < b.x(); };
  std::sort(poly.begin(), poly.end(), byU);
  std::sort(back.begin(), back.end(), [&](const auto& a, const auto& b) { return byU(b, a); });
  poly.insert(poly.end(), back.begin(), back.end());
  return poly;
}

// Upper and lower lip vertices coincide on a closed mouth, so a vertex is classified at a
// point nudged a tenth of the way towards the mean centroid of its triangles: that side of
// the contour is the lip it belongs to.
std::vector<LipRegion> classifyLips(const FaceModel& model, const FaceFrame& frame,
                                    const Projected& p) {
  const auto upper = lipPolygon(model, frame, upperLipContour(), noseSides());
  const auto lower = lipPolygon(model, frame, lowerLipContour(), chinSides());
  const Eigen::Index n = p.uv.rows();
  Points2 sum = Points2::Zero(n, 2);
  std::vector<int> count(static_cast<std::size_t>(n), 0);
  for (std::size_t t = 0; t < p.triangles.size(); t += 3) {
    const Eigen::RowVector2d c =
        (p.uv.row(p.triangles[t]) + p.uv.row(p.triangles[t + 1]) + p.uv.row(p.triangles[t + 2])) /
        3;
    for (int k = 0; k < 3; ++k) {
      sum.row(p.triangles[t + static_cast<std::size_t>(k)]) += c;
      ++count[static_cast<std::size_t>(p.triangles[t + static_cast<std::size_t>(k)])];
    }
  }
  std::vector<LipRegion> lips(static_cast<std::size_t>(n), LipRegion::Outside);
  for (Eigen::Index r = 0; r < n; ++r) {
    Eigen::Vector2d q = p.uv.row(r);
    const int c = count[static_cast<std::size_t>(r)];
    if (c > 0) q += 0.1 * (sum.row(r).transpose() / c - q);
    if (insidePolygon(upper, q)) {
      lips[static_cast<std::size_t>(r)] = LipRegion::Upper;
    } else if (insidePolygon(lower, q)) {
      lips[static_cast<std::size_t>(r)] = LipRegion::Lower;
    }
  }
  return lips;
}

// Each point's mean length of the edges of `triangles` that meet there (0 for a point on none):
// the local sampling distance of the mesh in alignment space.
std::vector<double> meanEdgeLength(const Points2& uv, std::span<const int> triangles) {
  std::vector<double> sum(static_cast<std::size_t>(uv.rows()), 0.0);
  std::vector<int> count(sum.size(), 0);
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
    for (std::size_t k = 0; k < 3; ++k) {
      const int a = triangles[t + k], b = triangles[t + (k + 1) % 3];
      const double length = (uv.row(a) - uv.row(b)).norm();
      for (int end : {a, b}) {
        sum[static_cast<std::size_t>(end)] += length;
        ++count[static_cast<std::size_t>(end)];
      }
    }
  }
  for (std::size_t i = 0; i < sum.size(); ++i) {
    if (count[i] > 0) sum[i] /= count[i];
  }
  return sum;
}

// The filter's support at a target point whose edges are `targetEdge` long where the source's
// are `sourceEdge` long (CloneOptions::adaptiveFilter).
double filterSupportAt(const CloneOptions& options, double targetEdge, double sourceEdge) {
  if (!options.adaptiveFilter) return options.filterSupport;
  constexpr double kNone = 1.25, kFull = 2.0;  // target / source edge length
  if (!(sourceEdge > 0)) return 0;
  const double ramp = std::clamp((targetEdge / sourceEdge - kNone) / (kFull - kNone), 0.0, 1.0);
  return ramp * options.filterSupport;
}

// N(FP) of each row: the factors of the region of its nearest required feature point.
Points3 regionFactors(const FaceModel& model, const Surface& s, const FapuMeasurement& fapu) {
  const auto ids = cloneFeaturePoints();
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> factors;
  for (std::string_view id : ids) {
    points.push_back(*model.featurePointPosition(std::string(id)));
    factors.push_back(motionFactors(id, fapu));
  }
  Points3 out(s.positions.rows(), 3);
  for (Eigen::Index r = 0; r < s.positions.rows(); ++r) {
    const Eigen::Vector3d v = s.positions.row(r);
    std::size_t best = 0;
    double bestD = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double d = (points[i] - v).squaredNorm();
      if (d < bestD) {
        bestD = d;
        best = i;
      }
    }
    out.row(r) = factors[best].transpose();
  }
  return out;
}

}  // namespace

Surface gatherSurface(const FaceModel& model, std::span<const int> excludedMeshes) {
  Surface s;
  const auto world = model.meshWorldMatrices();
  int rows = 0;
  s.firstRow.assign(model.meshes.size(), -1);
  for (std::size_t m = 0; m < model.meshes.size(); ++m) {
    if (std::find(excludedMeshes.begin(), excludedMeshes.end(), static_cast<int>(m)) !=
        excludedMeshes.end()) {
      continue;
    }
    s.firstRow[m] = rows;
    rows += model.meshes[m].vertexCount();
  }
  s.positions.resize(rows, 3);
  s.owner.reserve(static_cast<std::size_t>(rows));
  for (std::size_t m = 0; m < model.meshes.size(); ++m) {
    if (s.firstRow[m] < 0) continue;
    const IndexedFaceSet& mesh = model.meshes[m];
    for (int v = 0; v < mesh.vertexCount(); ++v) {
      s.positions.row(s.firstRow[m] + v) = (world[m] * mesh.coord.row(v).transpose()).transpose();
      s.owner.emplace_back(static_cast<int>(m), v);
    }
    for (int corner : mesh.triangles()) s.triangles.push_back(s.firstRow[m] + corner);
  }
  return s;
}

Mapping buildMapping(const FaceModel& source, const Surface& sourceSurface, const FaceModel& target,
                     const Surface& targetSurface, const CloneOptions& options) {
  const FapuMeasurement sourceFapu = measureFapu(source), targetFapu = measureFapu(target);
  const FaceFrame sourceFrame = faceFrame(source, sourceFapu);
  const FaceFrame targetFrame = faceFrame(target, targetFapu);
  const Projected src = projectSurface(sourceSurface, sourceFrame);
  const Projected tgt = projectSurface(targetSurface, targetFrame);

  Mapping map;
  map.sourceFactors = regionFactors(source, sourceSurface, sourceFapu);
  map.targetFactors = regionFactors(target, targetSurface, targetFapu);
  if (options.separateLips) {
    map.sourceLips = classifyLips(source, sourceFrame, src);
    map.targetLips = classifyLips(target, targetFrame, tgt);
  } else {
    map.sourceLips.assign(static_cast<std::size_t>(src.uv.rows()), LipRegion::Outside);
    map.targetLips.assign(static_cast<std::size_t>(tgt.uv.rows()), LipRegion::Outside);
  }

  // Alignment: the target's feature points go onto the source's; every other target point
  // moves by the displacement interpolated on the fixed triangulation.
  const auto ids = cloneFeaturePoints();
  Points2 fpTarget(static_cast<Eigen::Index>(ids.size()), 2);
  Points2 fpMove(static_cast<Eigen::Index>(ids.size()), 2);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const auto row = static_cast<Eigen::Index>(i);
    fpTarget.row(row) = projectedPoint(target, targetFrame, ids[i]);
    fpMove.row(row) = projectedPoint(source, sourceFrame, ids[i]).transpose() - fpTarget.row(row);
  }
  std::vector<int> fpTriangles;
  for (const auto& tri : alignmentTriangles()) {
    for (std::string_view id : tri) {
      fpTriangles.push_back(static_cast<int>(std::find(ids.begin(), ids.end(), id) - ids.begin()));
    }
  }
  const TriangleInterpolator alignment(fpTarget, fpTriangles);

  std::vector<std::uint8_t> tags(src.triangles.size() / 3, 0);
  for (std::size_t t = 0; t < tags.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const LipRegion lip = map.sourceLips[static_cast<std::size_t>(
          src.triangles[3 * t + static_cast<std::size_t>(k)])];
      if (lip == LipRegion::Upper) tags[t] |= kUpperTag;
      if (lip == LipRegion::Lower) tags[t] |= kLowerTag;
    }
  }
  const TriangleInterpolator motion(src.uv, src.triangles, src.depth, std::move(tags));

  const Eigen::Index n = tgt.uv.rows();
  // A vertex that no face uses is not part of the surface: it gets no motion.
  std::vector<bool> used(static_cast<std::size_t>(n), false);
  for (int corner : targetSurface.triangles) used[static_cast<std::size_t>(corner)] = true;
  // Every target point moved onto the source by the alignment.
  Points2 aligned = tgt.uv;
  for (Eigen::Index t = 0; t < n; ++t) {
    if (!used[static_cast<std::size_t>(t)]) continue;
    const Eigen::Vector2d p = tgt.uv.row(t);
    const TriangleWeights a = alignment.locate(p);
    for (int k = 0; k < 3; ++k) {
      aligned.row(t) += a.weights[k] * fpMove.row(a.corners[static_cast<std::size_t>(k)]);
    }
  }
  std::vector<double> sourceEdge, targetEdge;
  if (options.filterSupport > 0 && options.adaptiveFilter) {
    sourceEdge = meanEdgeLength(src.uv, src.triangles);
    targetEdge = meanEdgeLength(aligned, tgt.triangles);
  }

  map.rowStart.reserve(static_cast<std::size_t>(n) + 1);
  map.rowStart.push_back(0);
  std::vector<std::pair<int, double>> entries;
  // Adds a sample's share of the source motion at q (weight `share`) to `entries`.
  const auto addSample = [&](const TriangleWeights& w, const Eigen::Vector2d& q, double share) {
    if (w.triangle < 0) return;
    // Beyond the source's surface the motion fades out over outsideFalloff (ours).
    double fade = 1;
    if (!w.inside && options.outsideFalloff > 0) {
      Eigen::Vector2d nearest = Eigen::Vector2d::Zero();
      for (int k = 0; k < 3; ++k) {
        nearest += w.weights[k] * src.uv.row(w.corners[static_cast<std::size_t>(k)]).transpose();
      }
      fade = std::max(0.0, 1 - (q - nearest).norm() / options.outsideFalloff);
    }
    for (int k = 0; k < 3; ++k) {
      const int s = w.corners[static_cast<std::size_t>(k)];
      const double weight = share * fade * w.weights[k];
      if (weight == 0) continue;
      auto it =
          std::find_if(entries.begin(), entries.end(), [&](const auto& e) { return e.first == s; });
      if (it == entries.end()) {
        entries.emplace_back(s, weight);
      } else {
        it->second += weight;
      }
    }
  };
  for (Eigen::Index t = 0; t < n; ++t) {
    if (options.progress && t % 4096 == 0)
      options.progress("mapping", 0.5 * static_cast<double>(t) / static_cast<double>(n));
    if (!used[static_cast<std::size_t>(t)]) {
      map.rowStart.push_back(static_cast<int>(map.source.size()));
      continue;
    }
    const Eigen::Vector2d p = aligned.row(t);
    std::uint8_t excluded = 0;
    if (map.targetLips[static_cast<std::size_t>(t)] == LipRegion::Upper) excluded = kLowerTag;
    if (map.targetLips[static_cast<std::size_t>(t)] == LipRegion::Lower) excluded = kUpperTag;
    entries.clear();
    const TriangleWeights centre = motion.locate(p, excluded);
    // The filter: the centre and six points on a circle of diameter `support`, averaged.
    double support = 0;
    if (options.filterSupport > 0) {
      double here = 0;
      if (options.adaptiveFilter && centre.triangle >= 0) {
        for (int k = 0; k < 3; ++k) {
          here += centre.weights[k] *
                  sourceEdge[static_cast<std::size_t>(centre.corners[static_cast<std::size_t>(k)])];
        }
      }
      support = filterSupportAt(
          options, targetEdge.empty() ? 0 : targetEdge[static_cast<std::size_t>(t)], here);
    }
    const double share = support > 0 ? 1.0 / 7 : 1.0;
    addSample(centre, p, share);
    for (int k = 0; support > 0 && k < 6; ++k) {
      const double a = k * std::numbers::pi / 3;
      const Eigen::Vector2d q = p + 0.5 * support * Eigen::Vector2d(std::cos(a), std::sin(a));
      addSample(motion.locate(q, excluded), q, share);
    }
    for (const auto& [s, weight] : entries) {
      map.source.push_back(s);
      map.weight.push_back(weight);
    }
    map.rowStart.push_back(static_cast<int>(map.source.size()));
  }
  return map;
}

}  // namespace mpeg4face::clone
