// SPDX-License-Identifier: GPL-3.0-or-later
// FaceModel -> glTF 2.0 through tinygltf (Debian's shared libtinygltf; the implementation is
// in the .so, so TINYGLTF_IMPLEMENTATION must not be defined here).
#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <system_error>
#include <utility>
#include <vector>

#include "io/gltf_internal.hpp"
#include "io/gltf_names.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/gltf.hpp"

namespace mpeg4face {

using gltf_names::kExtrasKey;
using gltf_names::kVertexAttribute;

namespace {

class Writer {
 public:
  Writer(const FaceModel& model, const std::string& fileName, const tinygltf::Value::Object& extras)
      : model_(model), fileName_(fileName), extras_(extras) {
    gltf_.asset.version = "2.0";
    gltf_.asset.generator = "mpeg4face";
  }

  tinygltf::Model build() {
    for (size_t m = 0; m < model_.meshes.size(); ++m) writeMesh(m);
    writeNodes();
    writeAnimations();
    writeScene();
    if (!blob_.empty()) {
      tinygltf::Buffer buffer;
      buffer.data = std::move(blob_);
      gltf_.buffers.push_back(std::move(buffer));
    }
    return std::move(gltf_);
  }

 private:
  [[noreturn]] void fail(const std::string& field, const std::string& message) const {
    throw Error(fileName_, 0, field, message);
  }

  template <typename Derived>
  void checkFinite(const Eigen::DenseBase<Derived>& values, const std::string& field) const {
    if (!values.derived().allFinite()) fail(field, "has a non-finite value (NaN or infinity)");
  }

  int addView(const void* data, size_t bytes, int target) {
    blob_.resize((blob_.size() + 3) / 4 * 4, 0);  // 4-byte alignment for every accessor
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = blob_.size();
    view.byteLength = bytes;
    view.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    blob_.insert(blob_.end(), p, p + bytes);
    gltf_.bufferViews.push_back(std::move(view));
    return static_cast<int>(gltf_.bufferViews.size() - 1);
  }

  // Floats, `components` per element; with min/max when asked (POSITION, animation input).
  int addFloats(const std::vector<float>& values, int type, int target, bool bounds) {
    const auto components = static_cast<size_t>(tinygltf::GetNumComponentsInType(type));
    tinygltf::Accessor a;
    a.bufferView = addView(values.data(), values.size() * sizeof(float), target);
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.type = type;
    a.count = values.size() / components;
    if (bounds) {
      a.minValues.assign(components, std::numeric_limits<double>::infinity());
      a.maxValues.assign(components, -std::numeric_limits<double>::infinity());
      for (size_t i = 0; i < values.size(); ++i) {
        a.minValues[i % components] = std::min<double>(a.minValues[i % components], values[i]);
        a.maxValues[i % components] = std::max<double>(a.maxValues[i % components], values[i]);
      }
    }
    gltf_.accessors.push_back(std::move(a));
    return static_cast<int>(gltf_.accessors.size() - 1);
  }

  int addUnsigned(const std::vector<uint32_t>& values, bool small, int target) {
    tinygltf::Accessor a;
    if (small) {
      const std::vector<uint16_t> narrow(values.begin(), values.end());
      a.bufferView = addView(narrow.data(), narrow.size() * sizeof(uint16_t), target);
      a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    } else {
      a.bufferView = addView(values.data(), values.size() * sizeof(uint32_t), target);
      a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    }
    a.type = TINYGLTF_TYPE_SCALAR;
    a.count = values.size();
    gltf_.accessors.push_back(std::move(a));
    return static_cast<int>(gltf_.accessors.size() - 1);
  }

