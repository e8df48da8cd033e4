// SPDX-License-Identifier: GPL-3.0-or-later
// A VRML97 parser: a lexer over the whole text, a recursive-descent parser that reads the
// nodes a face needs into typed structs (and every other node generically, so that its DEFs
// still resolve), then a pass that builds the MpegFace from the Face node or the top level.
#include <algorithm>
#include <charconv>
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <variant>
#include <vector>

#include "mpeg4face/error.hpp"
#include "mpeg4face/file_io.hpp"
#include "mpeg4face/fit_node.hpp"
#include "mpeg4face/spec.hpp"
#include "mpeg4face/vrml.hpp"
#include "text_reader.hpp"
#include "vrml_names.hpp"

namespace mpeg4face {
namespace {

namespace names = vrml_names;

constexpr int kMaxDepth = 256;
// A Coordinate (Normal, TextureCoordinate) that several IndexedFaceSets USE is copied into
// each mesh. The first copy costs what the file holds; the numbers of the further copies
// are bounded by this, so that a small file cannot ask for unbounded memory.
constexpr std::size_t kMaxCopiedNumbers = std::size_t{1} << 24;

// ---------------------------------------------------------------------------------------
// Lexer

enum class Tok { End, Id, Number, String, LBrace, RBrace, LBracket, RBracket, Period };

struct Token {
  Tok kind = Tok::End;
  std::string_view text;  // for a string: between the quotes, escapes not yet removed
  int line = 0;
};

// VRML97 identifiers (ISO/IEC 14772-1 annex A): no control characters, space, " # ' , . [ \ ]
// { } or DEL; the first character also not a digit, + or -.
bool idRestChar(unsigned char c) {
  if (c <= 0x20 || c == 0x7f) return false;
  switch (c) {
    case '"':
    case '#':
    case '\'':
    case ',':
    case '.':
    case '[':
    case '\\':
    case ']':
    case '{':
    case '}':
      return false;
    default:
      return true;
  }
}
bool idFirstChar(unsigned char c) {
  return idRestChar(c) && !(c >= '0' && c <= '9') && c != '+' && c != '-';
}
bool isDigit(char c) { return c >= '0' && c <= '9'; }

std::string describe(const Token& t) {
  switch (t.kind) {
    case Tok::End:
      return "the end of the file";
    case Tok::String:
      return "a string";
    default:
      return text::quote(t.text);
  }
}

class Lexer {
 public:
  Lexer(std::string_view text, std::string file) : text_(text), file_(std::move(file)) {
    if (text_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3;
  }

  const std::string& file() const { return file_; }
  // The token `ahead` places after the current one (0 = current).
  const Token& peek(std::size_t ahead = 0) {
    while (buffer_.size() <= ahead) buffer_.push_back(scan());
    return buffer_[ahead];
  }
  Token take() {
    Token t = peek();
    buffer_.erase(buffer_.begin());
    return t;
  }
  [[noreturn]] void fail(int line, std::string_view field, const std::string& message) const {
    throw Error(file_, line, std::string(field), message);
  }

 private:
  Token scan() {
    // Whitespace (commas included, as VRML97 says) and comments.
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        ++line_;
        ++pos_;
      } else if (c == ' ' || c == '\t' || c == '\r' || c == ',' || c == '\f' || c == '\v') {
        ++pos_;
      } else if (c == '#') {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
      } else {
        break;
      }
    }
    Token t;
    t.line = line_;
    if (pos_ >= text_.size()) {
      t.line = lastLine_;  // "found the end of the file" on the last line, not after it
      return t;
    }
    lastLine_ = line_;
    const std::size_t begin = pos_;
    const auto c = static_cast<unsigned char>(text_[pos_]);
    const auto punct = [&](Tok kind) {
      t.kind = kind;
      t.text = text_.substr(pos_++, 1);
      return t;
    };
    switch (c) {
      case '{':
        return punct(Tok::LBrace);
      case '}':
        return punct(Tok::RBrace);
      case '[':
        return punct(Tok::LBracket);
      case ']':
        return punct(Tok::RBracket);
      default:
        break;
    }
    if (c == '"') {
      ++pos_;
      while (pos_ < text_.size() && text_[pos_] != '"') {
        if (text_[pos_] == '\\' && pos_ + 1 < text_.size()) ++pos_;
        if (text_[pos_] == '\n') ++line_;
        ++pos_;
      }
      if (pos_ >= text_.size()) fail(t.line, {}, "string not closed (it opens on this line)");
      t.kind = Tok::String;
      t.text = text_.substr(begin + 1, pos_ - begin - 1);
      ++pos_;
      return t;
    }
    if (c == '.' && !(pos_ + 1 < text_.size() && isDigit(text_[pos_ + 1])))
      return punct(Tok::Period);
    if (isDigit(static_cast<char>(c)) || c == '+' || c == '-' || c == '.') {
      // Everything up to the next separator; the parser checks the number (a stray letter
      // in "1.5x" is an error there, with the field's name).
      while (pos_ < text_.size() && idRestChar(static_cast<unsigned char>(text_[pos_]))) ++pos_;
      while (pos_ < text_.size() && text_[pos_] == '.') {  // '.' ends identifiers, not numbers
        ++pos_;
        while (pos_ < text_.size() && idRestChar(static_cast<unsigned char>(text_[pos_]))) ++pos_;
      }
      t.kind = Tok::Number;
      t.text = text_.substr(begin, pos_ - begin);
      return t;
    }
    if (idFirstChar(c)) {
      while (pos_ < text_.size() && idRestChar(static_cast<unsigned char>(text_[pos_]))) ++pos_;
      t.kind = Tok::Id;
      t.text = text_.substr(begin, pos_ - begin);
      return t;
    }
    fail(t.line, {}, "unexpected character " + text::quote(text_.substr(pos_, 1)));
  }

