// SPDX-License-Identifier: GPL-3.0-or-later
#include <charconv>
#include <set>
#include <string>
#include <vector>

#include "io/vrml_names.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fit/node.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/vrml.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

namespace names = vrml_names;

// The BIFS node interfaces (docs/vrml.md) as VRML97 PROTOs, so that a VRML97 reader accepts
// the nodes. A PROTO's first body node gives its type; an empty Group is a valid child
// anywhere and renders nothing. Face renders its renderedFace, the standard's output field
// for the animated face (empty in our files: a decoder fills it).
std::string protoDeclarations() {
  std::string s =
      "PROTO Face [\n"
      "  exposedField SFNode fap NULL\n"
      "  exposedField SFNode fdp NULL\n"
      "  exposedField SFNode fit NULL\n"
      "  exposedField SFNode ttsSource NULL\n"
      "  exposedField MFNode renderedFace []\n"
      "] { Group { children IS renderedFace } }\n"
      "PROTO FDP [\n"
      "  exposedField SFNode featurePointsCoord NULL\n"
      "  exposedField SFNode textureCoord NULL\n"
      "  exposedField MFNode faceDefTables []\n"
      "  exposedField MFNode faceSceneGraph []\n"
      "  field SFBool useOrthoTexture FALSE\n"
      "] { Group {} }\n"
      "PROTO FaceDefTables [\n"
      "  field SFInt32 fapID 1\n"
      "  field SFInt32 highLevelSelect 1\n"
      "  exposedField MFNode faceDefMesh []\n"
      "  exposedField MFNode faceDefTransform []\n"
      "] { Group {} }\n"
      "PROTO FaceDefMesh [\n"
      "  field SFNode faceSceneGraphNode NULL\n"
      "  field MFInt32 intervalBorders []\n"
      "  field MFInt32 coordIndex []\n"
      "  field MFVec3f displacements []\n"
      "] { Group {} }\n"
      "PROTO FaceDefTransform [\n"
      "  field SFNode faceSceneGraphNode NULL\n"
      "  field SFInt32 fieldId 1\n"
      "  field SFRotation rotationDef 0 0 1 0\n"
      "  field SFVec3f scaleDef 1 1 1\n"
      "  field SFVec3f translationDef 0 0 0\n"
      "] { Group {} }\n"
      "PROTO FIT [\n"
      "  exposedField MFInt32 FAPs []\n"
      "  exposedField MFInt32 Graph []\n"
      "  exposedField MFInt32 numeratorExp []\n"
      "  exposedField MFInt32 denominatorExp []\n"
      "  exposedField MFInt32 numeratorImpulse []\n"
      "  exposedField MFInt32 numeratorTerms []\n"
      "  exposedField MFInt32 denominatorTerms []\n"
      "  exposedField MFFloat numeratorCoefs []\n"
      "  exposedField MFFloat denominatorCoefs []\n"
      "] { Group {} }\n"
      "PROTO Viseme [\n"
      "  exposedField SFInt32 viseme_select1 0\n"
      "  exposedField SFInt32 viseme_select2 0\n"
      "  exposedField SFInt32 viseme_blend 0\n"
      "  exposedField SFBool viseme_def FALSE\n"
      "] { Group {} }\n"
      "PROTO Expression [\n"
      "  exposedField SFInt32 expression_select1 0\n"
      "  exposedField SFInt32 expression_intensity1 0\n"
      "  exposedField SFInt32 expression_select2 0\n"
      "  exposedField SFInt32 expression_intensity2 0\n"
      "  exposedField SFBool init_face FALSE\n"
      "  exposedField SFBool expression_def FALSE\n"
      "] { Group {} }\n"
      "PROTO FAP [\n"
      "  exposedField SFNode viseme NULL\n"
      "  exposedField SFNode expression NULL\n";
  for (const FapInfo& fap : fapTable()) {
    if (fap.number < 3) continue;
    s += "  exposedField SFInt32 ";
    s += fap.bifsName;
    s += " 0\n";
  }
  s += "] { Group {} }\n";
  return s;
}

