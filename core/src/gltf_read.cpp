// SPDX-License-Identifier: GPL-3.0-or-later
// glTF 2.0 -> FaceModel through tinygltf (Debian's shared libtinygltf; the implementation is
// in the .so, so TINYGLTF_IMPLEMENTATION must not be defined here).
//
// tinygltf only parses the JSON and loads the buffers; it does not check accessors against
// their buffers. Every accessor is therefore read here with explicit bounds and type checks,
// and problems are reported as mpeg4face::Error naming the JSON path that is at fault.
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
#include <tuple>
#include <utility>
#include <vector>

#include "gltf_internal.hpp"
#include "gltf_names.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/file_io.hpp"
#include "mpeg4face/gltf.hpp"

namespace mpeg4face {
namespace {

using gltf_names::kExtrasKey;
using gltf_names::kVertexAttribute;

// glTF needs no deep nesting; the limit keeps hostile input from exhausting the stack in
// tinygltf's recursive conversion of extras.
constexpr int kMaxJsonDepth = 100;
// Accessors without a buffer view are all zeros (plus sparse values); their count is not
// backed by any data, so it is capped to keep a tiny file from allocating gigabytes.
constexpr uint64_t kMaxSyntheticValues = uint64_t{1} << 22;

std::string str(uint64_t n) { return std::to_string(n); }

std::string typeName(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT2:
      return "MAT2";
    case TINYGLTF_TYPE_MAT3:
      return "MAT3";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "type " + std::to_string(type);
  }
}

std::string componentTypeName(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_INT:
      return "INT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return "FLOAT";
    default:
      return "component type " + std::to_string(componentType);
  }
}

int componentSize(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;  // INT and DOUBLE are not glTF 2.0 accessor types
  }
}

// Little-endian component at p (glTF is little-endian; so is every platform we build on).
template <typename T>
T load(const unsigned char* p) {
  T value;
  std::memcpy(&value, p, sizeof value);
  return value;
}

double readComponent(const unsigned char* p, int componentType, bool normalized) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return load<float>(p);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      const double v = load<uint8_t>(p);
      return normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const double v = load<int8_t>(p);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      const double v = load<uint16_t>(p);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      const double v = load<int16_t>(p);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return load<uint32_t>(p);
    default:
      return 0;
  }
}

// a * b + c without overflow; false when it does not fit.
bool mulAdd(uint64_t a, uint64_t b, uint64_t c, uint64_t& out) {
  uint64_t product = 0;
  return !__builtin_mul_overflow(a, b, &product) && !__builtin_add_overflow(product, c, &out);
}

// Which encodings an accessor may use; anything else is an Error.
struct AccessorSpec {
  int type = TINYGLTF_TYPE_SCALAR;
  bool floats = true;           // FLOAT
  bool normalizedInts = false;  // normalized (UNSIGNED_)BYTE / (UNSIGNED_)SHORT
  bool unsignedInts = false;    // plain UNSIGNED_BYTE / UNSIGNED_SHORT / UNSIGNED_INT
};

