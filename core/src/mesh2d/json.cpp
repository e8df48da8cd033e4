// SPDX-License-Identifier: GPL-3.0-or-later
// The 2D mesh sequence as JSON, with nlohmann::json.
#include "mpeg4face/mesh2d/json.hpp"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "io/json_reader.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"

namespace mpeg4face {
namespace {

using Json = nlohmann::json;

void appendNumber(std::string& out, double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", value);
  out += text;
}

}  // namespace

Mesh2dSequence parseMesh2dJson(std::string_view text, const std::string& source) {
  const Json j = parseJson<Json>(text, source);
  const JsonReader<Json> r{source};
  Mesh2dSequence s;
  s.width = r.integer(j, "(top)", "width");
  s.height = r.integer(j, "(top)", "height");
  const Json& mesh = r.member(j, "(top)", "mesh");
  if (mesh == "uniform") {
    s.type = Mesh2dType::Uniform;
    const Json& u = r.member(j, "(top)", "uniform");
    s.uniform.nodesX = r.integer(u, "uniform", "nodes_x");
    s.uniform.nodesY = r.integer(u, "uniform", "nodes_y");
    s.uniform.x0 = r.number(u, "uniform", "x0");
    s.uniform.y0 = r.number(u, "uniform", "y0");
    s.uniform.dx = r.number(u, "uniform", "dx");
    s.uniform.dy = r.number(u, "uniform", "dy");
    s.uniform.topology = r.integer(u, "uniform", "topology");
    try {
      uniformMeshTriangles(s.uniform);  // the parameters' ranges, before sizing anything
    } catch (const Error& e) {
      r.fail(e.field(), e.reason());
    }
  } else if (mesh == "delaunay") {
    s.type = Mesh2dType::Delaunay;
    s.boundary = r.integer(j, "(top)", "boundary");
  } else {
    r.fail("mesh", "expected \"uniform\" or \"delaunay\"");
  }
  const Json& frames = r.array(j, "(top)", "frames");
  for (size_t f = 0; f < frames.size(); ++f) {
    const std::string path = r.elementPath("frames", f);
    const Json& nodes = r.array(frames[f], path);
    Mesh2dNodes& frame = s.frames.emplace_back(static_cast<Eigen::Index>(nodes.size()), 2);
    for (size_t n = 0; n < nodes.size(); ++n) {
      const std::string at = r.elementPath(path, n);
      const Json& point = r.array(nodes[n], at);
      if (point.size() != 2) r.fail(at, "expected [x, y]");
      frame(static_cast<Eigen::Index>(n), 0) = r.number(point[0], r.elementPath(at, 0));
      frame(static_cast<Eigen::Index>(n), 1) = r.number(point[1], r.elementPath(at, 1));
    }
  }
  if (const auto it = j.find("triangles"); it != j.end()) {
    const Json& triangles = r.array(*it, "triangles");
    s.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
    for (size_t t = 0; t < triangles.size(); ++t) {
      const std::string at = r.elementPath("triangles", t);
      const Json& tri = r.array(triangles[t], at);
      if (tri.size() != 3) r.fail(at, "expected [i, j, k]");
      for (size_t k = 0; k < 3; ++k) {
        s.triangles(static_cast<Eigen::Index>(t), static_cast<Eigen::Index>(k)) =
            r.integer(tri[k], r.elementPath(at, k));
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
