// SPDX-License-Identifier: GPL-3.0-or-later
// A VRML97 parser: a lexer over the whole text (io/vrml_lexer.cpp), a recursive-descent parser
// that reads the nodes a face needs into typed structs (and every other node generically, so
// that its DEFs still resolve; io/vrml_parser.cpp, io/vrml_node_fields.cpp), then a pass here that
// builds the MpegFace from the Face node or the top level.
#include <algorithm>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "io/text_reader.hpp"
#include "io/vrml_names.hpp"
#include "io/vrml_reader.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fit/node.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/vrml.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace vrml_reader {
namespace {

namespace names = vrml_names;

// A Coordinate (Normal, TextureCoordinate) that several IndexedFaceSets USE is copied into
// each mesh. The first copy costs what the file holds; the numbers of the further copies
// are bounded by this, so that a small file cannot ask for unbounded memory.
constexpr std::size_t kMaxCopiedNumbers = std::size_t{1} << 24;

// ---------------------------------------------------------------------------------------
// From parsed nodes to the MpegFace

class Builder {
 public:
  Builder(const Parser& parser, std::string file) : parser_(parser), file_(std::move(file)) {}

  MpegFace build() {
    const std::vector<NodePtr>& faces = parser_.faces_;
    const FdpNode* fdp = nullptr;
    if (faces.size() > 1) {
      fail(faces[1]->line, "Face",
           "a second Face node (the first is on line " + std::to_string(faces[0]->line) +
               "): mpeg4face reads one face per file");
    }
    if (faces.size() == 1) {
      const Node& node = *faces[0];
      const FaceNode& faceNode = std::get<FaceNode>(node.data);
      if (!faceNode.topLevel) {
        fail(node.line, "Face", "a Face inside another node; only a top-level Face is read");
      }
      fdp = as<FdpNode>(faceNode.fdp);
      if (fdp == nullptr) fail(node.line, "Face.fdp", "the Face has no FDP, so no face model");
      for (const NodePtr& n : fdp->faceSceneGraph) place(n, -1);
      for (const NodePtr& n : fdp->faceDefTables) table(*n);
      featurePointsCoord(fdp->featurePointsCoord);
      if (const FitNode* fit = as<FitNode>(faceNode.fit)) {
        try {
          face_.fit = fitTableFromNode(fit->fields, file_);
        } catch (const Error& e) {
          fail(faceNode.fit->line, e.field(), e.reason());
        }
      }
    } else {
      for (const NodePtr& n : parser_.topLevel_) place(n, -1);
    }
    for (const NodePtr& n : parser_.topLevel_) {
      const WorldInfoNode* info = as<WorldInfoNode>(n);
      if (info != nullptr && info->title == names::kFeaturePointsTitle) featurePointInfo(*n, *info);
    }
    return std::move(face_);
  }

 private:
  [[noreturn]] void fail(int line, std::string_view field, const std::string& message) const {
    throw Error(file_, line, std::string(field), message);
  }

  void place(const NodePtr& node, int parent) {
    FaceModel& model = face_.faceSceneGraph;
    if (const GroupNode* group = as<GroupNode>(node)) {
      if (transformOf_.count(node.get()) != 0) {
        fail(node->line, node->type,
             text::quote(node->def) + " (DEF on this line) is used a second time in the scene " +
                 "graph; a face scene graph is a tree (one parent per Transform)");
      }
      const int t = static_cast<int>(model.transforms.size());
      transformOf_[node.get()] = t;
      model.transforms.push_back(group->transform);
      if (parent < 0) {
        model.roots.push_back(t);
      } else {
        model.transforms[static_cast<std::size_t>(parent)].children.push_back(t);
      }
      for (const NodePtr& child : group->children) place(child, t);
    } else if (const ShapeNode* shape = as<ShapeNode>(node)) {
      // Other geometry (Box, IndexedLineSet, ...) is not a mesh of the face.
      if (as<IndexedFaceSetNode>(shape->geometry) == nullptr) return;
      const int m = mesh(shape->geometry, *node);
      if (parent >= 0) model.transforms[static_cast<std::size_t>(parent)].meshes.push_back(m);
    }
  }

