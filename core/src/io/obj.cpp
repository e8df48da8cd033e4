// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/io/obj.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <string>
#include <unordered_map>
#include <utility>

#include "io/text_reader.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"

namespace mpeg4face {
namespace {

// One face corner: 0-based indices into the file's v, vt and vn lists, -1 when absent.
struct Corner {
  int v = -1;
  int vt = -1;
  int vn = -1;
};

// The faces of one g/o name, in file order (repeated names append here).
struct Group {
  std::string name;
  std::vector<Corner> corners;
  std::vector<int> faceSizes;
};

// An OBJ reference (1-based, or negative counting back from the last element defined so far)
// as a 0-based index. Only elements defined before the face count, as the format intends.
int resolve(std::string_view part, int defined, const char* element, std::string_view corner,
            const text::LineReader& reader) {
  int index = 0;
  if (!text::tryParseInt(part, index)) {
    reader.fail("f", std::string(element) + " index expected, found " +
                         (part.empty() ? "nothing" : text::quote(part)) +
                         (part.size() < corner.size() ? " in corner " + text::quote(corner) : ""));
  }
  if (index > 0 && index <= defined) return index - 1;
  if (index < 0 && index >= -defined) return defined + index;
  reader.fail("f",
              std::string(element) + " index " + std::to_string(index) +
                  (index == 0 ? " is invalid (OBJ counts from 1)"
                              : " out of range: " + std::to_string(defined) + " defined so far"));
}

// "v", "v/vt", "v//vn" or "v/vt/vn".
Corner parseCorner(std::string_view token, int vCount, int vtCount, int vnCount,
                   const text::LineReader& reader) {
  if (std::count(token.begin(), token.end(), '/') > 2) {
    reader.fail("f", "corner " + text::quote(token) + " has more than 3 parts (v/vt/vn)");
  }
  Corner corner;
  const std::size_t slash1 = token.find('/');
  corner.v = resolve(token.substr(0, slash1), vCount, "vertex", token, reader);
  if (slash1 == std::string_view::npos) return corner;
  const std::string_view rest = token.substr(slash1 + 1);
  const std::size_t slash2 = rest.find('/');
  const std::string_view vt = rest.substr(0, slash2);
  if (!vt.empty()) corner.vt = resolve(vt, vtCount, "texture coordinate", token, reader);
  if (slash2 == std::string_view::npos) return corner;
  const std::string_view vn = rest.substr(slash2 + 1);
  if (!vn.empty()) corner.vn = resolve(vn, vnCount, "normal", token, reader);
  return corner;
}

// Sorted distinct values of `indices`, and `map[value]` = its position among them.
std::vector<int> compact(std::vector<int> indices, std::vector<int>& map) {
  std::sort(indices.begin(), indices.end());
  indices.erase(std::unique(indices.begin(), indices.end()), indices.end());
  for (std::size_t i = 0; i < indices.size(); ++i) map[indices[i]] = static_cast<int>(i);
  return indices;
}

// The mesh of one group: only the vertices its faces use, in OBJ order. UVs are kept only if
// every corner has one (VRML's texCoordIndex must cover every face); normals only if each
// vertex has exactly one vn, since IndexedFaceSet normals are per vertex (split normals are
// dropped, not approximated; a consumer recomputes them).
IndexedFaceSet buildMesh(const Group& group, const std::vector<double>& v,
                         const std::vector<double>& vt, const std::vector<double>& vn,
                         std::vector<int>& map) {
  IndexedFaceSet mesh;
  mesh.name = group.name;
  std::vector<int> used;
  used.reserve(group.corners.size());
  bool allVt = true;
  bool allVn = true;
  for (const Corner& c : group.corners) {
    used.push_back(c.v);
    allVt = allVt && c.vt >= 0;
    allVn = allVn && c.vn >= 0;
  }
  mesh.sourceIndex = compact(std::move(used), map);
  const auto vertexCount = static_cast<Eigen::Index>(mesh.sourceIndex.size());
  mesh.coord.resize(vertexCount, 3);
  for (Eigen::Index i = 0; i < vertexCount; ++i) {
    const std::size_t s = 3 * static_cast<std::size_t>(mesh.sourceIndex[i]);
    mesh.coord.row(i) << v[s], v[s + 1], v[s + 2];
  }

  mesh.coordIndex.reserve(group.corners.size() + group.faceSizes.size());
  std::size_t k = 0;
  for (int size : group.faceSizes) {
    for (int i = 0; i < size; ++i) mesh.coordIndex.push_back(map[group.corners[k++].v]);
    mesh.coordIndex.push_back(-1);
  }

  if (allVn) {
    std::vector<int> normalOf(mesh.sourceIndex.size(), -1);
    std::size_t corner = 0;
    for (int index : mesh.coordIndex) {
      if (index < 0) continue;
      int& n = normalOf[index];
      const int given = group.corners[corner++].vn;
      if (n >= 0 && n != given) {
        allVn = false;
        break;
      }
      n = given;
    }
    if (allVn) {
      mesh.normal.resize(vertexCount, 3);
      for (Eigen::Index i = 0; i < vertexCount; ++i) {
        const std::size_t s = 3 * static_cast<std::size_t>(normalOf[i]);
        mesh.normal.row(i) << vn[s], vn[s + 1], vn[s + 2];
      }
    }
  }

  if (allVt) {
    std::vector<int> usedVt;
    usedVt.reserve(group.corners.size());
    for (const Corner& c : group.corners) usedVt.push_back(c.vt);
    usedVt = compact(std::move(usedVt), map);
    mesh.texCoord.resize(static_cast<Eigen::Index>(usedVt.size()), 2);
    for (std::size_t i = 0; i < usedVt.size(); ++i) {
      const std::size_t s = 2 * static_cast<std::size_t>(usedVt[i]);
      mesh.texCoord.row(static_cast<Eigen::Index>(i)) << vt[s], vt[s + 1];
    }
    mesh.texCoordIndex.reserve(mesh.coordIndex.size());
    k = 0;
    for (int size : group.faceSizes) {
      for (int i = 0; i < size; ++i) mesh.texCoordIndex.push_back(map[group.corners[k++].vt]);
      mesh.texCoordIndex.push_back(-1);
    }
  }
  return mesh;
}

}  // namespace

FaceModel parseObj(std::string_view text, const std::string& fileName) {
  text::LineReader reader(text, fileName);
  std::vector<double> v, vt, vn;  // x y z / u v / x y z, flat
  std::vector<Group> groups;
  std::unordered_map<std::string, std::size_t> groupByName;
  std::string defaultName = std::filesystem::path(fileName).stem().string();
  if (defaultName.empty()) defaultName = "mesh";
  std::string currentName = defaultName;
  // Groups are created on their first face, so a name without faces makes no mesh.
  constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::size_t current = kNone;
  std::size_t faceCount = 0;

  std::vector<std::string_view> tokens;
  std::string_view line;
  while (reader.next(line)) {
    text::splitWhitespace(line, tokens);
    if (tokens.empty()) continue;
    const std::string_view keyword = tokens[0];
    const std::size_t argc = tokens.size() - 1;
    if (keyword == "v" || keyword == "vn") {
      // v may carry a w or an r g b after x y z; they are checked but not kept.
      if (argc < 3 || (keyword == "vn" && argc != 3)) {
        reader.fail(keyword, "3 coordinates expected, found " + std::to_string(argc));
      }
      std::vector<double>& out = keyword == "v" ? v : vn;
      for (std::size_t i = 1; i <= 3; ++i) out.push_back(reader.toDouble(tokens[i], keyword));
      for (std::size_t i = 4; i <= argc; ++i) reader.toDouble(tokens[i], keyword);
    } else if (keyword == "vt") {
      // u [v [w]]; w is dropped.
      if (argc < 1 || argc > 3) {
        reader.fail("vt", "1 to 3 coordinates expected, found " + std::to_string(argc));
      }
      vt.push_back(reader.toDouble(tokens[1], "vt"));
      vt.push_back(argc >= 2 ? reader.toDouble(tokens[2], "vt") : 0.0);
      if (argc == 3) reader.toDouble(tokens[3], "vt");
    } else if (keyword == "f") {
      if (argc < 3) {
        reader.fail("f", "a face needs at least 3 corners, found " + std::to_string(argc));
      }
      if (current == kNone) {
        auto [it, added] = groupByName.try_emplace(currentName, groups.size());
        if (added) groups.push_back(Group{currentName, {}, {}});
        current = it->second;
      }
      Group& group = groups[current];
      const auto vCount = static_cast<int>(v.size() / 3);
      const auto vtCount = static_cast<int>(vt.size() / 2);
      const auto vnCount = static_cast<int>(vn.size() / 3);
      for (std::size_t i = 1; i <= argc; ++i) {
        group.corners.push_back(parseCorner(tokens[i], vCount, vtCount, vnCount, reader));
      }
      group.faceSizes.push_back(static_cast<int>(argc));
      ++faceCount;
    } else if (keyword == "g" || keyword == "o") {
      // The whole rest of the line names the mesh ("g a b" is one mesh "a b"); a bare g
      // returns to the default group, as in the OBJ specification.
      std::string_view name = text::trim(line);
      name = text::trim(name.substr(keyword.size()));
      currentName = name.empty() ? defaultName : text::toUtf8(name);
      current = kNone;
    }
    // Anything else (comments, s, usemtl, mtllib, l, p, vp, curves, ...) carries nothing an
    // IndexedFaceSet holds.
  }
  if (faceCount == 0) throw Error(fileName, 0, {}, "no faces (no 'f' lines)");

  FaceModel model;
  std::vector<int> map(std::max(v.size() / 3, vt.size() / 2), -1);
  for (const Group& group : groups) model.addMeshWithTransform(buildMesh(group, v, vt, vn, map));
  return model;
}

FaceModel readObj(const std::filesystem::path& path) {
  return parseObj(readFile(path), path.string());
}

std::string objText(const FaceModel& model) {
  model.validate();
  const std::vector<Eigen::Affine3d> world = model.meshWorldMatrices();
  std::string out = "# mpeg4face\n";
  char buffer[64];
  long long first = 1;  // OBJ number of the current mesh's vertex 0
  for (std::size_t m = 0; m < model.meshes.size(); ++m) {
    const IndexedFaceSet& mesh = model.meshes[m];
    // A name on one line; an empty one would make `o` name nothing.
    std::string name = mesh.name.empty() ? "mesh" + std::to_string(m) : mesh.name;
    std::replace(name.begin(), name.end(), '\n', ' ');
    std::replace(name.begin(), name.end(), '\r', ' ');
    out += "o " + name + "\n";
    for (int i = 0; i < mesh.vertexCount(); ++i) {
      const Eigen::Vector3d p = world[m] * mesh.coord.row(i).transpose();
      out += 'v';
      for (int c = 0; c < 3; ++c) {
        if (!std::isfinite(p[c])) {
          throw Error({}, 0, "meshes[" + std::to_string(m) + "].coord[" + std::to_string(i) + "]",
                      "position is not finite");
        }
        out += ' ';
        out.append(buffer, std::to_chars(buffer, buffer + sizeof buffer, p[c]).ptr);
      }
      out += '\n';
    }
    for (const auto& [begin, end] : mesh.faceRanges()) {
      out += 'f';
      for (int k = begin; k < end; ++k) {
        out += ' ';
        out += std::to_string(first + mesh.coordIndex[static_cast<std::size_t>(k)]);
      }
      out += '\n';
    }
    first += mesh.vertexCount();
  }
  return out;
}

void writeObj(const FaceModel& model, const std::filesystem::path& path) {
  writeFileAtomically(path, objText(model));
}

}  // namespace mpeg4face
