// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/model/landmarks.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <utility>
#include <memory>
#include <numeric>
#include <optional>

#include "model/landmark_rules.hpp"
#include "model/surface_closest_point.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "percentile.hpp"

namespace mpeg4face {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using landmark_fit::normalsOf;
using landmark_fit::Surface;

// The mesh `mesh` of `model` in model space, searchable.
Surface surfaceOf(const FaceModel& model, const std::vector<Eigen::Affine3d>& world, int mesh) {
  Surface s;
  s.mesh = mesh;
  const Points3& coord = model.meshes[static_cast<std::size_t>(mesh)].coord;
  s.points.resize(coord.rows(), 3);
  for (Eigen::Index v = 0; v < coord.rows(); ++v) {
    s.points.row(v) = world[static_cast<std::size_t>(mesh)] * Vector3d(coord.row(v).transpose());
  }
  s.triangles = model.meshes[static_cast<std::size_t>(mesh)].triangles();
  std::vector<int> ids(s.triangles.size() / 3);
  std::iota(ids.begin(), ids.end(), 0);
  if (!ids.empty()) s.search = std::make_unique<SurfaceClosestPoint>(s.points, s.triangles, ids);
  // Every triangle's edges, sorted: an edge that appears once is on the boundary.
  std::vector<std::pair<int, int>> sides;
  for (std::size_t t = 0; t + 2 < s.triangles.size(); t += 3) {
    for (std::size_t k = 0; k < 3; ++k) {
      const int a = s.triangles[t + k], b = s.triangles[t + (k + 1) % 3];
      sides.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(sides.begin(), sides.end());
  s.boundary.assign(static_cast<std::size_t>(coord.rows()), false);
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i;
    while (j < sides.size() && sides[j] == sides[i]) ++j;
    if (j - i == 1) {
      s.boundary[static_cast<std::size_t>(sides[i].first)] = true;
      s.boundary[static_cast<std::size_t>(sides[i].second)] = true;
    }
    s.edges.push_back(sides[i]);
    i = j;
  }
  return s;
}

// A similarity y = scale * rotation * x + translation.
struct Similarity {
  double scale = 1;
  Matrix3d rotation = Matrix3d::Identity();
  Vector3d translation = Vector3d::Zero();
  Vector3d operator()(const Vector3d& x) const { return scale * (rotation * x) + translation; }
};

// The weighted least-squares similarity taking `from` onto `to` (Umeyama 1991).
Similarity fitSimilarity(const std::vector<Vector3d>& from, const std::vector<Vector3d>& to,
                         const std::vector<double>& weight) {
  double total = 0;
  Vector3d mf = Vector3d::Zero(), mt = Vector3d::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) {
    total += weight[i];
    mf += weight[i] * from[i];
    mt += weight[i] * to[i];
  }
  Similarity s;
  if (!(total > 0)) return s;
  mf /= total;
  mt /= total;
  Matrix3d cov = Matrix3d::Zero();
  double spread = 0;
  for (std::size_t i = 0; i < from.size(); ++i) {
    cov += weight[i] * (to[i] - mt) * (from[i] - mf).transpose();
    spread += weight[i] * (from[i] - mf).squaredNorm();
  }
  Eigen::JacobiSVD<Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Matrix3d d = Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) d(2, 2) = -1;
  s.rotation = svd.matrixU() * d * svd.matrixV().transpose();
  s.scale = spread > 0 ? (svd.singularValues().asDiagonal() * d).trace() / spread : 1.0;
  s.translation = mt - s.scale * s.rotation * mf;
  return s;
}

// Centre, principal axes (columns, largest spread first) and RMS radius of a surface,
// weighted by triangle area so that the meshing does not matter.
struct Frame {
  Vector3d centre = Vector3d::Zero();
  Matrix3d axes = Matrix3d::Identity();
  double radius = 0;
};

