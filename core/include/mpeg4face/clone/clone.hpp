// SPDX-License-Identifier: GPL-3.0-or-later
// Facial Motion Cloning (Pandzic 2003): the motion of every shape of a source face (a FAP,
// viseme or expression: model/face_shape.hpp) is carried to a neutral target face that has feature
// points, so the target gets the same shapes and, from them, its FaceDefTables. Method and
// the feature-point triangulation in docs/clone.md.
#pragma once

#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mpeg4face/fat/generate.hpp"
#include "mpeg4face/fat/tables.hpp"
#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/model/face_shape.hpp"
#include "mpeg4face/model/fapu.hpp"

namespace mpeg4face {

// The cloned motion relaxed over the target (ours, docs/clone.md "Relaxing the cloned
// motion"). Where the target's surface meets the source's differently (its lids, mouth bag
// and nostrils landing on other parts of the source's), a cloned shape bends sharply where the
// source's is smooth and the region a shape moves ends in a step: on the MakeHuman head a plain
// clone of the ICT sample spikes 182 of the demo sentence's 190 frames. Defaults: those
// `mpeg4face animate` uses.
struct CloneRelaxation {
  // Passes of umbrella smoothing (relaxDisplacement) of each FAP shape's motion over the
  // face mesh (landmarkFaceMesh).
  int fapPasses = 4;
  // Passes over each viseme and expression shape's fringe only: the face vertices it moves
  // at most `fringeBelow` of its largest motion, still ones included (made of whole ARKit-like
  // shapes, smoothed all over their open mouths would open less).
  int fringePasses = 2;
  double fringeBelow = 0.2;
  // Each vertex of the surface's other meshes (eyelashes, brows: strips standing out of the
  // skin, which the source has no surface for) moves as the mean of this many face vertices
  // nearest to it (0: as cloned), then is smoothed along its own mesh in `attachedPasses`.
  int attachedNeighbours = 16;
  int attachedPasses = 4;
};

struct CloneOptions {
  // Support of the antialiasing (low-pass) filter in alignment-space units (the paper's
  // 0.02); 0 turns the filter off.
  double filterSupport = 0.02;
  // Apply the filter where the target samples the motion more coarsely than the source, the
  // only case that aliases (the paper's "from a face with a higher density to a face with a
  // lower density"): full support where the target's local edge length is at least twice
  // the source's, none where it is at most 1.25 times, linear between (ours, docs/clone.md).
  // false: the paper's fixed support at every vertex.
  bool adaptiveFilter = true;
  // Where the target samples more finely than the source (the inverse ramp: none up to 1.25
  // times as finely, full from twice), the same filter smooths the source's piecewise-linear
  // motion across its triangle borders, with a support of this many source edge lengths
  // (the source's mean local edge length in alignment space), narrowed to 0 at the feature
  // points, whose motion stays exact (ours, docs/clone.md); 0 turns it off.
  double smoothSupport = 1.0;
  // Keep the upper and lower lip regions apart (the paper's lip-region rule).
  bool separateLips = true;
  // A target point outside the source's surface takes the motion of the closest source
  // triangle (the paper's rule) faded linearly to 0 at this distance from it, in alignment
  // units (ours: a face mask's edge must not drag a whole body along); 0: no fading.
  double outsideFalloff = 0.5;
  // Map eyes, teeth, tongue and global head motion as transforms (clone/rigid.hpp).
  bool rigidParts = true;
  // Relax the cloned motion over the target (none: as the mapping carries it).
  std::optional<CloneRelaxation> relaxation;
  // Called with a stage name and the fraction done (0..1) of the whole job; may be empty.
  std::function<void(std::string_view stage, double fraction)> progress;
};

// The feature points the vertex mapping needs (the triangulation of docs/clone.md), in
// table order. 3.5, 3.6 (eye rotation centres) and 7.2 (neck base) are used by the rigid
// parts only: without them those motions are skipped with a warning.
std::span<const std::string_view> cloneFeaturePoints();
// Those of cloneFeaturePoints() that `model` does not bind, in table order.
std::vector<std::string> missingCloneFeaturePoints(const FaceModel& model);

struct CloneResult {
  // The target with rotation centres installed where needed (clone/rigid.hpp); the neutral
  // that `copies` deform.
  FaceModel targetNeutral;
  // One per source copy, in order: its name, fapID, highLevelSelect and amplitude, the target
  // vertices that move (a FAP shape moves a region of the face) and the target's Transforms
  // with the rigid parts' motion set (never empty).
  std::vector<FaceShape> copies;
  std::vector<std::string> warnings;
};

// Clones every copy (shape) of `sourceNeutral` onto `targetNeutral`. Vertex motion is each
// vertex's mesh-local displacement, taken to model space by the neutral world matrices
// (Transform changes are the rigid parts' business, not vertex motion). Throws
// mpeg4face::Error listing every missing feature point of either face (source / target
// named), and for a copy that does not fit the source neutral (checkFaceShape: naming the
// copy and mesh).
CloneResult cloneDeformedCopies(const FaceModel& sourceNeutral,
                                std::span<const FaceShape> sourceCopies,
                                const FaceModel& targetNeutral, const CloneOptions& options = {});

// A source given by its tables: one shape per non-zero interval border of each table (a
// one-interval table at a documented amplitude), visemes and expressions at 63, each
// evaluated alone from the neutral (FatEvaluator). Rules in docs/clone.md.
std::vector<FaceShape> shapesFromFaceDefTables(const MpegFace& face, const FapuMeasurement& fapu);

struct ClonedFace {
  MpegFace face;                  // the target with its FaceDefTables (generateFaceDefTables)
  std::vector<FaceShape> copies;  // CloneResult's, of face.faceSceneGraph
  std::vector<std::string> warnings;
};
// cloneDeformedCopies, then the target's tables from its copies as they are.
ClonedFace cloneFace(const FaceModel& sourceNeutral, std::span<const FaceShape> sourceCopies,
                     const FaceModel& targetNeutral, const CloneOptions& options = {});

}  // namespace mpeg4face