bool isKeyword(std::string_view id) {
  static constexpr std::string_view kKeywords[] = {
      "DEF", "EXTERNPROTO", "FALSE", "IS",      "NULL",     "PROTO",        "ROUTE",
      "TO",  "TRUE",        "USE",   "eventIn", "eventOut", "exposedField", "field"};
  for (std::string_view k : kKeywords) {
    if (k == id) return true;
  }
  return false;
}

void appendEscape(std::string& out, unsigned char c) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  out += names::kEscape;
  out += kHex[c >> 4];
  out += kHex[c & 0xf];
}

// The DEF name for `name` before it is made unique (see io/vrml_names.hpp).
std::string encodeName(std::string_view name) {
  std::string out;
  for (std::size_t i = 0; i < name.size(); ++i) {
    const auto c = static_cast<unsigned char>(name[i]);
    const bool letter = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
    const bool digitOrDash = (c >= '0' && c <= '9') || c == '-';
    if (letter || (digitOrDash && i > 0)) {
      out += static_cast<char>(c);
    } else {
      appendEscape(out, c);
    }
  }
  if (isKeyword(out)) {
    const auto first = static_cast<unsigned char>(out[0]);
    out.erase(0, 1);
    std::string escaped;
    appendEscape(escaped, first);
    out.insert(0, escaped);
  }
  return out;
}

std::string uniqueName(std::string_view name, std::set<std::string>& taken) {
  const std::string base = encodeName(name);
  if (!base.empty() && taken.insert(base).second) return base;
  for (int k = base.empty() ? 1 : 2;; ++k) {
    std::string candidate = base + std::string(names::kUniqueSuffix) + std::to_string(k);
    if (taken.insert(candidate).second) return candidate;
  }
}

std::string vrmlString(std::string_view s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + '"';
}

template <typename Matrix>
void requireFinite(const Matrix& m, const std::string& field) {
  if (!m.allFinite()) throw Error({}, 0, field, "holds a number that is not finite");
}

class Writer {
 public:
  explicit Writer(const MpegFace& face) : face_(face), model_(face.faceSceneGraph) {}

  std::string run() {
    check();
    order();
    out_ =
        "#VRML V2.0 utf8\n"
        "# An MPEG-4 face (ISO/IEC 14496 FDP with Face Animation Tables) written by mpeg4face.\n"
        "# The PROTOs declare the MPEG-4 nodes so that VRML97 readers accept them.\n\n";
    out_ += protoDeclarations();
    out_ += "\nFace {\n  fap FAP {}\n";
    writeFit(2);
    out_ += "  fdp FDP {\n";
    writeFeaturePointsCoord(4);
    writeSceneGraph(4);
    writeTables(4);
    out_ += "  }\n}\n";
    writeFeaturePointInfo();
    return std::move(out_);
  }

 private:
  void check() const {
    model_.validate();
    for (std::size_t m = 0; m < model_.meshes.size(); ++m) {
      const IndexedFaceSet& mesh = model_.meshes[m];
      const std::string where = "meshes[" + std::to_string(m) + "] '" + mesh.name + "' ";
      requireFinite(mesh.coord, where + "coord");
      requireFinite(mesh.normal, where + "normal");
      requireFinite(mesh.texCoord, where + "texCoord");
      for (int index : mesh.coordIndex) {
        if (index < -1) throw Error({}, 0, where + "coordIndex", "negative index other than -1");
      }
      for (int index : mesh.texCoordIndex) {
        if (index < -1) throw Error({}, 0, where + "texCoordIndex", "negative index other than -1");
      }
    }
    for (std::size_t t = 0; t < model_.transforms.size(); ++t) {
      const Transform& tr = model_.transforms[t];
      const std::string where = "transforms[" + std::to_string(t) + "] '" + tr.name + "' ";
      requireFinite(tr.translation, where + "translation");
      requireFinite(tr.rotation.coeffs(), where + "rotation");
      requireFinite(tr.scale, where + "scale");
      requireFinite(tr.center, where + "center");
    }
    const std::vector<Eigen::Affine3d> world = model_.meshWorldMatrices();
    for (const auto& [id, fp] : model_.featurePoints) {
      if (findFeaturePoint(id) == nullptr) {
        throw Error({}, 0, "featurePoints", "'" + id + "' is not an MPEG-4 feature point");
      }
      if (fp.mesh < 0) {
        requireFinite(fp.position, "featurePoints " + id);
      } else {  // validate() checked the vertex; featurePointsCoord holds its world position
        requireFinite(world[fp.mesh] * model_.meshes[fp.mesh].coord.row(fp.vertex).transpose(),
                      "featurePoints " + id + " (its vertex through the transforms)");
      }
    }
    for (std::size_t i = 0; i < face_.faceDefTables.size(); ++i) checkTable(i);
  }

