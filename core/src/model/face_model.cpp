// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/model/face_model.hpp"

#include <functional>
#include <numeric>

#include "mpeg4face/error.hpp"

namespace mpeg4face {

int IndexedFaceSet::faceCount() const { return static_cast<int>(faceRanges().size()); }

std::vector<std::pair<int, int>> IndexedFaceSet::faceRanges() const {
  std::vector<std::pair<int, int>> ranges;
  int begin = 0;
  const int size = static_cast<int>(coordIndex.size());
  for (int i = 0; i < size; ++i) {
    if (coordIndex[i] < 0) {
      ranges.emplace_back(begin, i);
      begin = i + 1;
    }
  }
  // VRML allows the last face without its -1.
  if (begin < size) ranges.emplace_back(begin, size);
  return ranges;
}

std::vector<int> IndexedFaceSet::triangles() const {
  std::vector<int> out;
  for (auto [begin, end] : faceRanges()) {
    for (int i = begin + 1; i + 1 < end; ++i) {
      out.insert(out.end(), {coordIndex[begin], coordIndex[i], coordIndex[i + 1]});
    }
  }
  return out;
}

Eigen::Affine3d Transform::localMatrix() const {
  Eigen::Affine3d m = Eigen::Affine3d::Identity();
  m.translate(translation + center).rotate(rotation).scale(scale).translate(-center);
  return m;
}

std::optional<int> FaceModel::findMesh(const std::string& name) const {
  for (size_t i = 0; i < meshes.size(); ++i) {
    if (meshes[i].name == name) return static_cast<int>(i);
  }
  return std::nullopt;
}

std::optional<int> FaceModel::findTransform(const std::string& name) const {
  for (size_t i = 0; i < transforms.size(); ++i) {
    if (transforms[i].name == name) return static_cast<int>(i);
  }
  return std::nullopt;
}

std::vector<Eigen::Affine3d> FaceModel::meshWorldMatrices() const {
  std::vector<Eigen::Affine3d> result(meshes.size(), Eigen::Affine3d::Identity());
  std::vector<bool> placed(meshes.size(), false);
  // Depth-first from the roots; a transform reached twice is not walked again, so a
  // malformed graph with a cycle cannot recurse forever (validate() reports it).
  std::vector<bool> visited(transforms.size(), false);
  std::function<void(int, const Eigen::Affine3d&)> walk = [&](int t, const Eigen::Affine3d& up) {
    if (t < 0 || t >= static_cast<int>(transforms.size()) || visited[t]) return;
    visited[t] = true;
    const Eigen::Affine3d m = up * transforms[t].localMatrix();
    for (int mesh : transforms[t].meshes) {
      if (mesh >= 0 && mesh < static_cast<int>(meshes.size()) && !placed[mesh]) {
        result[mesh] = m;
        placed[mesh] = true;
      }
    }
    for (int child : transforms[t].children) walk(child, m);
  };
  for (int root : roots) walk(root, Eigen::Affine3d::Identity());
  return result;
}

std::optional<Eigen::Vector3d> FaceModel::featurePointPosition(const std::string& id) const {
  auto it = featurePoints.find(id);
  if (it == featurePoints.end()) return std::nullopt;
  const FeaturePointBinding& fp = it->second;
  if (fp.mesh < 0) return fp.position;
  if (fp.mesh >= static_cast<int>(meshes.size()) || fp.vertex < 0 ||
      fp.vertex >= meshes[fp.mesh].vertexCount()) {
    return std::nullopt;
  }
  const Eigen::Vector3d local = meshes[fp.mesh].coord.row(fp.vertex).transpose();
  return meshWorldMatrices()[fp.mesh] * local;
}

int FaceModel::addMeshWithTransform(IndexedFaceSet mesh) {
  const int meshIndex = static_cast<int>(meshes.size());
  Transform t;
  t.name = mesh.name;
  t.meshes.push_back(meshIndex);
  meshes.push_back(std::move(mesh));
  roots.push_back(static_cast<int>(transforms.size()));
  transforms.push_back(std::move(t));
  return meshIndex;
}

FaceModel neutralFaceModel(const FaceModel& model) {
  // Field by field: a copy of the model would copy every morph target first (hundreds of
  // arrays the size of the mesh for a head with shape keys) only to drop them.
  FaceModel out;
  out.transforms = model.transforms;
  out.roots = model.roots;
  out.featurePoints = model.featurePoints;
  out.meshes.reserve(model.meshes.size());
  for (const IndexedFaceSet& mesh : model.meshes) {
    IndexedFaceSet& m = out.meshes.emplace_back();
    m.name = mesh.name;
    m.coord = mesh.coord;
    m.coordIndex = mesh.coordIndex;
    m.normal = mesh.normal;
    m.texCoord = mesh.texCoord;
    m.texCoordIndex = mesh.texCoordIndex;
    m.sourceIndex = mesh.sourceIndex;
  }
  return out;
}

void FaceModel::validate() const {
  const int meshCount = static_cast<int>(meshes.size());
  const int transformCount = static_cast<int>(transforms.size());
  for (const IndexedFaceSet& mesh : meshes) {
    const std::string where = "mesh '" + mesh.name + "'";
    for (int index : mesh.coordIndex) {
      if (index >= mesh.vertexCount()) {
        throw Error({}, 0, where + " coordIndex",
                    "vertex " + std::to_string(index) + " out of range (mesh has " +
                        std::to_string(mesh.vertexCount()) + " vertices)");
      }
    }
    if (mesh.normal.rows() != 0 && mesh.normal.rows() != mesh.coord.rows()) {
      throw Error({}, 0, where + " normal", "expected one normal per vertex");
    }
    if (!mesh.texCoordIndex.empty()) {
      if (mesh.texCoordIndex.size() != mesh.coordIndex.size()) {
        throw Error({}, 0, where + " texCoordIndex", "must have the layout of coordIndex");
      }
      for (int index : mesh.texCoordIndex) {
        if (index >= static_cast<int>(mesh.texCoord.rows())) {
          throw Error({}, 0, where + " texCoordIndex",
                      "texture coordinate " + std::to_string(index) + " out of range");
        }
      }
    } else if (mesh.texCoord.rows() != 0 && mesh.texCoord.rows() != mesh.coord.rows()) {
      throw Error({}, 0, where + " texCoord", "expected one per vertex (no texCoordIndex)");
    }
    for (const MorphTarget& target : mesh.morphTargets) {
      if (target.displacements.rows() != mesh.coord.rows()) {
        throw Error({}, 0, where + " morph target '" + target.name + "'",
                    "has " + std::to_string(target.displacements.rows()) + " displacements for " +
                        std::to_string(mesh.vertexCount()) + " vertices");
      }
    }
    if (!mesh.weights.empty() && mesh.weights.size() != mesh.morphTargets.size()) {
      throw Error({}, 0, where + " weights", "expected one weight per morph target");
    }
    if (!mesh.sourceIndex.empty() &&
        static_cast<Eigen::Index>(mesh.sourceIndex.size()) != mesh.coord.rows()) {
      throw Error({}, 0, where + " sourceIndex", "expected one entry per vertex");
    }
  }
  // Every transform has at most one parent and no transform is its own ancestor.
  std::vector<int> parent(transformCount, -1);
  for (int t = 0; t < transformCount; ++t) {
    const std::string where = "transform '" + transforms[t].name + "'";
    for (int mesh : transforms[t].meshes) {
      if (mesh < 0 || mesh >= meshCount) {
        throw Error({}, 0, where + " meshes", "mesh " + std::to_string(mesh) + " out of range");
      }
    }
    for (int child : transforms[t].children) {
      if (child < 0 || child >= transformCount) {
        throw Error({}, 0, where + " children",
                    "transform " + std::to_string(child) + " out of range");
      }
      if (parent[child] != -1 || child == t) {
        throw Error({}, 0, where + " children",
                    "transform '" + transforms[child].name + "' has more than one parent");
      }
      parent[child] = t;
    }
  }
  for (int root : roots) {
    if (root < 0 || root >= transformCount) {
      throw Error({}, 0, "roots", "transform " + std::to_string(root) + " out of range");
    }
    if (parent[root] != -1) {
      throw Error({}, 0, "roots", "transform '" + transforms[root].name + "' is also a child");
    }
  }
  for (int t = 0; t < transformCount; ++t) {
    int steps = 0;
    for (int p = parent[t]; p != -1; p = parent[p]) {
      if (++steps > transformCount) {
        throw Error({}, 0, "transform '" + transforms[t].name + "'", "is in a cycle");
      }
    }
  }
  for (const auto& [id, fp] : featurePoints) {
    if (fp.mesh >= meshCount) {
      throw Error({}, 0, "feature point " + id,
                  "mesh " + std::to_string(fp.mesh) + " out of range");
    }
    if (fp.mesh >= 0 && (fp.vertex < 0 || fp.vertex >= meshes[fp.mesh].vertexCount())) {
      throw Error({}, 0, "feature point " + id,
                  "vertex " + std::to_string(fp.vertex) + " out of range for mesh '" +
                      meshes[fp.mesh].name + "'");
    }
  }
}

std::vector<int> connectedPieces(const IndexedFaceSet& mesh) {
  std::vector<int> parent(static_cast<std::size_t>(mesh.vertexCount()));
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int v) {
    while (parent[static_cast<std::size_t>(v)] != v) {
      v = parent[static_cast<std::size_t>(v)] =
          parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(v)])];
    }
    return v;
  };
  const std::vector<int> triangles = mesh.triangles();
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
    for (std::size_t k = 1; k < 3; ++k) {
      parent[static_cast<std::size_t>(root(triangles[t + k]))] = root(triangles[t]);
    }
  }
  for (int v = 0; v < mesh.vertexCount(); ++v) parent[static_cast<std::size_t>(v)] = root(v);
  return parent;
}

}  // namespace mpeg4face
