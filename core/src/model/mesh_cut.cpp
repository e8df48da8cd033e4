// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/model/mesh_cut.hpp"

#include <cmath>
#include <string>
#include <vector>

#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

// The rows of `rows` that newIndex keeps (old -> new row, -1 dropped); empty stays empty.
template <typename Matrix>
Matrix keepRows(const Matrix& rows, const std::vector<int>& newIndex, int count) {
  if (rows.rows() == 0) return rows;
  Matrix out(count, rows.cols());
  for (size_t v = 0; v < newIndex.size(); ++v) {
    if (newIndex[v] >= 0) out.row(newIndex[v]) = rows.row(static_cast<Eigen::Index>(v));
  }
  return out;
}

// The faces of `mesh` inside the half space, with their vertices renumbered; `newIndex`
// receives old -> new vertex numbers (-1 for dropped ones).
IndexedFaceSet cutMesh(const IndexedFaceSet& mesh, const Eigen::Affine3d& world,
                       const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                       std::vector<int>& newIndex) {
  const int n = mesh.vertexCount();
  std::vector<char> inside(static_cast<size_t>(n));
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector3d p = world * Eigen::Vector3d(mesh.coord.row(v));
    inside[static_cast<size_t>(v)] = (p - point).dot(normal) >= 0.0;
  }
  IndexedFaceSet out;
  out.name = mesh.name;
  std::vector<char> used(static_cast<size_t>(n), 0);
  std::vector<std::pair<int, int>> keptFaces;
  for (const auto& [begin, end] : mesh.faceRanges()) {
    bool all = true;
    for (int i = begin; i < end && all; ++i) {
      all = inside[static_cast<size_t>(mesh.coordIndex[static_cast<size_t>(i)])] != 0;
    }
    if (!all) continue;
    keptFaces.emplace_back(begin, end);
    for (int i = begin; i < end; ++i)
      used[static_cast<size_t>(mesh.coordIndex[static_cast<size_t>(i)])] = 1;
  }
  newIndex.assign(static_cast<size_t>(n), -1);
  int count = 0;
  for (int v = 0; v < n; ++v) {
    if (used[static_cast<size_t>(v)]) newIndex[static_cast<size_t>(v)] = count++;
  }
  for (const auto& [begin, end] : keptFaces) {
    for (int i = begin; i < end; ++i) {
      out.coordIndex.push_back(
          newIndex[static_cast<size_t>(mesh.coordIndex[static_cast<size_t>(i)])]);
      if (!mesh.texCoordIndex.empty())
        out.texCoordIndex.push_back(mesh.texCoordIndex[static_cast<size_t>(i)]);
    }
    out.coordIndex.push_back(-1);
    if (!mesh.texCoordIndex.empty()) out.texCoordIndex.push_back(-1);
  }
  out.coord = keepRows(mesh.coord, newIndex, count);
  out.normal = keepRows(mesh.normal, newIndex, count);
  // With a texCoordIndex the UVs are indexed per corner, not per vertex: kept whole.
  out.texCoord =
      mesh.texCoordIndex.empty() ? keepRows(mesh.texCoord, newIndex, count) : mesh.texCoord;
  for (const MorphTarget& target : mesh.morphTargets) {
    out.morphTargets.push_back({target.name, keepRows(target.displacements, newIndex, count)});
  }
  out.weights = mesh.weights;
  if (!mesh.sourceIndex.empty()) {
    out.sourceIndex.resize(static_cast<size_t>(count));
    for (size_t v = 0; v < newIndex.size(); ++v) {
      if (newIndex[v] >= 0) out.sourceIndex[static_cast<size_t>(newIndex[v])] = mesh.sourceIndex[v];
    }
  }
  return out;
}

}  // namespace

FaceModel cutFaceModel(const FaceModel& model, const Eigen::Vector3d& point,
                       const Eigen::Vector3d& normal,
                       const std::function<bool(const IndexedFaceSet&)>& keepMesh) {
  model.validate();
  if (!normal.allFinite() || normal.norm() == 0.0 || !point.allFinite()) {
    throw Error({}, 0, "plane", "the normal must be finite and non-zero, the point finite");
  }
  FaceModel out;
  out.transforms = model.transforms;
  out.roots = model.roots;
  out.animations = model.animations;
  const std::vector<Eigen::Affine3d> world = model.meshWorldMatrices();
  std::vector<int> meshIndex(model.meshes.size(), -1);
  std::vector<std::vector<int>> vertexIndex(model.meshes.size());
  for (size_t m = 0; m < model.meshes.size(); ++m) {
    const IndexedFaceSet& mesh = model.meshes[m];
    if (keepMesh && !keepMesh(mesh)) continue;
    IndexedFaceSet cut = cutMesh(mesh, world[m], point, normal, vertexIndex[m]);
    if (cut.coordIndex.empty()) continue;
    meshIndex[m] = static_cast<int>(out.meshes.size());
    out.meshes.push_back(std::move(cut));
  }
  for (Transform& t : out.transforms) {
    std::vector<int> kept;
    for (int m : t.meshes) {
      if (meshIndex[static_cast<size_t>(m)] >= 0) kept.push_back(meshIndex[static_cast<size_t>(m)]);
    }
    t.meshes = kept;
  }
  for (const auto& [id, fp] : model.featurePoints) {
    if (fp.mesh < 0) {
      out.featurePoints[id] = fp;
      continue;
    }
    const int m = meshIndex[static_cast<size_t>(fp.mesh)];
    if (m < 0) continue;
    const int v = vertexIndex[static_cast<size_t>(fp.mesh)][static_cast<size_t>(fp.vertex)];
    if (v >= 0) out.featurePoints[id] = {m, v, fp.position};
  }
  for (MorphWeightAnimation& animation : out.animations) {
    std::vector<MorphWeightChannel> kept;
    for (MorphWeightChannel& channel : animation.channels) {
      if (channel.mesh < 0 || static_cast<size_t>(channel.mesh) >= meshIndex.size()) continue;
      const int m = meshIndex[static_cast<size_t>(channel.mesh)];
      if (m < 0) continue;
      channel.mesh = m;
      kept.push_back(std::move(channel));
    }
    animation.channels = std::move(kept);
  }
  return out;
}

}  // namespace mpeg4face
