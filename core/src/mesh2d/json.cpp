// SPDX-License-Identifier: GPL-3.0-or-later
// The 2D mesh sequence as JSON, with nlohmann::json.
#include "mpeg4face/mesh2d/json.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"

namespace mpeg4face {
namespace {

using Json = nlohmann::json;

// Reading with the JSON path of every value, for messages.
struct Reader {
  const std::string& source;

  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw Error(source, 0, path, what);
  }
  const Json& member(const Json& object, const char* key, const std::string& path) const {
    const auto it = object.find(key);
    if (it == object.end()) fail(path, "is missing");
    return *it;
  }
  const Json& array(const Json& value, const std::string& path) const {
    if (!value.is_array()) fail(path, "expected an array");
    return value;
  }
  int integer(const Json& value, const std::string& path) const {
    if (!value.is_number_integer()) fail(path, "expected an integer");
    const auto v = value.get<long long>();
    if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
      fail(path, "out of range");
    }
    return static_cast<int>(v);
  }
  double number(const Json& value, const std::string& path) const {
    if (!value.is_number()) fail(path, "expected a number");
    const double v = value.get<double>();
    if (!std::isfinite(v)) fail(path, "expected a finite number");
    return v;
  }
};

std::string index(const std::string& path, size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

// Line and column of a byte offset, 1-based.
std::pair<int, int> lineColumn(std::string_view text, size_t byte) {
  byte = std::min(byte, text.size());
  int line = 1, column = 1;
  for (size_t i = 0; i < byte; ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return {line, column};
}

void appendNumber(std::string& out, double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", value);
  out += text;
}

}  // namespace

Mesh2dSequence parseMesh2dJson(std::string_view text, const std::string& source) {
  Json j;
  try {
    j = Json::parse(text);
  } catch (const Json::parse_error& e) {
    // nlohmann's byte is one past the offending character.
    const auto [line, column] = lineColumn(text, e.byte > 0 ? e.byte - 1 : 0);
    throw Error(source, line, "JSON",
                "column " + std::to_string(column) + ": not valid JSON: " + e.what());
  } catch (const Json::exception& e) {  // out_of_range for 1e999
    throw Error(source, 0, "JSON", std::string("not valid JSON: ") + e.what());
  }
  const Reader r{source};
  if (!j.is_object()) r.fail("(top)", "expected an object");
  Mesh2dSequence s;
  s.width = r.integer(r.member(j, "width", "width"), "width");
  s.height = r.integer(r.member(j, "height", "height"), "height");
  const Json& mesh = r.member(j, "mesh", "mesh");
  if (mesh == "uniform") {
    s.type = Mesh2dType::Uniform;
    const Json& u = r.member(j, "uniform", "uniform");
    if (!u.is_object()) r.fail("uniform", "expected an object");
    s.uniform.nodesX = r.integer(r.member(u, "nodes_x", "uniform.nodes_x"), "uniform.nodes_x");
    s.uniform.nodesY = r.integer(r.member(u, "nodes_y", "uniform.nodes_y"), "uniform.nodes_y");
    s.uniform.x0 = r.number(r.member(u, "x0", "uniform.x0"), "uniform.x0");
    s.uniform.y0 = r.number(r.member(u, "y0", "uniform.y0"), "uniform.y0");
    s.uniform.dx = r.number(r.member(u, "dx", "uniform.dx"), "uniform.dx");
    s.uniform.dy = r.number(r.member(u, "dy", "uniform.dy"), "uniform.dy");
    s.uniform.topology = r.integer(r.member(u, "topology", "uniform.topology"), "uniform.topology");
    try {
      uniformMeshTriangles(s.uniform);  // the parameters' ranges, before sizing anything
    } catch (const Error& e) {
      r.fail(e.field(), e.reason());
    }
  } else if (mesh == "delaunay") {
    s.type = Mesh2dType::Delaunay;
    s.boundary = r.integer(r.member(j, "boundary", "boundary"), "boundary");
  } else {
    r.fail("mesh", "expected \"uniform\" or \"delaunay\"");
  }
  const Json& frames = r.array(r.member(j, "frames", "frames"), "frames");
  for (size_t f = 0; f < frames.size(); ++f) {
    const std::string path = index("frames", f);
    const Json& nodes = r.array(frames[f], path);
    Mesh2dNodes& frame = s.frames.emplace_back(static_cast<Eigen::Index>(nodes.size()), 2);
    for (size_t n = 0; n < nodes.size(); ++n) {
      const std::string at = index(path, n);
      const Json& point = r.array(nodes[n], at);
      if (point.size() != 2) r.fail(at, "expected [x, y]");
      frame(static_cast<Eigen::Index>(n), 0) = r.number(point[0], index(at, 0));
      frame(static_cast<Eigen::Index>(n), 1) = r.number(point[1], index(at, 1));
    }
  }
  if (const auto it = j.find("triangles"); it != j.end()) {
    const Json& triangles = r.array(*it, "triangles");
    s.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
    for (size_t t = 0; t < triangles.size(); ++t) {
      const std::string at = index("triangles", t);
      const Json& tri = r.array(triangles[t], at);
      if (tri.size() != 3) r.fail(at, "expected [i, j, k]");
      for (size_t k = 0; k < 3; ++k) {
        s.triangles(static_cast<Eigen::Index>(t), static_cast<Eigen::Index>(k)) =
            r.integer(tri[k], index(at, k));
      }
    }
  }
  validateMesh2d(s, source);
  return s;
}

Mesh2dSequence readMesh2dJson(const std::filesystem::path& path) {
  return parseMesh2dJson(readFile(path), path.string());
}

std::string mesh2dJson(const Mesh2dSequence& s) {
  // Written by hand: one frame per line keeps long sequences readable and diffable.
  std::string out = "{\n  \"width\": " + std::to_string(s.width) +
                    ",\n  \"height\": " + std::to_string(s.height) + ",\n  \"mesh\": ";
  if (s.type == Mesh2dType::Uniform) {
    const UniformMesh2d& u = s.uniform;
    out += "\"uniform\",\n  \"uniform\": {\"nodes_x\": " + std::to_string(u.nodesX) +
           ", \"nodes_y\": " + std::to_string(u.nodesY) + ", \"x0\": ";
    appendNumber(out, u.x0);
    out += ", \"y0\": ";
    appendNumber(out, u.y0);
    out += ", \"dx\": ";
    appendNumber(out, u.dx);
    out += ", \"dy\": ";
    appendNumber(out, u.dy);
    out += ", \"topology\": " + std::to_string(u.topology) + "}";
  } else {
    out += "\"delaunay\",\n  \"boundary\": " + std::to_string(s.boundary);
  }
  if (s.triangles.rows() > 0) {
    out += ",\n  \"triangles\": [";
    for (Eigen::Index t = 0; t < s.triangles.rows(); ++t) {
      out += (t == 0 ? "[" : ", [") + std::to_string(s.triangles(t, 0)) + ", " +
             std::to_string(s.triangles(t, 1)) + ", " + std::to_string(s.triangles(t, 2)) + "]";
    }
    out += "]";
  }
  out += ",\n  \"frames\": [";
  for (size_t f = 0; f < s.frames.size(); ++f) {
    out += f == 0 ? "\n    [" : ",\n    [";
    for (Eigen::Index n = 0; n < s.frames[f].rows(); ++n) {
      out += n == 0 ? "[" : ", [";
      appendNumber(out, s.frames[f](n, 0));
      out += ", ";
      appendNumber(out, s.frames[f](n, 1));
      out += "]";
    }
    out += "]";
  }
  out += "\n  ]\n}\n";
  return out;
}

void writeMesh2dJson(const std::filesystem::path& path, const Mesh2dSequence& sequence) {
  writeFileAtomically(path, mesh2dJson(sequence));
}

}  // namespace mpeg4face