  std::string_view text_;
  std::string file_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int lastLine_ = 1;  // the line of the last token
  std::vector<Token> buffer_;
};

std::string unescape(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\\' && i + 1 < s.size()) ++i;
    out += s[i];
  }
  return out;
}

// The name a DEF name stands for (see vrml_names.hpp): '%XX' escapes decoded, a trailing
// '%_<digits>' dropped. Other '%' are kept as they are.
int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}
std::string nameFromDef(std::string_view def) {
  const std::size_t suffix = def.rfind(names::kUniqueSuffix);
  if (suffix != std::string_view::npos) {
    const std::string_view digits = def.substr(suffix + names::kUniqueSuffix.size());
    if (!digits.empty() && std::all_of(digits.begin(), digits.end(), isDigit)) {
      def = def.substr(0, suffix);
    }
  }
  std::string out;
  for (std::size_t i = 0; i < def.size(); ++i) {
    if (def[i] == names::kEscape && i + 2 < def.size() && hexValue(def[i + 1]) >= 0 &&
        hexValue(def[i + 2]) >= 0) {
      out += static_cast<char>(hexValue(def[i + 1]) * 16 + hexValue(def[i + 2]));
      i += 2;
    } else {
      out += def[i];
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// Parsed nodes

struct Node;
using NodePtr = std::shared_ptr<Node>;

struct PointsNode {  // Coordinate, Normal (3 numbers per point), TextureCoordinate (2)
  int dimension = 3;
  std::vector<double> values;
  Eigen::Index count() const { return static_cast<Eigen::Index>(values.size()) / dimension; }
};
struct IndexedFaceSetNode {
  NodePtr coord, normal, texCoord;
  std::vector<int> coordIndex, normalIndex, texCoordIndex;
  bool ccw = true;
  bool normalPerVertex = true;
  bool keepNormals = false;   // set by finish(): the normals are one per vertex
  bool keepTexCoord = false;  // set by finish(): texCoordIndex or one per vertex
};
struct ShapeNode {
  NodePtr geometry;
};
struct GroupNode {  // Transform, Group, Anchor, Collision
  bool isTransform = false;
  Transform transform;
  Eigen::Quaterniond scaleOrientation = Eigen::Quaterniond::Identity();
  std::vector<NodePtr> children;
};
struct FaceNode {
  NodePtr fdp;
  NodePtr fit;
  bool topLevel = false;
};
struct FdpNode {
  NodePtr featurePointsCoord;
  std::vector<NodePtr> faceDefTables, faceSceneGraph;
};
struct FaceDefTablesNode {
  int fapID = 1;
  int highLevelSelect = 1;
  std::vector<NodePtr> faceDefMesh, faceDefTransform;
};
struct FaceDefMeshNode {
  NodePtr target;
  FaceDefMesh def;
};
struct FaceDefTransformNode {
  NodePtr target;
  int fieldId = 1;
  FaceDefTransform def;
};
struct FitNode {
  FitNodeFields fields;
};
struct WorldInfoNode {
  std::string title;
  std::vector<std::string> info;
};

struct Node {
  std::string_view type;
  std::string_view def;  // DEF name, empty without one
  int line = 0;
  std::vector<std::pair<std::string_view, int>> fieldLines;  // where each field was given
  std::variant<std::monostate, PointsNode, IndexedFaceSetNode, ShapeNode, GroupNode, FaceNode,
               FdpNode, FaceDefTablesNode, FaceDefMeshNode, FaceDefTransformNode, FitNode,
               WorldInfoNode>
      data;

  int lineOf(std::string_view field) const {
    for (const auto& [name, at] : fieldLines) {
      if (name == field) return at;
    }
    return line;
  }
  // "Transform.children" for messages.
  std::string field(std::string_view name) const {
    return std::string(type) + '.' + std::string(name);
  }
};

template <typename T>
T* as(const NodePtr& node) {
  return node ? std::get_if<T>(&node->data) : nullptr;
}

bool isStatementKeyword(std::string_view id) {
  return id == "PROTO" || id == "EXTERNPROTO" || id == "ROUTE";
}

// ---------------------------------------------------------------------------------------
// Parser

class Parser {
 public:
  Parser(std::string_view text, std::string file) : lex_(text, std::move(file)) {}

  void parseScene() {
    while (lex_.peek().kind != Tok::End) {
      if (lex_.peek().kind == Tok::Id && isStatementKeyword(lex_.peek().text)) {
        statement(lex_.take());
        continue;
      }
      NodePtr node = nodeStatement("scene");
      if (node == nullptr) continue;
      if (FaceNode* face = as<FaceNode>(node)) face->topLevel = true;
      topLevel_.push_back(std::move(node));
    }
  }

  [[noreturn]] void fail(int line, std::string_view field, const std::string& message) const {
    lex_.fail(line, field, message);
  }

  std::unordered_map<std::string_view, NodePtr> defs_;  // the last DEF of each name
  std::vector<NodePtr> topLevel_;
  std::vector<NodePtr> faces_;  // every Face node parsed, wherever it is

 private:
  // ---- statements that are not nodes: PROTO, EXTERNPROTO, ROUTE (keyword already taken)
  void statement(const Token& keyword) {
    if (keyword.text == "ROUTE") {
      for (int i = 0; i < 2; ++i) {
        expectId("ROUTE");
        expect(Tok::Period, "ROUTE", "'.'");
        expectId("ROUTE");
        if (i == 0) {
          const Token to = expectId("ROUTE");
          if (to.text != "TO") fail(to.line, "ROUTE", "'TO' expected, found " + describe(to));
        }
      }
      return;
    }
    // Our reader knows the nodes it reads; PROTO and EXTERNPROTO declarations are skipped.
    const Token name = expectId(keyword.text);
    const std::string what = std::string(keyword.text) + ' ' + std::string(name.text);
    skipBalanced(Tok::LBracket, what, keyword.line);
    if (keyword.text == "PROTO") {
      skipBalanced(Tok::LBrace, what, keyword.line);
    } else {
      strings(what);  // the EXTERNPROTO's URLs
    }
  }

  // Skips a [ ... ] or { ... } block with everything nested in it (counted, not recursed).
  void skipBalanced(Tok open, const std::string& what, int startLine) {
    const Token first = lex_.take();
    if (first.kind != open) {
      fail(first.line, what,
           std::string(open == Tok::LBracket ? "'['" : "'{'") + " expected, found " +
               describe(first));
    }
    for (int depth = 1; depth > 0;) {
      const Token t = lex_.take();
      if (t.kind == Tok::End) fail(startLine, what, "not closed (it opens on this line)");
      if (t.kind == Tok::LBrace || t.kind == Tok::LBracket) ++depth;
      if (t.kind == Tok::RBrace || t.kind == Tok::RBracket) --depth;
    }
  }

  Token expectId(std::string_view field) {
    const Token t = lex_.take();
    if (t.kind != Tok::Id) fail(t.line, field, "name expected, found " + describe(t));
    return t;
  }
  Token expect(Tok kind, std::string_view field, const char* what) {
    const Token t = lex_.take();
    if (t.kind != kind) fail(t.line, field, std::string(what) + " expected, found " + describe(t));
    return t;
  }

  // ---- nodes

  // NULL, USE name, or [DEF name] Type { body }. Returns nullptr for NULL.
  NodePtr nodeStatement(std::string_view field) {
    const Token t = lex_.take();
    if (t.kind != Tok::Id) fail(t.line, field, "node expected, found " + describe(t));
    if (t.text == "NULL") return nullptr;
    if (t.text == "USE") {
      const Token name = expectId(field);
      const auto it = defs_.find(name.text);
      if (it == defs_.end()) {
        fail(name.line, field, "USE " + text::quote(name.text) + " before any DEF of that name");
      }
      return it->second;
    }
    if (t.text == "DEF") {
      const Token name = expectId(field);
      const Token type = expectId(field);
      NodePtr node = nodeBody(type, name.text, field);
      // Bound after the body: a node cannot USE itself, so the graph has no cycles.
      defs_[name.text] = node;
      return node;
    }
    return nodeBody(t, {}, field);
  }

  NodePtr nodeBody(const Token& type, std::string_view def, std::string_view field) {
    const Token open = lex_.take();
    if (open.kind != Tok::LBrace) {
      fail(open.line, field,
           "'{' expected after node type " + text::quote(type.text) + ", found " + describe(open));
    }
    if (++depth_ > kMaxDepth) {
      fail(type.line, field, "nodes nested more than " + std::to_string(kMaxDepth) + " deep");
    }
    auto node = std::make_shared<Node>();
    node->type = type.text;
    node->def = def;
    node->line = type.line;
    initialize(*node);
    while (true) {
      const Token f = lex_.take();
      if (f.kind == Tok::RBrace) break;
      if (f.kind == Tok::End) fail(type.line, type.text, "node not closed (it opens on this line)");
      if (f.kind != Tok::Id) fail(f.line, type.text, "field name expected, found " + describe(f));
      if (bodyStatement(f)) continue;
      node->fieldLines.emplace_back(f.text, f.line);
      const std::string name = node->field(f.text);
      if (readField(*node, f.text, name)) continue;
      if (!std::holds_alternative<std::monostate>(node->data)) {
        fail(f.line, name, "no such field in " + std::string(type.text));
      }
      skipValue(name);  // a node we do not read
    }
    finish(*node);
    if (std::holds_alternative<FaceNode>(node->data)) faces_.push_back(node);
    --depth_;
    return node;
  }

  // PROTO / EXTERNPROTO / ROUTE inside a node, and a Script's interface declarations.
  bool bodyStatement(const Token& f) {
    if (isStatementKeyword(f.text)) {
      statement(f);
      return true;
    }
    if (f.text == "field" || f.text == "exposedField") {
      expectId(f.text);
      const Token name = expectId(f.text);
      skipValue(std::string(f.text) + ' ' + std::string(name.text));
      return true;
    }
    if (f.text == "eventIn" || f.text == "eventOut") {
      expectId(f.text);
      expectId(f.text);
      return true;
    }
    return false;
  }

  static void initialize(Node& node) {
    const std::string_view type = node.type;
    if (type == "Coordinate" || type == "Normal") {
      node.data = PointsNode{3, {}};
    } else if (type == "TextureCoordinate") {
      node.data = PointsNode{2, {}};
    } else if (type == "IndexedFaceSet") {
      node.data = IndexedFaceSetNode{};
    } else if (type == "Shape") {
      node.data = ShapeNode{};
    } else if (type == "Transform" || type == "Group" || type == "Anchor" || type == "Collision") {
      GroupNode group;
      group.isTransform = type == "Transform";
      group.transform.name = nameFromDef(node.def);
      node.data = std::move(group);
    } else if (type == "Face") {
      node.data = FaceNode{};
    } else if (type == "FDP") {
      node.data = FdpNode{};
    } else if (type == "FaceDefTables") {
      node.data = FaceDefTablesNode{};
    } else if (type == "FaceDefMesh") {
      node.data = FaceDefMeshNode{};
    } else if (type == "FaceDefTransform") {
      node.data = FaceDefTransformNode{};
    } else if (type == "FIT") {
      node.data = FitNode{};
    } else if (type == "WorldInfo") {
      node.data = WorldInfoNode{};
    }
  }

  // Reads field `f` of a node we read; false if that node has no such field. Fields that
  // do not matter for a face (appearance, colours, bounding boxes, ...) are skipped.
  bool readField(Node& node, std::string_view f, const std::string& name) {
    if (auto* n = std::get_if<PointsNode>(&node.data)) {
      if (f != (node.type == "Normal" ? "vector" : "point")) return false;
      numbers(name, n->values, n->dimension);
    } else if (auto* ifs = std::get_if<IndexedFaceSetNode>(&node.data)) {
      if (f == "coord")
        ifs->coord = nodeStatement(name);
      else if (f == "normal")
        ifs->normal = nodeStatement(name);
      else if (f == "texCoord")
        ifs->texCoord = nodeStatement(name);
      else if (f == "coordIndex")
        ints(name, ifs->coordIndex);
      else if (f == "normalIndex")
        ints(name, ifs->normalIndex);
      else if (f == "texCoordIndex")
        ints(name, ifs->texCoordIndex);
      else if (f == "normalPerVertex")
        ifs->normalPerVertex = boolean(name);
      else if (f == "ccw")
        ifs->ccw = boolean(name);
      else if (f == "color" || f == "colorIndex" || f == "colorPerVertex" || f == "convex" ||
               f == "creaseAngle" || f == "solid")
        skipValue(name);
      else
        return false;
    } else if (auto* shape = std::get_if<ShapeNode>(&node.data)) {
      if (f == "geometry")
        shape->geometry = nodeStatement(name);
      else if (f == "appearance")
        skipValue(name);
      else
        return false;
    } else if (auto* group = std::get_if<GroupNode>(&node.data)) {
      return groupField(node, *group, f, name);
    } else if (auto* face = std::get_if<FaceNode>(&node.data)) {
      if (f == "fdp")
        face->fdp = nodeStatement(name);
      else if (f == "fit")
        face->fit = nodeStatement(name);
      else if (f == "fap" || f == "ttsSource" || f == "renderedFace")
        skipValue(name);
      else
        return false;
    } else if (auto* fit = std::get_if<FitNode>(&node.data)) {
      FitNodeFields& x = fit->fields;
      const std::pair<std::string_view, std::vector<int>*> intFields[]{
          {"FAPs", &x.FAPs},
          {"Graph", &x.Graph},
          {"numeratorExp", &x.numeratorExp},
          {"denominatorExp", &x.denominatorExp},
          {"numeratorImpulse", &x.numeratorImpulse},
          {"numeratorTerms", &x.numeratorTerms},
          {"denominatorTerms", &x.denominatorTerms}};
      for (const auto& [key, values] : intFields) {
        if (f == key) {
          ints(name, *values);
          return true;
        }
      }
      if (f == "numeratorCoefs")
        numbers(name, x.numeratorCoefs, 1);
      else if (f == "denominatorCoefs")
        numbers(name, x.denominatorCoefs, 1);
      else
        return false;
    } else if (auto* fdp = std::get_if<FdpNode>(&node.data)) {
      if (f == "featurePointsCoord")
        fdp->featurePointsCoord = nodeStatement(name);
      else if (f == "faceDefTables")
        nodes(name, fdp->faceDefTables);
      else if (f == "faceSceneGraph")
        nodes(name, fdp->faceSceneGraph);
      else if (f == "textureCoord" || f == "useOrthoTexture")
        skipValue(name);
      else
        return false;
    } else if (auto* tables = std::get_if<FaceDefTablesNode>(&node.data)) {
      if (f == "fapID")
        tables->fapID = int32(name);
      else if (f == "highLevelSelect")
        tables->highLevelSelect = int32(name);
      else if (f == "faceDefMesh")
        nodes(name, tables->faceDefMesh);
      else if (f == "faceDefTransform")
        nodes(name, tables->faceDefTransform);
      else
        return false;
    } else if (auto* mesh = std::get_if<FaceDefMeshNode>(&node.data)) {
      if (f == "faceSceneGraphNode") {
        mesh->target = nodeStatement(name);
      } else if (f == "intervalBorders") {
        ints(name, mesh->def.intervalBorders);
      } else if (f == "coordIndex") {
        ints(name, mesh->def.coordIndex);
      } else if (f == "displacements") {
        std::vector<double> values;
        numbers(name, values, 3);
        mesh->def.displacements = Eigen::Map<const Points3>(
            values.data(), static_cast<Eigen::Index>(values.size() / 3), 3);
      } else {
        return false;
      }
    } else if (auto* transform = std::get_if<FaceDefTransformNode>(&node.data)) {
      if (f == "faceSceneGraphNode")
        transform->target = nodeStatement(name);
      else if (f == "fieldId")
        transform->fieldId = int32(name);
      else if (f == "rotationDef")
        transform->def.rotationDef = vector<4>(name);
      else if (f == "scaleDef")
        transform->def.scaleDef = vector<3>(name);
      else if (f == "translationDef")
        transform->def.translationDef = vector<3>(name);
      else
        return false;
    } else if (auto* info = std::get_if<WorldInfoNode>(&node.data)) {
      if (f == "title")
        info->title = string(name);
      else if (f == "info")
        info->info = strings(name);
      else
        return false;
    } else {
      return false;
    }
    return true;
  }

  bool groupField(const Node& node, GroupNode& group, std::string_view f, const std::string& name) {
    if (f == "children") {
      nodes(name, group.children);
    } else if (f == "bboxCenter" || f == "bboxSize") {
      skipValue(name);
    } else if (group.isTransform) {
      Transform& t = group.transform;
      if (f == "translation")
        t.translation = vector<3>(name);
      else if (f == "scale")
        t.scale = vector<3>(name);
      else if (f == "center")
        t.center = vector<3>(name);
      else if (f == "rotation")
        t.rotation = rotation(name);
      else if (f == "scaleOrientation")
        group.scaleOrientation = rotation(name);
      else
        return false;
    } else if (node.type == "Anchor" && (f == "description" || f == "parameter" || f == "url")) {
      skipValue(name);
    } else if (node.type == "Collision" && (f == "collide" || f == "proxy")) {
      skipValue(name);
    } else {
      return false;
    }
    return true;
  }

  // Checks that need the whole node: its other fields and the nodes it refers to.
  void finish(Node& node) {
    if (auto* ifs = std::get_if<IndexedFaceSetNode>(&node.data)) {
      finishIndexedFaceSet(node, *ifs);
    } else if (auto* group = std::get_if<GroupNode>(&node.data)) {
      const Eigen::Vector3d& s = group->transform.scale;
      const bool uniform = s.x() == s.y() && s.y() == s.z();
      if (!uniform && !group->scaleOrientation.vec().isZero(0)) {
        fail(node.lineOf("scaleOrientation"), node.field("scaleOrientation"),
             "a scaleOrientation with a non-uniform scale shears; the face model has no shear");
      }
    } else if (auto* fdm = std::get_if<FaceDefMeshNode>(&node.data)) {
      finishFaceDefMesh(node, *fdm);
    } else if (auto* fdt = std::get_if<FaceDefTransformNode>(&node.data)) {
      finishFaceDefTransform(node, *fdt);
    } else if (auto* tables = std::get_if<FaceDefTablesNode>(&node.data)) {
      finishFaceDefTables(node, *tables);
    } else if (auto* fdp = std::get_if<FdpNode>(&node.data)) {
      finishFdp(node, *fdp);
    } else if (auto* face = std::get_if<FaceNode>(&node.data)) {
      requireType(node, "fdp", face->fdp, "FDP");
      requireType(node, "fit", face->fit, "FIT");
    }
  }

  // The node in `slot` must be of type `type` (or absent).
  void requireType(const Node& node, std::string_view slot, const NodePtr& value,
                   std::string_view type) {
    if (value && value->type != type) {
      fail(node.lineOf(slot), node.field(slot),
           std::string(type) + " expected, found " + std::string(value->type));
    }
  }

  void finishIndexedFaceSet(const Node& node, IndexedFaceSetNode& ifs) {
    requireType(node, "coord", ifs.coord, "Coordinate");
    requireType(node, "normal", ifs.normal, "Normal");
    requireType(node, "texCoord", ifs.texCoord, "TextureCoordinate");
    const Eigen::Index vertexCount = ifs.coord ? as<PointsNode>(ifs.coord)->count() : 0;
    for (int index : ifs.coordIndex) {
      if (index < -1 || index >= vertexCount) {
        fail(node.lineOf("coordIndex"), node.field("coordIndex"),
             "vertex " + std::to_string(index) + " out of range (the coord has " +
                 std::to_string(vertexCount) + " points)");
      }
    }
    const std::size_t corners = ifs.coordIndex.size();
    // VRML97: an index list of texture coordinates or normals has at least the entries of
    // coordIndex, with -1 in the same places.
    const auto checkLayout = [&](std::vector<int>& indices, std::string_view slot,
                                 Eigen::Index count) {
      if (indices.empty()) return;
      if (indices.size() < corners) {
        fail(node.lineOf(slot), node.field(slot),
             "has " + std::to_string(indices.size()) + " entries, coordIndex " +
                 std::to_string(corners));
      }
      indices.resize(corners);
      for (std::size_t i = 0; i < corners; ++i) {
        if ((indices[i] == -1) != (ifs.coordIndex[i] == -1)) {
          fail(node.lineOf(slot), node.field(slot),
               "entry " + std::to_string(i) + " does not end a face where coordIndex does");
        }
        if (indices[i] < -1 || indices[i] >= count) {
          fail(node.lineOf(slot), node.field(slot),
               "index " + std::to_string(indices[i]) + " out of range (" + std::to_string(count) +
                   " values)");
        }
      }
    };
    const Eigen::Index texCount = ifs.texCoord ? as<PointsNode>(ifs.texCoord)->count() : 0;
    const Eigen::Index normalCount = ifs.normal ? as<PointsNode>(ifs.normal)->count() : 0;
    checkLayout(ifs.texCoordIndex, "texCoordIndex", texCount);
    if (ifs.normalPerVertex) checkLayout(ifs.normalIndex, "normalIndex", normalCount);
    if (ifs.texCoord && ifs.texCoordIndex.empty() && texCount != vertexCount) {
      // Texture coordinates indexed by coordIndex, but not one per vertex: say so explicitly.
      checkLayout(ifs.texCoordIndex = ifs.coordIndex, "texCoord", texCount);
    }
    // Without faces such texture coordinates belong to nothing.
    ifs.keepTexCoord = ifs.texCoord && (!ifs.texCoordIndex.empty() || texCount == vertexCount);
    // The face model holds one normal per vertex; other layouts are dropped (they can be
    // recomputed) rather than misassigned.
    ifs.keepNormals = ifs.normal && ifs.normalPerVertex && normalCount == vertexCount &&
                      (ifs.normalIndex.empty() || ifs.normalIndex == ifs.coordIndex);
    if (!ifs.ccw) {  // clockwise faces: reverse each so that the model's faces are CCW
      for (std::vector<int>* list : {&ifs.coordIndex, &ifs.texCoordIndex}) {
        if (list->empty()) continue;
        auto begin = list->begin();
        while (begin != list->end()) {
          auto end = std::find(begin, list->end(), -1);
          std::reverse(begin, end);
          begin = end == list->end() ? end : end + 1;
        }
      }
    }
  }

  void finishFaceDefMesh(const Node& node, FaceDefMeshNode& fdm) {
    const auto* target = as<IndexedFaceSetNode>(fdm.target);
    if (target == nullptr) {
      fail(node.lineOf("faceSceneGraphNode"), node.field("faceSceneGraphNode"),
           "an IndexedFaceSet expected, found " +
               (fdm.target ? std::string(fdm.target->type) : std::string("NULL")));
    }
    try {
      checkIntervalBorders(fdm.def.intervalBorders);
    } catch (const Error& e) {
      fail(node.lineOf("intervalBorders"), node.field("intervalBorders"), e.reason());
    }
    const Eigen::Index vertexCount = target->coord ? as<PointsNode>(target->coord)->count() : 0;
    for (int v : fdm.def.coordIndex) {
      if (v < 0 || v >= vertexCount) {
        fail(node.lineOf("coordIndex"), node.field("coordIndex"),
             "vertex " + std::to_string(v) + " out of range (the IndexedFaceSet has " +
                 std::to_string(vertexCount) + " points)");
      }
    }
    const auto expected =
        static_cast<Eigen::Index>(fdm.def.coordIndex.size()) * fdm.def.intervalCount();
    if (fdm.def.displacements.rows() != expected) {
      fail(node.lineOf("displacements"), node.field("displacements"),
           std::to_string(fdm.def.displacements.rows()) + " displacements, expected " +
               std::to_string(expected) + " (one per coordIndex entry and interval)");
    }
  }

  void finishFaceDefTransform(const Node& node, FaceDefTransformNode& fdt) {
    const auto* target = as<GroupNode>(fdt.target);
    if (target == nullptr || !target->isTransform) {
      fail(node.lineOf("faceSceneGraphNode"), node.field("faceSceneGraphNode"),
           "a Transform expected, found " +
               (fdt.target ? std::string(fdt.target->type) : std::string("NULL")));
    }
    if (fdt.fieldId < 1 || fdt.fieldId > 3) {
      fail(node.lineOf("fieldId"), node.field("fieldId"),
           std::to_string(fdt.fieldId) + " is not 1 (rotation), 2 (scale) or 3 (translation)");
    }
    fdt.def.fieldId = static_cast<FaceDefTransform::Field>(fdt.fieldId);
    if (fdt.fieldId == 1 && fdt.def.rotationDef.head<3>().isZero(0)) {
      fail(node.lineOf("rotationDef"), node.field("rotationDef"), "the rotation axis is zero");
    }
  }

  void finishFaceDefTables(const Node& node, const FaceDefTablesNode& tables) {
    if (tables.fapID < 1 || tables.fapID > kFapCount) {
      fail(node.lineOf("fapID"), node.field("fapID"),
           std::to_string(tables.fapID) + " is not a FAP number (1..68)");
    }
    const int highest = tables.fapID == 1 ? static_cast<int>(visemeTable().size()) - 1
                                          : static_cast<int>(expressionTable().size()) - 1;
    if (tables.fapID <= 2 && (tables.highLevelSelect < 0 || tables.highLevelSelect > highest)) {
      fail(node.lineOf("highLevelSelect"), node.field("highLevelSelect"),
           std::to_string(tables.highLevelSelect) + " is not a" +
               (tables.fapID == 1 ? " viseme (0..14)" : "n expression (0..6)"));
    }
    for (const NodePtr& n : tables.faceDefMesh) {
      if (!as<FaceDefMeshNode>(n)) {
        fail(node.lineOf("faceDefMesh"), node.field("faceDefMesh"),
             "FaceDefMesh expected, found " + std::string(n->type));
      }
    }
    for (const NodePtr& n : tables.faceDefTransform) {
      if (!as<FaceDefTransformNode>(n)) {
        fail(node.lineOf("faceDefTransform"), node.field("faceDefTransform"),
             "FaceDefTransform expected, found " + std::string(n->type));
      }
    }
  }

  void finishFdp(const Node& node, const FdpNode& fdp) {
    requireType(node, "featurePointsCoord", fdp.featurePointsCoord, "Coordinate");
    if (fdp.featurePointsCoord) {
      const Eigen::Index count = as<PointsNode>(fdp.featurePointsCoord)->count();
      if (count != 0 && count != kFeaturePointCount) {
        fail(node.lineOf("featurePointsCoord"), node.field("featurePointsCoord"),
             std::to_string(count) + " points; expected the " + std::to_string(kFeaturePointCount) +
                 " MPEG-4 feature points in order");
      }
    }
    for (const NodePtr& n : fdp.faceDefTables) {
      if (!as<FaceDefTablesNode>(n)) {
        fail(node.lineOf("faceDefTables"), node.field("faceDefTables"),
             "FaceDefTables expected, found " + std::string(n->type));
      }
    }
  }

  // ---- field values

  Token numberToken(std::string_view field) {
    const Token t = lex_.take();
    if (t.kind != Tok::Number) fail(t.line, field, "number expected, found " + describe(t));
    return t;
  }
  double real(std::string_view field) {
    const Token t = numberToken(field);
    return text::parseDouble(t.text, lex_.file(), t.line, field);
  }
  int int32(std::string_view field) {
    const Token t = numberToken(field);
    const std::string_view s = t.text;
    if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
      // VRML97 allows hexadecimal SFInt32: the 32-bit pattern, so 0xFFFFFFFF is -1.
      std::uint32_t bits = 0;
      const char* last = s.data() + s.size();
      const auto [end, ec] = std::from_chars(s.data() + 2, last, bits, 16);
      if (ec != std::errc() || end != last) {
        fail(t.line, field, "integer expected, found " + text::quote(s));
      }
      return static_cast<std::int32_t>(bits);
    }
    return text::parseInt(s, lex_.file(), t.line, field);
  }
  bool boolean(std::string_view field) {
    const Token t = lex_.take();
    if (t.kind == Tok::Id && t.text == "TRUE") return true;
    if (t.kind == Tok::Id && t.text == "FALSE") return false;
    fail(t.line, field, "TRUE or FALSE expected, found " + describe(t));
  }
  std::string string(std::string_view field) {
    const Token t = lex_.take();
    if (t.kind != Tok::String) fail(t.line, field, "string expected, found " + describe(t));
    return unescape(t.text);
  }
  std::vector<std::string> strings(std::string_view field) {
    std::vector<std::string> out;
    if (lex_.peek().kind != Tok::LBracket) {
      out.push_back(string(field));
      return out;
    }
    lex_.take();
    while (lex_.peek().kind != Tok::RBracket) out.push_back(string(field));
    lex_.take();
    return out;
  }
  template <int N>
  Eigen::Matrix<double, N, 1> vector(std::string_view field) {
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) v[i] = real(field);
    return v;
  }
  Eigen::Quaterniond rotation(std::string_view field) {
    const Eigen::Vector4d r = vector<4>(field);
    const Eigen::Vector3d axis = r.head<3>();
    // A zero axis has no direction; browsers take it as no rotation.
    if (axis.isZero(0)) return Eigen::Quaterniond::Identity();
    return Eigen::Quaterniond(Eigen::AngleAxisd(r[3], axis.normalized()));
  }
  // An MF field of numbers: [ a b c, ... ] or one value of `arity` numbers without brackets.
  void numbers(std::string_view field, std::vector<double>& out, int arity) {
    out.clear();
    if (lex_.peek().kind != Tok::LBracket) {
      for (int i = 0; i < arity; ++i) out.push_back(real(field));
      return;
    }
    const int line = lex_.take().line;
    while (lex_.peek().kind != Tok::RBracket) out.push_back(real(field));
    lex_.take();
    if (out.size() % static_cast<std::size_t>(arity) != 0) {
      fail(line, field,
           std::to_string(out.size()) + " numbers are not a whole number of " +
               std::to_string(arity) + "-component values");
    }
  }
  void ints(std::string_view field, std::vector<int>& out) {
    out.clear();
    if (lex_.peek().kind != Tok::LBracket) {
      out.push_back(int32(field));
      return;
    }
    lex_.take();
    while (lex_.peek().kind != Tok::RBracket) out.push_back(int32(field));
    lex_.take();
  }
  void nodes(std::string_view field, std::vector<NodePtr>& out) {
    out.clear();
    const bool list = lex_.peek().kind == Tok::LBracket;
    if (list) lex_.take();
    do {
      if (list && lex_.peek().kind == Tok::RBracket) break;
      if (NodePtr n = nodeStatement(field)) out.push_back(std::move(n));
    } while (list);
    if (list) lex_.take();
  }

  // A value of a field we do not read, of any type: numbers, strings, TRUE/FALSE, nodes, or
  // a bracketed list of them. Nodes in it are parsed, so that their DEFs count.
  void skipValue(std::string_view field) {
    if (lex_.peek().kind != Tok::LBracket) {
      skipSingle(field, false);
      return;
    }
    lex_.take();
    while (lex_.peek().kind != Tok::RBracket) skipSingle(field, true);
    lex_.take();
  }
  void skipSingle(std::string_view field, bool inList) {
    const Token t = lex_.peek();
    if (t.kind == Tok::Number) {
      // A run of numbers: SFVec3f, SFRotation, SFImage ... A field name cannot start with a
      // digit, so the run ends where the next field begins.
      lex_.take();
      while (!inList && lex_.peek().kind == Tok::Number) lex_.take();
      return;
    }
    if (t.kind == Tok::String || (t.kind == Tok::Id && (t.text == "TRUE" || t.text == "FALSE"))) {
      lex_.take();
      return;
    }
    if (t.kind == Tok::Id && (t.text == "NULL" || t.text == "USE" || t.text == "DEF" ||
                              lex_.peek(1).kind == Tok::LBrace)) {
      nodeStatement(field);
      return;
    }
    fail(t.line, field, "value expected, found " + describe(t));
  }

  Lexer lex_;
  int depth_ = 0;
};

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

MpegFace parseVrml(std::string_view text, const std::string& fileName) {
  checkHeader(text, fileName);
  Parser parser(text, fileName);
  parser.parseScene();
  return Builder(parser, fileName).build();
}

MpegFace readVrml(const std::filesystem::path& path) {
  return parseVrml(readFile(path), path.string());
}

}  // namespace mpeg4face
