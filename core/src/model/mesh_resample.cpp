// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/model/mesh_resample.hpp"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/ModifiedButterFlyT.hh>
#include <cmath>
#include <string>
#include <vector>

#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

// Double precision points, so that kept vertices come back bit for bit.
struct Traits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
};
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<Traits>;

std::string meshLabel(const IndexedFaceSet& mesh, int index) {
  return "mesh " + std::to_string(index) + " '" + mesh.name + "'";
}

// The mesh in OpenMesh, vertex i as handle i. Faces are fan-triangulated; triangles with a
// repeated corner have no area and are left out.
TriMesh toOpenMesh(const IndexedFaceSet& mesh, int meshIndex) {
  TriMesh out;
  out.reserve(static_cast<size_t>(mesh.vertexCount()), 3 * mesh.coordIndex.size(),
              mesh.coordIndex.size());
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    out.add_vertex(TriMesh::Point(mesh.coord(v, 0), mesh.coord(v, 1), mesh.coord(v, 2)));
  }
  const std::vector<std::pair<int, int>> faces = mesh.faceRanges();
  for (size_t f = 0; f < faces.size(); ++f) {
    const auto [begin, end] = faces[f];
    for (int i = begin + 1; i + 1 < end; ++i) {
      const int a = mesh.coordIndex[static_cast<size_t>(begin)];
      const int b = mesh.coordIndex[static_cast<size_t>(i)];
      const int c = mesh.coordIndex[static_cast<size_t>(i + 1)];
      if (a == b || b == c || a == c) continue;
      if (!out.add_face(out.vertex_handle(static_cast<unsigned>(a)),
                        out.vertex_handle(static_cast<unsigned>(b)),
                        out.vertex_handle(static_cast<unsigned>(c)))
               .is_valid()) {
        throw Error({}, 0, meshLabel(mesh, meshIndex) + " face " + std::to_string(f),
                    "not manifold (an edge with more than two faces, a vertex joining separate "
                    "fans, or a face turned against its neighbours); cannot resample");
      }
    }
  }
  return out;
}

// Writes the undeleted vertices and faces of `om` into `mesh` as a neutral triangle mesh;
// returns, per vertex handle index, the new vertex number (-1 for deleted ones). Vertices
// keep the order of their handles.
std::vector<int> fromOpenMesh(const TriMesh& om, IndexedFaceSet& mesh) {
  std::vector<int> newIndex(om.n_vertices(), -1);
  int count = 0;
  for (const auto v : om.all_vertices()) {
    if (!om.has_vertex_status() || !om.status(v).deleted()) newIndex[v.idx()] = count++;
  }
  mesh.coord.resize(count, 3);
  for (const auto v : om.all_vertices()) {
    if (newIndex[v.idx()] < 0) continue;
    const TriMesh::Point& p = om.point(v);
    mesh.coord.row(newIndex[v.idx()]) << p[0], p[1], p[2];
  }
  mesh.coordIndex.clear();
  for (const auto f : om.faces()) {  // faces() skips deleted faces
    for (const auto v : om.fv_range(f)) mesh.coordIndex.push_back(newIndex[v.idx()]);
    mesh.coordIndex.push_back(-1);
  }
  mesh.normal.resize(0, 3);
  mesh.texCoord.resize(0, 2);
  mesh.texCoordIndex.clear();
  mesh.morphTargets.clear();
  mesh.weights.clear();
  return newIndex;
}