  void checkTable(std::size_t i) const {
    const FaceDefTables& table = face_.faceDefTables[i];
    const std::string where = "faceDefTables[" + std::to_string(i) + "]";
    if (table.fapID < 1 || table.fapID > kFapCount) {
      throw Error({}, 0, where + ".fapID",
                  std::to_string(table.fapID) + " is not a FAP number (1..68)");
    }
    for (std::size_t j = 0; j < table.faceDefMesh.size(); ++j) {
      const FaceDefMesh& def = table.faceDefMesh[j];
      const std::string field = where + ".faceDefMesh[" + std::to_string(j) + "]";
      if (def.mesh < 0 || def.mesh >= static_cast<int>(model_.meshes.size())) {
        throw Error({}, 0, field + ".mesh", "mesh " + std::to_string(def.mesh) + " out of range");
      }
      try {
        checkIntervalBorders(def.intervalBorders);
      } catch (const Error& e) {
        throw Error({}, 0, field + ".intervalBorders", e.reason());
      }
      const int vertexCount = model_.meshes[def.mesh].vertexCount();
      for (int v : def.coordIndex) {
        if (v < 0 || v >= vertexCount) {
          throw Error({}, 0, field + ".coordIndex",
                      "vertex " + std::to_string(v) + " out of range (mesh '" +
                          model_.meshes[def.mesh].name + "' has " + std::to_string(vertexCount) +
                          " vertices)");
        }
      }
      const auto expected = static_cast<Eigen::Index>(def.coordIndex.size()) * def.intervalCount();
      if (def.displacements.rows() != expected) {
        throw Error({}, 0, field + ".displacements",
                    "has " + std::to_string(def.displacements.rows()) + " rows, expected " +
                        std::to_string(expected) + " (coordIndex entries x intervals)");
      }
      requireFinite(def.displacements, field + ".displacements");
    }
    for (std::size_t j = 0; j < table.faceDefTransform.size(); ++j) {
      const FaceDefTransform& def = table.faceDefTransform[j];
      const std::string field = where + ".faceDefTransform[" + std::to_string(j) + "]";
      if (def.transform < 0 || def.transform >= static_cast<int>(model_.transforms.size())) {
        throw Error({}, 0, field + ".transform",
                    "transform " + std::to_string(def.transform) + " out of range");
      }
      const int fieldId = static_cast<int>(def.fieldId);
      if (fieldId < 1 || fieldId > 3) {
        throw Error({}, 0, field + ".fieldId", std::to_string(fieldId) + " is not 1, 2 or 3");
      }
      requireFinite(def.rotationDef, field + ".rotationDef");
      requireFinite(def.scaleDef, field + ".scaleDef");
      requireFinite(def.translationDef, field + ".translationDef");
    }
  }

