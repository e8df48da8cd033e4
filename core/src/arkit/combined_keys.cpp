// SPDX-License-Identifier: GPL-3.0-or-later
// FAP keys refitted so that the combinations a stream sends reproduce the ARKit shapes'
// motion over the whole face, not only at the feature points. docs/arkit.md, "Keys that
// combine".
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <span>

#include "arkit/arkit_internal.hpp"
#include "mpeg4face/arkit/capture.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face::arkit {
namespace {

// How strongly each key stays what the mapping made it (a clean mix of shapes moving its
// own point, shared among its siblings) against reproducing the shapes' combinations: the
// weight of |K - K0|^2, per key, as a share of that key's own training energy (its row of
// F F'), so that keys the combinations hardly use stay near K0. Chosen by measurement with
// the parts' prior below (docs/arkit.md, "Keys that combine"): an ICT head with 15 of its
// shapes plays a capture closer to its shapes the lower it is (p95 15.5% at 0.3, 14.9% at
// 0.15), the Xface streams stretch the skin further (fear.fap's worst p99 1.83, 1.94).
constexpr double kPriorWeight = 0.15;
// The prior along the parts sent whole (each sibling group at its keys' amplitudes, alone and
// with each other part), as a share of the training's mean energy per key: the Xface streams
// send the lower lip past its keys with the jaw open, where keys fitted to the shapes alone
// put the lip's inside through the skin below it (ICT, before the side units: 98 frames at
// 0, 4 at 0.2, 20 at 1; with them, none at 0.1 or 0.2). At 0.2 the ICT head with 15 shapes
// had a spike at a lip corner (8.3) and its error p95 at 14.7%; at 0.1 none, 14.4%.
constexpr double kPartWeight = 0.1;
// The FAP values of a combination come from its motion of the feature points: a small
// ridge (relative to the mean diagonal) keeps sibling points that move alike from taking
// opposite values.
constexpr double kPointRidge = 1e-3;
// A refitted key keeps its own feature point's motion: it is scaled back to the amplitude,
// unless that motion fell below this share (the key is then left as the mapping made it).
constexpr double kMinOwnMotion = 0.5;
// Near each sibling's feature point a key stays nearer what the mapping made it (nothing
// there: the sibling's share), so that siblings sent at one value move each point by about
// that value (the standard's meaning of a FAP value; the Xface streams send the six
// lower-lip FAPs together far past their keys). The prior there is kSiblingPointHold times
// stronger, falling off as a Gaussian of kSiblingPointRadius times the distance from that
// point to the nearest other point of the group, with the jaw open (jawOpenCoord: closed, the
// inner lips' points touch and the hold was a notch at 2.2): smoothly, so that it makes no notch
// of its own. Chosen by measurement (docs/arkit.md, "Keys that combine"): held 1000 times,
// the capture's error p95 rose from 7.4% to 12% with a spike at the lower lip; with the
// holds on the open face, 30 times, the six lower-lip FAPs at one value moved 8.2 by 21%
// more than it (the test allows 15%), 100 times by 7%.
constexpr double kSiblingPointHold = 100;
constexpr double kSiblingPointRadius = 1.0 / 3;
// Rows of a refitted key below this share of its largest motion are dropped (the fit
// spreads rounding noise over every vertex of the meshes).
constexpr double kNegligibleMotion = 1e-4;

struct Column {
  std::size_t key;
  int mesh, vertex;           // the key's feature point
  Eigen::Vector3d direction;  // the FAP's direction times the key's sign (model space)
  double unit;                // model units per FAP unit
};

}  // namespace