  template <typename Points>
  Points points(const NodePtr& node) {
    const PointsNode& p = std::get<PointsNode>(node->data);
    if (!copied_.insert(node.get()).second) {  // a further use of a USE'd node
      copiedNumbers_ += p.values.size();
      if (copiedNumbers_ > kMaxCopiedNumbers) {
        fail(node->line, node->type,
             "USE'd by so many IndexedFaceSets that the copies would hold more than " +
                 std::to_string(kMaxCopiedNumbers) + " numbers");
      }
    }
    return Eigen::Map<const Points>(p.values.data(), p.count(), p.dimension);
  }

  int mesh(const NodePtr& node, const Node& shape) {
    const auto it = meshOf_.find(node.get());
    if (it != meshOf_.end()) return it->second;
    const IndexedFaceSetNode& ifs = std::get<IndexedFaceSetNode>(node->data);
    IndexedFaceSet mesh;
    mesh.name = nameFromDef(node->def.empty() ? shape.def : node->def);
    if (ifs.coord) mesh.coord = points<Points3>(ifs.coord);
    mesh.coordIndex = ifs.coordIndex;
    if (ifs.keepNormals) mesh.normal = points<Points3>(ifs.normal);
    if (ifs.keepTexCoord) {
      mesh.texCoord = points<Points2>(ifs.texCoord);
      mesh.texCoordIndex = ifs.texCoordIndex;
    }
    FaceModel& model = face_.faceSceneGraph;
    const int m = static_cast<int>(model.meshes.size());
    model.meshes.push_back(std::move(mesh));
    meshOf_[node.get()] = m;
    return m;
  }

  void table(const Node& node) {
    const FaceDefTablesNode& tables = std::get<FaceDefTablesNode>(node.data);
    FaceDefTables out;
    out.fapID = tables.fapID;
    out.highLevelSelect = tables.highLevelSelect;
    for (const NodePtr& n : tables.faceDefMesh) {
      const FaceDefMeshNode& fdm = std::get<FaceDefMeshNode>(n->data);
      const auto it = meshOf_.find(fdm.target.get());
      if (it == meshOf_.end()) {
        fail(n->lineOf("faceSceneGraphNode"), n->field("faceSceneGraphNode"),
             "the IndexedFaceSet " + text::quote(fdm.target->def) +
                 " is not a mesh of the faceSceneGraph");
      }
      out.faceDefMesh.push_back(fdm.def);
      out.faceDefMesh.back().mesh = it->second;
    }
    for (const NodePtr& n : tables.faceDefTransform) {
      const FaceDefTransformNode& fdt = std::get<FaceDefTransformNode>(n->data);
      const auto it = transformOf_.find(fdt.target.get());
      if (it == transformOf_.end()) {
        fail(n->lineOf("faceSceneGraphNode"), n->field("faceSceneGraphNode"),
             "the Transform " + text::quote(fdt.target->def) + " is not in the faceSceneGraph");
      }
      out.faceDefTransform.push_back(fdt.def);
      out.faceDefTransform.back().transform = it->second;
    }
    face_.faceDefTables.push_back(std::move(out));
  }

  // The 84 standard points in group/index order, each a free coordinate until the WorldInfo
  // says otherwise.
  void featurePointsCoord(const NodePtr& node) {
    const PointsNode* p = as<PointsNode>(node);
    if (p == nullptr || p->count() == 0) return;
    std::size_t row = 0;
    for (const FeaturePointInfo& info : featurePointTable()) {
      if (!info.inStandard) continue;
      FeaturePointBinding binding;
      binding.position =
          Eigen::Vector3d(p->values[row * 3], p->values[row * 3 + 1], p->values[row * 3 + 2]);
      face_.faceSceneGraph.featurePoints[std::string(info.id)] = binding;
      ++row;
    }
  }