  // The writing order. The reader numbers meshes in the order they first appear, but a
  // Transform holds its meshes and its child Transforms in two lists, so their interleaving
  // in `children` is chosen here: a mesh goes before the next child Transform when it is
  // already written or the next in number, otherwise that child comes first. This restores
  // the order of any face the reader made (a mesh of higher number follows the subtree that
  // introduced the lower one). The top level interleaves the meshes no Transform holds with
  // the roots the same way. An order no interleaving gives (a model made otherwise) is kept
  // by Shapes of every mesh in number order ahead of the roots: the reader numbers them
  // there, and a top-level Shape of a mesh that a Transform holds adds nothing to the model.
  void order() {
    std::vector<int> transformOrder, firstUse;
    std::vector<bool> meshSeen(model_.meshes.size(), false);
    std::vector<bool> reached(model_.transforms.size(), false);
    childItems_.resize(model_.transforms.size());
    const auto merge = [&](const std::vector<int>& meshes, const std::vector<int>& transforms,
                           std::vector<Item>& items, const auto& walk) {
      std::size_t i = 0, j = 0;
      while (i < meshes.size() || j < transforms.size()) {
        const bool meshNext = i < meshes.size() && (j == transforms.size() || meshSeen[meshes[i]] ||
                                                    meshes[i] == static_cast<int>(firstUse.size()));
        if (meshNext) {
          const int m = meshes[i++];
          if (!meshSeen[m]) firstUse.push_back(m);
          meshSeen[m] = true;
          items.push_back({true, m});
        } else {
          const int t = transforms[j++];
          items.push_back({false, t});
          walk(walk, t);
        }
      }
    };
    std::vector<bool> held(model_.meshes.size(), false);
    for (const Transform& tr : model_.transforms) {
      for (int m : tr.meshes) held[m] = true;
    }
    std::vector<int> unheld;
    for (std::size_t m = 0; m < held.size(); ++m) {
      if (!held[m]) unheld.push_back(static_cast<int>(m));
    }
    // validate() ruled out cycles and shared children, so this walk ends.
    const auto walk = [&](const auto& self, int t) -> void {
      reached[t] = true;
      transformOrder.push_back(t);
      const Transform& tr = model_.transforms[t];
      merge(tr.meshes, tr.children, childItems_[t], self);
    };
    merge(unheld, model_.roots, topItems_, walk);
    for (std::size_t t = 0; t < reached.size(); ++t) {
      if (!reached[t]) {
        throw Error({}, 0,
                    "transforms[" + std::to_string(t) + "] '" + model_.transforms[t].name + "'",
                    "is not reachable from the roots: a VRML scene graph has no place for it");
      }
    }
    bool inNumberOrder = true;
    for (std::size_t k = 0; k < firstUse.size(); ++k) {
      inNumberOrder = inNumberOrder && firstUse[k] == static_cast<int>(k);
    }
    if (!inNumberOrder) {
      topItems_.clear();
      for (std::size_t m = 0; m < model_.meshes.size(); ++m) {
        topItems_.push_back({true, static_cast<int>(m)});
      }
      for (int root : model_.roots) topItems_.push_back({false, root});
    }
    // DEF names: meshes first, so that a mesh keeps its plain name when its transform has
    // the same one.
    std::set<std::string> taken;
    meshDef_.resize(model_.meshes.size());
    transformDef_.resize(model_.transforms.size());
    for (std::size_t m = 0; m < model_.meshes.size(); ++m) {
      meshDef_[m] = uniqueName(model_.meshes[m].name, taken);
    }
    for (int t : transformOrder) transformDef_[t] = uniqueName(model_.transforms[t].name, taken);
    meshWritten_.assign(model_.meshes.size(), false);
  }

  // A child of a Transform or of the faceSceneGraph, in writing order.
  struct Item {
    bool isMesh = false;
    int index = 0;  // into meshes or transforms
  };
  void writeItems(const std::vector<Item>& items, int n) {
    for (const Item& item : items) {
      if (item.isMesh) {
        writeShape(item.index, n);
      } else {
        writeTransform(item.index, n);
      }
    }
  }

  void indent(int n) { out_.append(static_cast<std::size_t>(n), ' '); }

  template <typename T>
  void number(T value) {
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
    out_.append(buffer, result.ptr);
  }

  template <typename Vector>
  void numbers(const Vector& v) {
    for (Eigen::Index i = 0; i < v.size(); ++i) {
      if (i > 0) out_ += ' ';
      number(v[i]);
    }
  }

