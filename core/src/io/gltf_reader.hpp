// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: the pieces of the glTF reader (gltf_read*.cpp), which turns the tinygltf::Model
// of io/gltf_read.cpp into a FaceModel, checking every accessor against its buffer. Not
// installed; tinygltf is a private dependency of the core.
#pragma once

#include <tiny_gltf.h>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "io/gltf_internal.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face::gltf_reader {

// Accessors without a buffer view are all zeros (plus sparse values); their count is not
// backed by any data, so it is capped to keep a tiny file from allocating gigabytes.
constexpr uint64_t kMaxSyntheticValues = uint64_t{1} << 22;

inline std::string str(uint64_t n) { return std::to_string(n); }

// Which encodings an accessor may use; anything else is an Error.
struct AccessorSpec {
  int type = TINYGLTF_TYPE_SCALAR;
  bool floats = true;           // FLOAT
  bool normalizedInts = false;  // normalized (UNSIGNED_)BYTE / (UNSIGNED_)SHORT
  bool unsignedInts = false;    // plain UNSIGNED_BYTE / UNSIGNED_SHORT / UNSIGNED_INT
};

// The vertices of one glTF mesh while its primitives are gathered, one entry per glTF vertex.
struct MeshVertices {
  std::vector<double> position;  // x y z
  std::vector<double> normal;    // x y z, zeros where a primitive has none
  std::vector<double> uv;        // u v (glTF orientation), zeros where a primitive has none
  std::vector<uint64_t> source;  // _MPEG4FACE_VERTEX values (weld mode)
  std::vector<int> primitive;    // primitive of each vertex (weld mode, for messages)
  std::vector<std::vector<double>> displacement;  // per morph target, x y z
  bool hasNormal = false;
  bool hasUv = false;
  std::vector<uint64_t> triangles;  // three glTF vertices per triangle

  uint64_t count() const { return position.size() / 3; }
};

class Reader {
 public:
  Reader(const tinygltf::Model& gltf, const std::string& fileName);

  gltf_internal::ReadResult read();

 private:
  [[noreturn]] void fail(const std::string& field, const std::string& message) const {
    throw Error(fileName_, 0, field, message);
  }

  // --- io/gltf_read_accessor.cpp: buffer views and accessors, bounds-checked.
  std::pair<const unsigned char*, uint64_t> viewBytes(int index, const std::string& field,
                                                      const std::string& what) const;
  void spend(uint64_t values, const std::string& field);
  std::vector<double> readAccessor(int index, const std::string& field, const AccessorSpec& spec,
                                   std::optional<uint64_t> expectedCount = std::nullopt);
  void readSparse(const tinygltf::Accessor& a, const std::string& what, const std::string& field,
                  uint64_t components, uint64_t elementSize, std::vector<double>& values) const;
  static int attribute(const std::map<std::string, int>& attributes, const std::string& name);
  uint64_t accessorCount(int index) const;

  // --- io/gltf_read_mesh.cpp: meshes, their primitives and morph targets.
  IndexedFaceSet readMesh(size_t meshIndex);
  void readPrimitive(const tinygltf::Primitive& prim, const std::string& pp, int primIndex,
                     bool weld, uint64_t totalVertices,
                     std::map<std::vector<int>, uint64_t>& sharedBase, MeshVertices& v);
  void weldVertices(const MeshVertices& v, const std::string& prefix, IndexedFaceSet& out) const;

  // --- io/gltf_read_scene.cpp: the asset, the node tree, the scene and its extras.
  void checkAssetAndExtensions() const;
  static bool markedAs(const tinygltf::Node& node, const char* key);
  static bool isMeshInstance(const tinygltf::Node& node);
  bool isCenter(size_t index) const;
  void readNodes();
  Transform readTransform(size_t index) const;
  void decompose(const std::vector<double>& m, const std::string& field, const std::string& who,
                 Transform& t) const;
  int sceneIndex() const;
  void readRoots();
  void readFeaturePoints(gltf_internal::ReadResult& result);

  // --- io/gltf_read_animation.cpp: morph-weight and Transform animation.
  void readAnimations();
  std::pair<MorphWeightChannel::Interpolation, size_t> interpolation(
      const tinygltf::AnimationSampler& sampler, const std::string& sp) const;
  std::vector<double> keyTimes(const tinygltf::AnimationSampler& sampler, const std::string& sp);
  MorphWeightChannel readChannel(const tinygltf::AnimationSampler& sampler, const std::string& sp,
                                 const std::string& cp, int mesh);
  TransformChannel readTransformChannel(const tinygltf::AnimationSampler& sampler,
                                        const std::string& sp, int transform,
                                        const std::string& path);

  const tinygltf::Model& gltf_;
  const std::string& fileName_;
  FaceModel model_;
  std::vector<int> parent_;       // glTF parent node of each node, -1 for none
  std::vector<int> transformOf_;  // Transform of each node, -1 for mesh-instance helpers
  uint64_t valueBudget_ = 0;
};

}  // namespace mpeg4face::gltf_reader
