// SPDX-License-Identifier: GPL-3.0-or-later
// glTF reader: the asset, the node tree (Transforms, with the helper nodes writeGltf adds),
// the scene's roots and its extras with the feature points; Reader::read runs every step.
#include <algorithm>
#include <cmath>

#include "io/gltf_names.hpp"
#include "io/gltf_reader.hpp"

namespace mpeg4face::gltf_reader {

using gltf_names::kExtrasKey;

gltf_internal::ReadResult Reader::read() {
  checkAssetAndExtensions();
  for (size_t i = 0; i < gltf_.meshes.size(); ++i) model_.meshes.push_back(readMesh(i));
  readNodes();
  readRoots();
  readAnimations();
  gltf_internal::ReadResult result;
  readFeaturePoints(result);
  try {
    model_.validate();
  } catch (const Error& e) {
    throw Error(fileName_, 0, e.field(), e.reason());
  }
  result.model = std::move(model_);
  result.transformOfNode = std::move(transformOf_);
  return result;
}

void Reader::checkAssetAndExtensions() const {
  const std::string& version = gltf_.asset.version;
  if (!version.starts_with("2.")) {
    fail("asset.version", "glTF " + version + " is not supported (only 2.x)");
  }
  for (size_t i = 0; i < gltf_.extensionsRequired.size(); ++i) {
    const std::string& ext = gltf_.extensionsRequired[i];
    // Appearance-only extensions do not change the geometry we read.
    const bool harmless = ext.starts_with("KHR_materials_") || ext.starts_with("KHR_texture_") ||
                          ext.starts_with("EXT_texture_") || ext == "KHR_lights_punctual" ||
                          ext == "KHR_mesh_quantization";
    if (!harmless) {
      fail("extensionsRequired[" + str(i) + "]",
           "the file requires extension " + ext + ", which mpeg4face does not support");
    }
  }
}

// Whether `node` carries {"mpeg4face": {<key>: true}} in its extras.
bool Reader::markedAs(const tinygltf::Node& node, const char* key) {
  const tinygltf::Value& extras = node.extras;
  if (!extras.IsObject() || !extras.Has(kExtrasKey)) return false;
  const tinygltf::Value& ours = extras.Get(kExtrasKey);
  return ours.IsObject() && ours.Has(key) && ours.Get(key).IsBool() && ours.Get(key).Get<bool>();
}

// A node that writeGltf added only to instance one more mesh of a Transform.
bool Reader::isMeshInstance(const tinygltf::Node& node) {
  return markedAs(node, "meshInstance") && node.mesh >= 0 && node.children.empty() &&
         node.matrix.empty() && node.translation.empty() && node.rotation.empty() &&
         node.scale.empty();
}

// A node that writeGltf added to carry -center of its parent's Transform: the parent's only
// child, translated only, holding the Transform's meshes and children.
bool Reader::isCenter(size_t index) const {
  const tinygltf::Node& node = gltf_.nodes[index];
  if (!markedAs(node, "center") || parent_[index] < 0 || !node.matrix.empty() ||
      !node.rotation.empty() || !node.scale.empty() || node.translation.size() != 3) {
    return false;
  }
  const tinygltf::Node& parent = gltf_.nodes[parent_[index]];
  return parent.mesh < 0 && parent.children.size() == 1 && !markedAs(parent, "center");
}

void Reader::readNodes() {
  const size_t count = gltf_.nodes.size();
  parent_.assign(count, -1);
  for (size_t i = 0; i < count; ++i) {
    const tinygltf::Node& node = gltf_.nodes[i];
    const std::string np = "nodes[" + str(i) + "]";
    if (node.mesh >= 0 && static_cast<size_t>(node.mesh) >= gltf_.meshes.size()) {
      fail(np + ".mesh", "mesh " + std::to_string(node.mesh) + " does not exist");
    }
    if (node.mesh < -1) fail(np + ".mesh", "negative mesh index");
    for (int child : node.children) {
      if (child < 0 || static_cast<size_t>(child) >= count) {
        fail(np + ".children", "node " + std::to_string(child) + " does not exist");
      }
      if (parent_[child] != -1 || static_cast<size_t>(child) == i) {
        fail(np + ".children",
             "node " + std::to_string(child) + " has more than one parent (glTF nodes form trees)");
      }
      parent_[child] = static_cast<int>(i);
    }
  }
  // Nodes reachable from the parentless ones form trees; any other node is in a cycle.
  std::vector<bool> reached(count, false);
  std::vector<size_t> stack;
  for (size_t i = 0; i < count; ++i) {
    if (parent_[i] < 0) stack.push_back(i);
  }
  while (!stack.empty()) {
    const size_t i = stack.back();
    stack.pop_back();
    reached[i] = true;
    for (int child : gltf_.nodes[i].children) stack.push_back(static_cast<size_t>(child));
  }
  for (size_t i = 0; i < count; ++i) {
    if (!reached[i]) {
      fail("nodes[" + std::to_string(parent_[i]) + "].children",
           "node " + str(i) + " is its own ancestor (the nodes form a cycle)");
    }
  }
  transformOf_.assign(count, -1);
  std::vector<bool> helper(count, false);
  std::vector<int> center(count, -1);  // the centre node under each node, -1 for none
  for (size_t i = 0; i < count; ++i) {
    if (isCenter(i)) {
      helper[i] = true;
      center[parent_[i]] = static_cast<int>(i);
    } else {
      helper[i] = parent_[i] >= 0 && isMeshInstance(gltf_.nodes[i]);
    }
  }
  for (size_t i = 0; i < count; ++i) {
    if (helper[i]) continue;
    transformOf_[i] = static_cast<int>(model_.transforms.size());
    model_.transforms.push_back(readTransform(i));
    if (center[i] >= 0) {
      // The node is T + C, R, S over a node -C: the VRML Transform T, R, S about C.
      const std::vector<double>& minus = gltf_.nodes[center[i]].translation;
      for (double x : minus) {
        if (!std::isfinite(x)) {
          fail("nodes[" + str(center[i]) + "].translation", "has a non-finite value");
        }
      }
      Transform& t = model_.transforms.back();
      t.center = -Eigen::Vector3d(minus[0], minus[1], minus[2]);
      t.translation -= t.center;
    }
  }
  for (size_t i = 0; i < count; ++i) {
    if (helper[i]) continue;
    Transform& t = model_.transforms[transformOf_[i]];
    // The Transform's meshes and children hang under its centre node, if it has one.
    const tinygltf::Node& node = gltf_.nodes[center[i] >= 0 ? center[i] : i];
    if (node.mesh >= 0) t.meshes.push_back(node.mesh);
    for (int child : node.children) {
      if (helper[child]) {
        t.meshes.push_back(gltf_.nodes[child].mesh);
      } else {
        t.children.push_back(transformOf_[child]);
      }
    }
  }
}

Transform Reader::readTransform(size_t index) const {
  const tinygltf::Node& node = gltf_.nodes[index];
  const std::string np = "nodes[" + str(index) + "]";
  Transform t;
  t.name = node.name.empty() ? "node" + str(index) : node.name;
  const std::string who = "node '" + t.name + "'";
  auto finite = [&](const std::vector<double>& values, const std::string& field) {
    for (double x : values) {
      if (!std::isfinite(x)) fail(field, who + " has a non-finite value");
    }
  };
  if (!node.matrix.empty()) {
    if (node.matrix.size() != 16) fail(np + ".matrix", who + ": a matrix has 16 numbers");
    finite(node.matrix, np + ".matrix");
    decompose(node.matrix, np + ".matrix", who, t);
    return t;
  }
  if (!node.translation.empty()) {
    if (node.translation.size() != 3) fail(np + ".translation", who + ": expected 3 numbers");
    finite(node.translation, np + ".translation");
    t.translation = Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]);
  }
  if (!node.scale.empty()) {
    if (node.scale.size() != 3) fail(np + ".scale", who + ": expected 3 numbers");
    finite(node.scale, np + ".scale");
    t.scale = Eigen::Vector3d(node.scale[0], node.scale[1], node.scale[2]);
  }
  if (!node.rotation.empty()) {
    if (node.rotation.size() != 4)
      fail(np + ".rotation", who + ": expected a quaternion (4 numbers)");
    finite(node.rotation, np + ".rotation");
    // glTF stores x y z w; Eigen's constructor takes w x y z.
    Eigen::Quaterniond q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
    if (!(q.norm() > 1e-12)) fail(np + ".rotation", who + ": the quaternion is zero");
    t.rotation = q.normalized();
  }
  return t;
}

