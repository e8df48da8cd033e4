// SPDX-License-Identifier: GPL-3.0-or-later
// The 2D mesh object (docs/mesh2d.md) from Python. A sequence is a dict with the JSON form's
// keys; "frames" is a float64 array (frames, nodes, 2) and "triangles" an int32 array (M, 3).
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <filesystem>
#include <optional>

#include "bindings.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "mpeg4face/mesh2d/codec.hpp"
#include "mpeg4face/mesh2d/json.hpp"
#include "mpeg4face/mesh2d/portrait.hpp"
#if MPEG4FACE_PYTHON_IMAGES
#include "mpeg4face/mesh2d/design.hpp"
#include "mpeg4face/mesh2d/render.hpp"
#endif

namespace mpeg4face::python {
namespace {

using namespace pybind11::literals;
using Path = std::filesystem::path;

py::dict toDict(const Mesh2dSequence& s) {
  py::dict d("width"_a = s.width, "height"_a = s.height,
             "mesh"_a = s.type == Mesh2dType::Uniform ? "uniform" : "delaunay");
  if (s.type == Mesh2dType::Uniform) {
    const UniformMesh2d& u = s.uniform;
    d["uniform"] = py::dict("nodes_x"_a = u.nodesX, "nodes_y"_a = u.nodesY, "x0"_a = u.x0,
                            "y0"_a = u.y0, "dx"_a = u.dx, "dy"_a = u.dy, "topology"_a = u.topology);
  } else {
    d["boundary"] = s.boundary;
  }
  const auto nodes = static_cast<py::ssize_t>(s.frames.empty() ? 0 : s.frames[0].rows());
  py::array_t<double> frames({static_cast<py::ssize_t>(s.frames.size()), nodes, py::ssize_t{2}});
  for (size_t f = 0; f < s.frames.size(); ++f) {
    std::memcpy(frames.mutable_data(static_cast<py::ssize_t>(f)), s.frames[f].data(),
                sizeof(double) * static_cast<size_t>(nodes) * 2);
  }
  d["frames"] = frames;
  py::array_t<int32_t> triangles({static_cast<py::ssize_t>(s.triangles.rows()), py::ssize_t{3}});
  if (s.triangles.rows() > 0) {
    std::memcpy(triangles.mutable_data(), s.triangles.data(),
                sizeof(int32_t) * static_cast<size_t>(s.triangles.size()));
  }
  d["triangles"] = triangles;
  return d;
}

// Through the JSON reader, so that Python input gets the same checks and messages.
Mesh2dSequence fromDict(const py::dict& d) {
  py::dict copy = d.attr("copy")();  // a new dict: the caller's keeps its arrays
  const py::module_ numpy = py::module_::import("numpy");
  for (const char* key : {"frames", "triangles"}) {
    if (copy.contains(key)) copy[key] = numpy.attr("asarray")(copy[key]).attr("tolist")();
  }
  const std::string text = py::module_::import("json").attr("dumps")(copy).cast<std::string>();
  return parseMesh2dJson(text, "sequence");
}

}  // namespace

void bindMesh2d(py::module_& m) {
  m.def(
      "read_mesh2d", [](const Path& path) { return toDict(readMesh2dJson(path)); }, "path"_a,
      "A 2D mesh sequence (.json) as a dict (docs/mesh2d.md).");
  m.def(
      "write_mesh2d",
      [](const py::dict& sequence, const Path& path) { writeMesh2dJson(path, fromDict(sequence)); },
      "sequence"_a, "path"_a, "Writes a 2D mesh sequence dict as JSON (atomically).");
  m.def(
      "mesh2d_triangles",
      [](const py::dict& sequence) {
        Mesh2dSequence s = fromDict(sequence);
        s.triangles = meshTriangles(s);
        const py::dict d = toDict(s);
        return py::object(d["triangles"]);
      },
      "sequence"_a, "The triangles the intra plane's geometry implies (CGAL for Delaunay).");
  m.def(
      "mesh2d_traversal",
      [](const py::dict& sequence) {
        Mesh2dSequence s = fromDict(sequence);
        if (s.triangles.rows() == 0) s.triangles = meshTriangles(s);
        const Mesh2dTraversal t = mesh2dTraversal(s.frames[0], s.triangles);
        py::array_t<int32_t> vertices(
            {static_cast<py::ssize_t>(t.vertices.size()), py::ssize_t{3}});
        for (size_t i = 0; i < t.vertices.size(); ++i) {
          for (size_t k = 0; k < 3; ++k) {
            vertices.mutable_at(static_cast<py::ssize_t>(i), static_cast<py::ssize_t>(k)) =
                t.vertices[i][k];
          }
        }
        return py::dict("triangle"_a = t.triangle, "vertices"_a = vertices,
                        "node_order"_a = t.nodeOrder);
      },
      "sequence"_a,
      "The breadth-first traversal (section 3.3.2.1): per label the triangle's index and its "
      "vertices (l, m, n) with <l m> the base edge, and the order node motion is coded in.");
  m.def(
      "encode_mesh2d",
      [](const py::dict& sequence, double step) {
        Mesh2dCodingStats stats;
        const std::vector<uint8_t> data = encodeMesh2d(fromDict(sequence), step, nullptr, &stats);
        return py::make_tuple(
            py::bytes(reinterpret_cast<const char*>(data.data()), data.size()),
            py::dict("total_bits"_a = stats.totalBits, "header_bits"_a = stats.headerBits,
                     "intra_bits"_a = stats.intraBits, "inter_bits"_a = stats.interBits));
      },
      "sequence"_a, "step"_a = 0.5,
      "Codes a sequence as .m2d bytes; returns (bytes, stats: total/header/intra bits, "
      "inter_bits per inter plane).");
  m.def(
      "decode_mesh2d",
      [](const py::bytes& data) {
        const std::string bytes = data;
        return toDict(decodeMesh2d(
            std::span(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()), "bytes"));
      },
      "data"_a, "Decodes .m2d bytes to a sequence dict (triangles included).");
#if MPEG4FACE_PYTHON_IMAGES
  m.def(
      "design_mesh2d",
      [](const Path& image, std::optional<std::pair<int, int>> uniform, std::optional<int> delaunay,
         std::optional<Path> mask, int topology) {
        if (uniform.has_value() == delaunay.has_value()) {
          throw py::value_error("give uniform=(cols, rows) or delaunay=N");
        }
        const Image texture = readImage(image);
        if (uniform) {
          Mesh2dSequence s = designUniformMesh2d(texture.width, texture.height, uniform->first,
                                                 uniform->second, topology);
          s.triangles = meshTriangles(s);
          return toDict(s);
        }
        const Image maskImage = mask ? readImage(*mask) : Image();
        return toDict(designDelaunayMesh2d(texture, *delaunay, mask ? &maskImage : nullptr));
      },
      "image"_a, "uniform"_a = py::none(), "delaunay"_a = py::none(), "mask"_a = py::none(),
      "topology"_a = 0,
      "A mesh designed on an image file: uniform cells or about N Delaunay nodes.");
  m.def(
      "render_mesh2d",
      [](const Path& image, const py::dict& sequence, const Path& out, std::optional<Path> audio,
         double fps) {
        Mesh2dVideoOptions options;
        options.fps = fps;
        if (audio) options.audio = *audio;
        renderMesh2d(readImage(image), fromDict(sequence), out, options);
      },
      "image"_a, "sequence"_a, "out"_a, "audio"_a = py::none(), "fps"_a = 25.0,
      "Renders the image warped by every plane: PNG frames into a folder, or an .mp4.");
#else
  // A module built without OpenCV (the wheel) keeps the names, so that code using them fails
  // with the reason instead of an AttributeError.
  for (const char* name : {"design_mesh2d", "render_mesh2d"}) {
    m.def(
        name,
        [name](const py::args&, const py::kwargs&) {
          throw Error(std::string(name) +
                      ": this build of mpeg4face has no image functions (it was built without "
                      "OpenCV, as the wheel is); use the command-line tool's `mesh2d design` / "
                      "`mesh2d render`, or build the module with -DMPEG4FACE_PYTHON_IMAGES=ON");
        },
        "Not in this build: it was made without OpenCV.");
  }
#endif
  m.def(
      "portrait_mesh2d",
      [](int width, int height, const Path& featurePoints, const std::optional<Path>& stream,
         const std::optional<Path>& tracks) {
        if (stream.has_value() == tracks.has_value()) {
          throw py::value_error("portrait_mesh2d needs a stream or tracks (one of them)");
        }
        const PortraitFeaturePoints points =
            parsePortraitFeaturePoints(readFile(featurePoints), featurePoints.string());
        if (tracks) {
          return toDict(
              portraitMesh2d(width, height, points,
                             parsePortraitTracks(readFile(*tracks), points, tracks->string())));
        }
        return toDict(portraitMesh2d(width, height, points, readFapStream(*stream)));
      },
      "width"_a, "height"_a, "feature_points"_a, "stream"_a = py::none(), "tracks"_a = py::none(),
      "The talking portrait's sequence: feature points (CSV fp,x,y) moved by a FAP stream, or\n"
      "along tracks (CSV frame,fp,x,y).");
}

}  // namespace mpeg4face::python
