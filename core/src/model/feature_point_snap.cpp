// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/model/feature_point_snap.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>

#include "model/surface_closest_point.hpp"

namespace mpeg4face {
namespace {

std::string percent(double fraction) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f%%", 100 * fraction);
  return text;
}

// A free point to bind: not 7.1 or 7.2, the centres of rotation inside the head.
bool toBind(const std::string& id, const FeaturePointBinding& binding) {
  return binding.mesh < 0 && !id.starts_with("7.");
}

}  // namespace

FeaturePointSnap snapFeaturePointsToVertices(FaceModel& model, double tolerance) {
  FeaturePointSnap result;
  const bool anyFree = std::any_of(model.featurePoints.begin(), model.featurePoints.end(),
                                   [](const auto& p) { return toBind(p.first, p.second); });
  if (!anyFree) return result;

  // Every mesh in model space, as the feature points' positions are.
  const std::vector<Eigen::Affine3d> world = model.meshWorldMatrices();
  std::vector<Points3> points(model.meshes.size());
  std::vector<std::vector<int>> triangles(model.meshes.size());
  std::vector<std::unique_ptr<SurfaceClosestPoint>> surfaces(model.meshes.size());
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (std::size_t m = 0; m < model.meshes.size(); ++m) {
    const Points3& coord = model.meshes[m].coord;
    points[m].resize(coord.rows(), 3);
    for (Eigen::Index v = 0; v < coord.rows(); ++v) {
      points[m].row(v) = world[m] * Eigen::Vector3d(coord.row(v).transpose());
    }
    if (coord.rows() > 0) {
      low = low.cwiseMin(points[m].colwise().minCoeff().transpose());
      high = high.cwiseMax(points[m].colwise().maxCoeff().transpose());
    }
    triangles[m] = model.meshes[m].triangles();
    if (triangles[m].empty()) continue;
    std::vector<int> ids(triangles[m].size() / 3);
    std::iota(ids.begin(), ids.end(), 0);
    surfaces[m] = std::make_unique<SurfaceClosestPoint>(points[m], triangles[m], ids);
  }
  // The face's size: the feature points' extent, or the model's if they are too few.
  Eigen::Vector3d pointsLow = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d pointsHigh = -pointsLow;
  int placed = 0;
  for (const auto& [id, binding] : model.featurePoints) {
    if (const std::optional<Eigen::Vector3d> p = model.featurePointPosition(id)) {
      pointsLow = pointsLow.cwiseMin(*p);
      pointsHigh = pointsHigh.cwiseMax(*p);
      ++placed;
    }
  }
  const double size = (placed >= 3 ? pointsHigh - pointsLow : high - low).norm();

  for (auto& [id, binding] : model.featurePoints) {
    if (!toBind(id, binding)) continue;
    const Eigen::Vector3d& q = binding.position;
    double best = std::numeric_limits<double>::infinity();
    int mesh = -1;
    ClosestPoint found;
    for (std::size_t m = 0; m < surfaces.size(); ++m) {
      if (!surfaces[m]) continue;
      const ClosestPoint c = surfaces[m]->closest(q);
      if (c.triangle < 0 || (c.point - q).norm() >= best) continue;
      best = (c.point - q).norm();
      mesh = static_cast<int>(m);
      found = c;
    }
    if (mesh < 0 || !(size > 0) || best > tolerance * size) {
      result.unbound.push_back(
          "feature point " + id + " is left free: " +
          (mesh < 0 ? std::string("the model has no triangles")
                    : percent(best / size) + " of the face's size off the nearest surface (" +
                          percent(tolerance) + " allowed)"));
      continue;
    }
    const int vertex = nearestCorner(points[static_cast<std::size_t>(mesh)], found, q);
    const double away =
        (points[static_cast<std::size_t>(mesh)].row(vertex).transpose() - q).norm();
    binding = {mesh, vertex, Eigen::Vector3d::Zero()};
    result.notes.push_back("feature point " + id + " bound to vertex " + std::to_string(vertex) +
                           " of mesh '" + model.meshes[static_cast<std::size_t>(mesh)].name +
                           "' (" + percent(best / size) + " of the face's size off its surface, " +
                           percent(away / size) + " from the vertex)");
  }
  return result;
}

}  // namespace mpeg4face
