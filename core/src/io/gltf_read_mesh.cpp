// SPDX-License-Identifier: GPL-3.0-or-later
// glTF reader: meshes, their primitives and morph targets, and the vertices writeGltf split
// welded back together.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "io/gltf_names.hpp"
#include "io/gltf_reader.hpp"

namespace mpeg4face::gltf_reader {

using gltf_names::kVertexAttribute;

IndexedFaceSet Reader::readMesh(size_t meshIndex) {
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
    if (__builtin_add_overflow(totalVertices, accessorCount(attribute(prim.attributes, "POSITION")),
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
      for (size_t k = 0; k < 3; ++k) out.coordIndex.push_back(static_cast<int>(v.triangles[i + k]));
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

void Reader::readPrimitive(const tinygltf::Primitive& prim, const std::string& pp, int primIndex,
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
void Reader::weldVertices(const MeshVertices& v, const std::string& prefix,
                          IndexedFaceSet& out) const {
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

}  // namespace mpeg4face::gltf_reader
