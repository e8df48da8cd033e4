// SPDX-License-Identifier: GPL-3.0-or-later
// A capture's FAP playback against its ARKit playback: docs/arkit.md, "Fidelity".
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "mpeg4face/arkit/capture.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/model/surface_bump.hpp"
#include "percentile.hpp"

namespace mpeg4face {
namespace {

constexpr double kMovingFrame = 0.015;  // of ES0: the frames compared
constexpr double kMovingArea = 0.02;    // of the frame's peak: the vertices compared
constexpr double kNearPoint = 0.05;     // of ES0: "near a feature point"
constexpr double kSpikeOfPeak = 0.10;
constexpr double kSpikeOfReference = 3;

// One area mesh: its rings, its area vertices and their rows, and which lie near a point.
struct AreaMesh {
  WeldedRings rings;
  std::vector<std::pair<int, int>> vertexRow;  // (vertex, area row)
  std::vector<bool> nearPoint;                 // per entry of vertexRow
  Eigen::Matrix3d linear;
};

}  // namespace

CaptureFidelity measureCaptureFidelity(const LiveLinkCapture& capture, const ArkitCaptureFace& face,
                                       const FapStream& stream) {
  if (stream.frames.empty()) throw Error({}, 0, "stream", "the stream has no frames");
  if (capture.frameCount() == 0) throw Error({}, 0, "capture", "the capture has no frames");
  if (!face.fromTables) {
    throw Error({}, 0, "FAP keys",
                "the face has no FAP keys: there is no FAP playback to compare with its shapes");
  }
  const FaceModel& model = face.face.faceSceneGraph;
  const std::vector<Eigen::Affine3d> world = model.meshWorldMatrices();
  const double es0 = face.fapu.ES0.value;
  std::vector<Eigen::Vector3d> points;  // the bound feature points, model space
  for (const auto& [id, b] : model.featurePoints) {
    if (b.mesh >= 0)
      points.push_back(world[static_cast<std::size_t>(b.mesh)] *
                       model.meshes[static_cast<std::size_t>(b.mesh)].coord.row(b.vertex).transpose());
  }
  std::map<int, AreaMesh> meshes;
  for (std::size_t r = 0; r < face.area.size(); ++r) {
    const auto [m, v] = face.area[r];
    auto [it, made] = meshes.try_emplace(m);
    if (made) {
      it->second.rings = weldedRings(model.meshes[static_cast<std::size_t>(m)]);
      it->second.linear = world[static_cast<std::size_t>(m)].linear();
    }
    const Eigen::Vector3d at =
        world[static_cast<std::size_t>(m)] * model.meshes[static_cast<std::size_t>(m)].coord.row(v).transpose();
    bool near = false;
    for (const Eigen::Vector3d& p : points) near = near || (p - at).norm() <= kNearPoint * es0;
    it->second.vertexRow.emplace_back(v, static_cast<int>(r));
    it->second.nearPoint.push_back(near);
  }

  const FatEvaluator evaluator(face.face, face.fapu);
  const FatState neutral = evaluator.neutralState();
  FatState state = evaluator.neutralState();
  const auto rows = static_cast<Eigen::Index>(face.area.size());
  CaptureFidelity out;
  std::vector<double> errors, bumps, referenceBumps, pointBumps, referencePointBumps;
  std::set<std::pair<int, int>> spikes;
  for (const FapFrame& frame : stream.frames) {
    const Eigen::VectorXd weights =
        captureWeightsAt(capture, capture.times.front() + frame.number / stream.frameRate);
    const Eigen::VectorXd reference = face.shapeMotion * weights.head(face.shapeMotion.cols());
    const auto referenceXyz = reference.reshaped<Eigen::RowMajor>(rows, 3);
    const double peak = referenceXyz.rowwise().norm().maxCoeff();
    if (!(peak >= kMovingFrame * es0)) continue;
    ++out.frames;
    evaluator.evaluate(frame, state);
    for (const auto& [m, mesh] : meshes) {
      const auto count = static_cast<Eigen::Index>(mesh.rings.weld.size());
      Points3 played = Points3::Zero(count, 3), shapes = Points3::Zero(count, 3);
      for (const auto& [v, r] : mesh.vertexRow) {
        played.row(v) = (mesh.linear * (state.coord[static_cast<std::size_t>(m)].row(v) -
                                        neutral.coord[static_cast<std::size_t>(m)].row(v))
                                           .transpose())
                            .transpose();
        shapes.row(v) = referenceXyz.row(r);
      }
      const SurfaceBump bump = surfaceBump(mesh.rings, played);
      const SurfaceBump referenceBump = surfaceBump(mesh.rings, shapes);
      for (std::size_t i = 0; i < mesh.vertexRow.size(); ++i) {
        const int v = mesh.vertexRow[i].first;
        const double moved = shapes.row(v).norm();
        if (moved < kMovingArea * peak) continue;
        errors.push_back((played.row(v) - shapes.row(v)).norm() / peak);
        const double b = bump.bump[v] / peak, rb = referenceBump.bump[v] / peak;
        if (!std::isfinite(b) || !std::isfinite(rb)) continue;
        bumps.push_back(b);
        referenceBumps.push_back(rb);
        if (mesh.nearPoint[i]) {
          pointBumps.push_back(b);
          referencePointBumps.push_back(rb);
        }
        if (b > kSpikeOfPeak && b > kSpikeOfReference * rb) spikes.emplace(m, v);
      }
    }
  }
  if (!errors.empty()) {
    double sum = 0;
    for (double e : errors) sum += e;
    out.errorMean = sum / static_cast<double>(errors.size());
  }
  out.errorP95 = percentile(errors, 0.95);
  out.bumpP99 = percentile(bumps, 0.99);
  out.referenceBumpP99 = percentile(referenceBumps, 0.99);
  out.pointBumpP99 = percentile(pointBumps, 0.99);
  out.referencePointBumpP99 = percentile(referencePointBumps, 0.99);
  out.bumpMax = bumps.empty() ? 0 : *std::max_element(bumps.begin(), bumps.end());
  out.referenceBumpMax =
      referenceBumps.empty() ? 0 : *std::max_element(referenceBumps.begin(), referenceBumps.end());
  out.spikes.assign(spikes.begin(), spikes.end());
  return out;
}

}  // namespace mpeg4face