  void featurePointInfo(const Node& node, const WorldInfoNode& info) {
    FaceModel& model = face_.faceSceneGraph;
    const std::vector<Eigen::Affine3d> world = model.meshWorldMatrices();
    std::vector<std::string_view> tokens;
    std::vector<std::string> seen;
    for (std::size_t i = 0; i < info.info.size(); ++i) {
      const std::string& entry = info.info[i];
      const auto bad = [&](const std::string& why) {
        fail(node.lineOf("info"), node.field("info"),
             "entry " + std::to_string(i + 1) + " " + text::quote(entry) + ": " + why);
      };
      text::splitWhitespace(entry, tokens);
      if (tokens.empty()) bad("empty");
      const std::string id(tokens[0]);
      if (findFeaturePoint(id) == nullptr) bad("not an MPEG-4 feature point");
      if (std::find(seen.begin(), seen.end(), id) != seen.end()) bad("the point is listed twice");
      seen.push_back(id);
      if (tokens.size() == 2 && tokens[1] == names::kNone) {
        model.featurePoints.erase(id);
      } else if (tokens.size() == 5 && tokens[1] == names::kMesh && tokens[3] == names::kVertex) {
        const auto def = parser_.defs_.find(tokens[2]);
        const auto mesh =
            def == parser_.defs_.end() ? meshOf_.end() : meshOf_.find(def->second.get());
        if (mesh == meshOf_.end()) bad("no IndexedFaceSet of the faceSceneGraph has that DEF name");
        FeaturePointBinding binding;
        binding.mesh = mesh->second;
        if (!text::tryParseInt(tokens[4], binding.vertex) || binding.vertex < 0 ||
            binding.vertex >= model.meshes[static_cast<std::size_t>(binding.mesh)].vertexCount()) {
          bad("vertex " + text::quote(tokens[4]) + " is not a vertex of that mesh");
        }
        // Its position in the face is what featurePointsCoord holds when the face is written.
        const IndexedFaceSet& held = model.meshes[static_cast<std::size_t>(binding.mesh)];
        if (!(world[static_cast<std::size_t>(binding.mesh)] *
              held.coord.row(binding.vertex).transpose())
                 .allFinite()) {
          bad("the vertex's position in the face (scaled and moved by the Transforms above its "
              "mesh) is beyond the range of double");
        }
        model.featurePoints[id] = binding;
      } else if (tokens.size() == 5 && tokens[1] == names::kPosition) {
        FeaturePointBinding binding;
        for (int c = 0; c < 3; ++c) {
          if (!text::tryParseDouble(tokens[2 + c], binding.position[c])) {
            bad(text::quote(tokens[2 + c]) + " is not a finite number");
          }
        }
        model.featurePoints[id] = binding;
      } else {
        bad("expected '<id> mesh <DEF name> vertex <n>', '<id> none' or '<id> position <x> <y> "
            "<z>'");
      }
    }
  }

  const Parser& parser_;
  std::string file_;
  MpegFace face_;
  std::unordered_map<const Node*, int> meshOf_, transformOf_;
  std::unordered_set<const Node*> copied_;  // the points nodes copied into a mesh so far
  std::size_t copiedNumbers_ = 0;
};

void checkHeader(std::string_view text, const std::string& file) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  const auto starts = [&](std::string_view s) { return text.substr(0, s.size()) == s; };
  if (starts("#VRML V2.0 utf8")) return;
  std::string why = "not a VRML97 file: the first line must be '#VRML V2.0 utf8'";
  if (starts("\x1f\x8b")) why = "gzip-compressed; decompress it first (gunzip)";
  if (starts("#VRML V1.0")) why = "VRML 1.0 is not supported, only VRML97 ('#VRML V2.0 utf8')";
  if (starts("#X3D")) why = "X3D is not supported, only VRML97 ('#VRML V2.0 utf8')";
  throw Error(file, 1, {}, why);
}

}  // namespace
}  // namespace vrml_reader

MpegFace parseVrml(std::string_view text, const std::string& fileName) {
  vrml_reader::checkHeader(text, fileName);
  vrml_reader::Parser parser(text, fileName);
  parser.parseScene();
  return vrml_reader::Builder(parser, fileName).build();
}

MpegFace readVrml(const std::filesystem::path& path) {
  return parseVrml(readFile(path), path.string());
}

}  // namespace mpeg4face