// --------------------------------------------------------------------------------------
// Reading
// --------------------------------------------------------------------------------------

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
  Reader(const tinygltf::Model& gltf, const std::string& fileName)
      : gltf_(gltf), fileName_(fileName) {
    for (const tinygltf::Buffer& b : gltf_.buffers) valueBudget_ += 4 * b.data.size();
    valueBudget_ += kMaxSyntheticValues;
  }

  gltf_internal::ReadResult read() {
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

 private:
  [[noreturn]] void fail(const std::string& field, const std::string& message) const {
    throw Error(fileName_, 0, field, message);
  }

  void checkAssetAndExtensions() const {
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

  // The bytes of buffer view `index`, checked against its buffer.
  std::pair<const unsigned char*, uint64_t> viewBytes(int index, const std::string& field,
                                                      const std::string& what) const {
    if (index < 0 || static_cast<size_t>(index) >= gltf_.bufferViews.size()) {
      fail(field,
           what + " refers to buffer view " + std::to_string(index) + ", which does not exist");
    }
    const tinygltf::BufferView& view = gltf_.bufferViews[index];
    if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= gltf_.buffers.size()) {
      fail(field, what + ": buffer view " + std::to_string(index) + " refers to buffer " +
                      std::to_string(view.buffer) + ", which does not exist");
    }
    const std::vector<unsigned char>& data = gltf_.buffers[view.buffer].data;
    if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset) {
      fail(field, what + ": buffer view " + std::to_string(index) + " (bytes " +
                      str(view.byteOffset) + ".." + str(view.byteOffset + view.byteLength) +
                      ") runs past the end of buffer " + std::to_string(view.buffer) + " (" +
                      str(data.size()) + " bytes)");
    }
    return {data.data() + view.byteOffset, view.byteLength};
  }

  void spend(uint64_t values, const std::string& field) {
    if (values > valueBudget_) {
      fail(field, "the file decodes far more data than its buffers hold (" + str(values) +
                      " more values); refusing it");
    }
    valueBudget_ -= values;
  }

  // Reads accessor `index` (referenced at JSON path `field`) as doubles, count * components,
  // after checking its type, its component type and that every element lies in its buffer.
  std::vector<double> readAccessor(int index, const std::string& field, const AccessorSpec& spec,
                                   std::optional<uint64_t> expectedCount = std::nullopt) {
    if (index < 0 || static_cast<size_t>(index) >= gltf_.accessors.size()) {
      fail(field, "accessor " + std::to_string(index) + " does not exist (the file has " +
                      str(gltf_.accessors.size()) + ")");
    }
    const tinygltf::Accessor& a = gltf_.accessors[index];
    const std::string what = "accessor " + std::to_string(index);
    if (a.type != spec.type) {
      fail(field, what + " has type " + typeName(a.type) + ", expected " + typeName(spec.type));
    }
    const int ct = a.componentType;
    const bool isFloat = ct == TINYGLTF_COMPONENT_TYPE_FLOAT;
    const bool smallInt =
        ct == TINYGLTF_COMPONENT_TYPE_BYTE || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
        ct == TINYGLTF_COMPONENT_TYPE_SHORT || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    const bool unsignedInt = ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                             ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
                             ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    const bool ok = (isFloat && spec.floats) || (smallInt && a.normalized && spec.normalizedInts) ||
                    (unsignedInt && !a.normalized && spec.unsignedInts);
    if (!ok) {
      fail(field, what + " has component type " + (a.normalized ? "normalized " : "") +
                      componentTypeName(ct) + ", which is not allowed here");
    }
    if (expectedCount && a.count != *expectedCount) {
      fail(field, what + " has " + str(a.count) + " elements, expected " + str(*expectedCount));
    }
    const uint64_t components = static_cast<uint64_t>(tinygltf::GetNumComponentsInType(a.type));
    const uint64_t size = static_cast<uint64_t>(componentSize(ct));
    const uint64_t elementSize = components * size;
    uint64_t valueCount = 0;
    if (!mulAdd(a.count, components, 0, valueCount)) fail(field, what + " count is too large");

    std::vector<double> values;
    if (a.bufferView != -1) {  // tinygltf's "absent"; other negative values are errors
      const auto [bytes, length] = viewBytes(a.bufferView, field, what);
      const uint64_t viewStride = gltf_.bufferViews[a.bufferView].byteStride;
      const uint64_t stride = viewStride != 0 ? viewStride : elementSize;
      if (stride < elementSize) {
        fail(field, what + ": byteStride " + str(stride) + " is smaller than one element (" +
                        str(elementSize) + " bytes)");
      }
      // The last element ends at byteOffset + (count - 1) * stride + elementSize.
      uint64_t end = 0;
      if (a.count > 0 &&
          (a.byteOffset > length || !mulAdd(a.count - 1, stride, a.byteOffset + elementSize, end) ||
           end > length)) {
        fail(field, what + " (" + str(a.count) + " x " + typeName(a.type) + " " +
                        componentTypeName(ct) + " from byte " + str(a.byteOffset) +
                        ") runs past the end of buffer view " + std::to_string(a.bufferView) +
                        " (" + str(length) + " bytes)");
      }
      spend(valueCount, field);
      values.resize(valueCount);
      for (uint64_t i = 0; i < a.count; ++i) {
        const unsigned char* element = bytes + a.byteOffset + i * stride;
        for (uint64_t c = 0; c < components; ++c) {
          values[i * components + c] = readComponent(element + c * size, ct, a.normalized);
        }
      }
    } else {
      if (valueCount > kMaxSyntheticValues) {
        fail(field, what + " has no buffer view and " + str(a.count) + " elements; at most " +
                        str(kMaxSyntheticValues / components) + " are accepted");
      }
      spend(valueCount, field);
      values.assign(valueCount, 0.0);  // the spec's initial value without a buffer view
    }
    if (a.sparse.isSparse) readSparse(a, what, field, components, elementSize, values);
    return values;
  }

  void readSparse(const tinygltf::Accessor& a, const std::string& what, const std::string& field,
                  uint64_t components, uint64_t elementSize, std::vector<double>& values) const {
    const auto& sparse = a.sparse;
    if (sparse.count < 1 || static_cast<uint64_t>(sparse.count) > a.count) {
      fail(field, what + ": sparse count " + std::to_string(sparse.count) +
                      " must be between 1 and the accessor count " + str(a.count));
    }
    const uint64_t n = static_cast<uint64_t>(sparse.count);
    const int indexType = sparse.indices.componentType;
    if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
      fail(field, what + ": sparse indices have component type " + componentTypeName(indexType) +
                      ", expected an unsigned integer type");
    }
    if (sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0) {
      fail(field, what + ": negative sparse byteOffset");
    }
    const uint64_t indexSize = static_cast<uint64_t>(componentSize(indexType));
    const auto [indexBytes, indexLength] =
        viewBytes(sparse.indices.bufferView, field, what + " sparse indices");
    const auto [valueBytes, valueLength] =
        viewBytes(sparse.values.bufferView, field, what + " sparse values");
    uint64_t indexEnd = 0;
    uint64_t valueEnd = 0;
    if (!mulAdd(n, indexSize, static_cast<uint64_t>(sparse.indices.byteOffset), indexEnd) ||
        indexEnd > indexLength) {
      fail(field, what + ": sparse indices run past the end of buffer view " +
                      std::to_string(sparse.indices.bufferView));
    }
    if (!mulAdd(n, elementSize, static_cast<uint64_t>(sparse.values.byteOffset), valueEnd) ||
        valueEnd > valueLength) {
      fail(field, what + ": sparse values run past the end of buffer view " +
                      std::to_string(sparse.values.bufferView));
    }
    const uint64_t size = elementSize / components;
    for (uint64_t k = 0; k < n; ++k) {
      const auto target = static_cast<uint64_t>(
          readComponent(indexBytes + sparse.indices.byteOffset + k * indexSize, indexType, false));
      if (target >= a.count) {
        fail(field, what + ": sparse index " + str(target) + " is out of range (count " +
                        str(a.count) + ")");
      }
      const unsigned char* element = valueBytes + sparse.values.byteOffset + k * elementSize;
      for (uint64_t c = 0; c < components; ++c) {
        values[target * components + c] =
            readComponent(element + c * size, a.componentType, a.normalized);
      }
    }
  }

  // The accessor index of `attributes[name]`, or -1.
  static int attribute(const std::map<std::string, int>& attributes, const std::string& name) {
    auto it = attributes.find(name);
    return it == attributes.end() ? -1 : it->second;
  }

  uint64_t accessorCount(int index) const {
    return index >= 0 && static_cast<size_t>(index) < gltf_.accessors.size()
               ? gltf_.accessors[index].count
               : 0;
  }

  IndexedFaceSet readMesh(size_t meshIndex) {
    const tinygltf::Mesh& mesh = gltf_.meshes[meshIndex];
    const std::string prefix = "meshes[" + str(meshIndex) + "]";
    IndexedFaceSet out;
    out.name = mesh.name.empty() ? "mesh" + str(meshIndex) : mesh.name;

    const size_t targetCount = mesh.primitives.empty() ? 0 : mesh.primitives[0].targets.size();
    size_t welded = 0;
    uint64_t totalVertices = 0;
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      const tinygltf::Primitive& prim = mesh.primitives[p];
      if (prim.targets.size() != targetCount) {
        fail(prefix + ".primitives[" + str(p) + "].targets",
             "has " + str(prim.targets.size()) + " morph targets but primitive 0 has " +
                 str(targetCount) + " (glTF requires the same number)");
      }
      welded += prim.attributes.count(kVertexAttribute);
      if (__builtin_add_overflow(totalVertices,
                                 accessorCount(attribute(prim.attributes, "POSITION")),
                                 &totalVertices)) {
        totalVertices = std::numeric_limits<uint64_t>::max();
      }
    }
    const bool weld = welded > 0;
    if (weld && welded != mesh.primitives.size()) {
      fail(prefix + ".primitives",
           std::string(kVertexAttribute) + " is on some primitives only; expected all or none");
    }

    MeshVertices v;
    v.displacement.resize(targetCount);
    // Primitives sharing all their vertex accessors (e.g. one per material) share vertices.
    std::map<std::vector<int>, uint64_t> sharedBase;
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      readPrimitive(mesh.primitives[p], prefix + ".primitives[" + str(p) + "]", static_cast<int>(p),
                    weld, totalVertices, sharedBase, v);
    }
    if (weld) {
      weldVertices(v, prefix, out);
    } else {
      const uint64_t n = v.count();
      out.coord = Eigen::Map<const Points3>(v.position.data(), static_cast<Eigen::Index>(n), 3);
      if (v.hasNormal) {
        out.normal = Eigen::Map<const Points3>(v.normal.data(), static_cast<Eigen::Index>(n), 3);
      }
      if (v.hasUv) {
        out.texCoord.resize(static_cast<Eigen::Index>(n), 2);
        for (uint64_t i = 0; i < n; ++i) {
          // glTF puts the UV origin at the top left, VRML/OBJ at the bottom left.
          out.texCoord.row(static_cast<Eigen::Index>(i)) << v.uv[2 * i], 1.0 - v.uv[2 * i + 1];
        }
      }
      for (size_t t = 0; t < targetCount; ++t) {
        MorphTarget target;
        target.displacements =
            Eigen::Map<const Points3>(v.displacement[t].data(), static_cast<Eigen::Index>(n), 3);
        out.morphTargets.push_back(std::move(target));
      }
      out.coordIndex.reserve(v.triangles.size() / 3 * 4);
      for (size_t i = 0; i < v.triangles.size(); i += 3) {
        for (size_t k = 0; k < 3; ++k)
          out.coordIndex.push_back(static_cast<int>(v.triangles[i + k]));
        out.coordIndex.push_back(-1);
      }
    }

    // Target names: the de-facto convention of Blender, three.js and the Khronos samples.
    const tinygltf::Value* names = nullptr;
    if (mesh.extras.IsObject() && mesh.extras.Has("targetNames") &&
        mesh.extras.Get("targetNames").IsArray()) {
      names = &mesh.extras.Get("targetNames");
    }
    for (size_t t = 0; t < targetCount; ++t) {
      const bool named =
          names != nullptr && t < names->ArrayLen() && names->Get(static_cast<int>(t)).IsString();
      out.morphTargets[t].name =
          named ? names->Get(static_cast<int>(t)).Get<std::string>() : "target" + str(t);
    }
    if (!mesh.weights.empty()) {
      if (mesh.weights.size() != targetCount) {
        fail(prefix + ".weights", "has " + str(mesh.weights.size()) + " weights for " +
                                      str(targetCount) + " morph targets");
      }
      out.weights = mesh.weights;
    }
    return out;
  }

  void readPrimitive(const tinygltf::Primitive& prim, const std::string& pp, int primIndex,
                     bool weld, uint64_t totalVertices,
                     std::map<std::vector<int>, uint64_t>& sharedBase, MeshVertices& v) {
    const int mode = prim.mode;  // tinygltf fills in the default, TRIANGLES
    if (mode < TINYGLTF_MODE_POINTS || mode > TINYGLTF_MODE_TRIANGLE_FAN) {
      fail(pp + ".mode", "unknown primitive mode " + std::to_string(mode));
    }
    const int position = attribute(prim.attributes, "POSITION");
    if (position < 0) fail(pp + ".attributes", "has no POSITION");
    const int normal = attribute(prim.attributes, "NORMAL");
    const int uv = attribute(prim.attributes, "TEXCOORD_0");
    const int source = attribute(prim.attributes, kVertexAttribute);
    std::vector<int> key = {position, normal, uv, source};
    for (const auto& target : prim.targets) key.push_back(attribute(target, "POSITION"));

    uint64_t base = v.count();
    uint64_t n = 0;
    if (auto it = sharedBase.find(key); it != sharedBase.end()) {
      base = it->second;
      n = accessorCount(position);
    } else {
      const std::vector<double> pos =
          readAccessor(position, pp + ".attributes.POSITION", {.type = TINYGLTF_TYPE_VEC3});
      n = pos.size() / 3;
      v.position.insert(v.position.end(), pos.begin(), pos.end());
      if (normal >= 0) {
        const std::vector<double> values =
            readAccessor(normal, pp + ".attributes.NORMAL", {.type = TINYGLTF_TYPE_VEC3}, n);
        v.normal.resize(3 * base);  // zeros for earlier primitives without normals
        v.normal.insert(v.normal.end(), values.begin(), values.end());
        v.hasNormal = true;
      }
      if (uv >= 0) {
        const std::vector<double> values =
            readAccessor(uv, pp + ".attributes.TEXCOORD_0",
                         {.type = TINYGLTF_TYPE_VEC2, .floats = true, .normalizedInts = true}, n);
        v.uv.resize(2 * base);
        v.uv.insert(v.uv.end(), values.begin(), values.end());
        v.hasUv = true;
      }
      if (weld) {
        const std::string field = pp + ".attributes." + kVertexAttribute;
        const std::vector<double> values = readAccessor(source, field,
                                                        {.type = TINYGLTF_TYPE_SCALAR,
                                                         .floats = true,
                                                         .normalizedInts = false,
                                                         .unsignedInts = true},
                                                        n);
        for (double id : values) {
          // Every original vertex has at least one glTF vertex, so ids stay below the total.
          if (!(id >= 0) || id != std::floor(id) || id >= static_cast<double>(totalVertices)) {
            std::ostringstream number;
            number << id;
            fail(field, "vertex number " + number.str() + " is out of range (the mesh has " +
                            str(totalVertices) + " glTF vertices)");
          }
          v.source.push_back(static_cast<uint64_t>(id));
          v.primitive.push_back(primIndex);
        }
      }
      for (size_t t = 0; t < prim.targets.size(); ++t) {
        const int target = attribute(prim.targets[t], "POSITION");
        std::vector<double>& d = v.displacement[t];
        if (target >= 0) {
          const std::vector<double> values = readAccessor(
              target, pp + ".targets[" + str(t) + "].POSITION", {.type = TINYGLTF_TYPE_VEC3}, n);
          d.insert(d.end(), values.begin(), values.end());
        } else {
          d.resize(d.size() + 3 * n, 0.0);  // a target moving only normals
        }
      }
      sharedBase.emplace(std::move(key), base);
    }
    // Keep the optional arrays one entry per vertex so far.
    v.normal.resize(v.position.size(), 0.0);
    v.uv.resize(2 * v.count(), 0.0);

    // Vertex order of the primitive: its indices, or 0..n-1.
    std::vector<uint64_t> order;
    if (prim.indices != -1) {  // tinygltf's "absent"
      const std::vector<double> indices =
          readAccessor(prim.indices, pp + ".indices",
                       {.type = TINYGLTF_TYPE_SCALAR, .floats = false, .unsignedInts = true});
      order.reserve(indices.size());
      for (size_t k = 0; k < indices.size(); ++k) {
        const auto index = static_cast<uint64_t>(indices[k]);
        if (index >= n) {
          fail(pp + ".indices", "index " + str(index) + " at position " + str(k) +
                                    " is out of range (the primitive has " + str(n) + " vertices)");
        }
        order.push_back(index);
      }
    } else {
      order.resize(n);
      for (uint64_t k = 0; k < n; ++k) order[k] = k;
    }

    // Points and lines make no faces; their vertices are kept so numbering stays intact.
    auto add = [&](uint64_t a, uint64_t b, uint64_t c, bool skipDegenerate) {
      if (skipDegenerate && (a == b || b == c || a == c)) return;
      v.triangles.insert(v.triangles.end(), {base + a, base + b, base + c});
    };
    const size_t count = order.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (count % 3 != 0) {
        fail(pp + (prim.indices != -1 ? ".indices" : ".attributes.POSITION"),
             str(count) + " vertices do not make whole triangles");
      }
      for (size_t k = 0; k + 2 < count; k += 3) add(order[k], order[k + 1], order[k + 2], false);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      // Degenerate triangles only stitch strips together.
      for (size_t k = 0; k + 2 < count; ++k) {
        if (k % 2 == 0) {
          add(order[k], order[k + 1], order[k + 2], true);
        } else {
          add(order[k], order[k + 2], order[k + 1], true);
        }
      }
    } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
      for (size_t k = 1; k + 1 < count; ++k) add(order[k], order[k + 1], order[0], true);
    }
  }

  // Joins the glTF vertices that writeGltf split (one per vertex and UV pair) back into the
  // IndexedFaceSet's vertices, with texCoord + texCoordIndex per corner.
  void weldVertices(const MeshVertices& v, const std::string& prefix, IndexedFaceSet& out) const {
    const uint64_t n = v.count();
    auto field = [&](uint64_t g) {
      return prefix + ".primitives[" + std::to_string(v.primitive[g]) + "].attributes." +
             kVertexAttribute;
    };
    uint64_t vertexCount = 0;
    for (uint64_t g = 0; g < n; ++g) {
      // Each vertex has at least one glTF vertex, so the numbers stay below their count.
      if (v.source[g] >= n) {
        fail(field(g), "vertex number " + str(v.source[g]) + " is out of range (the mesh has " +
                           str(n) + " glTF vertices)");
      }
      vertexCount = std::max(vertexCount, v.source[g] + 1);
    }
    std::vector<int64_t> first(vertexCount, -1);
    for (uint64_t g = 0; g < n; ++g) {
      const uint64_t id = v.source[g];
      if (first[id] < 0) {
        first[id] = static_cast<int64_t>(g);
        continue;
      }
      const auto f = static_cast<uint64_t>(first[id]);
      for (int c = 0; c < 3; ++c) {
        if (v.position[3 * g + c] != v.position[3 * f + c]) {
          fail(field(g), "joins glTF vertices " + str(f) + " and " + str(g) +
                             ", which have different positions");
        }
      }
    }
    const auto rows = static_cast<Eigen::Index>(vertexCount);
    out.coord.resize(rows, 3);
    if (v.hasNormal) out.normal.resize(rows, 3);
    out.morphTargets.resize(v.displacement.size());
    for (auto& target : out.morphTargets) target.displacements.resize(rows, 3);
    for (uint64_t id = 0; id < vertexCount; ++id) {
      if (first[id] < 0) {
        fail(field(0), "no glTF vertex belongs to vertex " + str(id));
      }
      const auto g = static_cast<uint64_t>(first[id]);
      const auto r = static_cast<Eigen::Index>(id);
      out.coord.row(r) << v.position[3 * g], v.position[3 * g + 1], v.position[3 * g + 2];
      if (v.hasNormal) {
        out.normal.row(r) << v.normal[3 * g], v.normal[3 * g + 1], v.normal[3 * g + 2];
      }
      for (size_t t = 0; t < v.displacement.size(); ++t) {
        const std::vector<double>& d = v.displacement[t];
        out.morphTargets[t].displacements.row(r) << d[3 * g], d[3 * g + 1], d[3 * g + 2];
      }
    }
    // One texCoord row per distinct UV.
    std::vector<int> uvRow;
    if (v.hasUv) {
      std::map<std::pair<double, double>, int> rowOf;
      std::vector<std::pair<double, double>> uvs;
      uvRow.resize(n);
      for (uint64_t g = 0; g < n; ++g) {
        const std::pair<double, double> uv{v.uv[2 * g], 1.0 - v.uv[2 * g + 1]};
        auto [it, added] = rowOf.emplace(uv, static_cast<int>(uvs.size()));
        if (added) uvs.push_back(uv);
        uvRow[g] = it->second;
      }
      out.texCoord.resize(static_cast<Eigen::Index>(uvs.size()), 2);
      for (size_t i = 0; i < uvs.size(); ++i) {
        out.texCoord.row(static_cast<Eigen::Index>(i)) << uvs[i].first, uvs[i].second;
      }
    }
    for (size_t i = 0; i < v.triangles.size(); i += 3) {
      for (size_t k = 0; k < 3; ++k) {
        const uint64_t g = v.triangles[i + k];
        out.coordIndex.push_back(static_cast<int>(v.source[g]));
        if (v.hasUv) out.texCoordIndex.push_back(uvRow[g]);
      }
      out.coordIndex.push_back(-1);
      if (v.hasUv) out.texCoordIndex.push_back(-1);
    }
  }

  // Whether `node` carries {"mpeg4face": {<key>: true}} in its extras.
  static bool markedAs(const tinygltf::Node& node, const char* key) {
    const tinygltf::Value& extras = node.extras;
    if (!extras.IsObject() || !extras.Has(kExtrasKey)) return false;
    const tinygltf::Value& ours = extras.Get(kExtrasKey);
    return ours.IsObject() && ours.Has(key) && ours.Get(key).IsBool() && ours.Get(key).Get<bool>();
  }

  // A node that writeGltf added only to instance one more mesh of a Transform.
  static bool isMeshInstance(const tinygltf::Node& node) {
    return markedAs(node, "meshInstance") && node.mesh >= 0 && node.children.empty() &&
           node.matrix.empty() && node.translation.empty() && node.rotation.empty() &&
           node.scale.empty();
  }

  // A node that writeGltf added to carry -center of its parent's Transform: the parent's only
  // child, translated only, holding the Transform's meshes and children.
  bool isCenter(size_t index) const {
    const tinygltf::Node& node = gltf_.nodes[index];
    if (!markedAs(node, "center") || parent_[index] < 0 || !node.matrix.empty() ||
        !node.rotation.empty() || !node.scale.empty() || node.translation.size() != 3) {
      return false;
    }
    const tinygltf::Node& parent = gltf_.nodes[parent_[index]];
    return parent.mesh < 0 && parent.children.size() == 1 && !markedAs(parent, "center");
  }

  void readNodes() {
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
          fail(np + ".children", "node " + std::to_string(child) +
                                     " has more than one parent (glTF nodes form trees)");
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

  Transform readTransform(size_t index) const {
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
      t.translation =
          Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]);
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
  void decompose(const std::vector<double>& m, const std::string& field, const std::string& who,
                 Transform& t) const {
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

  int sceneIndex() const {
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

  void readRoots() {
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

  void readAnimations() {
    for (size_t a = 0; a < gltf_.animations.size(); ++a) {
      const tinygltf::Animation& anim = gltf_.animations[a];
      const std::string ap = "animations[" + str(a) + "]";
      MorphWeightAnimation out;
      out.name = anim.name.empty() ? "animation" + str(a) : anim.name;
      std::vector<std::pair<int, int>> done;  // (mesh, sampler) already read
      for (size_t c = 0; c < anim.channels.size(); ++c) {
        const tinygltf::AnimationChannel& channel = anim.channels[c];
        const std::string cp = ap + ".channels[" + str(c) + "]";
        const std::string& path = channel.target_path;
        const bool weights = path == "weights";
        if (!weights && path != "translation" && path != "rotation" && path != "scale") {
          continue;  // e.g. KHR_animation_pointer: not part of the face model
        }
        const int node = channel.target_node;
        if (node < 0 || static_cast<size_t>(node) >= gltf_.nodes.size()) {
          fail(cp + ".target.node", "node " + std::to_string(node) + " does not exist");
        }
        const int sampler = channel.sampler;
        if (sampler < 0 || static_cast<size_t>(sampler) >= anim.samplers.size()) {
          fail(cp + ".sampler", "sampler " + std::to_string(sampler) + " does not exist");
        }
        const std::string sp = ap + ".samplers[" + std::to_string(sampler) + "]";
        if (!weights) {
          if (transformOf_[node] < 0) {
            fail(cp + ".target.node", "node " + std::to_string(node) +
                                          " is a helper node of mpeg4face's own (see its "
                                          "extras), which cannot be animated");
          }
          out.transformChannels.push_back(
              readTransformChannel(anim.samplers[sampler], sp, transformOf_[node], path));
          continue;
        }
        const int mesh = gltf_.nodes[node].mesh;
        if (mesh < 0) fail(cp + ".target.node", "node " + std::to_string(node) + " has no mesh");
        // Instances of one mesh animated by one sampler are one channel of the face model.
        if (std::find(done.begin(), done.end(), std::pair{mesh, sampler}) != done.end()) continue;
        done.emplace_back(mesh, sampler);
        out.channels.push_back(readChannel(anim.samplers[sampler], sp, cp, mesh));
      }
      if (!out.channels.empty() || !out.transformChannels.empty()) {
        model_.animations.push_back(std::move(out));
      }
    }
  }

  // The interpolation of a sampler and the number of outputs per key it needs (3 for cubic
  // splines: in-tangent, value, out-tangent).
  std::pair<MorphWeightChannel::Interpolation, size_t> interpolation(
      const tinygltf::AnimationSampler& sampler, const std::string& sp) const {
    if (sampler.interpolation == "LINEAR") return {MorphWeightChannel::Interpolation::Linear, 1};
    if (sampler.interpolation == "STEP") return {MorphWeightChannel::Interpolation::Step, 1};
    if (sampler.interpolation == "CUBICSPLINE") {
      return {MorphWeightChannel::Interpolation::CubicSpline, 3};
    }
    fail(sp + ".interpolation", "unknown interpolation '" + sampler.interpolation + "'");
  }

  std::vector<double> keyTimes(const tinygltf::AnimationSampler& sampler, const std::string& sp) {
    std::vector<double> times =
        readAccessor(sampler.input, sp + ".input", {.type = TINYGLTF_TYPE_SCALAR});
    if (times.empty()) fail(sp + ".input", "has no key times");
    for (size_t i = 0; i < times.size(); ++i) {
      if (!std::isfinite(times[i]) || (i > 0 && times[i] < times[i - 1])) {
        fail(sp + ".input", "key times must be finite and increasing (key " + str(i) + ")");
      }
    }
    return times;
  }

  MorphWeightChannel readChannel(const tinygltf::AnimationSampler& sampler, const std::string& sp,
                                 const std::string& cp, int mesh) {
    MorphWeightChannel channel;
    channel.mesh = mesh;
    size_t factor = 1;
    std::tie(channel.interpolation, factor) = interpolation(sampler, sp);
    const size_t targets = model_.meshes[mesh].morphTargets.size();
    if (targets == 0) {
      fail(cp, "animates the weights of mesh '" + model_.meshes[mesh].name +
                   "', which has no morph targets");
    }
    channel.times = keyTimes(sampler, sp);
    const uint64_t expected = channel.times.size() * targets * factor;
    channel.weights =
        readAccessor(sampler.output, sp + ".output",
                     {.type = TINYGLTF_TYPE_SCALAR, .floats = true, .normalizedInts = true});
    if (channel.weights.size() != expected) {
      fail(sp + ".output", "has " + str(channel.weights.size()) + " values; " +
                               str(channel.times.size()) + " keys x " + str(targets) +
                               " morph targets" + (factor == 3 ? " x 3 (cubic spline)" : "") +
                               " need " + str(expected));
    }
    return channel;
  }

  TransformChannel readTransformChannel(const tinygltf::AnimationSampler& sampler,
                                        const std::string& sp, int transform,
                                        const std::string& path) {
    TransformChannel channel;
    channel.transform = transform;
    size_t factor = 1;
    std::tie(channel.interpolation, factor) = interpolation(sampler, sp);
    const bool rotation = path == "rotation";
    channel.path = rotation                ? TransformChannel::Path::Rotation
                   : path == "translation" ? TransformChannel::Path::Translation
                                           : TransformChannel::Path::Scale;
    channel.times = keyTimes(sampler, sp);
    // glTF allows normalized integers for rotations only.
    const AccessorSpec spec = {.type = rotation ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3,
                               .floats = true,
                               .normalizedInts = rotation};
    channel.values =
        readAccessor(sampler.output, sp + ".output", spec, channel.times.size() * factor);
    if (channel.path == TransformChannel::Path::Translation) {
      // The node's translation is the Transform's plus its centre (see readNodes); the
      // tangents of a cubic spline need no offset.
      const Eigen::Vector3d& center = model_.transforms[transform].center;
      for (size_t key = 0; key < channel.times.size(); ++key) {
        double* value = channel.values.data() + (key * factor + (factor == 3 ? 1 : 0)) * 3;
        for (int i = 0; i < 3; ++i) value[i] -= center[i];
      }
    }
    return channel;
  }

  // The feature points from the scene's extras.mpeg4face, which `result` gets as a whole.
  void readFeaturePoints(gltf_internal::ReadResult& result) {
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
        binding.position =
            Eigen::Vector3d(p.Get(0).GetNumberAsDouble(), p.Get(1).GetNumberAsDouble(),
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

  const tinygltf::Model& gltf_;
  const std::string& fileName_;
  FaceModel model_;
  std::vector<int> parent_;       // glTF parent node of each node, -1 for none
  std::vector<int> transformOf_;  // Transform of each node, -1 for mesh-instance helpers
  uint64_t valueBudget_ = 0;
};

// --- tinygltf glue --------------------------------------------------------------------

// External files may only come from baseDir or below it; with no baseDir, from nowhere.
struct FsContext {
  std::filesystem::path baseDir;
  std::string refused;  // an existing file that was not allowed, for the message

  bool allowed(const std::string& file) const {
    if (baseDir.empty()) return false;
    std::error_code ec;
    const auto base = std::filesystem::weakly_canonical(std::filesystem::absolute(baseDir), ec);
    if (ec) return false;
    const auto path = std::filesystem::weakly_canonical(std::filesystem::absolute(file), ec);
    if (ec) return false;
    const std::filesystem::path rel = path.lexically_relative(base);
    return !rel.empty() && *rel.begin() != ".." && rel != ".";
  }
};

bool fileExists(const std::string& path, void* user) {
  try {
    auto* ctx = static_cast<FsContext*>(user);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return false;
    if (ctx->allowed(path)) return true;
    ctx->refused = path;
    return false;
  } catch (...) {
    return false;  // must not throw through tinygltf
  }
}

std::string expandFilePath(const std::string& path, void*) { return path; }

bool readWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                   void* user) {
  try {
    const auto* ctx = static_cast<const FsContext*>(user);
    if (!ctx->allowed(path)) {
      if (err) *err += "outside the folder of the glTF file: " + path;
      return false;
    }
    const std::string bytes = readFile(path);
    out->assign(bytes.begin(), bytes.end());
    return true;
  } catch (const std::exception& e) {
    if (err) *err += e.what();
    return false;
  }
}

bool writeWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&,
                    void*) {
  if (err) *err += "mpeg4face does not let tinygltf write files";
  return false;
}

// Images are not part of the face model: skip decoding them.
bool skipImage(tinygltf::Image*, const int, std::string*, std::string*, int, int,
               const unsigned char*, int, void*) {
  return true;
}

uint32_t readU32(std::string_view bytes, size_t offset) {
  uint32_t value = 0;
  std::memcpy(&value, bytes.data() + offset, 4);
  return value;
}

// Checks the GLB container and returns the part tinygltf may read. tinygltf 2.7 lets a BIN
// chunk extend 8 bytes past the declared length (it forgets the chunk header), so the
// chunk layout is checked here before tinygltf sees it.
std::string_view checkGlb(std::string_view bytes, const std::string& fileName) {
  auto fail = [&](const std::string& field, const std::string& message) {
    throw Error(fileName, 0, field, message);
  };
  if (bytes.size() < 12) {
    fail("GLB header", "truncated: " + str(bytes.size()) + " bytes, the header alone needs 12");
  }
  const uint32_t version = readU32(bytes, 4);
  if (version != 2) fail("GLB header", "GLB version " + str(version) + " (only 2 is supported)");
  const uint64_t length = readU32(bytes, 8);
  if (length > bytes.size()) {
    fail("GLB header",
         "truncated: the header says " + str(length) + " bytes, the file has " + str(bytes.size()));
  }
  if (length < 20) fail("GLB header", "no JSON chunk");
  const uint64_t jsonLength = readU32(bytes, 12);
  if (readU32(bytes, 16) != 0x4E4F534A) fail("GLB chunk 0", "the first chunk is not JSON");
  const uint64_t jsonEnd = 20 + jsonLength;
  if (jsonEnd > length) {
    fail("GLB chunk 0", "truncated: the JSON chunk of " + str(jsonLength) +
                            " bytes runs past the end of the file (" + str(length) + " bytes)");
  }
  if (jsonEnd + 8 <= length) {
    const uint64_t binLength = readU32(bytes, jsonEnd);
    if (jsonEnd + 8 + binLength > length) {
      fail("GLB chunk 1", "truncated: the chunk of " + str(binLength) +
                              " bytes runs past the end of the file (" + str(length) + " bytes)");
    }
  }
  return bytes.substr(0, length);
}

// Nesting depth of JSON text, strings skipped.
int jsonDepth(std::string_view json) {
  int depth = 0;
  int deepest = 0;
  bool inString = false;
  for (size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (inString) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        inString = false;
      }
    } else if (c == '"') {
      inString = true;
    } else if (c == '{' || c == '[') {
      deepest = std::max(deepest, ++depth);
    } else if (c == '}' || c == ']') {
      --depth;
    }
  }
  return deepest;
}

