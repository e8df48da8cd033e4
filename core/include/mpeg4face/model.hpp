// SPDX-License-Identifier: GPL-3.0-or-later
// The face model: the scene graph of named Transforms holding IndexedFaceSets, with morph
// targets, poses and the feature-point bindings of the FDP, its FAPU, and geometry that works on
// it.
//
//   model/face_model.hpp      FaceModel: Transforms, IndexedFaceSets, morph targets, FDP
//   model/face_shape.hpp      FaceShape: what a FAP, viseme or expression moves, sparse
//   model/fapu.hpp            the FAPU measured from feature points; Table 6's checks
//   model/feature_point_snap.hpp  free feature points bound to the vertex they lie on
//   model/landmarks.hpp       feature points found by registering a template head
//   model/vertex_normals.hpp  smooth normals of a moving triangle mesh
//   model/mesh_cut.hpp        a part cut out of a model by a plane (a head off a body)
//   model/mesh_resample.hpp   meshes resampled to other densities (OpenMesh)
//   model/surface_bump.hpp    bumps and spikes of a displacement field over a mesh
#pragma once

#include "mpeg4face/model/face_model.hpp"      // IWYU pragma: export
#include "mpeg4face/model/face_shape.hpp"      // IWYU pragma: export
#include "mpeg4face/model/fapu.hpp"            // IWYU pragma: export
#include "mpeg4face/model/feature_point_snap.hpp"  // IWYU pragma: export
#include "mpeg4face/model/landmarks.hpp"       // IWYU pragma: export
#include "mpeg4face/model/mesh_cut.hpp"        // IWYU pragma: export
#include "mpeg4face/model/mesh_resample.hpp"   // IWYU pragma: export
#include "mpeg4face/model/surface_bump.hpp"    // IWYU pragma: export
#include "mpeg4face/model/vertex_normals.hpp"  // IWYU pragma: export
