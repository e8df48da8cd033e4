// SPDX-License-Identifier: GPL-3.0-or-later
// The MPEG-4 2D mesh object (Tekalp & Ostermann 2000, section 3): a sequence of mesh object
// planes over an image, frame 0 the intra plane whose geometry is coded, the others inter
// planes whose node motion is coded. Pixel coordinates, x right, y down. The mesh's topology is
// always implied by its geometry: a uniform mesh by its five parameters and topology code
// (section 3.3.1.1, Fig. 20), a Delaunay mesh by its nodes, the first N_b of them the boundary
// polygon in order, triangulated by a constrained Delaunay triangulation (3.3.1.2; CGAL).
// Triangles are listed clockwise on the screen (positive cross product with y down).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace mpeg4face {

enum class Mesh2dType { Uniform, Delaunay };

// The five parameters of a uniform mesh (3.3.1.1) and where its top-left node lies. Topology
// code (Fig. 20): 0 every cell split top-left to bottom-right; 1 bottom-left to top-right;
// 2 alternating, starting top-left to bottom-right; 3 alternating, starting bottom-left to
// top-right (alternating in a checkerboard over the cells).
struct UniformMesh2d {
  int nodesX = 2;
  int nodesY = 2;
  double x0 = 0;
  double y0 = 0;
  double dx = 1;  // cell width, pixels
  double dy = 1;  // cell height, pixels
  int topology = 0;
};

// Node positions of one mesh object plane: one row per node, columns x, y in pixels.
using Mesh2dNodes = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;
// Triangles: three node indices per row, clockwise on the screen.
using Mesh2dTriangles = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct Mesh2dSequence {
  int width = 0;  // the image the mesh lies on, pixels
  int height = 0;
  Mesh2dType type = Mesh2dType::Uniform;
  int boundary = 0;       // N_b: the first N_b nodes are the boundary polygon (Delaunay)
  UniformMesh2d uniform;  // Uniform only
  Mesh2dTriangles triangles;
  std::vector<Mesh2dNodes> frames;  // frames[0] is the intra plane
};

// The nodes of a uniform mesh, row by row from the top-left one.
Mesh2dNodes uniformMeshNodes(const UniformMesh2d& mesh);
// Its triangles per topology code (Fig. 20). Throws mpeg4face::Error naming the field if a
// parameter is out of range (fewer than 2 nodes a side, a cell size <= 0, code not 0..3).
Mesh2dTriangles uniformMeshTriangles(const UniformMesh2d& mesh);

// The constrained Delaunay triangulation of `nodes`, the first `boundary` of them the boundary
// polygon in order (either orientation), with the triangles inside it only. Throws
// mpeg4face::Error naming the node (field "nodes[i]") if the boundary has fewer than 3 nodes or
// intersects itself, two nodes coincide, or an interior node is not strictly inside the
// boundary. `source` names the input in errors.
Mesh2dTriangles delaunayMeshTriangles(const Mesh2dNodes& nodes, int boundary,
                                      const std::string& source = {});

// The triangles that the intra plane's geometry implies (either kind).
Mesh2dTriangles meshTriangles(const Mesh2dSequence& sequence, const std::string& source = {});

// Checks a sequence is consistent: sizes positive, at least one frame, every frame with the
// intra plane's node count, finite coordinates, uniform nodes where the parameters put them,
// triangle indices in range. Throws mpeg4face::Error naming the field ("frames[3][12]",
// "triangles[5][1]") at fault.
void validateMesh2d(const Mesh2dSequence& sequence, const std::string& source = {});

}  // namespace mpeg4face