Frame principalFrame(const Surface& s) {
  Frame f;
  double area = 0;
  Matrix3d second = Matrix3d::Zero();
  for (int t = 0; t < s.triangleCount(); ++t) {
    const Vector3d a = s.corner(t, 0), b = s.corner(t, 1), c = s.corner(t, 2);
    const double w = 0.5 * (b - a).cross(c - a).norm();
    const Vector3d m = (a + b + c) / 3;
    area += w;
    f.centre += w * m;
    second += w * m * m.transpose();
  }
  if (!(area > 0)) return f;
  f.centre /= area;
  const Matrix3d cov = second / area - f.centre * f.centre.transpose();
  Eigen::SelfAdjointEigenSolver<Matrix3d> eig(cov);
  f.axes = eig.eigenvectors().rowwise().reverse();
  f.radius = std::sqrt(std::max(0.0, cov.trace()));
  return f;
}

// Every rotation taking the template's principal axes onto the target's up to their signs
// and order: the file's up axis, facing direction and handedness of its axes are unknown.
std::vector<Matrix3d> axisCandidates(const Frame& from, const Frame& to) {
  std::vector<Matrix3d> out;
  std::array<int, 3> order = {0, 1, 2};
  do {
    for (int signs = 0; signs < 8; ++signs) {
      Matrix3d p = Matrix3d::Zero();
      for (int k = 0; k < 3; ++k) {
        p(order[static_cast<std::size_t>(k)], k) = (signs >> k & 1) ? -1 : 1;
      }
      const Matrix3d r = to.axes * p * from.axes.transpose();
      if (r.determinant() > 0) out.push_back(r);
    }
  } while (std::next_permutation(order.begin(), order.end()));
  return out;
}

// The median distance (relative to the template's RMS radius carried by the scale) past
// which the aligned template is no face of the head's: the sample heads fit each other within
// 1.8-2.4%, a sphere or a cube leaves 7.6-7.8%.
constexpr double kNoFace = 0.045;
// A pin's weight against one matched vertex.
constexpr double kPinWeight = 1e3;
// How far from where the template puts an eye, tooth or tongue point a mesh of the head may
// lie, in ES0.
constexpr double kPartReach = 0.25;

// How many of a template part's vertices vote for the head's mesh it lands on.
constexpr std::size_t kPartVoters = 200;

struct Pair {
  Vector3d from, to;
  double weight;
};

// Trimmed similarity ICP of template points onto the target surface; returns the median
// distance left, relative to the template radius carried by the scale.
double similarityIcp(const std::vector<Vector3d>& sample, const Surface& target,
                     const std::vector<Pair>& pins, double templateRadius, int iterations,
                     Similarity& s) {
  std::vector<ClosestPoint> hints(sample.size());
  std::vector<double> distance(sample.size());
  double median = std::numeric_limits<double>::infinity();
  for (int it = 0; it <= iterations; ++it) {
    for (std::size_t i = 0; i < sample.size(); ++i) {
      hints[i] = target.search->closest(s(sample[i]), it > 0 ? &hints[i] : nullptr);
      distance[i] = (hints[i].point - s(sample[i])).norm();
    }
    std::vector<double> sorted = distance;
    median = percentile(sorted, 0.5) / (s.scale * templateRadius);
    if (it == iterations) break;
    const double keep = percentile(sorted, 0.8);
    std::vector<Vector3d> from, to;
    std::vector<double> weight;
    for (std::size_t i = 0; i < sample.size(); ++i) {
      if (distance[i] > keep) continue;
      from.push_back(sample[i]);
      to.push_back(hints[i].point);
      weight.push_back(1.0);
    }
    const double pinWeight = pins.empty() ? 0 : 0.5 * static_cast<double>(from.size()) /
                                                    static_cast<double>(pins.size());
    for (const Pair& p : pins) {
      from.push_back(p.from);
      to.push_back(p.to);
      weight.push_back(pinWeight * p.weight);
    }
    s = fitSimilarity(from, to, weight);
  }
  return median;
}