  // `name value\n` at `n` spaces.
  template <typename Vector>
  void vectorField(int n, std::string_view name, const Vector& v) {
    indent(n);
    out_ += name;
    out_ += ' ';
    numbers(v);
    out_ += '\n';
  }

  // Rows of `points` one per line inside `name [ ... ]`; `comments` (if given) after each.
  template <typename Points>
  void pointList(int n, std::string_view name, const Points& points,
                 const std::vector<std::string>* comments = nullptr) {
    indent(n);
    out_ += name;
    out_ += " [\n";
    for (Eigen::Index r = 0; r < points.rows(); ++r) {
      indent(n + 2);
      numbers(points.row(r));
      out_ += ',';
      if (comments != nullptr) {
        out_ += "  # ";
        out_ += (*comments)[static_cast<std::size_t>(r)];
      }
      out_ += '\n';
    }
    indent(n);
    out_ += "]\n";
  }

  // A polygon index list, one face per line.
  void indexList(int n, std::string_view name, const std::vector<int>& indices) {
    indent(n);
    out_ += name;
    out_ += " [\n";
    bool lineOpen = false;
    for (int index : indices) {
      if (!lineOpen)
        indent(n + 2);
      else
        out_ += ' ';
      number(index);
      lineOpen = index >= 0;
      if (!lineOpen) out_ += '\n';
    }
    if (lineOpen) out_ += '\n';
    indent(n);
    out_ += "]\n";
  }

  void intList(std::string_view name, const std::vector<int>& values) {
    out_ += name;
    out_ += " [";
    for (int v : values) {
      out_ += ' ';
      number(v);
    }
    out_ += " ]\n";
  }

  void writeFit(int n) {
    if (!face_.fit) return;
    const FitNodeFields f = fitNodeFields(*face_.fit);
    indent(n);
    out_ += "fit FIT {\n";
    for (const auto& [name, values] : {std::pair{"FAPs", &f.FAPs}, std::pair{"Graph", &f.Graph},
                                       std::pair{"numeratorExp", &f.numeratorExp},
                                       std::pair{"denominatorExp", &f.denominatorExp},
                                       std::pair{"numeratorImpulse", &f.numeratorImpulse},
                                       std::pair{"numeratorTerms", &f.numeratorTerms},
                                       std::pair{"denominatorTerms", &f.denominatorTerms}}) {
      indent(n + 2);
      intList(name, *values);
    }
    for (const auto& [name, values] : {std::pair{"numeratorCoefs", &f.numeratorCoefs},
                                       std::pair{"denominatorCoefs", &f.denominatorCoefs}}) {
      indent(n + 2);
      out_ += name;
      out_ += " [";
      for (double v : *values) {
        out_ += ' ';
        number(v);
      }
      out_ += " ]\n";
    }
    indent(n);
    out_ += "}\n";
  }

  void writeFeaturePointsCoord(int n) {
    if (model_.featurePoints.empty()) return;
    const std::vector<Eigen::Affine3d> world = model_.meshWorldMatrices();
    Points3 points(kFeaturePointCount, 3);
    std::vector<std::string> comments;
    int row = 0;
    for (const FeaturePointInfo& info : featurePointTable()) {
      if (!info.inStandard) continue;
      Eigen::Vector3d p = Eigen::Vector3d::Zero();  // the filler of an unbound point
      comments.emplace_back(info.id);
      const auto it = model_.featurePoints.find(std::string(info.id));
      if (it == model_.featurePoints.end()) {
        comments.back() += " none";
      } else if (it->second.mesh < 0) {
        p = it->second.position;
      } else {
        const FeaturePointBinding& fp = it->second;
        p = world[fp.mesh] * model_.meshes[fp.mesh].coord.row(fp.vertex).transpose();
        comments.back() += " vertex";
      }
      points.row(row++) = p.transpose();
    }
    indent(n);
    out_ += "featurePointsCoord Coordinate {\n";
    pointList(n + 2, "point", points, &comments);
    indent(n);
    out_ += "}\n";
  }

