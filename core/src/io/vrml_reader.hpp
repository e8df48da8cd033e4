// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: the pieces of the VRML97 reader (io/vrml_read.cpp): the tokens of io/vrml_lexer.cpp,
// the parsed nodes, and the Parser of io/vrml_parser.cpp and io/vrml_node_fields.cpp. Not
// installed.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <variant>
#include <vector>

#include "mpeg4face/error.hpp"
#include "mpeg4face/fit/node.hpp"
#include "mpeg4face/io/vrml.hpp"
#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face::vrml_reader {

// --- io/vrml_lexer.cpp: tokens, and the text a string or a DEF name stands for.

enum class Tok { End, Id, Number, String, LBrace, RBrace, LBracket, RBracket, Period };

struct Token {
  Tok kind = Tok::End;
  std::string_view text;  // for a string: between the quotes, escapes not yet removed
  int line = 0;
};

// What a message calls a token.
std::string describe(const Token& t);
// A string token's text with its escapes removed.
std::string unescape(std::string_view s);
// The name a DEF name stands for (see io/vrml_names.hpp): '%XX' escapes decoded, a trailing
// '%_<digits>' dropped. Other '%' are kept as they are.
std::string nameFromDef(std::string_view def);

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
  Token scan();

  std::string_view text_;
  std::string file_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int lastLine_ = 1;  // the line of the last token
  std::vector<Token> buffer_;
};

// --- Parsed nodes

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

// --- io/vrml_parser.cpp (statements, nodes, field values) and io/vrml_node_fields.cpp (the fields
// and checks of the nodes a face needs): a recursive-descent parser that reads those nodes
// into typed structs, and every other node generically so that its DEFs still resolve.
class Parser {
 public:
  Parser(std::string_view text, std::string file) : lex_(text, std::move(file)) {}

  void parseScene();

  [[noreturn]] void fail(int line, std::string_view field, const std::string& message) const {
    lex_.fail(line, field, message);
  }

  std::unordered_map<std::string_view, NodePtr> defs_;  // the last DEF of each name
  std::vector<NodePtr> topLevel_;
  std::vector<NodePtr> faces_;  // every Face node parsed, wherever it is

 private:
  // io/vrml_parser.cpp
  void statement(const Token& keyword);
  void skipBalanced(Tok open, const std::string& what, int startLine);
  Token expectId(std::string_view field);
  Token expect(Tok kind, std::string_view field, const char* what);
  NodePtr nodeStatement(std::string_view field);
  NodePtr nodeBody(const Token& type, std::string_view def, std::string_view field);
  bool bodyStatement(const Token& f);
  Token numberToken(std::string_view field);
  double real(std::string_view field);
  int int32(std::string_view field);
  bool boolean(std::string_view field);
  std::string string(std::string_view field);
  std::vector<std::string> strings(std::string_view field);
  Eigen::Quaterniond rotation(std::string_view field);
  void numbers(std::string_view field, std::vector<double>& out, int arity);
  void ints(std::string_view field, std::vector<int>& out);
  void nodes(std::string_view field, std::vector<NodePtr>& out);
  void skipValue(std::string_view field);
  void skipSingle(std::string_view field, bool inList);
  template <int N>
  Eigen::Matrix<double, N, 1> vector(std::string_view field) {
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) v[i] = real(field);
    return v;
  }

  // io/vrml_node_fields.cpp
  static void initialize(Node& node);
  bool readField(Node& node, std::string_view f, const std::string& name);
  bool groupField(const Node& node, GroupNode& group, std::string_view f, const std::string& name);
  void finish(Node& node);
  void requireType(const Node& node, std::string_view slot, const NodePtr& value,
                   std::string_view type);
  void finishIndexedFaceSet(const Node& node, IndexedFaceSetNode& ifs);
  void finishFaceDefMesh(const Node& node, FaceDefMeshNode& fdm);
  void finishFaceDefTransform(const Node& node, FaceDefTransformNode& fdt);
  void finishFaceDefTables(const Node& node, const FaceDefTablesNode& tables);
  void finishFdp(const Node& node, const FdpNode& fdp);

  Lexer lex_;
  int depth_ = 0;
};

}  // namespace mpeg4face::vrml_reader
