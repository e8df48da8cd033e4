// SPDX-License-Identifier: GPL-3.0-or-later
// Resampling a face model's meshes to fewer or more vertices (OpenMesh), for clone targets
// of other densities than the faces we have. Feature points stay bound to the same
// positions. Design notes in docs/mesh-resample.md.
#pragma once

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face {

// Both functions work on each mesh alone and return a model with the same transforms,
// roots and meshes (same order and names). Each mesh comes back triangulated (faces with
// repeated corners are dropped) and as a neutral: its normals, texCoords, morph targets and
// weights are dropped, and so are the morph-weight channels of animations (transform
// channels stay). Vertices no face uses are kept. Feature points bound to vertices are
// renumbered to the new vertices at the same positions; free coordinates are kept. Meshes
// that share vertices in their source file are resampled separately, so their common
// border may open. Throws mpeg4face::Error for a model that fails validate(), and naming the
// mesh and face for a face OpenMesh cannot hold (a non-manifold edge or vertex).

// Quadric edge-collapse decimation (OpenMesh Decimater, ModQuadricT) of each mesh to
// round(vertexFraction * its vertex count) vertices, or as near as the decimater gets.
// Vertices bound to feature points are locked: never removed nor moved. The surviving
// vertices keep their positions exactly and their order, and their sourceIndex if the mesh
// has one. Throws mpeg4face::Error unless 0 < vertexFraction <= 1.
FaceModel decimateFaceModel(const FaceModel& model, double vertexFraction);

// `iterations` rounds of modified butterfly subdivision (Zorin, Schröder and Sweldens 1996;
// OpenMesh ModifiedButterflyT): interpolating, so the original vertices keep their indices
// and positions exactly and feature points keep their vertex numbers; each round splits
// every edge (vertex count ~4x per round). sourceIndex is dropped. Throws
// mpeg4face::Error unless 0 <= iterations <= 4 (each round quadruples memory).
FaceModel subdivideFaceModel(const FaceModel& model, int iterations);

}  // namespace mpeg4face