  void writeSceneGraph(int n) {
    indent(n);
    out_ += "faceSceneGraph [\n";
    writeItems(topItems_, n + 2);
    indent(n);
    out_ += "]\n";
  }

  void writeTransform(int t, int n) {
    const Transform& tr = model_.transforms[t];
    indent(n);
    out_ += "DEF " + transformDef_[t] + " Transform {\n";
    if (!tr.translation.isZero(0)) vectorField(n + 2, "translation", tr.translation);
    if (!tr.rotation.vec().isZero(0)) {
      const Eigen::AngleAxisd aa(tr.rotation);
      Eigen::Vector4d r;
      r << aa.axis(), aa.angle();
      vectorField(n + 2, "rotation", r);
    }
    if (tr.scale != Eigen::Vector3d::Ones()) vectorField(n + 2, "scale", tr.scale);
    if (!tr.center.isZero(0)) vectorField(n + 2, "center", tr.center);
    if (!tr.meshes.empty() || !tr.children.empty()) {
      indent(n + 2);
      out_ += "children [\n";
      writeItems(childItems_[t], n + 4);
      indent(n + 2);
      out_ += "]\n";
    }
    indent(n);
    out_ += "}\n";
  }

  void writeShape(int m, int n) {
    indent(n);
    if (meshWritten_[m]) {
      out_ += "Shape { geometry USE " + meshDef_[m] + " }\n";
      return;
    }
    meshWritten_[m] = true;
    const IndexedFaceSet& mesh = model_.meshes[m];
    out_ += "Shape {\n";
    indent(n + 2);
    out_ += "geometry DEF " + meshDef_[m] + " IndexedFaceSet {\n";
    const int k = n + 4;
    if (mesh.coord.rows() > 0) {
      indent(k);
      out_ += "coord Coordinate {\n";
      pointList(k + 2, "point", mesh.coord);
      indent(k);
      out_ += "}\n";
    }
    indexList(k, "coordIndex", mesh.coordIndex);
    if (mesh.normal.rows() > 0) {
      indent(k);
      out_ += "normal Normal {\n";
      pointList(k + 2, "vector", mesh.normal);
      indent(k);
      out_ += "}\n";
    }
    if (mesh.texCoord.rows() > 0) {
      indent(k);
      out_ += "texCoord TextureCoordinate {\n";
      pointList(k + 2, "point", mesh.texCoord);
      indent(k);
      out_ += "}\n";
    }
    if (!mesh.texCoordIndex.empty()) indexList(k, "texCoordIndex", mesh.texCoordIndex);
    indent(n + 2);
    out_ += "}\n";
    indent(n);
    out_ += "}\n";
  }

  void writeTables(int n) {
    if (face_.faceDefTables.empty()) return;
    indent(n);
    out_ += "faceDefTables [\n";
    for (const FaceDefTables& table : face_.faceDefTables) {
      const int k = n + 4;
      indent(n + 2);
      out_ += "FaceDefTables {\n";
      indent(k);
      out_ += "fapID ";
      number(table.fapID);
      out_ += '\n';
      if (table.fapID <= 2 || table.highLevelSelect != 1) {
        indent(k);
        out_ += "highLevelSelect ";
        number(table.highLevelSelect);
        out_ += '\n';
      }
      if (!table.faceDefMesh.empty()) {
        indent(k);
        out_ += "faceDefMesh [\n";
        for (const FaceDefMesh& def : table.faceDefMesh) writeFaceDefMesh(def, k + 2);
        indent(k);
        out_ += "]\n";
      }
      if (!table.faceDefTransform.empty()) {
        indent(k);
        out_ += "faceDefTransform [\n";
        for (const FaceDefTransform& def : table.faceDefTransform)
          writeFaceDefTransform(def, k + 2);
        indent(k);
        out_ += "]\n";
      }
      indent(n + 2);
      out_ += "}\n";
    }
    indent(n);
    out_ += "]\n";
  }

