// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh geometry of the 2D mesh object. CGAL is heavy to compile: it stays in this file.
#include "mpeg4face/mesh2d/mesh2d.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <cmath>
#include <list>
#include <string>

#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_2;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<int, Kernel>;
struct FaceInfo {
  int nesting = -1;  // constraints crossed from the outside; odd = inside the boundary
};
using FaceBase = CGAL::Constrained_triangulation_face_base_2<
    Kernel, CGAL::Triangulation_face_base_with_info_2<FaceInfo, Kernel>>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
// Exact_predicates_tag: the boundary is checked simple first, so constraints never cross.
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;

std::string nodeField(int i) { return "nodes[" + std::to_string(i) + "]"; }

// Flood fill from the infinite face, the nesting level growing by one across a constraint
// (CGAL's polygon-with-holes example): faces of odd level are inside.
void markDomains(Cdt& cdt) {
  std::list<Cdt::Edge> border;
  auto fill = [&](Cdt::Face_handle start, int level) {
    std::list<Cdt::Face_handle> queue{start};
    while (!queue.empty()) {
      const Cdt::Face_handle f = queue.front();
      queue.pop_front();
      if (f->info().nesting != -1) continue;
      f->info().nesting = level;
      for (int i = 0; i < 3; ++i) {
        const Cdt::Face_handle n = f->neighbor(i);
        if (n->info().nesting != -1) continue;
        if (cdt.is_constrained(Cdt::Edge(f, i))) {
          border.emplace_back(f, i);
        } else {
          queue.push_back(n);
        }
      }
    }
  };
  fill(cdt.infinite_face(), 0);
  while (!border.empty()) {
    const Cdt::Edge e = border.front();
    border.pop_front();
    const Cdt::Face_handle n = e.first->neighbor(e.second);
    if (n->info().nesting == -1) fill(n, e.first->info().nesting + 1);
  }
}

}  // namespace

Mesh2dNodes uniformMeshNodes(const UniformMesh2d& mesh) {
  Mesh2dNodes nodes(static_cast<Eigen::Index>(mesh.nodesX) * mesh.nodesY, 2);
  for (int j = 0; j < mesh.nodesY; ++j) {
    for (int i = 0; i < mesh.nodesX; ++i) {
      nodes.row(j * mesh.nodesX + i) << mesh.x0 + i * mesh.dx, mesh.y0 + j * mesh.dy;
    }
  }
  return nodes;
}

Mesh2dTriangles uniformMeshTriangles(const UniformMesh2d& mesh) {
  constexpr int kMaxNodes = 1 << 22;
  if (mesh.nodesX < 2 || mesh.nodesX > kMaxNodes) {
    throw Error({}, 0, "uniform.nodes_x", "needs 2.." + std::to_string(kMaxNodes) + " nodes");
  }
  if (mesh.nodesY < 2 || static_cast<long long>(mesh.nodesX) * mesh.nodesY > kMaxNodes) {
    throw Error({}, 0, "uniform.nodes_y",
                "needs >= 2 nodes and at most " + std::to_string(kMaxNodes) + " in all");
  }
  if (!(mesh.dx > 0) || !std::isfinite(mesh.dx)) throw Error({}, 0, "uniform.dx", "must be > 0");
  if (!(mesh.dy > 0) || !std::isfinite(mesh.dy)) throw Error({}, 0, "uniform.dy", "must be > 0");
  if (mesh.topology < 0 || mesh.topology > 3) {
    throw Error({}, 0, "uniform.topology", "must be 0..3 (Fig. 20's codes 00, 01, 10, 11)");
  }
  Mesh2dTriangles triangles(2 * static_cast<Eigen::Index>(mesh.nodesX - 1) * (mesh.nodesY - 1), 3);
  Eigen::Index t = 0;
  for (int j = 0; j + 1 < mesh.nodesY; ++j) {
    for (int i = 0; i + 1 < mesh.nodesX; ++i) {
      const int a = j * mesh.nodesX + i, b = a + 1, c = a + mesh.nodesX, d = c + 1;
      // Codes 2 and 3 alternate the diagonal in a checkerboard, starting at the top-left cell.
      const bool checker = (i + j) % 2 == 1;
      const bool topLeftToBottomRight =
          mesh.topology == 0 || (mesh.topology == 2 && !checker) || (mesh.topology == 3 && checker);
      if (topLeftToBottomRight) {
        triangles.row(t++) << a, b, d;
        triangles.row(t++) << a, d, c;
      } else {
        triangles.row(t++) << a, b, c;
        triangles.row(t++) << b, d, c;
      }
    }
  }
  return triangles;
}