std::string percentText(double fraction) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f%%", 100 * fraction);
  return text;
}

// The template's meshes that hold feature points, and the skin (the one holding most).
int skinOf(const FaceModel& head) {
  std::vector<int> count(head.meshes.size(), 0);
  for (const auto& [id, b] : head.featurePoints) {
    const auto m = static_cast<std::size_t>(b.mesh);
    if (b.mesh >= 0 && m < head.meshes.size()) ++count[m];
  }
  const auto best = std::max_element(count.begin(), count.end());
  if (best == count.end() || *best < 10) {
    throw Error("template: fewer than 10 feature points on any mesh; a template needs its "
                "face's feature points on the vertices of its skin mesh");
  }
  return static_cast<int>(best - count.begin());
}

// A pin's model-space position; throws mpeg4face::Error naming it if its vertex is not in
// the head.
Vector3d pinPosition(const FaceModel& target, const std::vector<Eigen::Affine3d>& world,
                     const std::string& id, const FeaturePointBinding& pin) {
  if (pin.mesh < 0) return pin.position;
  const auto mesh = static_cast<std::size_t>(pin.mesh);
  if (mesh >= target.meshes.size() || pin.vertex < 0 ||
      pin.vertex >= target.meshes[mesh].vertexCount()) {
    throw Error({}, 0, "pin " + id,
                "vertex " + std::to_string(pin.vertex) + " of mesh " +
                    std::to_string(pin.mesh) + " is not in the head");
  }
  return world[mesh] * Vector3d(target.meshes[mesh].coord.row(pin.vertex).transpose());
}

}  // namespace

int landmarkFaceMesh(const FaceModel& head) {
  int best = -1;
  std::size_t most = 0;
  for (std::size_t m = 0; m < head.meshes.size(); ++m) {
    const std::size_t n = head.meshes[m].triangles().size();
    if (n > most) {
      most = n;
      best = static_cast<int>(m);
    }
  }
  return best;
}

