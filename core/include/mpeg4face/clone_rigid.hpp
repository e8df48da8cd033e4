// SPDX-License-Identifier: GPL-3.0-or-later
// The rigid parts of Facial Motion Cloning (Pandzic 2003, "Treating eyes, teeth, tongue and
// global motion"): the Transforms that move the eyes, the teeth, the tongue and the whole
// head are found from the feature points on their meshes, and their rotations (eyes, head)
// and translations (teeth, tongue) are carried from source to target copies.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "mpeg4face/face_model.hpp"
#include "mpeg4face/fapu.hpp"
#include "mpeg4face/fat_generate.hpp"

namespace mpeg4face {

struct RigidPart {
  enum class Kind { LeftEye, RightEye, UpperTeeth, LowerTeeth, Tongue, Head } kind;
  int sourceTransform = -1;       // the source's lowest moving Transform over the meshes
  int targetTransform = -1;       // the target's lowest Transform over its meshes
  std::vector<int> sourceMeshes;  // found from the part's feature points (+ connected)
  std::vector<int> targetMeshes;
};

struct RigidPartMap {
  std::vector<RigidPart> parts;  // only parts found in both faces
  // Meshes moved as rigid parts, excluded from the vertex mapping (never the Head part's).
  std::vector<int> sourceRigidMeshes, targetRigidMeshes;
  std::vector<std::string> warnings;  // a part that moves in the source but is not found
};

// Finds the parts in both faces. Where a target eye's or the head's Transform does not
// rotate about the eye centre (3.5 / 3.6) or the neck base (7.2), installs the centre in
// `target` (Transform::center, compensated so that nothing moves).
RigidPartMap matchRigidParts(const FaceModel& sourceNeutral,
                             std::span<const DeformedCopy> sourceCopies, FaceModel& target);

// Sets, in `targetCopy` (a copy of the target neutral), the Transform fields of every part
// from the change `sourceCopy` makes to the source neutral: rotations as they are,
// translations scaled by the FAPU ratio (MNS0 for teeth and tongue).
void cloneRigidMotion(const RigidPartMap& map, const FaceModel& sourceNeutral,
                      const FapuMeasurement& sourceFapu, const DeformedCopy& sourceCopy,
                      const FapuMeasurement& targetFapu, FaceModel& targetCopy);

}  // namespace mpeg4face