// The model with every mesh replaced by `resample(mesh, meshIndex, lockedVertices)`, which
// returns the new vertex number of each old vertex (-1 if removed); feature points follow.
template <typename Resample>
FaceModel resampleMeshes(const FaceModel& model, Resample resample) {
  model.validate();
  FaceModel out = model;
  std::vector<std::vector<bool>> locked(model.meshes.size());
  for (size_t m = 0; m < model.meshes.size(); ++m) {
    locked[m].assign(static_cast<size_t>(model.meshes[m].vertexCount()), false);
  }
  for (const auto& [id, fp] : model.featurePoints) {
    if (fp.mesh >= 0) locked[static_cast<size_t>(fp.mesh)][static_cast<size_t>(fp.vertex)] = true;
  }
  std::vector<std::vector<int>> newIndex(model.meshes.size());
  for (size_t m = 0; m < model.meshes.size(); ++m) {
    newIndex[m] = resample(out.meshes[m], static_cast<int>(m), locked[m]);
  }
  for (auto& [id, fp] : out.featurePoints) {
    if (fp.mesh < 0) continue;
    fp.vertex = newIndex[static_cast<size_t>(fp.mesh)][static_cast<size_t>(fp.vertex)];
    if (fp.vertex < 0) {  // cannot happen: bound vertices are locked
      throw Error({}, 0, "feature point " + id, "its vertex was removed by resampling");
    }
  }
  for (MorphWeightAnimation& animation : out.animations) animation.channels.clear();
  return out;
}

}  // namespace

FaceModel decimateFaceModel(const FaceModel& model, double vertexFraction) {
  if (!(vertexFraction > 0.0 && vertexFraction <= 1.0)) {
    throw Error({}, 0, "vertexFraction",
                "must be in (0, 1], got " + std::to_string(vertexFraction));
  }
  return resampleMeshes(
      model, [&](IndexedFaceSet& mesh, int meshIndex, const std::vector<bool>& locked) {
        const std::vector<int> sourceIndex = mesh.sourceIndex;
        TriMesh om = toOpenMesh(mesh, meshIndex);
        om.request_vertex_status();
        om.request_edge_status();
        om.request_face_status();
        for (size_t v = 0; v < locked.size(); ++v) {
          if (locked[v]) om.status(om.vertex_handle(static_cast<unsigned>(v))).set_locked(true);
        }
        const auto target =
            static_cast<size_t>(std::lround(vertexFraction * static_cast<double>(om.n_vertices())));
        if (target < om.n_vertices()) {
          OpenMesh::Decimater::DecimaterT<TriMesh> decimater(om);
          OpenMesh::Decimater::ModQuadricT<TriMesh>::Handle quadric;
          decimater.add(quadric);
          decimater.module(quadric).unset_max_err();
          if (!decimater.initialize()) {
            throw Error({}, 0, meshLabel(mesh, meshIndex), "OpenMesh's decimater did not start");
          }
          decimater.decimate_to(target);
        }
        std::vector<int> newIndex = fromOpenMesh(om, mesh);
        mesh.sourceIndex.clear();
        if (!sourceIndex.empty()) {
          mesh.sourceIndex.resize(static_cast<size_t>(mesh.vertexCount()));
          for (size_t v = 0; v < newIndex.size(); ++v) {
            if (newIndex[v] >= 0)
              mesh.sourceIndex[static_cast<size_t>(newIndex[v])] = sourceIndex[v];
          }
        }
        return newIndex;
      });
}

FaceModel subdivideFaceModel(const FaceModel& model, int iterations) {
  if (iterations < 0 || iterations > 4) {
    throw Error({}, 0, "iterations", "must be 0 to 4, got " + std::to_string(iterations));
  }
  return resampleMeshes(
      model, [&](IndexedFaceSet& mesh, int meshIndex, const std::vector<bool>& /*locked*/) {
        TriMesh om = toOpenMesh(mesh, meshIndex);
        const size_t original = om.n_vertices();
        if (iterations > 0 && om.n_faces() > 0) {
          OpenMesh::Subdivider::Uniform::ModifiedButterflyT<TriMesh> butterfly;
          butterfly.attach(om);
          butterfly(static_cast<size_t>(iterations));
          butterfly.detach();
        }
        fromOpenMesh(om, mesh);
        mesh.sourceIndex.clear();
        // Interpolating: vertex handles 0..original-1 are the old vertices, unmoved.
        std::vector<int> newIndex(original);
        for (size_t v = 0; v < original; ++v) newIndex[v] = static_cast<int>(v);
        return newIndex;
      });
}

}  // namespace mpeg4face