std::string trimmed(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  for (char& c : s) {
    if (c == '\n') c = ';';
  }
  return s;
}

// Where a tinygltf failure is: it gives only a message, but it fills the model's arrays in
// file order, so the element being parsed when it stopped is the next one.
std::pair<int, std::string> locateTinygltfError(const std::string& err, const tinygltf::Model& g) {
  auto has = [&](const char* s) { return err.find(s) != std::string::npos; };
  if (has("Chunk") || has("glTF binary") || has("glTF Binary")) return {0, "GLB"};
  if (has("parse_error") || has("parse error") || has("JSON string too short") ||
      has("not a JSON object")) {
    int line = 0;
    if (auto at = err.find("at line "); at != std::string::npos) {
      line = std::atoi(err.c_str() + at + 8);
    }
    return {line, "JSON"};
  }
  if (has("\"asset\"")) return {0, "asset"};
  if (has("primitive indices accessor") || has("invalid bufferView")) {
    for (size_t m = 0; m < g.meshes.size(); ++m) {
      for (size_t p = 0; p < g.meshes[m].primitives.size(); ++p) {
        const int i = g.meshes[m].primitives[p].indices;
        if (i < 0) continue;
        if (static_cast<size_t>(i) >= g.accessors.size() || g.accessors[i].bufferView < 0 ||
            static_cast<size_t>(g.accessors[i].bufferView) >= g.bufferViews.size()) {
          return {0, "meshes[" + str(m) + "].primitives[" + str(p) + "].indices"};
        }
      }
    }
    return {0, "meshes"};
  }
  if (has("File ") || has("'uri'") || has("Buffer") || has("byteLength") || has("BIN")) {
    return {0, "buffers[" + str(g.buffers.size()) + "]"};
  }
  if (has("byteStride") || has("BufferView"))
    return {0, "bufferViews[" + str(g.bufferViews.size()) + "]"};
  if (has("ccessor") || has("componentType") || has("`type`")) {
    return {0, "accessors[" + str(g.accessors.size()) + "]"};
  }
  if (has("nimation")) return {0, "animations[" + str(g.animations.size()) + "]"};
  if (has("image")) return {0, "images[" + str(g.images.size()) + "]"};
  return {0, {}};
}

}  // namespace

