// SPDX-License-Identifier: GPL-3.0-or-later
// VRML97 reader: the recursive-descent parser's statements, nodes and field values (the
// fields of the nodes a face needs are read in io/vrml_node_fields.cpp).
#include <charconv>
#include <cstdint>

#include "io/text_reader.hpp"
#include "io/vrml_reader.hpp"

namespace mpeg4face::vrml_reader {

namespace {

constexpr int kMaxDepth = 256;

bool isStatementKeyword(std::string_view id) {
  return id == "PROTO" || id == "EXTERNPROTO" || id == "ROUTE";
}

}  // namespace

void Parser::parseScene() {
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

// ---- statements that are not nodes: PROTO, EXTERNPROTO, ROUTE (keyword already taken)
void Parser::statement(const Token& keyword) {
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
void Parser::skipBalanced(Tok open, const std::string& what, int startLine) {
  const Token first = lex_.take();
  if (first.kind != open) {
    fail(
        first.line, what,
        std::string(open == Tok::LBracket ? "'['" : "'{'") + " expected, found " + describe(first));
  }
  for (int depth = 1; depth > 0;) {
    const Token t = lex_.take();
    if (t.kind == Tok::End) fail(startLine, what, "not closed (it opens on this line)");
    if (t.kind == Tok::LBrace || t.kind == Tok::LBracket) ++depth;
    if (t.kind == Tok::RBrace || t.kind == Tok::RBracket) --depth;
  }
}

Token Parser::expectId(std::string_view field) {
  const Token t = lex_.take();
  if (t.kind != Tok::Id) fail(t.line, field, "name expected, found " + describe(t));
  return t;
}

Token Parser::expect(Tok kind, std::string_view field, const char* what) {
  const Token t = lex_.take();
  if (t.kind != kind) fail(t.line, field, std::string(what) + " expected, found " + describe(t));
  return t;
}

// ---- nodes

// NULL, USE name, or [DEF name] Type { body }. Returns nullptr for NULL.
NodePtr Parser::nodeStatement(std::string_view field) {
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

NodePtr Parser::nodeBody(const Token& type, std::string_view def, std::string_view field) {
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
bool Parser::bodyStatement(const Token& f) {
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

// ---- field values

Token Parser::numberToken(std::string_view field) {
  const Token t = lex_.take();
  if (t.kind != Tok::Number) fail(t.line, field, "number expected, found " + describe(t));
  return t;
}

double Parser::real(std::string_view field) {
  const Token t = numberToken(field);
  return text::parseDouble(t.text, lex_.file(), t.line, field);
}

int Parser::int32(std::string_view field) {
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

bool Parser::boolean(std::string_view field) {
  const Token t = lex_.take();
  if (t.kind == Tok::Id && t.text == "TRUE") return true;
  if (t.kind == Tok::Id && t.text == "FALSE") return false;
  fail(t.line, field, "TRUE or FALSE expected, found " + describe(t));
}

std::string Parser::string(std::string_view field) {
  const Token t = lex_.take();
  if (t.kind != Tok::String) fail(t.line, field, "string expected, found " + describe(t));
  return unescape(t.text);
}

std::vector<std::string> Parser::strings(std::string_view field) {
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

Eigen::Quaterniond Parser::rotation(std::string_view field) {
  const Eigen::Vector4d r = vector<4>(field);
  const Eigen::Vector3d axis = r.head<3>();
  // A zero axis has no direction; browsers take it as no rotation.
  if (axis.isZero(0)) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(r[3], axis.normalized()));
}

// An MF field of numbers: [ a b c, ... ] or one value of `arity` numbers without brackets.
void Parser::numbers(std::string_view field, std::vector<double>& out, int arity) {
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

void Parser::ints(std::string_view field, std::vector<int>& out) {
  out.clear();
  if (lex_.peek().kind != Tok::LBracket) {
    out.push_back(int32(field));
    return;
  }
  lex_.take();
  while (lex_.peek().kind != Tok::RBracket) out.push_back(int32(field));
  lex_.take();
}

void Parser::nodes(std::string_view field, std::vector<NodePtr>& out) {
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
void Parser::skipValue(std::string_view field) {
  if (lex_.peek().kind != Tok::LBracket) {
    skipSingle(field, false);
    return;
  }
  lex_.take();
  while (lex_.peek().kind != Tok::RBracket) skipSingle(field, true);
  lex_.take();
}

void Parser::skipSingle(std::string_view field, bool inList) {
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

}  // namespace mpeg4face::vrml_reader
