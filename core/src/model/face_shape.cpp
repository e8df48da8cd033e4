// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/model/face_shape.hpp"

#include <algorithm>
#include <utility>

#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

std::string shapeField(const FaceShape& shape) { return "copy '" + shape.name + "'"; }

[[noreturn]] void fail(const FaceShape& shape, const std::string& where, const std::string& why) {
  const std::string label = shapeField(shape);
  throw Error({}, 0, where.empty() ? label : label + " " + where, why);
}

std::string meshField(const FaceModel& neutral, std::size_t m) {
  return "mesh '" + neutral.meshes[m].name + "'";
}

void checkTransforms(const FaceModel& neutral, const FaceShape& shape) {
  const std::vector<Transform>& ts = shape.transforms;
  if (ts.empty()) return;
  if (ts.size() != neutral.transforms.size()) {
    fail(shape, "",
         "has " + std::to_string(ts.size()) + " transforms, the neutral model " +
             std::to_string(neutral.transforms.size()));
  }
  for (std::size_t i = 0; i < ts.size(); ++i) {
    const Transform& a = ts[i];
    const Transform& b = neutral.transforms[i];
    const std::string t = "transform '" + b.name + "'";
    if (a.children != b.children || a.meshes != b.meshes) {
      fail(shape, t, "has other children or meshes than in the neutral model");
    }
    if (a.center != b.center) {
      fail(shape, t, "center moved: only translation, rotation and scale can be animated");
    }
    if (!a.translation.allFinite() || !a.scale.allFinite() || !a.rotation.coeffs().allFinite()) {
      fail(shape, t, "has a value that is not finite");
    }
  }
}

bool sameTransform(const Transform& a, const Transform& b) {
  return a.translation == b.translation && a.rotation.coeffs() == b.rotation.coeffs() &&
         a.scale == b.scale && a.center == b.center && a.children == b.children &&
         a.meshes == b.meshes;
}

}  // namespace

void checkFaceShape(const FaceModel& neutral, const FaceShape& shape) {
  int previous = -1;
  for (const MeshDisplacement& d : shape.meshes) {
    if (d.mesh <= previous || d.mesh >= static_cast<int>(neutral.meshes.size())) {
      fail(shape, "",
           "moves mesh " + std::to_string(d.mesh) + ": meshes are listed ascending, the neutral " +
               "model has " + std::to_string(neutral.meshes.size()));
    }
    previous = d.mesh;
    const std::string where = meshField(neutral, static_cast<std::size_t>(d.mesh));
    if (d.displacement.rows() != static_cast<Eigen::Index>(d.vertices.size())) {
      fail(shape, where,
           "has " + std::to_string(d.displacement.rows()) + " displacements for " +
               std::to_string(d.vertices.size()) + " vertices");
    }
    const int count = neutral.meshes[static_cast<std::size_t>(d.mesh)].vertexCount();
    for (std::size_t k = 0; k < d.vertices.size(); ++k) {
      const int v = d.vertices[k];
      if (v < 0 || v >= count || (k > 0 && v <= d.vertices[k - 1])) {
        fail(shape, where,
             "vertex " + std::to_string(v) + ": vertices are listed ascending, the mesh has " +
                 std::to_string(count));
      }
      if (!d.displacement.row(static_cast<Eigen::Index>(k)).allFinite()) {
        fail(shape, where, "vertex " + std::to_string(v) + " is not a finite number");
      }
    }
  }
  checkTransforms(neutral, shape);
}

const std::vector<Transform>& shapeTransforms(const FaceModel& neutral, const FaceShape& shape) {
  return shape.transforms.empty() ? neutral.transforms : shape.transforms;
}

MeshDisplacement sparseDisplacement(int mesh, const Points3& displacement) {
  MeshDisplacement out;
  out.mesh = mesh;
  for (Eigen::Index v = 0; v < displacement.rows(); ++v) {
    if (!displacement.row(v).isZero(0)) out.vertices.push_back(static_cast<int>(v));
  }
  out.displacement.resize(static_cast<Eigen::Index>(out.vertices.size()), 3);
  for (std::size_t k = 0; k < out.vertices.size(); ++k) {
    out.displacement.row(static_cast<Eigen::Index>(k)) = displacement.row(out.vertices[k]);
  }
  return out;
}

Points3 denseDisplacement(const FaceShape& shape, int mesh, int vertexCount) {
  Points3 out = Points3::Zero(vertexCount, 3);
  for (const MeshDisplacement& d : shape.meshes) {
    if (d.mesh != mesh) continue;
    for (std::size_t k = 0; k < d.vertices.size(); ++k) {
      out.row(d.vertices[k]) = d.displacement.row(static_cast<Eigen::Index>(k));
    }
  }
  return out;
}

std::vector<MeshDisplacement> meshDisplacements(const FaceModel& neutral,
                                                std::span<const Points3> coord) {
  std::vector<MeshDisplacement> out;
  for (std::size_t m = 0; m < neutral.meshes.size(); ++m) {
    MeshDisplacement d =
        sparseDisplacement(static_cast<int>(m), coord[m] - neutral.meshes[m].coord);
    if (!d.vertices.empty()) out.push_back(std::move(d));
  }
  return out;
}

FaceShape shapeFromDeformedModel(const FaceModel& neutral, const FaceModel& deformed,
                                 std::string name) {
  FaceShape shape;
  shape.name = std::move(name);
  if (deformed.meshes.size() != neutral.meshes.size()) {
    fail(shape, "",
         "has " + std::to_string(deformed.meshes.size()) + " meshes, the neutral model " +
             std::to_string(neutral.meshes.size()));
  }
  for (std::size_t m = 0; m < neutral.meshes.size(); ++m) {
    const IndexedFaceSet& a = deformed.meshes[m];
    const IndexedFaceSet& b = neutral.meshes[m];
    if (a.vertexCount() != b.vertexCount()) {
      fail(shape, meshField(neutral, m),
           "has " + std::to_string(a.vertexCount()) + " vertices, the neutral model " +
               std::to_string(b.vertexCount()));
    }
    if (a.coordIndex != b.coordIndex) {
      fail(shape, meshField(neutral, m), "has other faces than the neutral model");
    }
  }
  std::vector<Points3> coord;
  for (const IndexedFaceSet& mesh : deformed.meshes) coord.push_back(mesh.coord);
  shape.meshes = meshDisplacements(neutral, coord);
  if (!std::ranges::equal(deformed.transforms, neutral.transforms, sameTransform)) {
    shape.transforms = deformed.transforms;
  }
  checkFaceShape(neutral, shape);
  return shape;
}

FaceModel deformedModel(const FaceModel& neutral, const FaceShape& shape) {
  FaceModel model = neutral;
  for (const MeshDisplacement& d : shape.meshes) {
    Points3& coord = model.meshes[static_cast<std::size_t>(d.mesh)].coord;
    for (std::size_t k = 0; k < d.vertices.size(); ++k) {
      coord.row(d.vertices[k]) += d.displacement.row(static_cast<Eigen::Index>(k));
    }
  }
  if (!shape.transforms.empty()) model.transforms = shape.transforms;
  return model;
}

}  // namespace mpeg4face
