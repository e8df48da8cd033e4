// SPDX-License-Identifier: GPL-3.0-or-later
// The rigid parts of Facial Motion Cloning (Pandzic 2003, "Treating eyes, teeth, tongue and
// global motion"): the Transforms that move the eyes, the teeth, the tongue and the whole
// head are found from the feature points on their meshes, and their rotations (eyes, head)
// and translations (teeth, tongue) are carried from source to target copies. Rules in
// docs/clone-rigid.md.
#pragma once

#include <Eigen/Core>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/model/face_shape.hpp"
#include "mpeg4face/model/fapu.hpp"

namespace mpeg4face {

struct RigidPart {
  enum class Kind { LeftEye, RightEye, UpperTeeth, LowerTeeth, Tongue, Head } kind = Kind::Head;
  int sourceTransform = -1;       // the source's lowest moving Transform over the meshes
  int targetTransform = -1;       // the target's lowest Transform over its meshes
  std::vector<int> sourceMeshes;  // found from the part's feature points (+ connected)
  std::vector<int> targetMeshes;
  // Model-space points the motion is taken about: the eyeball centre (eyes), the neck base
  // 7.2 (else 7.1; head), the meshes' bounding-box centre (teeth, tongue). In the target it
  // is where the Transform rotates after matchRigidParts.
  Eigen::Vector3d sourceCentre = Eigen::Vector3d::Zero();
  Eigen::Vector3d targetCentre = Eigen::Vector3d::Zero();
  // Target / source size of the part (bounding-box diagonals): the translation scale when
  // the part's FAPU is not measured in both faces.
  double sizeRatio = 1.0;
};

// "left eye", "upper teeth", ... for messages.
std::string_view rigidPartName(RigidPart::Kind kind);

struct RigidPartMap {
  std::vector<RigidPart> parts;  // parts that move in the source and are found in both faces
  // Meshes of every eye, teeth and tongue part identified in each face (moving or not),
  // excluded from the vertex mapping. Never the Head part's meshes. Sorted.
  std::vector<int> sourceRigidMeshes, targetRigidMeshes;
  // A Transform that moves in the source but belongs to no part, a moving part not found in
  // the target: that motion is skipped.
  std::vector<std::string> warnings;
};

// Finds the parts in both faces. Where a target eye's or the head's Transform does not
// rotate about the eyeball centre or the neck base (7.2), installs the centre in `target`
// (Transform::center, translation compensated so that nothing moves); where the part's
// meshes have no Transform of their own, inserts one (appended, so existing indices stay).
// Throws mpeg4face::Error for a source copy whose Transform tree differs from the neutral.
RigidPartMap matchRigidParts(const FaceModel& sourceNeutral,
                             std::span<const FaceShape> sourceCopies, FaceModel& target);

// Sets, in `transforms` (a copy of the Transforms of the target neutral matchRigidParts
// returned), the Transform fields of every part from the change `sourceCopy` makes to the
// source neutral: rotation and scale change as they are, the centre's displacement scaled by
// the FAPU ratio (ES for eyes and head, MNS for teeth and tongue; the size ratio if not
// measured). Throws mpeg4face::Error if `sourceCopy` or `transforms` lacks a part's Transform.
void cloneRigidMotion(const RigidPartMap& map, const FaceModel& sourceNeutral,
                      const FapuMeasurement& sourceFapu, const FaceShape& sourceCopy,
                      const FaceModel& targetNeutral, const FapuMeasurement& targetFapu,
                      std::vector<Transform>& transforms);

}  // namespace mpeg4face