gltf_internal::ReadResult gltf_internal::parseGltf(std::string_view bytes,
                                                   const std::string& fileName,
                                                   const std::filesystem::path& baseDir) {
  if (bytes.empty()) throw Error(fileName, 0, {}, "empty file");
  if (bytes.size() > std::numeric_limits<uint32_t>::max()) {
    throw Error(fileName, 0, {}, "larger than 4 GiB, which tinygltf cannot read");
  }
  const bool binary = bytes.starts_with("glTF");
  std::string_view json = bytes;
  if (binary) {
    bytes = checkGlb(bytes, fileName);
    json = bytes.substr(20, readU32(bytes, 12));
  } else {
    size_t first = json.starts_with("\xEF\xBB\xBF") ? 3 : 0;  // a UTF-8 byte order mark
    while (first < json.size() && std::isspace(static_cast<unsigned char>(json[first]))) ++first;
    if (first == json.size() || json[first] != '{') {
      throw Error(fileName, 0, {},
                  "not glTF: neither the GLB magic 'glTF' nor a JSON object at the start");
    }
  }
  if (jsonDepth(json) > kMaxJsonDepth) {
    throw Error(fileName, 0, "JSON",
                "nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  }

  FsContext fs{baseDir, {}};
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({&fileExists, &expandFilePath, &readWholeFile, &writeWholeFile, &fs});
  loader.SetImageLoader(&skipImage, nullptr);
  tinygltf::Model gltf;
  std::string err;
  std::string warn;
  bool ok = false;
  try {
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    const auto size = static_cast<unsigned int>(bytes.size());
    ok = binary
             ? loader.LoadBinaryFromMemory(&gltf, &err, &warn, data, size, baseDir.string())
             : loader.LoadASCIIFromString(&gltf, &err, &warn, bytes.data(), size, baseDir.string());
  } catch (const std::exception& e) {  // tinygltf has a few .at() on hostile input
    ok = false;
    err += e.what();
  }
  // Harmless: tinygltf reads the file fine; some exporters do not pad the JSON chunk.
  if (ok && trimmed(err) == "JSON Chunk end does not aligned to a 4-byte boundary.") err.clear();
  // tinygltf reports some problems in `err` but still succeeds (and then silently drops the
  // element, which would shift every JSON path we report): treat them as errors too.
  if (!ok || !err.empty()) {
    if (err.empty()) err = "tinygltf could not read the file";
    std::string message = trimmed(err);
    if (!fs.refused.empty()) {
      message += " (" + fs.refused + " exists, but only files in the glTF file's folder are read)";
    } else if (baseDir.empty() && message.find("File not found") != std::string::npos) {
      message += " (no base folder was given, so no external file can be read)";
    }
    if (!warn.empty()) message += " (tinygltf warnings: " + trimmed(warn) + ")";
    const auto [line, field] = locateTinygltfError(err, gltf);
    throw Error(fileName, line, field, message);
  }
  return Reader(gltf, fileName).read();
}

FaceModel parseGltf(std::string_view bytes, const std::string& fileName,
                    const std::filesystem::path& baseDir) {
  return gltf_internal::parseGltf(bytes, fileName, baseDir).model;
}

gltf_internal::ReadResult gltf_internal::readGltf(const std::filesystem::path& path) {
  const std::string bytes = readFile(path);
  std::filesystem::path baseDir = path.parent_path();
  if (baseDir.empty()) baseDir = ".";
  return parseGltf(bytes, path.string(), baseDir);
}

FaceModel readGltf(const std::filesystem::path& path) {
  return gltf_internal::readGltf(path).model;
}

}  // namespace mpeg4face