Mesh2dTriangles delaunayMeshTriangles(const Mesh2dNodes& nodes, int boundary,
                                      const std::string& source) {
  const auto count = static_cast<int>(nodes.rows());
  if (boundary < 3 || boundary > count) {
    throw Error(
        source, 0, "boundary",
        "needs 3.." + std::to_string(count) + " boundary nodes, not " + std::to_string(boundary));
  }
  CGAL::Polygon_2<Kernel> polygon;
  for (int i = 0; i < boundary; ++i) polygon.push_back(Point(nodes(i, 0), nodes(i, 1)));
  if (!polygon.is_simple()) {
    // Name the first edge that meets a non-adjacent one (a quadratic search: for the sizes
    // a person draws by hand).
    if (boundary > 1000) throw Error(source, 0, "boundary", "the boundary intersects itself");
    auto segment = [&](int i) {
      return Kernel::Segment_2(polygon[i], polygon[(i + 1) % boundary]);
    };
    for (int i = 0; i < boundary; ++i) {
      for (int j = i + 1; j < boundary; ++j) {
        const bool adjacent = j == i + 1 || (i == 0 && j == boundary - 1);
        if (polygon[i] == polygon[j]) {
          throw Error(source, 0, nodeField(j), "coincides with boundary node " + std::to_string(i));
        }
        if (!adjacent && CGAL::do_intersect(segment(i), segment(j))) {
          throw Error(source, 0, nodeField(i),
                      "the boundary intersects itself: its edge from node " + std::to_string(i) +
                          " meets the edge from node " + std::to_string(j));
        }
      }
    }
    throw Error(source, 0, "boundary", "the boundary polygon is not simple");
  }
  for (int i = boundary; i < count; ++i) {
    const auto side = polygon.bounded_side(Point(nodes(i, 0), nodes(i, 1)));
    if (side != CGAL::ON_BOUNDED_SIDE) {
      throw Error(source, 0, nodeField(i),
                  side == CGAL::ON_BOUNDARY ? "an interior node lies on the boundary"
                                            : "an interior node lies outside the boundary");
    }
  }
  Cdt cdt;
  std::vector<Cdt::Vertex_handle> handles(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    const Cdt::Vertex_handle v = cdt.insert(Point(nodes(i, 0), nodes(i, 1)));
    if (cdt.number_of_vertices() != static_cast<size_t>(i) + 1) {
      throw Error(source, 0, nodeField(i), "coincides with node " + std::to_string(v->info()));
    }
    v->info() = i;
    handles[static_cast<size_t>(i)] = v;
  }
  for (int i = 0; i < boundary; ++i) {
    cdt.insert_constraint(handles[static_cast<size_t>(i)],
                          handles[static_cast<size_t>((i + 1) % boundary)]);
  }
  markDomains(cdt);
  std::vector<int> flat;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (f->info().nesting % 2 != 1) continue;
    // CGAL's faces are counterclockwise with y up, so clockwise on the screen with y down.
    for (int k = 0; k < 3; ++k) flat.push_back(f->vertex(k)->info());
  }
  Mesh2dTriangles triangles(static_cast<Eigen::Index>(flat.size() / 3), 3);
  std::copy(flat.begin(), flat.end(), triangles.data());
  return triangles;
}

Mesh2dTriangles meshTriangles(const Mesh2dSequence& sequence, const std::string& source) {
  if (sequence.frames.empty()) throw Error(source, 0, "frames", "has no intra plane");
  if (sequence.type == Mesh2dType::Uniform) return uniformMeshTriangles(sequence.uniform);
  return delaunayMeshTriangles(sequence.frames[0], sequence.boundary, source);
}

void validateMesh2d(const Mesh2dSequence& sequence, const std::string& source) {
  if (sequence.width <= 0) throw Error(source, 0, "width", "must be > 0");
  if (sequence.height <= 0) throw Error(source, 0, "height", "must be > 0");
  if (sequence.frames.empty()) throw Error(source, 0, "frames", "has no intra plane (frame 0)");
  const Eigen::Index count = sequence.frames[0].rows();
  for (size_t f = 0; f < sequence.frames.size(); ++f) {
    const Mesh2dNodes& frame = sequence.frames[f];
    const std::string field = "frames[" + std::to_string(f) + "]";
    if (frame.rows() != count) {
      throw Error(
          source, 0, field,
          "has " + std::to_string(frame.rows()) + " nodes, frame 0 has " + std::to_string(count));
    }
    for (Eigen::Index n = 0; n < count; ++n) {
      if (!frame.row(n).allFinite()) {
        throw Error(source, 0, field + "[" + std::to_string(n) + "]", "is not a finite point");
      }
    }
  }
  if (sequence.type == Mesh2dType::Uniform) {
    uniformMeshTriangles(sequence.uniform);  // checks the parameters
    const long long expectedCount =
        static_cast<long long>(sequence.uniform.nodesX) * sequence.uniform.nodesY;
    if (expectedCount != count) {
      throw Error(source, 0, "frames[0]",
                  "has " + std::to_string(count) + " nodes, the uniform mesh " +
                      std::to_string(expectedCount));
    }
    const Mesh2dNodes expected = uniformMeshNodes(sequence.uniform);
    for (Eigen::Index n = 0; n < count; ++n) {
      if ((expected.row(n) - sequence.frames[0].row(n)).cwiseAbs().maxCoeff() > 1e-3) {
        throw Error(source, 0, "frames[0][" + std::to_string(n) + "]",
                    "is not where the uniform parameters put node " + std::to_string(n));
      }
    }
  } else if (sequence.boundary < 3 || sequence.boundary > count) {
    throw Error(source, 0, "boundary",
                "needs 3.." + std::to_string(count) + " boundary nodes, not " +
                    std::to_string(sequence.boundary));
  }
  for (Eigen::Index t = 0; t < sequence.triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int i = sequence.triangles(t, k);
      if (i < 0 || i >= count) {
        throw Error(
            source, 0, "triangles[" + std::to_string(t) + "][" + std::to_string(k) + "]",
            "node " + std::to_string(i) + " is out of range 0.." + std::to_string(count - 1));
      }
    }
  }
}

}  // namespace mpeg4face