// glTF matrices must be decomposable into T * R * S; shear or projection cannot be a
// Transform, so they are errors rather than silently approximated.
void Reader::decompose(const std::vector<double>& m, const std::string& field,
                       const std::string& who, Transform& t) const {
  const Eigen::Map<const Eigen::Matrix4d> matrix(m.data());  // column-major, like glTF
  const double scaleOfMatrix = std::max(1.0, matrix.cwiseAbs().maxCoeff());
  if ((matrix.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() >
      1e-6 * scaleOfMatrix) {
    fail(field, who + " has a projective matrix (last row is not 0 0 0 1)");
  }
  Eigen::Matrix3d a = matrix.topLeftCorner<3, 3>();
  Eigen::Vector3d s(a.col(0).norm(), a.col(1).norm(), a.col(2).norm());
  if (!(s.minCoeff() > 1e-12 * scaleOfMatrix)) {
    fail(field, who + " has a singular matrix (a zero scale); it cannot be decomposed");
  }
  if (a.determinant() < 0) s.x() = -s.x();  // a mirror: one negative scale
  const Eigen::Matrix3d r = a * s.cwiseInverse().asDiagonal();
  const double shear = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (shear > 1e-5) {
    fail(field, who +
                    " has a matrix with shear, which a translation, rotation and scale "
                    "cannot express (deviation " +
                    std::to_string(shear) + ")");
  }
  t.translation = matrix.topRightCorner<3, 1>();
  t.rotation = Eigen::Quaterniond(r).normalized();
  t.scale = s;
}

int Reader::sceneIndex() const {
  if (gltf_.scenes.empty()) {
    if (gltf_.defaultScene >= 0)
      fail("scene",
           "refers to scene " + std::to_string(gltf_.defaultScene) + ", but there are no scenes");
    return -1;
  }
  const int s = gltf_.defaultScene >= 0 ? gltf_.defaultScene : 0;
  if (static_cast<size_t>(s) >= gltf_.scenes.size()) {
    fail("scene", "scene " + std::to_string(s) + " does not exist");
  }
  return s;
}

void Reader::readRoots() {
  const int s = sceneIndex();
  if (s < 0) {
    for (size_t i = 0; i < gltf_.nodes.size(); ++i) {
      if (parent_[i] < 0) model_.roots.push_back(transformOf_[i]);
    }
    return;
  }
  const std::string field = "scenes[" + std::to_string(s) + "].nodes";
  std::vector<bool> seen(gltf_.nodes.size(), false);
  for (int node : gltf_.scenes[s].nodes) {
    if (node < 0 || static_cast<size_t>(node) >= gltf_.nodes.size()) {
      fail(field, "node " + std::to_string(node) + " does not exist");
    }
    if (parent_[node] >= 0) {
      fail(field, "node " + std::to_string(node) + " is a child of node " +
                      std::to_string(parent_[node]) + ", not a root");
    }
    if (seen[node]) fail(field, "node " + std::to_string(node) + " is listed twice");
    seen[node] = true;
    model_.roots.push_back(transformOf_[node]);
  }
}

// The feature points from the scene's extras.mpeg4face, which `result` gets as a whole.
void Reader::readFeaturePoints(gltf_internal::ReadResult& result) {
  const int s = sceneIndex();
  if (s < 0) return;
  const tinygltf::Value& extras = gltf_.scenes[s].extras;
  if (!extras.IsObject() || !extras.Has(kExtrasKey)) return;
  const std::string base = "scenes[" + std::to_string(s) + "].extras." + kExtrasKey;
  const tinygltf::Value& ours = extras.Get(kExtrasKey);
  if (!ours.IsObject()) fail(base, "must be an object");
  result.extras = ours;
  result.extrasField = base;
  if (!ours.Has("featurePoints")) return;
  const tinygltf::Value& points = ours.Get("featurePoints");
  if (!points.IsObject()) fail(base + ".featurePoints", "must be an object");
  for (const std::string& id : points.Keys()) {
    const std::string field = base + ".featurePoints." + id;
    const tinygltf::Value& entry = points.Get(id);
    if (!entry.IsObject()) fail(field, "must be an object");
    FeaturePointBinding binding;
    if (entry.Has("position")) {
      const tinygltf::Value& p = entry.Get("position");
      if (!p.IsArray() || p.ArrayLen() != 3 || !p.Get(0).IsNumber() || !p.Get(1).IsNumber() ||
          !p.Get(2).IsNumber()) {
        fail(field + ".position", "expected [x, y, z]");
      }
      binding.position = Eigen::Vector3d(p.Get(0).GetNumberAsDouble(), p.Get(1).GetNumberAsDouble(),
                                         p.Get(2).GetNumberAsDouble());
      if (!binding.position.allFinite()) fail(field + ".position", "non-finite coordinate");
    } else {
      if (entry.Has("meshIndex")) {
        // Written when mesh names are not unique.
        const tinygltf::Value& index = entry.Get("meshIndex");
        if (!index.IsInt() || index.Get<int>() < 0 ||
            static_cast<size_t>(index.Get<int>()) >= model_.meshes.size()) {
          fail(field + ".meshIndex", "not a mesh index");
        }
        binding.mesh = index.Get<int>();
      } else {
        if (!entry.Has("mesh") || !entry.Get("mesh").IsString()) {
          fail(field, "expected {\"mesh\": name, \"vertex\": n} or {\"position\": [x, y, z]}");
        }
        const std::string& name = entry.Get("mesh").Get<std::string>();
        const std::optional<int> mesh = model_.findMesh(name);
        if (!mesh) fail(field + ".mesh", "no mesh is named '" + name + "'");
        binding.mesh = *mesh;
      }
      if (!entry.Has("vertex") || !entry.Get("vertex").IsInt()) {
        fail(field + ".vertex", "expected a vertex number");
      }
      binding.vertex = entry.Get("vertex").Get<int>();
      if (binding.vertex < 0 || binding.vertex >= model_.meshes[binding.mesh].vertexCount()) {
        fail(field + ".vertex", "vertex " + std::to_string(binding.vertex) +
                                    " is out of range for mesh '" +
                                    model_.meshes[binding.mesh].name + "'");
      }
    }
    model_.featurePoints[id] = binding;
  }
}

}  // namespace mpeg4face::gltf_reader
