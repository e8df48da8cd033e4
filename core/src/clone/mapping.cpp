// SPDX-License-Identifier: GPL-3.0-or-later
// The vertex mapping of Facial Motion Cloning (Pandzic 2003): normalisation, projection,
// alignment on the feature-point triangulation, interpolation from the source's own
// triangles with the low-pass filter and the lip rule, all folded once into sparse weights
// per target vertex so that each copy costs one sparse product. docs/clone.md.
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>

#include "clone/clone_internal.hpp"
#include "model/surface_closest_point.hpp"
#include "clone/triangle_interpolation.hpp"
#include "mpeg4face/error.hpp"

namespace mpeg4face::clone {
namespace {

constexpr std::uint8_t kUpperTag = 1, kLowerTag = 2;

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

// Each point's mean of the centroids of the triangles it is a corner of (itself when on none):
// the side of the point its surface lies on.
Points2 meanTriangleCentroid(const Points2& uv, std::span<const int> triangles) {
  Points2 sum = Points2::Zero(uv.rows(), 2);
  std::vector<int> count(static_cast<std::size_t>(uv.rows()), 0);
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
    const Eigen::RowVector2d c =
        (uv.row(triangles[t]) + uv.row(triangles[t + 1]) + uv.row(triangles[t + 2])) / 3;
    for (std::size_t k = 0; k < 3; ++k) {
      sum.row(triangles[t + k]) += c;
      ++count[static_cast<std::size_t>(triangles[t + k])];
    }
  }
  for (Eigen::Index r = 0; r < uv.rows(); ++r) {
    const int c = count[static_cast<std::size_t>(r)];
    sum.row(r) = c > 0 ? Eigen::RowVector2d(sum.row(r) / c) : Eigen::RowVector2d(uv.row(r));
  }
  return sum;
}

// Each point's mean length of the edges of `triangles` that meet there (0 for a point on none):
// the local sampling distance of the mesh (in alignment space, or in 3D).
template <class Points>
std::vector<double> meanEdgeLength(const Points& uv, std::span<const int> triangles) {
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

// The filter's support at a target point whose edges are `targetEdge` long where the
// source's are `sourceEdge` long in alignment space (`targetEdge3`, `sourceEdge3` in normalised
// 3D space), `featureDistance` from the nearest feature point: the antialiasing support where
// the target samples more coarsely (CloneOptions::adaptiveFilter), the smoothing one where it
// samples more finely (CloneOptions::smoothSupport).
double filterSupportAt(const CloneOptions& options, double targetEdge, double sourceEdge,
                       double targetEdge3, double sourceEdge3, double featureDistance) {
  // Ramps of the edge-length ratio: antialiasing from 1.25 (two versions of one mesh differ
  // that much locally) to 2; smoothing only where the source is much coarser, from 3 to 6
  // (a dense source's motion, interpolated quadratically, is smooth enough on a finer target,
  // and smoothing it would only blur it). The smoothing's ratio is taken in 3D: near the
  // projection's axis (the chin's underside) the cylinder stretches u many times.
  const auto ramp = [](double ratio, double none, double full) {
    return std::clamp((ratio - none) / (full - none), 0.0, 1.0);
  };
  double support = options.adaptiveFilter ? 0 : options.filterSupport;
  if (!(sourceEdge > 0) || !(targetEdge > 0)) return support;
  if (options.adaptiveFilter) {
    support = ramp(targetEdge / sourceEdge, 1.25, 2.0) * options.filterSupport;
  }
  if (!(sourceEdge3 > 0) || !(targetEdge3 > 0)) return support;
  const double smooth = ramp(sourceEdge3 / targetEdge3, 3.0, 6.0) *
                        std::min(options.smoothSupport * sourceEdge3, featureDistance);
  return std::max(support, smooth);
}

// The required feature points' projected points, in cloneFeaturePoints() order.
Points2 projectedFeaturePoints(const FaceModel& model, const FaceFrame& frame) {
  const auto ids = cloneFeaturePoints();
  Points2 uv(static_cast<Eigen::Index>(ids.size()), 2);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    uv.row(static_cast<Eigen::Index>(i)) = projectedPoint(model, frame, ids[i]);
  }
  return uv;
}

// The alignment triangulation as rows of cloneFeaturePoints(), with the slits filled if
// `filled` (for the normalisation factors).
std::vector<int> featurePointTriangles(bool filled) {
  const auto ids = cloneFeaturePoints();
  std::vector<int> out;
  for (const auto& part :
       {alignmentTriangles(), filled ? slitTriangles() : decltype(slitTriangles()){}}) {
    for (const auto& tri : part) {
      for (std::string_view id : tri) {
        out.push_back(static_cast<int>(std::find(ids.begin(), ids.end(), id) - ids.begin()));
      }
    }
  }
  return out;
}

// The normalisation factors of each required feature point's region (motionFactors).
std::vector<Eigen::Vector3d> featurePointFactors(const FapuMeasurement& fapu) {
  std::vector<Eigen::Vector3d> factors;
  for (std::string_view id : cloneFeaturePoints()) factors.push_back(motionFactors(id, fapu));
  return factors;
}

// N(FP) at a point located in the feature-point triangulation: the factors of the feature
// points' regions interpolated (outside it: the closest triangle's), so that they change
// gradually from region to region.
Eigen::Vector3d regionFactors(const TriangleWeights& w,
                              const std::vector<Eigen::Vector3d>& factors) {
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < 3; ++k) {
    f += w.weights[static_cast<Eigen::Index>(k)] * factors[static_cast<std::size_t>(w.corners[k])];
  }
  return f;
}

}  // namespace

