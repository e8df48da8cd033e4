// SPDX-License-Identifier: GPL-3.0-or-later
// What one FAP, viseme or expression at one amplitude does to the neutral face, kept as what
// moves: the FaceDefTables generator's input (fat/generate.hpp), Facial Motion Cloning's
// input and output (clone/clone.hpp), the shape keys of a model (fat/names.hpp), and what Python
// and the Blender add-on exchange. A shape moves a region of the face: 68 full copies of a large
// head would cost more memory, and time to fill and compare, than making the tables.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face {

// The vertices of one mesh that a shape moves, and by how much (mesh-local coordinates):
// vertex vertices[k] moves by displacement.row(k); vertices not listed do not move.
struct MeshDisplacement {
  int mesh = 0;
  std::vector<int> vertices;  // ascending
  Points3 displacement;
};

struct FaceShape {
  std::string name;         // for messages: a file or shape-key name
  int fapID = 3;            // 3..68; 1 for a viseme, 2 for an expression
  int highLevelSelect = 0;  // the viseme (1..14) or expression (1..6) for fapID 1 / 2
  // The FAP value the shape shows (in its FAPU, not 0); for a viseme or expression its
  // amount 1..63 (63 = fully).
  int amplitude = 0;
  std::vector<MeshDisplacement> meshes;  // meshes with a vertex that moves, ascending
  // Empty: the neutral's Transforms, unchanged; else one per neutral Transform, the same
  // tree and centres, translation / rotation / scale as this shape sets them.
  std::vector<Transform> transforms;
};

// Throws mpeg4face::Error (field "copy '<name>'" and the mesh or Transform) for a mesh index
// out of range or not ascending, vertices not ascending or not in the mesh, a displacement
// row count other than the vertices', a value that is not finite, and Transforms other in
// count, tree or centre than the neutral's.
void checkFaceShape(const FaceModel& neutral, const FaceShape& shape);

// The shape's Transforms: its own, or the neutral's when it changes none.
const std::vector<Transform>& shapeTransforms(const FaceModel& neutral, const FaceShape& shape);

// The rows of `displacement` (one per vertex of mesh `mesh`) that are not zero.
MeshDisplacement sparseDisplacement(int mesh, const Points3& displacement);

// The displacement of every vertex of mesh `mesh` (vertexCount rows, 0 where the shape lists
// none): a morph target.
Points3 denseDisplacement(const FaceShape& shape, int mesh, int vertexCount);

// The vertices of each mesh whose position in `coord` (one per neutral mesh) differs from the
// neutral's, as displacements.
std::vector<MeshDisplacement> meshDisplacements(const FaceModel& neutral,
                                                std::span<const Points3> coord);

// For input that arrives as a whole deformed model (a file, a test): the shape that moves
// `neutral` to `deformed`, named `name`, its FAP fields left for the caller. Throws
// mpeg4face::Error as checkFaceShape does, and for other meshes, vertex counts or faces.
FaceShape shapeFromDeformedModel(const FaceModel& neutral, const FaceModel& deformed,
                                 std::string name);

// The neutral moved by the shape: for writing a file or checking a whole pose.
FaceModel deformedModel(const FaceModel& neutral, const FaceShape& shape);

}  // namespace mpeg4face
