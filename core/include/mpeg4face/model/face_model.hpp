// SPDX-License-Identifier: GPL-3.0-or-later
// The face model: a VRML/BIFS-like scene graph of named Transform nodes holding named
// IndexedFaceSet meshes, plus the feature-point bindings of the FDP.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace mpeg4face {

// N x 3 and N x 2 row-major arrays: one row per vertex, the layout numpy uses.
using Points3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Points2 = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

// A named displacement of every vertex of a mesh (glTF morph target, Blender shape key).
struct MorphTarget {
  std::string name;
  Points3 displacements;  // rows = mesh vertex count
};

// VRML IndexedFaceSet: polygons as vertex indices, each face ended by -1.
struct IndexedFaceSet {
  std::string name;
  Points3 coord;                   // vertex positions
  std::vector<int> coordIndex;     // polygon corners, -1 after each face
  Points3 normal;                  // per-vertex normals, or 0 rows
  Points2 texCoord;                // UVs, or 0 rows
  std::vector<int> texCoordIndex;  // same layout as coordIndex; empty: texCoord per vertex
  std::vector<MorphTarget> morphTargets;
  std::vector<double> weights;  // default morph weights (empty or one per target)
  // For a mesh cut from a file with one shared vertex list (OBJ groups): each vertex's
  // 0-based index in that file, so feature points and targets given in the file's vertex
  // numbering still find it. Empty otherwise.
  std::vector<int> sourceIndex;

  int vertexCount() const { return static_cast<int>(coord.rows()); }
  int faceCount() const;
  // Faces as [begin, end) ranges into coordIndex, for iteration without -1 bookkeeping.
  std::vector<std::pair<int, int>> faceRanges() const;
  // Fan-triangulated faces, three indices per triangle.
  std::vector<int> triangles() const;
};

// VRML Transform: the child's point p maps to T * C * R * S * -C * p.
struct Transform {
  std::string name;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  std::vector<int> children;  // indices into FaceModel::transforms
  std::vector<int> meshes;    // indices into FaceModel::meshes

  Eigen::Affine3d localMatrix() const;
};

// Where a feature point is: a vertex of a mesh, or a free coordinate (model space).
struct FeaturePointBinding {
  int mesh = -1;    // index into FaceModel::meshes, -1 for a free coordinate
  int vertex = -1;  // vertex of that mesh
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // used when mesh == -1
};

// glTF-style animation of morph weights, one channel per mesh.
struct MorphWeightChannel {
  int mesh = 0;
  enum class Interpolation { Linear, Step, CubicSpline } interpolation = Interpolation::Linear;
  std::vector<double> times;    // seconds, increasing
  std::vector<double> weights;  // times.size() * targetCount (x3 for CubicSpline)
};
// glTF-style animation of one field of a Transform (a node translation / rotation / scale
// channel). The values are the Transform's own fields, so an animated rotation or scale
// stays about the Transform's centre.
struct TransformChannel {
  int transform = 0;  // index into FaceModel::transforms
  enum class Path { Translation, Rotation, Scale } path = Path::Rotation;
  MorphWeightChannel::Interpolation interpolation = MorphWeightChannel::Interpolation::Linear;
  std::vector<double> times;  // seconds, increasing
  // Per key x y z (translation, scale) or the quaternion x y z w (rotation, glTF's order);
  // x3 for CubicSpline (in-tangent, value, out-tangent).
  std::vector<double> values;
};
struct MorphWeightAnimation {
  std::string name;
  std::vector<MorphWeightChannel> channels;
  std::vector<TransformChannel> transformChannels;
};

struct FaceModel {
  std::vector<IndexedFaceSet> meshes;
  std::vector<Transform> transforms;
  std::vector<int> roots;  // top-level transforms (the faceSceneGraph)
  std::map<std::string, FeaturePointBinding> featurePoints;  // keyed by id, e.g. "2.1"
  std::vector<MorphWeightAnimation> animations;

  // Indices by name; nullopt if absent.
  std::optional<int> findMesh(const std::string& name) const;
  std::optional<int> findTransform(const std::string& name) const;

  // Model-space matrix of each mesh: the product of the transforms above its first use
  // (identity for a mesh no transform holds).
  std::vector<Eigen::Affine3d> meshWorldMatrices() const;
  // Model-space position of a bound feature point; nullopt if the id is not bound.
  std::optional<Eigen::Vector3d> featurePointPosition(const std::string& id) const;
  // Adds a mesh under a new root transform of the same name; returns the mesh index.
  int addMeshWithTransform(IndexedFaceSet mesh);
  // Throws mpeg4face::Error naming the first broken reference (index out of range,
  // face index outside the mesh, morph target of the wrong size, transform cycle).
  void validate() const;
};

// The basis of a model with shape keys: the same model without morph targets, weights and
// animations (the neutral face that deformed copies and tables start from).
FaceModel neutralFaceModel(const FaceModel& model);

// Per vertex of `mesh`, its connected piece (a tooth row, a tongue: the vertices its
// triangles join): one vertex of the piece, the same for all of them.
std::vector<int> connectedPieces(const IndexedFaceSet& mesh);

}  // namespace mpeg4face
