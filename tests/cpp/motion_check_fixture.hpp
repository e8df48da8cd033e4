// SPDX-License-Identifier: GPL-3.0-or-later
// A small synthetic head for the motion check's tests: flat sheets of triangles in one mesh,
// feature points for the FAPU, and shape keys that stretch, flip, push one sheet through
// another, and move the lip corners and the jaw.
#pragma once

#include <string>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face::test {

// An n x n grid of vertices at `origin` (spacing `step`, in the xy plane), two triangles
// per square, appended to `mesh`; returns its first vertex.
inline int addSheet(IndexedFaceSet& mesh, const Eigen::Vector3d& origin, int n, double step) {
  const int first = mesh.vertexCount();
  mesh.coord.conservativeResize(first + n * n, 3);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      mesh.coord.row(first + j * n + i) =
          (origin + Eigen::Vector3d(i * step, j * step, 0)).transpose();
    }
  }
  for (int j = 0; j + 1 < n; ++j) {
    for (int i = 0; i + 1 < n; ++i) {
      const int a = first + j * n + i, b = a + 1, c = a + n, d = c + 1;
      mesh.coordIndex.insert(mesh.coordIndex.end(), {a, b, d, -1, a, d, c, -1});
    }
  }
  return first;
}

struct MotionHead {
  FaceModel model;
  int stretchSheet = 0;                  // far from the lips and lids
  int crossSheetA = 0, crossSheetB = 0;  // B 0.5 above A, both 3 x 3, step 1
  int lipSheetA = 0, lipSheetB = 0;      // the same at the mouth, step 0.1
  int innerLeft = 0, innerRight = 0, outerLeft = 0, outerRight = 0, chin = 0, lowerLip = 0;

  void key(const std::string& name, int vertex, const Eigen::Vector3d& move) {
    IndexedFaceSet& mesh = model.meshes[0];
    for (MorphTarget& t : mesh.morphTargets) {
      if (t.name == name) {
        t.displacements.row(vertex) += move.transpose();
        return;
      }
    }
    MorphTarget t{name, Points3::Zero(mesh.vertexCount(), 3)};
    t.displacements.row(vertex) = move.transpose();
    mesh.morphTargets.push_back(std::move(t));
  }
};

// The face is 2 wide at the mouth (MW0 = |8.3 - 8.4| = 2), ES0 = 2, MNS0 = 1.
inline MotionHead motionHead() {
  MotionHead h;
  IndexedFaceSet mesh;
  mesh.name = "skin";
  h.stretchSheet = addSheet(mesh, {10, 0, 0}, 3, 1);
  h.crossSheetA = addSheet(mesh, {-10, 0, 0}, 3, 1);
  h.crossSheetB = addSheet(mesh, {-10, 0, 0.5}, 3, 1);
  h.lipSheetA = addSheet(mesh, {-0.1, -0.1, 0}, 3, 0.1);
  h.lipSheetB = addSheet(mesh, {-0.1, -0.1, 0.05}, 3, 0.1);
  // Points only, in no triangle: the lip corners, the chin and the lower lip.
  const int points = mesh.vertexCount();
  mesh.coord.conservativeResize(points + 6, 3);
  mesh.coord.bottomRows(6) << 0.8, 0, 0, -0.8, 0, 0, 1, 0, 0, -1, 0, 0, 0, -2, 0, 0, -0.2, 0;
  h.innerLeft = points, h.innerRight = points + 1, h.outerLeft = points + 2;
  h.outerRight = points + 3, h.chin = points + 4, h.lowerLip = points + 5;
  h.model.addMeshWithTransform(std::move(mesh));
  const auto free = [&](const char* id, double x, double y) {
    h.model.featurePoints[id] = {-1, -1, Eigen::Vector3d(x, y, 0)};
  };
  free("3.5", -1, 2), free("3.6", 1, 2), free("9.15", 0, 1), free("2.2", 0, 0);
  free("2.3", 0, -0.05);
  const auto bound = [&](const char* id, int v) {
    h.model.featurePoints[id] = {0, v, Eigen::Vector3d::Zero()};
  };
  bound("2.4", h.innerLeft), bound("2.5", h.innerRight), bound("8.3", h.outerLeft);
  bound("8.4", h.outerRight), bound("2.1", h.chin), bound("8.2", h.lowerLip);
  return h;
}

}  // namespace mpeg4face::test
