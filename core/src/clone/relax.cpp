// SPDX-License-Identifier: GPL-3.0-or-later
// The cloned motion relaxed over the target: CloneRelaxation (clone/clone.hpp), why in
// docs/clone.md "Relaxing the cloned motion".
#include <algorithm>
#include <utility>

#include "clone/clone_internal.hpp"
#include "mpeg4face/model/landmarks.hpp"
#include "mpeg4face/model/surface_bump.hpp"

namespace mpeg4face::clone {
namespace {

// A shape's displacement of mesh `m` (mesh-local), one row per vertex.
Points3 denseDisplacement(const FaceShape& shape, const IndexedFaceSet& mesh, int m) {
  Points3 out = Points3::Zero(mesh.vertexCount(), 3);
  for (const MeshDisplacement& d : shape.meshes) {
    if (d.mesh != m) continue;
    for (std::size_t k = 0; k < d.vertices.size(); ++k) {
      out.row(d.vertices[k]) = d.displacement.row(static_cast<Eigen::Index>(k));
    }
  }
  return out;
}

// `shape`'s displacement of mesh `m` replaced by `dense`'s rows that move.
void setDisplacement(FaceShape& shape, int m, const Points3& dense) {
  std::erase_if(shape.meshes, [m](const MeshDisplacement& d) { return d.mesh == m; });
  MeshDisplacement d;
  d.mesh = m;
  for (Eigen::Index v = 0; v < dense.rows(); ++v) {
    if (!dense.row(v).isZero(0)) d.vertices.push_back(static_cast<int>(v));
  }
  if (d.vertices.empty()) return;
  d.displacement.resize(static_cast<Eigen::Index>(d.vertices.size()), 3);
  for (std::size_t k = 0; k < d.vertices.size(); ++k) {
    d.displacement.row(static_cast<Eigen::Index>(k)) = dense.row(d.vertices[k]);
  }
  const auto at = std::lower_bound(
      shape.meshes.begin(), shape.meshes.end(), m,
      [](const MeshDisplacement& e, int mesh) { return e.mesh < mesh; });
  shape.meshes.insert(at, std::move(d));
}

// An attached mesh: per vertex, the `k` face vertices nearest to it in model space, and the
// linear map from the face's frame to the mesh's own.
struct Attachment {
  int mesh = -1;
  std::size_t k = 0;
  std::vector<int> nearest;  // k per vertex
  WeldedRings rings;
  Eigen::Matrix3d fromFace;
};

// `faceAt`: the face mesh's vertices in model space.
Attachment attach(const FaceModel& target, const std::vector<Eigen::Affine3d>& world, int face,
                  const Points3& faceAt, int mesh, int k) {
  const auto m = static_cast<std::size_t>(mesh);
  const Points3& coord = target.meshes[m].coord;
  Attachment out;
  out.mesh = mesh;
  out.k = static_cast<std::size_t>(std::min<Eigen::Index>(k, faceAt.rows()));
  out.rings = weldedRings(target.meshes[m]);
  out.fromFace = world[m].linear().inverse() * world[static_cast<std::size_t>(face)].linear();
  std::vector<std::pair<double, int>> near(static_cast<std::size_t>(faceAt.rows()));
  for (Eigen::Index v = 0; v < coord.rows(); ++v) {
    const Eigen::RowVector3d p = (world[m] * coord.row(v).transpose()).transpose();
    for (Eigen::Index f = 0; f < faceAt.rows(); ++f) {
      near[static_cast<std::size_t>(f)] = {(faceAt.row(f) - p).squaredNorm(),
                                           static_cast<int>(f)};
    }
    std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(out.k),
                      near.end());
    for (std::size_t j = 0; j < out.k; ++j) out.nearest.push_back(near[j].second);
  }
  return out;
}

}  // namespace

void relaxClonedShapes(const FaceModel& target, const std::vector<int>& surfaceMeshes,
                       const CloneRelaxation& relaxation, std::vector<FaceShape>& shapes) {
  const int face = landmarkFaceMesh(target);
  if (face < 0 || std::find(surfaceMeshes.begin(), surfaceMeshes.end(), face) ==
                      surfaceMeshes.end()) {
    return;
  }
  const IndexedFaceSet& faceMesh = target.meshes[static_cast<std::size_t>(face)];
  const WeldedRings rings = weldedRings(faceMesh);
  const std::vector<Eigen::Affine3d> world = target.meshWorldMatrices();
  std::vector<Attachment> attached;
  if (relaxation.attachedNeighbours > 0) {
    Points3 faceAt(faceMesh.coord.rows(), 3);
    for (Eigen::Index v = 0; v < faceAt.rows(); ++v) {
      faceAt.row(v) =
          (world[static_cast<std::size_t>(face)] * faceMesh.coord.row(v).transpose()).transpose();
    }
    for (int m : surfaceMeshes) {
      if (m == face || target.meshes[static_cast<std::size_t>(m)].vertexCount() == 0) continue;
      attached.push_back(attach(target, world, face, faceAt, m, relaxation.attachedNeighbours));
    }
  }
  for (FaceShape& shape : shapes) {
    Points3 d = denseDisplacement(shape, faceMesh, face);
    if (shape.fapID > 2) {
      relaxDisplacement(rings, d, relaxation.fapPasses);
    } else {
      const Eigen::VectorXd size = d.rowwise().norm();
      const double largest = size.size() ? size.maxCoeff() : 0.0;
      std::vector<bool> fringe(static_cast<std::size_t>(size.size()));
      for (Eigen::Index v = 0; v < size.size(); ++v) {
        fringe[static_cast<std::size_t>(v)] = size[v] <= relaxation.fringeBelow * largest;
      }
      relaxDisplacement(rings, d, relaxation.fringePasses, fringe);
    }
    setDisplacement(shape, face, d);
    for (const Attachment& a : attached) {
      // The mean face motion around each vertex, in the attached mesh's own frame.
      const std::size_t count = a.rings.weld.size();
      Points3 follow = Points3::Zero(static_cast<Eigen::Index>(count), 3);
      for (std::size_t v = 0; v < count && a.k; ++v) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (std::size_t j = 0; j < a.k; ++j) sum += d.row(a.nearest[v * a.k + j]).transpose();
        follow.row(static_cast<Eigen::Index>(v)) =
            (a.fromFace * sum / static_cast<double>(a.k)).transpose();
      }
      relaxDisplacement(a.rings, follow, relaxation.attachedPasses);
      setDisplacement(shape, a.mesh, follow);
    }
  }
}

}  // namespace mpeg4face::clone
