// SPDX-License-Identifier: GPL-3.0-or-later
// Cutting a part out of a face model by a plane, e.g. the head of a whole-body model
// (docs/makehuman-head.md) for clone targets and benchmarks of head size.
#pragma once

#include <Eigen/Core>
#include <functional>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face {

// Keeps, of every mesh that `keepMesh` accepts (all if empty), the faces whose corners all
// lie on the side of the plane through `point` that `normal` points to (dot(p - point,
// normal) >= 0, p in model space) and the vertices those faces use, in their old order.
// Per-vertex data (normals, texCoords, morph targets, sourceIndex) is kept for those
// vertices, texCoordIndex for those faces. Meshes left without faces are removed and the
// transforms' mesh lists renumbered (transforms themselves stay, also when empty).
// Feature points on kept vertices are renumbered; those on removed vertices or meshes are
// dropped; free coordinates stay. Morph-weight animation channels of removed meshes are
// dropped, the others renumbered. Throws mpeg4face::Error for a model that fails validate()
// and for a zero or non-finite normal.
FaceModel cutFaceModel(const FaceModel& model, const Eigen::Vector3d& point,
                       const Eigen::Vector3d& normal,
                       const std::function<bool(const IndexedFaceSet&)>& keepMesh = {});

}  // namespace mpeg4face