LandmarkResult findFeaturePoints(const FaceModel& target, const FaceModel& templateHead,
                                 const LandmarkOptions& options) {
  const auto progress = [&](double f, std::string_view step) {
    if (options.progress) options.progress(f, step);
  };
  target.validate();
  templateHead.validate();
  LandmarkResult result;

  const int faceMesh = landmarkFaceMesh(target);
  if (faceMesh < 0) throw Error("the head has no faces: there is no surface to place points on");
  result.faceMesh = faceMesh;
  const std::vector<Eigen::Affine3d> targetWorld = target.meshWorldMatrices();
  const Surface face = surfaceOf(target, targetWorld, faceMesh);

  const int skinMesh = skinOf(templateHead);
  const std::vector<Eigen::Affine3d> templateWorld = templateHead.meshWorldMatrices();
  const Surface skin = surfaceOf(templateHead, templateWorld, skinMesh);
  const FapuMeasurement templateFapu = measureFapu(templateHead);
  if (!templateFapu.ES0.measured) {
    throw Error("template: ES0 cannot be measured (" + templateFapu.ES0.method + ")");
  }
  const double templateEs0 = templateFapu.ES0.value;

  // Pins the template also has on its skin pull the fit.
  std::vector<Pair> pins;
  std::map<int, Vector3d> pinnedVertex;  // template skin vertex -> target position
  for (const auto& [id, binding] : options.pins) {
    const Vector3d at = pinPosition(target, targetWorld, id, binding);
    const auto t = templateHead.featurePoints.find(id);
    if (t == templateHead.featurePoints.end() || t->second.mesh != skinMesh) continue;
    pins.push_back({skin.points.row(t->second.vertex).transpose(), at, 1.0});
    pinnedVertex[t->second.vertex] = at;
  }

  // 1. Similarity alignment: from the pins if they fix it, else from every axis candidate.
  progress(0.0, "alignment");
  const Frame from = principalFrame(skin), to = principalFrame(face);
  if (!(to.radius > 0)) throw Error("the head's face mesh has no area");
  std::vector<Vector3d> sample;
  const Eigen::Index stride = std::max<Eigen::Index>(1, skin.points.rows() / 600);
  for (Eigen::Index v = 0; v < skin.points.rows(); v += stride) {
    sample.push_back(skin.points.row(v));
  }
  // Three pins or more fix the alignment and say where the face is.
  const bool pinned = pins.size() >= 3;
  std::vector<Similarity> starts;
  if (pinned) {
    std::vector<Vector3d> a, b;
    std::vector<double> w;
    for (const Pair& p : pins) {
      a.push_back(p.from);
      b.push_back(p.to);
      w.push_back(1);
    }
    starts.push_back(fitSimilarity(a, b, w));
  } else {
    for (const Matrix3d& r : axisCandidates(from, to)) {
      Similarity s;
      s.rotation = r;
      s.scale = to.radius / from.radius;
      s.translation = to.centre - s.scale * r * from.centre;
      starts.push_back(s);
    }
  }
  double bestScore = std::numeric_limits<double>::infinity();
  Similarity best;
  std::vector<std::pair<double, Similarity>> tried;
  for (Similarity s : starts) {
    const double score = similarityIcp(sample, face, pins, from.radius, 12, s);
    tried.emplace_back(score, s);
  }
  std::sort(tried.begin(), tried.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  sample.clear();
  const Eigen::Index fine = std::max<Eigen::Index>(1, skin.points.rows() / 3000);
  for (Eigen::Index v = 0; v < skin.points.rows(); v += fine) sample.push_back(skin.points.row(v));
  for (std::size_t k = 0; k < std::min<std::size_t>(3, tried.size()); ++k) {
    Similarity s = tried[k].second;
    const double score = similarityIcp(sample, face, pins, from.radius, 30, s);
    if (score < bestScore) {
      bestScore = score;
      best = s;
    }
  }
  // The face alone decides the last of the alignment: necks, backs of heads and hair differ
  // more between heads than faces do.
  double faceScore = 0;  // the face alone's residual, measured below
  {
    Vector3d centre = Vector3d::Zero();
    std::vector<Vector3d> facePoints;
    for (const auto& [id, b] : templateHead.featurePoints) {
      const char group = id[0];
      if (b.mesh != skinMesh || id[1] != '.' ||
          std::string_view("234589").find(group) == std::string_view::npos) {
        continue;
      }
      facePoints.push_back(skin.points.row(b.vertex));
      centre += facePoints.back();
    }
    centre /= static_cast<double>(std::max<std::size_t>(1, facePoints.size()));
    double reach = 0;
    for (const Vector3d& p : facePoints) reach = std::max(reach, (p - centre).norm());
    sample.clear();
    for (Eigen::Index v = 0; v < skin.points.rows(); ++v) {
      const Vector3d p = skin.points.row(v);
      if ((p - centre).norm() < 1.1 * reach) sample.push_back(p);
    }
    const std::size_t keep = 3000;
    if (sample.size() > keep) {
      std::vector<Vector3d> thinned;
      for (std::size_t i = 0; i < keep; ++i) thinned.push_back(sample[i * sample.size() / keep]);
      sample = std::move(thinned);
    }
    faceScore = similarityIcp(sample, face, pins, from.radius, 30, best);
  }
  result.scale = best.scale;
  // Whether there is a face: pinned, the template's face alone against the head (a mask has
  // no back of the head); else the whole template (its face alone fits a sphere within 5.1%,
  // too near the 4.5% limit to tell).
  result.alignmentResidual = pinned ? faceScore : bestScore;
  result.alignment.linear() = best.scale * best.rotation;
  result.alignment.translation() = best.translation;
  const double es0 = templateEs0 * best.scale;  // the target's ES0, as far as we know yet
  if (result.alignmentResidual > kNoFace) {
    throw Error("no face found: the best alignment of the template leaves half its " +
                std::string(pinned ? "face " : "surface ") +
                percentText(result.alignmentResidual) +
                " of the head's size or more from it (a face fits within " + percentText(kNoFace) +
                ")");
  }

  // 2. Non-rigid ICP: each template vertex moves to the target, the displacement field kept
  // smooth by a membrane term whose stiffness falls step by step.
  const Eigen::Index n = skin.points.rows();
  Points3 aligned(n, 3);
  for (Eigen::Index v = 0; v < n; ++v) aligned.row(v) = best(skin.points.row(v).transpose());
  Eigen::SparseMatrix<double> laplacian(n, n);
  {
    std::vector<Eigen::Triplet<double>> entries;
    for (Eigen::Index v = 0; v < n; ++v) entries.emplace_back(v, v, 0.0);
    for (const auto& [a, b] : skin.edges) {
      entries.emplace_back(a, a, 1.0);
      entries.emplace_back(b, b, 1.0);
      entries.emplace_back(a, b, -1.0);
      entries.emplace_back(b, a, -1.0);
    }
    laplacian.setFromTriplets(entries.begin(), entries.end());
  }
  const Points3 restTerm = laplacian * aligned;
  Points3 fitted = aligned;
  std::vector<ClosestPoint> match(static_cast<std::size_t>(n));
  std::vector<double> weight(static_cast<std::size_t>(n), 0.0);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  bool analysed = false;
  const std::array<double, 7> stiffness = {50, 20, 10, 5, 2, 1, 0.5};
  const int rounds = 3;
  for (std::size_t stage = 0; stage < stiffness.size(); ++stage) {
    progress(0.1 + 0.8 * static_cast<double>(stage) / static_cast<double>(stiffness.size()),
             "non-rigid fit");
    for (int round = 0; round < rounds; ++round) {
      const std::vector<Vector3d> normals = normalsOf(fitted, skin.triangles);
      const double reach = std::max(0.05, 0.5 / static_cast<double>(stage + 1)) * es0;
      Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(n);
      Points3 rhs = stiffness[stage] * restTerm;
      for (Eigen::Index v = 0; v < n; ++v) {
        const auto i = static_cast<std::size_t>(v);
        const Vector3d y = fitted.row(v);
        match[i] = face.search->closest(y, match[i].triangle >= 0 ? &match[i] : nullptr);
        const ClosestPoint& c = match[i];
        const bool onEdge = face.boundary[static_cast<std::size_t>(c.corners[0])] ||
                            face.boundary[static_cast<std::size_t>(c.corners[1])] ||
                            face.boundary[static_cast<std::size_t>(c.corners[2])];
        const double facing = normals[i].dot(face.triangleNormal(c.triangle));
        weight[i] = (!onEdge && !skin.boundary[i] && facing > 0.5 &&
                     (c.point - y).norm() < reach)
                        ? 1.0
                        : 0.0;
        diagonal(v) = weight[i];
        rhs.row(v) += weight[i] * c.point.transpose();
      }
      for (const auto& [vertex, at] : pinnedVertex) {
        diagonal(vertex) += kPinWeight;
        rhs.row(vertex) += kPinWeight * at.transpose();
      }
      Eigen::SparseMatrix<double> system = stiffness[stage] * laplacian;
      for (Eigen::Index v = 0; v < n; ++v) system.coeffRef(v, v) += diagonal(v) + 1e-9;
      if (!analysed) {
        solver.analyzePattern(system);
        analysed = true;
      }
      solver.factorize(system);
      if (solver.info() != Eigen::Success) throw Error("the non-rigid fit's system is singular");
      fitted = solver.solve(rhs);
    }
  }

  // How far the fitted template lies from the target: per vertex, and the median over the
  // vertices that found their match.
  std::vector<double> residual(static_cast<std::size_t>(n), 0.0);
  {
    std::vector<double> matched;
    for (Eigen::Index v = 0; v < n; ++v) {
      const auto i = static_cast<std::size_t>(v);
      match[i] = face.search->closest(fitted.row(v).transpose(), &match[i]);
      residual[i] = (match[i].point - fitted.row(v).transpose()).norm() / es0;
      if (weight[i] > 0) matched.push_back(residual[i]);
    }
    result.fitResidual = percentile(matched, 0.5);
  }
  progress(0.9, "placing points");

  // 3. Each template point carried onto the target.
  const Vector3d front = best.rotation * Vector3d::UnitZ();  // where the face looks
  // The displacement the fit gives a template position: that of the skin vertices nearest
  // it, inverse-distance weighted, on top of the similarity.
  const auto carry = [&](const Vector3d& p) {
    std::vector<std::pair<double, Eigen::Index>> near;
    for (Eigen::Index v = 0; v < n; ++v) {
      near.emplace_back((skin.points.row(v).transpose() - p).squaredNorm(), v);
    }
    const std::size_t k = std::min<std::size_t>(8, near.size());
    std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(k), near.end());
    Vector3d shift = Vector3d::Zero();
    double total = 0;
    for (std::size_t j = 0; j < k; ++j) {
      const double w = 1.0 / (std::sqrt(near[j].first) + 1e-3 * templateEs0);
      shift += w * (fitted.row(near[j].second) - aligned.row(near[j].second)).transpose();
      total += w;
    }
    return Vector3d(best(p) + shift / total);
  };
  // Confidence from the residual of the fit around a template vertex: 1 within 1% of ES0,
  // 0.5 at 3%.
  const auto confidenceAt = [&](const Vector3d& p) {
    double sum = 0;
    int count = 0;
    for (Eigen::Index v = 0; v < n; ++v) {
      if ((skin.points.row(v).transpose() - p).norm() > 0.1 * templateEs0) continue;
      sum += residual[static_cast<std::size_t>(v)] * residual[static_cast<std::size_t>(v)];
      ++count;
    }
    const double rms = count ? std::sqrt(sum / count) : 1.0;
    const double excess = std::max(0.0, rms - 0.01) / 0.02;
    return 1.0 / (1.0 + excess * excess);
  };
  // Other target meshes (eyes, teeth, tongue), searched for the points the template has on
  // its own such meshes.
  std::vector<Surface> parts;
  for (std::size_t m = 0; m < target.meshes.size(); ++m) {
    if (static_cast<int>(m) == faceMesh || target.meshes[m].triangles().empty()) continue;
    parts.push_back(surfaceOf(target, targetWorld, static_cast<int>(m)));
  }
  // Per template mesh its connectedPieces (when needed); (mesh, piece) -> parts index, or -1.
  std::vector<std::vector<int>> templatePieces(templateHead.meshes.size());
  std::map<std::pair<int, int>, int> partVotes;
  for (const auto& [id, binding] : templateHead.featurePoints) {
    const std::optional<Vector3d> at = templateHead.featurePointPosition(id);
    if (!at) continue;
    PlacedFeaturePoint placed;
    if (binding.mesh == skinMesh) {
      const Vector3d y = fitted.row(binding.vertex);
      const ClosestPoint c = face.search->closest(y);
      const int nearest = nearestCorner(face.points, c, c.point);
      placed.binding.mesh = faceMesh;
      placed.binding.vertex = nearest;
      placed.binding.position = face.points.row(nearest);
      placed.confidence = confidenceAt(*at);
      placed.rule = "fit";
    } else if (binding.mesh < 0) {
      placed.binding.position = carry(*at);
      placed.confidence = 0.5 * confidenceAt(*at);
      placed.rule = "carried (inside the head)";
    } else {
      const Vector3d y = carry(*at);
      // The head's mesh that the template's part (the connected piece of its mesh that holds
      // the point: an upper tooth row, a tongue) lands on, by a vote of the piece's vertices:
      // upper and lower teeth meet in a closed mouth, so the mesh nearest the point alone
      // put a lower tooth's point on the upper row and the tongue tip on the lower teeth.
      const Surface* on = nullptr;
      const auto mesh = static_cast<std::size_t>(binding.mesh);
      if (templatePieces[mesh].empty()) {
        templatePieces[mesh] = connectedPieces(templateHead.meshes[mesh]);
      }
      const int label = templatePieces[mesh][static_cast<std::size_t>(binding.vertex)];
      const auto key = std::pair{binding.mesh, label};
      auto voted = partVotes.find(key);
      if (voted == partVotes.end()) {
        const Points3& coord = templateHead.meshes[mesh].coord;
        std::vector<int> piece;
        for (std::size_t v = 0; v < templatePieces[mesh].size(); ++v) {
          if (templatePieces[mesh][v] == label) piece.push_back(static_cast<int>(v));
        }
        std::vector<int> votes(parts.size(), 0);
        const std::size_t step = std::max<std::size_t>(1, piece.size() / kPartVoters);
        for (std::size_t i = 0; i < piece.size(); i += step) {
          const Vector3d q = carry(templateWorld[mesh] * Vector3d(coord.row(piece[i]).transpose()));
          double nearest = std::numeric_limits<double>::infinity();
          std::size_t closest = parts.size();
          for (std::size_t k = 0; k < parts.size(); ++k) {
            const double d = (parts[k].search->closest(q).point - q).norm();
            if (d < nearest) {
              nearest = d;
              closest = k;
            }
          }
          if (closest < parts.size() && nearest <= kPartReach * es0) ++votes[closest];
        }
        const auto most = std::max_element(votes.begin(), votes.end());
        voted = partVotes.emplace(key, most == votes.end() || *most == 0
                                           ? -1
                                           : static_cast<int>(most - votes.begin()))
                    .first;
      }
      if (voted->second >= 0) on = &parts[static_cast<std::size_t>(voted->second)];
      const ClosestPoint c = on ? on->search->closest(y) : ClosestPoint{};
      const double nearest = on ? (c.point - y).norm() : std::numeric_limits<double>::infinity();
      const std::string& partName =
          templateHead.meshes[static_cast<std::size_t>(binding.mesh)].name;
      if (!on || nearest > kPartReach * es0) {
        result.notPlaced.push_back(id + ": no mesh of the head within " +
                                   percentText(kPartReach) + " of ES0 of where the template's '" +
                                   partName + "' puts it");
        continue;
      }
      const bool pupil = id == "3.5" || id == "3.6";
      int vertex = pupil ? c.corners[0] : nearestCorner(on->points, c, c.point);
      if (pupil) {
        // The pupil: the eye mesh's most forward vertex near the carried point.
        double ahead = -std::numeric_limits<double>::infinity();
        for (Eigen::Index v = 0; v < on->points.rows(); ++v) {
          const Vector3d q = on->points.row(v);
          if ((q - y).norm() > 0.3 * es0 || q.dot(front) <= ahead) continue;
          ahead = q.dot(front);
          vertex = static_cast<int>(v);
        }
      }
      placed.binding.mesh = on->mesh;
      placed.binding.vertex = vertex;
      placed.binding.position = on->points.row(vertex);
      placed.confidence = confidenceAt(*at) / (1.0 + nearest / (0.05 * es0));
      placed.rule = pupil ? std::string("fit, most forward on the eye mesh") : "fit, on mesh '" +
                    target.meshes[static_cast<std::size_t>(on->mesh)].name + "'";
    }
    result.points[id] = placed;
  }
  landmark_fit::refineByRules(templateHead, face, parts, best.rotation, es0, result);
  for (const auto& [id, binding] : options.pins) {
    PlacedFeaturePoint pin;
    pin.binding = binding;
    pin.binding.position = pinPosition(target, targetWorld, id, binding);
    pin.confidence = 1;
    pin.rule = "pin";
    result.points[id] = pin;
  }
  progress(1.0, "done");
  return result;
}

}  // namespace mpeg4face
