// SPDX-License-Identifier: GPL-3.0-or-later
// Free feature points bound to vertices. A point given as a free model-space position
// (FeaturePointBinding::mesh -1: a CSV's fp,x,y,z, another tool's landmarks) works for the
// FAPU, but the ARKit mapping, its keys and the clone's lip contact need a vertex: a free
// point that lies on a mesh's surface is bound to that mesh's nearest vertex.
#pragma once

#include <string>
#include <vector>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face {

// How far off the surface a free point may lie and still be bound, as a fraction of the
// face's size: the diagonal of the box around every feature point (around the model if it has
// fewer than 3), so that a whole body does not widen it. 2%, 3-5 mm on a face.
inline constexpr double kFeaturePointSnapTolerance = 0.02;

struct FeaturePointSnap {
  // One line per point bound, e.g. "feature point 2.1 bound to vertex 412 of mesh 'skin'
  // (0.05% of the face's size off its surface, 0.31% from the vertex)".
  std::vector<std::string> notes;
  // One line per free point left free, farther from every mesh than the tolerance.
  std::vector<std::string> unbound;
};

// Binds `model`'s free feature points in place: each to the nearest corner of the closest
// triangle of the mesh whose surface is closest to it, if that is within `tolerance` (as
// kFeaturePointSnapTolerance). Points already on a vertex are left as they are, and so are
// 7.1 and 7.2, the centres of the head's and neck's rotation, inside the head.
FeaturePointSnap snapFeaturePointsToVertices(FaceModel& model,
                                             double tolerance = kFeaturePointSnapTolerance);

}  // namespace mpeg4face
