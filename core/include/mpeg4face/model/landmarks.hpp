// SPDX-License-Identifier: GPL-3.0-or-later
// Automatic feature points: a head's MPEG-4 feature points placed by registering a template
// head that has them (the ICT sample) onto it. A similarity alignment that assumes nothing of
// the file's axes, units or position; non-rigid ICP (Amberg et al. 2007, with the per-vertex
// transforms reduced to translations) with a stiffness schedule; each template point carried
// onto the target's surface and refined by its own rule where it has one. The user's own
// points (pins) are kept and constrain the fit. Method and figures in docs/landmarks.md.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face {

struct LandmarkOptions {
  // Feature points the user placed (vertex or model-space position of the target), kept
  // exactly in the result and pulled on by the fit. Ids the template lacks are kept but do
  // not constrain it.
  std::map<std::string, FeaturePointBinding> pins;
  // Called with the fraction done (0..1) and the step, e.g. "non-rigid fit".
  std::function<void(double, std::string_view)> progress;
};

struct PlacedFeaturePoint {
  FeaturePointBinding binding;  // a vertex of the target, or a free position (7.1, 7.2)
  // 0..1: how well the fitted template lies on the target around the point (1: within 1% of
  // ES0, 0.5 at 3%), lower for points carried off the surface; 1 for pins.
  double confidence = 0;
  std::string rule;  // how it was placed, e.g. "pin", "fit", "fit, most forward on eye mesh"
};

struct LandmarkResult {
  std::map<std::string, PlacedFeaturePoint> points;  // keyed by id, e.g. "2.1"
  // Template points not placed, with the reason, e.g. "9.9: no teeth mesh near ...".
  std::vector<std::string> notPlaced;
  int faceMesh = -1;  // the target mesh taken as the face's skin
  // The template-to-target similarity found (model space), and its scale.
  Eigen::Affine3d alignment = Eigen::Affine3d::Identity();
  double scale = 1;
  // Median distance of the aligned (not yet fitted) template to the target, in fractions of
  // the template's RMS radius carried by the scale: heads 1-2%, no face past 4.5%. With three
  // or more pins, of the template's face alone (a mask has no back of the head).
  double alignmentResidual = 0;
  // Median distance of the fitted template's face to the target, in fractions of the
  // template's ES0 carried to the target.
  double fitResidual = 0;
};

// The mesh findFeaturePoints takes as the head's face: the one with the most triangles; -1
// if no mesh has any.
int landmarkFaceMesh(const FaceModel& head);

// Places the feature points of `templateHead` (a head with feature points on the vertices of
// its skin, eyes, teeth and tongue meshes, in MPEG-4's axes: y up, looking along +z) on
// `target`. The target's face is landmarkFaceMesh(target); eyes, teeth and tongue are
// found among its other meshes by where the template puts them. Throws mpeg4face::Error,
// naming what is missing, for a target without faces, a template without enough feature
// points, and a target on which no alignment makes the template's face fit (a sphere, a cube:
// "no face found").
LandmarkResult findFeaturePoints(const FaceModel& target, const FaceModel& templateHead,
                                 const LandmarkOptions& options = {});

}  // namespace mpeg4face