Eigen::Vector2d projectedPoint(const FaceModel& model, const FaceFrame& frame,
                               std::string_view id) {
  return project(frame, *model.featurePointPosition(std::string(id)));
}

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

  // The feature-point triangulation in each face's projection: the target's for the
  // alignment, both for the normalisation factors.
  const std::vector<int> fpTriangles = featurePointTriangles(false);
  const Points2 fpSource = projectedFeaturePoints(source, sourceFrame);
  const Points2 fpTarget = projectedFeaturePoints(target, targetFrame);
  const Points2 fpMove = fpSource - fpTarget;
  const TriangleInterpolator sourceFeatures(fpSource, featurePointTriangles(true));
  const TriangleInterpolator targetFeatures(fpTarget, featurePointTriangles(true));
  const TriangleInterpolator alignment(fpTarget, fpTriangles);

  Mapping map;
  map.sourceFactors.resize(src.uv.rows(), 3);
  const auto sourceFactorsOf = featurePointFactors(sourceFapu);
  for (Eigen::Index r = 0; r < src.uv.rows(); ++r) {
    map.sourceFactors.row(r) =
        regionFactors(sourceFeatures.locate(src.uv.row(r).transpose()), sourceFactorsOf)
            .transpose();
  }
  // The target's, with its alignment below.
  map.targetFactors = Points3::Zero(tgt.uv.rows(), 3);
  const auto targetFactorsOf = featurePointFactors(targetFapu);
  const Points2 sourceCentroid = meanTriangleCentroid(src.uv, src.triangles);
  if (options.separateLips) {
    map.sourceLips = classifyLips(source, sourceFrame, src, sourceCentroid, sourceSurface);
    map.targetLips = classifyLips(target, targetFrame, tgt,
                                  meanTriangleCentroid(tgt.uv, tgt.triangles), targetSurface);
  } else {
    map.sourceLips.assign(static_cast<std::size_t>(src.uv.rows()), LipRegion::Outside);
    map.targetLips.assign(static_cast<std::size_t>(tgt.uv.rows()), LipRegion::Outside);
  }

  std::vector<std::uint8_t> tags(src.triangles.size() / 3, 0);
  for (std::size_t t = 0; t < tags.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const LipRegion lip = map.sourceLips[static_cast<std::size_t>(
          src.triangles[3 * t + static_cast<std::size_t>(k)])];
      if (lip == LipRegion::Upper) tags[t] |= kUpperTag;
      if (lip == LipRegion::Lower) tags[t] |= kLowerTag;
    }
  }
  // Hidden layers are matched in 3D (below): the source's points in normalised space.
  Points3 sourceSpace(src.uv.rows(), 3);
  for (Eigen::Index r = 0; r < src.uv.rows(); ++r) {
    sourceSpace.row(r) =
        unproject(sourceFrame, src.uv.row(r), src.depth[static_cast<std::size_t>(r)]).transpose();
  }
  const TriangleInterpolator motion(src.uv, src.triangles, src.depth, tags);

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
    // Inside the alignment triangulation the filled one agrees with it.
    map.targetFactors.row(t) =
        regionFactors(a.inside ? a : targetFeatures.locate(p), targetFactorsOf).transpose();
    for (int k = 0; k < 3; ++k) {
      aligned.row(t) += a.weights[k] * fpMove.row(a.corners[static_cast<std::size_t>(k)]);
    }
  }
  std::vector<double> sourceEdge, targetEdge;
  if ((options.filterSupport > 0 && options.adaptiveFilter) || options.smoothSupport > 0) {
    sourceEdge = meanEdgeLength(src.uv, src.triangles);
    targetEdge = meanEdgeLength(aligned, tgt.triangles);
  }
  std::vector<double> sourceEdge3, targetEdge3;  // the same in normalised 3D space
  if (!sourceEdge.empty()) {
    sourceEdge3 = meanEdgeLength(sourceSpace, src.triangles);
    const Points3 targetSpace =
        (targetSurface.positions.rowwise() - targetFrame.centre.transpose()).array().rowwise() /
        targetFrame.positionScale.transpose().array();
    targetEdge3 = meanEdgeLength(targetSpace, tgt.triangles);
  }
  // How far each target point lies under its own face's outer surface (a fold, an inner
  // layer: the paper's smallest-depth rule would give it the outer layer's motion); it takes
  // the source's layer as far under the source's outer surface (ours). A point less than a
  // thousandth of its edges under it (rounding: samePlaceTolerance) is on it.
  std::vector<double> belowTop(static_cast<std::size_t>(n), 0.0);
  {
    const TriangleInterpolator own(tgt.uv, tgt.triangles, tgt.depth, {}, false);
    const std::vector<double> onSurface = samePlaceTolerance(tgt);
    for (Eigen::Index t = 0; t < n; ++t) {
      if (!used[static_cast<std::size_t>(t)]) continue;
      const TriangleWeights w = own.locate(tgt.uv.row(t).transpose());
      if (!w.overlap) continue;  // alone at its place: on the outer surface
      double top = 0;
      for (std::size_t k = 0; k < 3; ++k) {
        top += w.weights[static_cast<Eigen::Index>(k)] *
               tgt.depth[static_cast<std::size_t>(w.corners[k])];
      }
      const auto row = static_cast<std::size_t>(t);
      const double below = tgt.depth[row] - top;
      if (below > onSurface[row]) belowTop[row] = below;
    }
  }
  // A target vertex at a source vertex's place takes exactly its motion (ours; the filter's
  // other samples are added where the meshes' densities differ): where surfaces overlap
  // (eyeballs under the lids) the smallest-depth rule would give it the outer one's.
  const SamePlace samePlace(src, sourceCentroid);
  const Points2 alignedCentroid = meanTriangleCentroid(aligned, tgt.triangles);

  // A per-point value of the source (its depth, its local edge length) interpolated at a
  // located point.
  const auto valueAt = [](const TriangleWeights& w, const std::vector<double>& values) {
    double v = 0;
    for (std::size_t k = 0; k < 3; ++k) {
      v += w.weights[static_cast<Eigen::Index>(k)] * values[static_cast<std::size_t>(w.corners[k])];
    }
    return v;
  };
  map.rowStart.reserve(static_cast<std::size_t>(n) + 1);
  map.rowStart.push_back(0);
  std::vector<std::pair<int, double>> entries, terms;
  std::vector<int> entryOf(static_cast<std::size_t>(src.uv.rows()), -1);  // index in entries
  std::vector<std::pair<TriangleWeights, Eigen::Vector2d>> samples;
  std::optional<ButterflyMidpoints> midpoints;  // made when first needed
  double curve = 0;  // per target point: how much of the quadratic interpolation
  LipRegion otherLip = LipRegion::Outside;
  const auto otherLipPoint = [&](int s) {
    return otherLip != LipRegion::Outside &&
           map.sourceLips[static_cast<std::size_t>(s)] == otherLip;
  };
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
    // Linear in the triangle, and by `curve` the quadratic through the corners and the
    // butterfly midpoints of its edges: N_k = b_k (2 b_k - 1) at a corner, 4 b_k b_l at an edge.
    terms.clear();
    for (std::size_t k = 0; k < 3; ++k) {
      const double b = w.weights[static_cast<Eigen::Index>(k)];
      terms.emplace_back(w.corners[k], (1 - curve) * b + curve * b * (2 * b - 1));
    }
    for (std::size_t k = 0; curve > 0 && k < 3; ++k) {
      const std::size_t l = (k + 1) % 3;
      const double b = 4 * curve * w.weights[static_cast<Eigen::Index>(k)] *
                       w.weights[static_cast<Eigen::Index>(l)];
      if (b == 0) continue;
      if (!midpoints) midpoints.emplace(sourceSurface.triangles, sourceSurface.positions.rows());
      midpoints->add(w.corners[k], w.corners[l], b, otherLipPoint, terms);
    }
    for (const auto& [s, term] : terms) {
      const double weight = share * fade * term;
      if (weight == 0) continue;
      int& at = entryOf[static_cast<std::size_t>(s)];
      if (at < 0) {
        at = static_cast<int>(entries.size());
        entries.emplace_back(s, weight);
      } else {
        entries[static_cast<std::size_t>(at)].second += weight;
      }
    }
  };
  // First the centre sample of every target point, and for a point under its face's outer
  // surface the place in the source's normalised space it would match in 3D (below).
  struct Centre {
    TriangleWeights weights;
    LipRegion otherLip = LipRegion::Outside;
    std::uint8_t excluded = 0;
    bool hidden = false;    // to be matched in 3D
    Eigen::Vector3d place;  // there
    double reach = 0;       // a 3D match nearer than this is taken
    double support = 0;     // the filter's
    double curve = 0;       // how much of the quadratic interpolation
  };
  std::vector<Centre> centres(static_cast<std::size_t>(n));
  for (Eigen::Index t = 0; t < n; ++t) {
    if (!used[static_cast<std::size_t>(t)]) continue;
    Centre& c = centres[static_cast<std::size_t>(t)];
    const Eigen::Vector2d p = aligned.row(t);
    const LipRegion lip = map.targetLips[static_cast<std::size_t>(t)];
    c.otherLip = lip == LipRegion::Upper   ? LipRegion::Lower
                 : lip == LipRegion::Lower ? LipRegion::Upper
                                           : LipRegion::Outside;
    c.excluded = c.otherLip == LipRegion::Lower   ? kLowerTag
                 : c.otherLip == LipRegion::Upper ? kUpperTag
                                                  : 0;
    const double depth = tgt.depth[static_cast<std::size_t>(t)];
    const Eigen::Vector2d side = alignedCentroid.row(t).transpose();
    const int same = samePlace.find(p, depth, side, c.otherLip, map.sourceLips);
    const double below = belowTop[static_cast<std::size_t>(t)];
    if (same >= 0) {  // the centre sample is that vertex (triangle: any valid index)
      c.weights.triangle = 0;
      c.weights.corners = {same, same, same};
      c.weights.weights = Eigen::Vector3d(1, 0, 0);
      c.weights.inside = true;
    } else {
      c.weights = motion.locate(p, c.excluded, below);
    }
    // The filter: the centre and six points on a circle of diameter `support`, averaged.
    c.support = options.adaptiveFilter ? 0 : options.filterSupport;
    if (!sourceEdge.empty() && c.weights.triangle >= 0) {
      const double here = valueAt(c.weights, sourceEdge);
      const double here3 = valueAt(c.weights, sourceEdge3);
      const double there = targetEdge[static_cast<std::size_t>(t)];
      const double there3 = targetEdge3[static_cast<std::size_t>(t)];
      // The distance to the nearest feature point matters only where the target is finer.
      double featureDistance = 0;
      if (options.smoothSupport > 0 && here3 > 3 * there3) {
        featureDistance = (fpSource.rowwise() - p.transpose()).rowwise().norm().minCoeff();
      }
      c.support = filterSupportAt(options, there, here, there3, here3, featureDistance);
      // Where the target samples more finely than the source, the motion between the
      // source's points is interpolated quadratically (ours): from 1.5 times (two versions of
      // one mesh differ that much locally) to 2.5 times.
      if (there3 > 0) c.curve = std::clamp((here3 / there3 - 1.5) / (2.5 - 1.5), 0.0, 1.0);
    }
    if (same < 0 && below > 0 && c.weights.inside) {
      // Under the outer surface (a fold, an inner layer) the projection says little: layers
      // lie over each other, and a steep wall such as an eye socket's covers little of it.
      // The point is taken into the source's normalised space as far under the source's
      // outer surface as it lies under its own; where the source's surface is less than half
      // as far from it in 3D as the layer found in the projection, its closest point there
      // is taken instead (ours).
      const double wanted = valueAt(motion.locate(p, c.excluded), src.depth) + below;
      c.place = unproject(sourceFrame, p, wanted);
      c.reach = 0.5 * std::abs(valueAt(c.weights, src.depth) - wanted);
      // Where the layer found is already within an eighth of the source's local edge, the 3D
      // match would change little: not searched.
      const double edge = sourceEdge3.empty() ? 0 : valueAt(c.weights, sourceEdge3);
      c.hidden = c.reach > 0.125 * edge;
    }
    if (same < 0 && !c.hidden && c.curve > 0 && c.weights.inside) {
      // On a finer target (where it is interpolated quadratically) the points lie on the smooth
      // surface, a little off the source's flat triangles. Where the cylinder sees the source
      // edge on (the chin's underside: its normal more than 60 degrees from the radial
      // direction), that lands them far along the surface in the projection; they are matched
      // in 3D at their own depth instead, within one source edge (ours).
      const auto corner = [&](int k) -> Eigen::Vector3d {
        return sourceSpace.row(src.triangles[3 * static_cast<std::size_t>(c.weights.triangle) +
                                             static_cast<std::size_t>(k)]);
      };
      const Eigen::Vector3d normal = (corner(1) - corner(0)).cross(corner(2) - corner(0));
      const Eigen::Vector3d at = unproject(sourceFrame, p, valueAt(c.weights, src.depth));
      const Eigen::Vector3d radial(at.x(), 0, at.z());
      if (std::abs(normal.dot(radial)) < 0.5 * normal.norm() * radial.norm()) {
        c.place = unproject(sourceFrame, p, depth);
        c.reach = valueAt(c.weights, sourceEdge3);
        c.hidden = c.reach > 0;
      }
    }
  }
  // The closest-point tree holds the source's triangles that a 3D match or its filter's
  // samples can reach: those whose box meets a cell of a grid that such a point's reach and
  // support touch.
  std::unique_ptr<SurfaceClosestPoint> hiddenLayers;
  {
    Eigen::AlignedBox3d all;
    double cell = 0;
    for (const Centre& c : centres) {
      if (!c.hidden) continue;
      all.extend(c.place);
      cell = std::max(cell, c.reach + c.support);
    }
    if (!all.isEmpty()) {
      all.min().array() -= cell;
      all.max().array() += cell;
      cell = std::max(cell, all.sizes().maxCoeff() / 64);
      const Eigen::Array3i size = (all.sizes().array() / cell).ceil().cast<int>().max(1);
      const auto cellOf = [&](const Eigen::Vector3d& x) {
        return ((x - all.min()).array() / cell).floor().cast<int>().max(0).min(size - 1).eval();
      };
      std::vector<bool> reached(static_cast<std::size_t>(size.prod()), false);
      const auto index = [&](int x, int y, int z) {
        return (static_cast<std::size_t>(z) * static_cast<std::size_t>(size.y()) +
                static_cast<std::size_t>(y)) *
                   static_cast<std::size_t>(size.x()) +
               static_cast<std::size_t>(x);
      };
      const auto forCells = [&](const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, auto f) {
        const Eigen::Array3i a = cellOf(lo), b = cellOf(hi);
        for (int z = a.z(); z <= b.z(); ++z)
          for (int y = a.y(); y <= b.y(); ++y)
            for (int x = a.x(); x <= b.x(); ++x)
              if (f(index(x, y, z))) return true;
        return false;
      };
      for (const Centre& c : centres) {
        if (!c.hidden) continue;
        const Eigen::Vector3d r = Eigen::Vector3d::Constant(c.reach + c.support);
        forCells(c.place - r, c.place + r, [&](std::size_t i) {
          reached[i] = true;
          return false;
        });
      }
      // With the triangle each point was located in by the projection: a start for its search.
      std::vector<bool> start(src.triangles.size() / 3, false);
      for (const Centre& c : centres) {
        if (c.hidden) start[static_cast<std::size_t>(c.weights.triangle)] = true;
      }
      std::vector<int> near;
      for (std::size_t t = 0; t + 2 < src.triangles.size(); t += 3) {
        if (start[t / 3]) {
          near.push_back(static_cast<int>(t / 3));
          continue;
        }
        Eigen::AlignedBox3d box;
        for (std::size_t k = 0; k < 3; ++k)
          box.extend(sourceSpace.row(src.triangles[t + k]).transpose());
        if (!box.intersects(all)) continue;
        if (forCells(box.min(), box.max(), [&](std::size_t i) { return reached[i]; })) {
          near.push_back(static_cast<int>(t / 3));
        }
      }
      hiddenLayers = std::make_unique<SurfaceClosestPoint>(sourceSpace, src.triangles, near);
    }
  }
  // The closest point of the source's surface to q, none if its triangle is of an excluded lip.
  const auto closestOnSource = [&](const Eigen::Vector3d& q, std::uint8_t excluded,
                                   const ClosestPoint& hint) {
    ClosestPoint hit = hiddenLayers->closest(q, &hint);
    if (hit.triangle >= 0 && (tags[static_cast<std::size_t>(hit.triangle)] & excluded) != 0) {
      hit.triangle = -1;
    }
    return hit;
  };

  // The located point's place on the source's surface in its normalised space.
  const auto placeOf = [&](const TriangleWeights& w) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < 3; ++k) {
      x += w.weights[static_cast<Eigen::Index>(k)] * sourceSpace.row(w.corners[k]).transpose();
    }
    return x;
  };
  for (Eigen::Index t = 0; t < n; ++t) {
    if (options.progress && t % 4096 == 0)
      options.progress("mapping", 0.5 * static_cast<double>(t) / static_cast<double>(n));
    if (!used[static_cast<std::size_t>(t)]) {
      map.rowStart.push_back(static_cast<int>(map.source.size()));
      continue;
    }
    const Eigen::Vector2d p = aligned.row(t);
    const Centre& c = centres[static_cast<std::size_t>(t)];
    otherLip = c.otherLip;
    const std::uint8_t excluded = c.excluded;
    const double below = belowTop[static_cast<std::size_t>(t)];
    TriangleWeights centre = c.weights;
    ClosestPoint hidden;  // the centre sample matched in 3D
    if (c.hidden) {
      ClosestPoint located;
      located.triangle = c.weights.triangle;
      located.point = placeOf(c.weights);
      hidden = closestOnSource(c.place, excluded, located);
      if (hidden.triangle >= 0 && (hidden.point - c.place).norm() < c.reach) {
        centre.triangle = hidden.triangle;
        centre.corners = hidden.corners;
        centre.weights = hidden.weights;
      } else {
        hidden.triangle = -1;
      }
    }
    entries.clear();
    curve = c.curve;
    const double support = c.support;
    // The filter's samples around the centre, each where the source's surface lies there. A
    // sample that lands on another part of the surface, more than three times as far in 3D as
    // it lies from the centre in the projection (across a fold: the chin's underside, seen
    // edge on by the cylinder, under the chin's front), is left out (ours).
    samples.assign(1, {centre, p});
    const Eigen::Vector3d centreSpace =
        centre.triangle >= 0 ? placeOf(centre) : Eigen::Vector3d::Zero();
    // On a hidden layer the circle lies in the plane of the source triangle found in 3D.
    Eigen::Vector3d e1 = Eigen::Vector3d::Zero(), e2 = e1;
    if (hidden.triangle >= 0 && support > 0) {
      const Eigen::Vector3d a = sourceSpace.row(hidden.corners[0]);
      e1 = (Eigen::Vector3d(sourceSpace.row(hidden.corners[1])) - a).normalized();
      e2 = (Eigen::Vector3d(sourceSpace.row(hidden.corners[2])) - a);
      e2 = (e2 - e2.dot(e1) * e1).normalized();
    }
    for (int k = 0; support > 0 && k < 6; ++k) {
      const double a = k * std::numbers::pi / 3;
      const Eigen::Vector2d q = p + 0.5 * support * Eigen::Vector2d(std::cos(a), std::sin(a));
      if (hidden.triangle < 0) {
        const TriangleWeights w = motion.locate(q, excluded, below);
        if (centre.inside && w.triangle >= 0 && (placeOf(w) - centreSpace).norm() > 1.5 * support) {
          continue;
        }
        samples.push_back({w, q});
        continue;
      }
      const ClosestPoint h = closestOnSource(
          hidden.point + 0.5 * support * (std::cos(a) * e1 + std::sin(a) * e2), excluded, hidden);
      if (h.triangle < 0) continue;
      TriangleWeights w;
      w.triangle = h.triangle;
      w.corners = h.corners;
      w.weights = h.weights;
      w.inside = true;
      samples.push_back({w, q});
    }
    for (const auto& [w, q] : samples) addSample(w, q, 1.0 / static_cast<double>(samples.size()));
    for (const auto& [s, weight] : entries) {
      map.source.push_back(s);
      map.weight.push_back(weight);
      entryOf[static_cast<std::size_t>(s)] = -1;
    }
    map.rowStart.push_back(static_cast<int>(map.source.size()));
  }
  return map;
}

}  // namespace mpeg4face::clone