  void writeFaceDefMesh(const FaceDefMesh& def, int n) {
    indent(n);
    out_ += "FaceDefMesh {\n";
    indent(n + 2);
    out_ += "faceSceneGraphNode USE " + meshDef_[def.mesh] + '\n';
    indent(n + 2);
    intList("intervalBorders", def.intervalBorders);
    indent(n + 2);
    intList("coordIndex", def.coordIndex);
    // One line per affected vertex: its displacement in each interval.
    indent(n + 2);
    out_ += "displacements [\n";
    const int intervals = def.intervalCount();
    for (Eigen::Index r = 0; r < def.displacements.rows(); ++r) {
      if (r % intervals == 0) indent(n + 4);
      numbers(def.displacements.row(r));
      out_ += (r + 1) % intervals == 0 ? ",\n" : ", ";
    }
    indent(n + 2);
    out_ += "]\n";
    indent(n);
    out_ += "}\n";
  }

  void writeFaceDefTransform(const FaceDefTransform& def, int n) {
    indent(n);
    out_ += "FaceDefTransform {\n";
    indent(n + 2);
    out_ += "faceSceneGraphNode USE " + transformDef_[def.transform] + '\n';
    indent(n + 2);
    out_ += "fieldId ";
    number(static_cast<int>(def.fieldId));
    out_ += '\n';
    // Every definition that differs from its default, whatever fieldId uses, so that the
    // table reads back as it was.
    if (def.rotationDef != Eigen::Vector4d(0, 0, 1, 0))
      vectorField(n + 2, "rotationDef", def.rotationDef);
    if (def.scaleDef != Eigen::Vector3d::Ones()) vectorField(n + 2, "scaleDef", def.scaleDef);
    if (!def.translationDef.isZero(0)) vectorField(n + 2, "translationDef", def.translationDef);
    indent(n);
    out_ += "}\n";
  }

  void writeFeaturePointInfo() {
    std::vector<std::string> info;
    for (const FeaturePointInfo& fpInfo : featurePointTable()) {
      const std::string id(fpInfo.id);
      const auto it = model_.featurePoints.find(id);
      if (it == model_.featurePoints.end()) {
        if (fpInfo.inStandard) info.push_back(id + ' ' + std::string(names::kNone));
      } else if (it->second.mesh >= 0) {
        info.push_back(id + ' ' + std::string(names::kMesh) + ' ' + meshDef_[it->second.mesh] +
                       ' ' + std::string(names::kVertex) + ' ' + std::to_string(it->second.vertex));
      } else if (!fpInfo.inStandard) {
        std::string line = id + ' ' + std::string(names::kPosition);
        for (int c = 0; c < 3; ++c) {
          char buffer[32];
          line += ' ';
          line.append(buffer,
                      std::to_chars(buffer, buffer + sizeof buffer, it->second.position[c]).ptr);
        }
        info.push_back(line);
      }
    }
    // Nothing bound at all: no featurePointsCoord was written, so nothing needs explaining.
    if (model_.featurePoints.empty()) return;
    out_ += "\nWorldInfo {\n  title " + vrmlString(names::kFeaturePointsTitle) + "\n  info [\n";
    for (const std::string& line : info) out_ += "    " + vrmlString(line) + '\n';
    out_ += "  ]\n}\n";
  }

  const MpegFace& face_;
  const FaceModel& model_;
  std::string out_;
  std::vector<std::string> meshDef_, transformDef_;
  std::vector<bool> meshWritten_;
  std::vector<Item> topItems_;
  std::vector<std::vector<Item>> childItems_;  // per transform
};

}  // namespace

std::string vrmlText(const MpegFace& face) { return Writer(face).run(); }

void writeVrml(const MpegFace& face, const std::filesystem::path& path) {
  std::string text;
  try {
    text = vrmlText(face);
  } catch (const Error& e) {
    throw Error(path.string(), 0, e.field(), e.reason());
  }
  writeFileAtomically(path, text);
}

}  // namespace mpeg4face