void fitKeysToShapeCombinations(const FaceModel& head, const ArkitShapes& shapes,
                                const FapuMeasurement& fapu, const ArkitMapping& mapping,
                                std::vector<std::map<int, Points3>>& keyMotion) {
  const std::vector<Eigen::Affine3d> world = head.meshWorldMatrices();
  // The columns: keys of a linear FAP whose point is bound to a vertex, not eyeball turns.
  std::vector<Column> columns;
  std::set<int> meshes;
  for (std::size_t k = 0; k < mapping.keys.size(); ++k) {
    const ArkitFapKey& key = mapping.keys[k];
    const FapInfo& info = fapInfo(key.fap);
    const auto binding = head.featurePoints.find(std::string(info.featurePoint));
    const std::optional<Eigen::Vector3d> direction = fapDirection(info.positiveMotion);
    const double unit = fapu.unit(info.fapu);
    if (key.transform >= 0 || keyMotion[k].empty() || binding == head.featurePoints.end() ||
        binding->second.mesh < 0 || !direction || unit <= 0 || key.amplitude == 0)
      continue;
    columns.push_back({k, binding->second.mesh, binding->second.vertex,
                       (key.amplitude > 0 ? 1.0 : -1.0) * *direction, unit});
    for (const auto& [m, d] : keyMotion[k]) meshes.insert(m);
  }
  std::vector<const ArkitShape*> trained;  // the eye shapes belong to the eye FAPs
  for (const ArkitShape& shape : shapes.shapes) {
    if (!isArkitEyeShape(shape.ref.shape)) trained.push_back(&shape);
  }
  if (columns.empty() || trained.empty()) return;
  const auto nc = static_cast<Eigen::Index>(columns.size());
  const auto ns = static_cast<Eigen::Index>(trained.size());

  // Per unit of each key and per shape: the model-space motion of every bound feature point.
  std::vector<std::pair<int, int>> points;
  for (const auto& [id, b] : head.featurePoints) {
    if (b.mesh >= 0 && meshes.contains(b.mesh)) points.emplace_back(b.mesh, b.vertex);
  }
  const auto np = static_cast<Eigen::Index>(points.size());
  Eigen::MatrixXd keyAtPoints = Eigen::MatrixXd::Zero(3 * np, nc);
  Eigen::MatrixXd shapeAtPoints = Eigen::MatrixXd::Zero(3 * np, ns);
  for (Eigen::Index p = 0; p < np; ++p) {
    const auto [m, v] = points[static_cast<std::size_t>(p)];
    const Eigen::Matrix3d linear = world[static_cast<std::size_t>(m)].linear();
    for (Eigen::Index c = 0; c < nc; ++c) {
      const Column& col = columns[static_cast<std::size_t>(c)];
      const auto it = keyMotion[col.key].find(m);
      if (it == keyMotion[col.key].end()) continue;
      keyAtPoints.block<3, 1>(3 * p, c) =
          linear * it->second.row(v).transpose() /
          std::abs(mapping.keys[col.key].amplitude);
    }
    for (Eigen::Index s = 0; s < ns; ++s) {
      for (const ArkitTarget& t : trained[static_cast<std::size_t>(s)]->targets) {
        if (t.mesh != m) continue;
        const IndexedFaceSet& mesh = head.meshes[static_cast<std::size_t>(m)];
        shapeAtPoints.block<3, 1>(3 * p, s) =
            linear * mesh.morphTargets[static_cast<std::size_t>(t.target)]
                         .displacements.row(v)
                         .transpose();
      }
    }
  }

  // The training set: each shape alone and every pair at weight 1. Its FAP values are what
  // the keys need to move the feature points as the combination does (keys >= 0).
  Eigen::MatrixXd pointGram = keyAtPoints.transpose() * keyAtPoints;
  pointGram.diagonal().array() += kPointRidge * pointGram.diagonal().mean();
  const Eigen::MatrixXd pointRhs = keyAtPoints.transpose() * shapeAtPoints;
  const Eigen::VectorXd lower = Eigen::VectorXd::Zero(nc);
  const Eigen::VectorXd upper =
      Eigen::VectorXd::Constant(nc, std::numeric_limits<double>::infinity());
  Eigen::MatrixXd valueGram = Eigen::MatrixXd::Zero(nc, nc);  // F F'
  Eigen::MatrixXd weightValue = Eigen::MatrixXd::Zero(ns, nc);  // W F'
  // The units combined: each shape, and each left shape with its right one (a stream sends
  // the two sides together: the lower lip's FAPs at one value are both mouthLowerDowns).
  std::vector<std::vector<Eigen::Index>> units;
  for (Eigen::Index a = 0; a < ns; ++a) units.push_back({a});
  for (Eigen::Index a = 0; a < ns; ++a) {
    const ArkitShapeRef& left = trained[static_cast<std::size_t>(a)]->ref;
    if (arkitShapeSide(left) != FaceSide::Left) continue;
    std::string mirrored = arkitShapeLabel(left);
    for (const auto& [from, to] : {std::pair{"Left", "Right"}, std::pair{"left", "right"}}) {
      if (const auto at = mirrored.rfind(from); at != std::string::npos)
        mirrored.replace(at, std::string_view(from).size(), to);
    }
    for (Eigen::Index b = 0; b < ns; ++b) {
      const ArkitShapeRef& right = trained[static_cast<std::size_t>(b)]->ref;
      if (arkitShapeSide(right) == FaceSide::Right && arkitShapeLabel(right) == mirrored)
        units.push_back({a, b});
    }
  }
  Eigen::VectorXd f = lower;
  for (std::size_t a = 0; a < units.size(); ++a) {
    for (std::size_t b = a; b < units.size(); ++b) {
      std::vector<Eigen::Index> combination = units[a];
      if (b != a) combination.insert(combination.end(), units[b].begin(), units[b].end());
      std::sort(combination.begin(), combination.end());
      if (std::adjacent_find(combination.begin(), combination.end()) != combination.end())
        continue;
      Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nc);
      for (const Eigen::Index s : combination) rhs += pointRhs.col(s);
      boundedLeastSquares(pointGram, rhs, lower, upper, f);
      valueGram += f * f.transpose();
      for (const Eigen::Index s : combination) weightValue.row(s) += f.transpose();
    }
  }
  // Per mesh, per column: the Gaussians of kSiblingPointHold (centre, 1/r^2).
  std::map<int, std::vector<std::vector<std::pair<Eigen::RowVector3d, double>>>> holds;
  std::map<int, Points3> opened;  // where the holds are measured: the lips apart
  for (int m : meshes) {
    auto& held = holds[m];
    held.resize(columns.size());
    const IndexedFaceSet& mesh = head.meshes[static_cast<std::size_t>(m)];
    const Points3& at = opened.emplace(m, jawOpenCoord(head, shapes, m)).first->second;
    for (std::size_t c = 0; c < columns.size(); ++c) {
      std::vector<Eigen::RowVector3d> group;  // the group's points on this mesh, own first
      int own = -1;
      for (int fap : siblingFaps(mapping.keys[columns[c].key].fap)) {
        const auto b = head.featurePoints.find(std::string(fapInfo(fap).featurePoint));
        if (b == head.featurePoints.end() || b->second.mesh != m || b->second.vertex < 0 ||
            b->second.vertex >= mesh.vertexCount())
          continue;
        if (fap == mapping.keys[columns[c].key].fap) own = static_cast<int>(group.size());
        group.push_back(at.row(b->second.vertex));
      }
      for (std::size_t i = 0; i < group.size(); ++i) {
        if (static_cast<int>(i) == own) continue;
        double nearest = std::numeric_limits<double>::infinity();
        for (std::size_t j = 0; j < group.size(); ++j) {
          if (j != i) nearest = std::min(nearest, (group[j] - group[i]).squaredNorm());
        }
        if (nearest > 0 && std::isfinite(nearest)) {
          held[c].emplace_back(group[i],
                               1 / (kSiblingPointRadius * kSiblingPointRadius * nearest));
        }
      }
    }
  }

  // K = (M W F' + beta K0) (F F' + beta I)^-1, mesh by mesh: each vertex's motion per unit
  // of each key, the least-squares fit of the combinations near the mapping's keys.
  const Eigen::VectorXd prior =
      kPriorWeight * (valueGram.diagonal().array() + 1e-3 * valueGram.diagonal().mean());
  // The parts sent whole: each sibling group (one sign) at its keys' amplitudes, alone and
  // with each other part, should still move as the mapping's keys add up there.
  std::map<std::pair<const int*, bool>, Eigen::VectorXd> parts;
  for (Eigen::Index c = 0; c < nc; ++c) {
    const ArkitFapKey& key = mapping.keys[columns[static_cast<std::size_t>(c)].key];
    const std::span<const int> group = siblingFaps(key.fap);
    const int* id = group.empty() ? &key.fap : group.data();
    parts.try_emplace({id, key.amplitude > 0}, Eigen::VectorXd::Zero(nc))
        .first->second[c] = std::abs(key.amplitude);
  }
  Eigen::MatrixXd partGram = Eigen::MatrixXd::Zero(nc, nc);
  for (auto a = parts.begin(); a != parts.end(); ++a) {
    for (auto b = a; b != parts.end(); ++b) {
      const Eigen::VectorXd sent = b == a ? a->second : Eigen::VectorXd(a->second + b->second);
      partGram += sent * sent.transpose();
    }
  }
  const double partScale = kPartWeight * valueGram.diagonal().mean() / partGram.diagonal().mean();
  Eigen::MatrixXd priorGram = partScale * partGram;
  priorGram.diagonal() += prior;
  valueGram += priorGram;
  const Eigen::LDLT<Eigen::MatrixXd> solver(valueGram);
  Eigen::VectorXd own = Eigen::VectorXd::Zero(nc);
  std::map<int, Eigen::MatrixXd> fitted;
  for (int m : meshes) {
    const IndexedFaceSet& mesh = head.meshes[static_cast<std::size_t>(m)];
    const Eigen::Index rows = 3 * static_cast<Eigen::Index>(mesh.vertexCount());
    Eigen::MatrixXd k0 = Eigen::MatrixXd::Zero(rows, nc);  // the mapping's keys, per unit
    for (Eigen::Index c = 0; c < nc; ++c) {
      const Column& col = columns[static_cast<std::size_t>(c)];
      const auto it = keyMotion[col.key].find(m);
      if (it == keyMotion[col.key].end()) continue;
      k0.col(c) =
          it->second.reshaped<Eigen::RowMajor>() / std::abs(mapping.keys[col.key].amplitude);
    }
    Eigen::MatrixXd rhs = k0 * priorGram;
    for (Eigen::Index s = 0; s < ns; ++s) {
      for (const ArkitTarget& t : trained[static_cast<std::size_t>(s)]->targets) {
        if (t.mesh != m) continue;
        rhs += mesh.morphTargets[static_cast<std::size_t>(t.target)]
                   .displacements.reshaped<Eigen::RowMajor>() *
               weightValue.row(s);
      }
    }
    Eigen::MatrixXd k = solver.solve(rhs.transpose()).transpose();
    // Vertices near a sibling's point: the same fit with that key's prior held harder.
    const auto& held = holds[m];
    const Points3& at = opened.at(m);
    for (int v = 0; v < mesh.vertexCount(); ++v) {
      Eigen::VectorXd extra = Eigen::VectorXd::Zero(nc);
      for (Eigen::Index c = 0; c < nc; ++c) {
        double near = 0;
        for (const auto& [centre, inverse] : held[static_cast<std::size_t>(c)])
          near += std::exp(-(at.row(v) - centre).squaredNorm() * inverse);
        extra[c] = kSiblingPointHold * near * prior[c];
      }
      if (extra.maxCoeff() <= 1e-3 * prior.minCoeff()) continue;
      Eigen::MatrixXd gram = valueGram;
      gram.diagonal() += extra;
      k.middleRows(3 * v, 3) =
          gram.ldlt()
              .solve((rhs.middleRows(3 * v, 3) + k0.middleRows(3 * v, 3) * extra.asDiagonal())
                         .transpose())
              .transpose();
    }
    const Eigen::Matrix3d linear = world[static_cast<std::size_t>(m)].linear();
    for (Eigen::Index c = 0; c < nc; ++c) {
      const Column& col = columns[static_cast<std::size_t>(c)];
      if (col.mesh == m)
        own[c] = (linear * k.block<3, 1>(3 * col.vertex, c)).dot(col.direction) / col.unit;
    }
    fitted.emplace(m, std::move(k));
  }
  for (Eigen::Index c = 0; c < nc; ++c) {
    const Column& col = columns[static_cast<std::size_t>(c)];
    if (own[c] < kMinOwnMotion) continue;
    const double amplitude = std::abs(mapping.keys[col.key].amplitude);
    std::map<int, Points3> motion;
    for (auto& [m, k] : fitted) {
      Points3 d = (k.col(c) * (amplitude / own[c])).reshaped<Eigen::RowMajor>(k.rows() / 3, 3);
      const double largest = d.rowwise().norm().maxCoeff();
      if (largest <= 0) continue;
      for (Eigen::Index v = 0; v < d.rows(); ++v) {
        if (d.row(v).norm() < kNegligibleMotion * largest) d.row(v).setZero();
      }
      motion.emplace(m, std::move(d));
    }
    keyMotion[col.key] = std::move(motion);
  }
}

}  // namespace mpeg4face::arkit