  void writeMesh(size_t meshIndex) {
    const IndexedFaceSet& mesh = model_.meshes[meshIndex];
    const std::string where = "mesh '" + mesh.name + "'";
    const int n = mesh.vertexCount();
    if (n == 0) fail(where, "has no vertices; glTF cannot store an empty mesh");
    checkFinite(mesh.coord, where + " coord");
    checkFinite(mesh.normal, where + " normal");
    checkFinite(mesh.texCoord, where + " texCoord");
    for (const MorphTarget& t : mesh.morphTargets) {
      checkFinite(t.displacements, where + " morph target '" + t.name + "'");
    }
    for (double w : mesh.weights) {
      if (!std::isfinite(w)) fail(where + " weights", "has a non-finite value");
    }

    // Corners (positions in coordIndex) of the fan-triangulated polygons.
    std::vector<int> corners;
    for (auto [begin, end] : mesh.faceRanges()) {
      for (int k = begin + 1; k + 1 < end; ++k) corners.insert(corners.end(), {begin, k, k + 1});
    }

    // glTF has one index per vertex, so a vertex with several UVs (a seam) becomes one glTF
    // vertex per (vertex, UV) pair, ordered by vertex; _MPEG4FACE_VERTEX records the origin.
    const bool split = !mesh.texCoordIndex.empty() && mesh.texCoord.rows() > 0;
    const bool perVertexUv = mesh.texCoordIndex.empty() && mesh.texCoord.rows() == n;
    std::vector<int> source;  // IndexedFaceSet vertex of each glTF vertex
    std::vector<int> uvOf;    // texCoord row of each glTF vertex, -1 for none
    std::vector<uint32_t> indices;
    if (split) {
      std::vector<std::vector<int>> uvsOfVertex(n);
      auto uvAt = [&](int corner) { return mesh.texCoordIndex[corner]; };
      for (int corner : corners) {
        std::vector<int>& uvs = uvsOfVertex[mesh.coordIndex[corner]];
        if (std::find(uvs.begin(), uvs.end(), uvAt(corner)) == uvs.end())
          uvs.push_back(uvAt(corner));
      }
      std::vector<int> firstGltf(n);
      for (int v = 0; v < n; ++v) {
        firstGltf[v] = static_cast<int>(source.size());
        if (uvsOfVertex[v].empty()) uvsOfVertex[v].push_back(-1);  // kept for its number
        for (int t : uvsOfVertex[v]) {
          source.push_back(v);
          uvOf.push_back(t);
        }
      }
      for (int corner : corners) {
        const int v = mesh.coordIndex[corner];
        const std::vector<int>& uvs = uvsOfVertex[v];
        const auto slot = std::find(uvs.begin(), uvs.end(), uvAt(corner)) - uvs.begin();
        indices.push_back(static_cast<uint32_t>(firstGltf[v] + slot));
      }
    } else {
      for (int v = 0; v < n; ++v) {
        source.push_back(v);
        uvOf.push_back(perVertexUv ? v : -1);
      }
      for (int corner : corners) indices.push_back(static_cast<uint32_t>(mesh.coordIndex[corner]));
    }
    const size_t count = source.size();

    tinygltf::Primitive prim;
    std::vector<float> values;
    values.reserve(3 * count);
    for (int v : source) {
      for (int c = 0; c < 3; ++c) values.push_back(static_cast<float>(mesh.coord(v, c)));
    }
    prim.attributes["POSITION"] =
        addFloats(values, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
    if (mesh.normal.rows() == n) {
      values.clear();
      for (int v : source) {
        Eigen::Vector3d normal = mesh.normal.row(v).transpose();
        // glTF requires unit normals; a zero normal (unknown) gets an arbitrary unit one.
        normal = normal.norm() > 1e-12 ? normal.normalized() : Eigen::Vector3d::UnitZ();
        for (int c = 0; c < 3; ++c) values.push_back(static_cast<float>(normal[c]));
      }
      prim.attributes["NORMAL"] =
          addFloats(values, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER, false);
    }
    if (split || perVertexUv) {
      values.clear();
      for (int t : uvOf) {
        const double u = t >= 0 ? mesh.texCoord(t, 0) : 0.0;
        const double v = t >= 0 ? mesh.texCoord(t, 1) : 0.0;
        values.push_back(static_cast<float>(u));
        values.push_back(static_cast<float>(1.0 - v));  // glTF's UV origin is the top left
      }
      prim.attributes["TEXCOORD_0"] =
          addFloats(values, TINYGLTF_TYPE_VEC2, TINYGLTF_TARGET_ARRAY_BUFFER, false);
    }
    if (split) {
      // FLOAT: glTF forbids UNSIGNED_INT vertex attributes, and a 2-byte UNSIGNED_SHORT
      // would need a 4-byte stride anyway. Floats hold integers exactly up to 2^24.
      if (n > (1 << 24)) {
        fail(where,
             "has more than 2^24 vertices, too many to number in " + std::string(kVertexAttribute));
      }
      const std::vector<float> ids(source.begin(), source.end());
      prim.attributes[kVertexAttribute] =
          addFloats(ids, TINYGLTF_TYPE_SCALAR, TINYGLTF_TARGET_ARRAY_BUFFER, false);
    }
    if (indices.empty()) {
      prim.mode = TINYGLTF_MODE_POINTS;  // no faces: keep the vertices anyway
    } else {
      prim.mode = TINYGLTF_MODE_TRIANGLES;
      prim.indices = addUnsigned(indices, count <= 65535, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    }
    for (const MorphTarget& target : mesh.morphTargets) {
      values.clear();
      for (int v : source) {
        for (int c = 0; c < 3; ++c)
          values.push_back(static_cast<float>(target.displacements(v, c)));
      }
      prim.targets.push_back({{"POSITION", addFloats(values, TINYGLTF_TYPE_VEC3,
                                                     TINYGLTF_TARGET_ARRAY_BUFFER, true)}});
    }

    tinygltf::Mesh out;
    out.name = mesh.name;
    out.primitives.push_back(std::move(prim));
    out.weights = mesh.weights;
    if (!mesh.morphTargets.empty()) {
      tinygltf::Value::Array names;
      for (const MorphTarget& target : mesh.morphTargets) names.emplace_back(target.name);
      out.extras = tinygltf::Value(
          tinygltf::Value::Object{{"targetNames", tinygltf::Value(std::move(names))}});
    }
    gltf_.meshes.push_back(std::move(out));
  }

  void writeNodes() {
    // Node i is Transform i; helper nodes (centre, further meshes) follow.
    meshNodes_.assign(model_.meshes.size(), {});
    for (size_t t = 0; t < model_.transforms.size(); ++t) {
      const Transform& transform = model_.transforms[t];
      const std::string where = "transform '" + transform.name + "'";
      checkFinite(transform.translation, where + " translation");
      checkFinite(transform.scale, where + " scale");
      checkFinite(transform.center, where + " center");
      checkFinite(transform.rotation.coeffs(), where + " rotation");
      if (!(transform.rotation.norm() > 1e-12)) fail(where + " rotation", "the quaternion is zero");
      const Eigen::Quaterniond r = transform.rotation.normalized();
      // glTF has no centre: T * C * R * S * -C is this node (T + C, R, S) over a centre node
      // (-C), so that rotating or scaling this node, by an animation or in a modeller, stays
      // about the centre.
      const Eigen::Vector3d translation = transform.translation + transform.center;
      tinygltf::Node node;
      node.name = transform.name;
      if (translation != Eigen::Vector3d::Zero())
        node.translation = {translation.x(), translation.y(), translation.z()};
      if (r.coeffs() != Eigen::Quaterniond::Identity().coeffs()) {
        node.rotation = {r.x(), r.y(), r.z(), r.w()};
      }
      if (transform.scale != Eigen::Vector3d::Ones()) {
        node.scale = {transform.scale.x(), transform.scale.y(), transform.scale.z()};
      }
      gltf_.nodes.push_back(std::move(node));
    }
    for (size_t t = 0; t < model_.transforms.size(); ++t) {
      const Transform& transform = model_.transforms[t];
      int holder = static_cast<int>(t);  // the node that holds the Transform's content
      if (transform.center != Eigen::Vector3d::Zero()) {
        tinygltf::Node centre;
        centre.name = transform.name + ".center";
        centre.translation = {-transform.center.x(), -transform.center.y(), -transform.center.z()};
        centre.extras = helperExtras("center");
        holder = static_cast<int>(gltf_.nodes.size());
        gltf_.nodes[t].children = {holder};
        gltf_.nodes.push_back(std::move(centre));
      }
      std::vector<int> children;
      if (transform.meshes.size() == 1) {
        gltf_.nodes[holder].mesh = transform.meshes[0];
        meshNodes_[transform.meshes[0]].push_back(holder);
      } else {
        for (int mesh : transform.meshes) {
          tinygltf::Node helper;
          helper.name = model_.meshes[mesh].name;
          helper.mesh = mesh;
          helper.extras = helperExtras("meshInstance");
          children.push_back(static_cast<int>(gltf_.nodes.size()));
          meshNodes_[mesh].push_back(children.back());
          gltf_.nodes.push_back(std::move(helper));
        }
      }
      children.insert(children.end(), transform.children.begin(), transform.children.end());
      gltf_.nodes[holder].children = std::move(children);
    }
  }

  // {"mpeg4face": {<key>: true}}: marks a node the reader folds back into its Transform.
  static tinygltf::Value helperExtras(const char* key) {
    return tinygltf::Value(tinygltf::Value::Object{
        {kExtrasKey, tinygltf::Value(tinygltf::Value::Object{{key, tinygltf::Value(true)}})}});
  }

  // Key times as 32-bit floats, checked to be finite and strictly increasing.
  std::vector<float> keyTimes(const std::vector<double>& seconds, const std::string& where) const {
    if (seconds.empty()) fail(where + " times", "no key times");
    std::vector<float> times(seconds.begin(), seconds.end());
    for (size_t i = 0; i < times.size(); ++i) {
      if (!std::isfinite(times[i]) || (i > 0 && !(times[i] > times[i - 1]))) {
        fail(where + " times",
             "key times must be finite and strictly increasing (as "
             "32-bit floats); key " +
                 std::to_string(i) + " is not");
      }
    }
    return times;
  }

  // Adds a sampler to `out`; returns its index.
  int addSampler(tinygltf::Animation& out, const std::vector<float>& times,
                 const std::vector<float>& values, int type,
                 MorphWeightChannel::Interpolation interpolation) {
    tinygltf::AnimationSampler sampler;
    sampler.input = addFloats(times, TINYGLTF_TYPE_SCALAR, 0, true);
    sampler.output = addFloats(values, type, 0, false);
    switch (interpolation) {
      case MorphWeightChannel::Interpolation::Linear:
        sampler.interpolation = "LINEAR";
        break;
      case MorphWeightChannel::Interpolation::Step:
        sampler.interpolation = "STEP";
        break;
      case MorphWeightChannel::Interpolation::CubicSpline:
        sampler.interpolation = "CUBICSPLINE";
        break;
    }
    out.samplers.push_back(std::move(sampler));
    return static_cast<int>(out.samplers.size() - 1);
  }

  void writeAnimations() {
    for (const MorphWeightAnimation& animation : model_.animations) {
      tinygltf::Animation out;
      out.name = animation.name;
      for (size_t c = 0; c < animation.channels.size(); ++c) {
        const MorphWeightChannel& channel = animation.channels[c];
        const std::string where = "animation '" + animation.name + "' channel " + std::to_string(c);
        if (channel.mesh < 0 || static_cast<size_t>(channel.mesh) >= model_.meshes.size()) {
          fail(where, "mesh " + std::to_string(channel.mesh) + " does not exist");
        }
        const IndexedFaceSet& mesh = model_.meshes[channel.mesh];
        const size_t targets = mesh.morphTargets.size();
        if (targets == 0) fail(where, "mesh '" + mesh.name + "' has no morph targets");
        if (meshNodes_[channel.mesh].empty()) {
          fail(where, "mesh '" + mesh.name +
                          "' is not held by any transform; glTF animates the weights of nodes");
        }
        const std::vector<float> times = keyTimes(channel.times, where);
        const bool cubic = channel.interpolation == MorphWeightChannel::Interpolation::CubicSpline;
        const size_t expected = times.size() * targets * (cubic ? 3 : 1);
        if (channel.weights.size() != expected) {
          fail(where + " weights", "has " + std::to_string(channel.weights.size()) +
                                       " values, expected " + std::to_string(expected));
        }
        std::vector<float> weights(channel.weights.begin(), channel.weights.end());
        for (float w : weights) {
          if (!std::isfinite(w)) fail(where + " weights", "has a non-finite value");
        }
        const int sampler =
            addSampler(out, times, weights, TINYGLTF_TYPE_SCALAR, channel.interpolation);
        // Every instance of the mesh follows the same sampler.
        for (int node : meshNodes_[channel.mesh]) {
          tinygltf::AnimationChannel target;
          target.sampler = sampler;
          target.target_node = node;
          target.target_path = "weights";
          out.channels.push_back(std::move(target));
        }
      }
      for (size_t c = 0; c < animation.transformChannels.size(); ++c) {
        writeTransformChannel(
            animation.transformChannels[c],
            "animation '" + animation.name + "' transform channel " + std::to_string(c), out);
      }
      // tinygltf would write an animation without channels, which glTF forbids.
      if (!out.channels.empty()) gltf_.animations.push_back(std::move(out));
    }
  }

  void writeTransformChannel(const TransformChannel& channel, const std::string& where,
                             tinygltf::Animation& out) {
    if (channel.transform < 0 ||
        static_cast<size_t>(channel.transform) >= model_.transforms.size()) {
      fail(where, "transform " + std::to_string(channel.transform) + " does not exist");
    }
    const Transform& transform = model_.transforms[channel.transform];
    const std::vector<float> times = keyTimes(channel.times, where);
    const bool cubic = channel.interpolation == MorphWeightChannel::Interpolation::CubicSpline;
    const bool rotation = channel.path == TransformChannel::Path::Rotation;
    const size_t components = rotation ? 4 : 3;
    const size_t perKey = cubic ? 3 : 1;  // in-tangent, value, out-tangent
    if (channel.values.size() != times.size() * components * perKey) {
      fail(where + " values", "has " + std::to_string(channel.values.size()) +
                                  " values, expected " +
                                  std::to_string(times.size() * components * perKey));
    }
    for (double v : channel.values) {
      if (!std::isfinite(v)) fail(where + " values", "has a non-finite value");
    }
    std::vector<double> values = channel.values;
    for (size_t key = 0; key < times.size(); ++key) {
      double* value = values.data() + (key * perKey + (cubic ? 1 : 0)) * components;
      if (channel.path == TransformChannel::Path::Translation) {
        // The node's translation is T + C (see writeNodes); tangents need no offset.
        for (int i = 0; i < 3; ++i) value[i] += transform.center[i];
      } else if (rotation) {
        Eigen::Map<Eigen::Vector4d> q(value);
        if (!(q.norm() > 1e-12)) {
          fail(where + " values", "key " + std::to_string(key) + " has a zero quaternion");
        }
        q.normalize();  // glTF requires unit quaternions
      }
    }
    std::vector<float> floats(values.begin(), values.end());
    for (float v : floats) {
      if (!std::isfinite(v)) fail(where + " values", "has a value too large for a 32-bit float");
    }
    tinygltf::AnimationChannel target;
    target.sampler =
        addSampler(out, times, floats, rotation ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3,
                   channel.interpolation);
    target.target_node = channel.transform;
    target.target_path = channel.path == TransformChannel::Path::Translation ? "translation"
                         : rotation                                          ? "rotation"
                                                                             : "scale";
    out.channels.push_back(std::move(target));
  }

  void writeScene() {
    tinygltf::Scene scene;
    scene.nodes = model_.roots;
    tinygltf::Value::Object ours = extras_;
    if (!model_.featurePoints.empty()) {
      tinygltf::Value::Object points;
      for (const auto& [id, fp] : model_.featurePoints) {
        tinygltf::Value::Object entry;
        if (fp.mesh < 0) {
          checkFinite(fp.position, "feature point " + id);
          entry["position"] = tinygltf::Value(tinygltf::Value::Array{
              tinygltf::Value(fp.position.x()), tinygltf::Value(fp.position.y()),
              tinygltf::Value(fp.position.z())});
        } else {
          const std::string& name = model_.meshes[fp.mesh].name;
          entry["mesh"] = tinygltf::Value(name);
          entry["vertex"] = tinygltf::Value(fp.vertex);
          // An empty name (read back as "mesh<N>") or one shared by several meshes does not
          // say which mesh.
          if (name.empty() || model_.findMesh(name) != fp.mesh) {
            entry["meshIndex"] = tinygltf::Value(fp.mesh);
          }
        }
        points[id] = tinygltf::Value(std::move(entry));
      }
      ours["featurePoints"] = tinygltf::Value(std::move(points));
    }
    if (!ours.empty()) {
      scene.extras =
          tinygltf::Value(tinygltf::Value::Object{{kExtrasKey, tinygltf::Value(std::move(ours))}});
    }
    gltf_.scenes.push_back(std::move(scene));
    gltf_.defaultScene = 0;
  }

  const FaceModel& model_;
  const std::string& fileName_;
  const tinygltf::Value::Object& extras_;  // more of scenes[0].extras.mpeg4face
  tinygltf::Model gltf_;
  std::vector<unsigned char> blob_;
  std::vector<std::vector<int>> meshNodes_;  // nodes instancing each mesh
};

}  // namespace

void gltf_internal::writeGltf(const FaceModel& model, const std::filesystem::path& path,
                              const tinygltf::Value::Object& extras) {
  const std::string fileName = path.string();
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != ".gltf" && ext != ".glb") {
    throw Error(fileName, 0, {}, "unknown glTF extension '" + ext + "' (expected .gltf or .glb)");
  }
  const bool binary = ext == ".glb";
  try {
    model.validate();
  } catch (const Error& e) {
    throw Error(fileName, 0, e.field(), e.reason());
  }
  const tinygltf::Model gltf = Writer(model, fileName, extras).build();
  std::ostringstream out;
  try {
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&gltf, out, /*prettyPrint=*/!binary, binary)) {
      throw Error(fileName, 0, {}, "tinygltf could not serialize the model");
    }
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {  // e.g. a name that is not valid UTF-8
    throw Error(fileName, 0, {}, std::string("cannot serialize the model: ") + e.what());
  }
  writeFileAtomically(path, out.str());
}

void writeGltf(const FaceModel& model, const std::filesystem::path& path) {
  gltf_internal::writeGltf(model, path, {});
}

}  // namespace mpeg4face
