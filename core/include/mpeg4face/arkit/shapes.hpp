// SPDX-License-Identifier: GPL-3.0-or-later
// Apple ARKit's 52 blendshapes as a source of MPEG-4 motion: which of a head's morph targets
// are ARKit shapes, the non-negative combination of them that makes each low-level FAP
// (measured on the head itself), and the head with FAP, viseme and expression keys in the
// shape-key grammar (fat/names.hpp) made from them. Method and rules in docs/arkit.md.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/model/fapu.hpp"

namespace mpeg4face {

// --- Names -----------------------------------------------------------------------------------
inline constexpr int kArkitShapeCount = 52;
// Apple's 52 ARKit blendshapes in Live Link Face's column order (EyeBlinkLeft,
// EyeLookDownLeft, ..., TongueOut), spelled as Apple does (eyeBlinkLeft).
std::span<const std::string_view> arkitShapeNames();
// The 52, then the shapes ICT-FaceKit adds that the mapping uses too: cheekRaiserLeft,
// cheekRaiserRight, pupilDilateLeft, pupilDilateRight (indices 52..55).
std::span<const std::string_view> arkitKnownShapeNames();

// A side of the face (the face's own left is +x).
enum class FaceSide { Centre, Left, Right };

// An ARKit shape a morph target is: its index into arkitKnownShapeNames(), and the half of
// it when the target is one side of a shape ARKit has whole (ICT's browInnerUp_L is the
// left half of browInnerUp).
struct ArkitShapeRef {
  int shape = 0;
  FaceSide half = FaceSide::Centre;  // Centre: the whole shape
  bool operator==(const ArkitShapeRef&) const = default;
};
// The ARKit shape a morph-target name is, nullopt if none. Case, '_', '-' and ' ' are
// ignored, a prefix up to the last '.', ':' or '|' is dropped (blendShape1.eyeBlinkLeft), and
// a side suffix L / R / Left / Right after a separator stands for Left / Right: eyeBlinkLeft,
// EyeBlinkLeft, eyeBlink_L, eye_blink_left, eyeBlink.L, blendShape1.eyeBlinkLeft. A side
// suffix on a shape ARKit has whole (browInnerUp_L, cheekPuff_R) names its half.
std::optional<ArkitShapeRef> arkitShapeIndex(std::string_view targetName);
// Whether a shape belongs to the eye FAPs only: the eyeLook shapes (the eyeballs' turns) and
// pupilDilate.
bool isArkitEyeShape(int shape);
// The side a shape moves: Left / Right for eyeBlinkLeft / ..Right and for halves; Centre for
// whole shapes, and for jawLeft / jawRight / mouthLeft / mouthRight, which move the jaw or
// mouth sideways as a whole.
FaceSide arkitShapeSide(const ArkitShapeRef& ref);
// "eyeBlinkLeft", "browInnerUp (left half)".
std::string arkitShapeLabel(const ArkitShapeRef& ref);

// --- The shapes of a head --------------------------------------------------------------------
// One morph target of an ARKit shape: target `target` of mesh `mesh`.
struct ArkitTarget {
  int mesh = 0;
  int target = 0;
};
struct ArkitShape {
  ArkitShapeRef ref;
  std::string name;                  // the head's morph-target name
  std::vector<ArkitTarget> targets;  // every mesh with a target of that name
};
// The ARKit shapes a head carries, in arkitKnownShapeNames() order (a whole shape before its
// halves, left before right). Displacements stay in the head's morph targets (mesh space);
// arkitFeaturePointMotion gives them in model space where the mapping needs them.
struct ArkitShapes {
  std::vector<ArkitShape> shapes;
  // The shape's index in `shapes`, nullopt if the head lacks it.
  std::optional<int> find(const ArkitShapeRef& ref) const;
};
// Throws mpeg4face::Error (field "morph targets") listing the names looked for when the head
// has none; two targets that are the same shape (eyeBlinkLeft and eyeBlink_L) likewise.
ArkitShapes findArkitShapes(const FaceModel& head);

// The model-space motion of feature points under each shape at weight 1: rows 3 p .. 3 p + 2
// for points[p], one column per shape of `shapes`. Only feature points bound to a vertex can
// move; `points` lists those of `ids` the head binds so.
struct ArkitPointMotion {
  std::vector<std::string> points;
  Eigen::MatrixXd motion;
};
ArkitPointMotion arkitFeaturePointMotion(const FaceModel& head, const ArkitShapes& shapes,
                                         std::span<const std::string> ids);

// min |A x - b| subject to x >= 0 (Lawson and Hanson's active-set method).
Eigen::VectorXd nonNegativeLeastSquares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b);

// --- The mapping -----------------------------------------------------------------------------
// One FAP key: the FAP at `amplitude` is the shapes at `weights`.
struct ArkitFapKey {
  int fap = 0;
  int amplitude = 0;  // the FAP value the key shows, signed
  // (index into ArkitShapes::shapes, weight in 0..1), largest first.
  std::vector<std::pair<int, double>> weights;
  // The share of the asked motion of the feature point along the FAP's direction that the
  // least-squares combination gives (the key's weights are then scaled so that the point
  // moves by the amplitude exactly).
  double reached = 1;
  // The other feature points' motion (and the FAP's own point's across its direction) that
  // the key brings and should not, as a root of summed squares, relative to the amplitude's
  // motion; for an eyeball rotation the part of the shape's rotation off the FAP's axis.
  double residual = 0;
  // The other feature point whose motion is most off (relative to the amplitude's motion).
  std::string worstPoint;
  double worstMotion = 0;
  // Eyeball rotations (23..26): the eye's Transform and its rotation at the key; -1 else.
  int transform = -1;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};
struct ArkitMissedFap {
  int fap = 0;
  int sign = 0;  // +1 / -1: that direction only; 0: the FAP
  std::string reason;
};
struct ArkitMapping {
  std::vector<ArkitFapKey> keys;       // FAP order, positive before negative
  std::vector<ArkitMissedFap> missed;  // FAP order
};
// For each low-level FAP with a feature point and a linear direction (and each sign where
// bidirectional), the non-negative combination of the head's ARKit shapes that moves the
// FAP's feature point along its direction by its amplitude while moving the other FAPs'
// feature points least (NNLS per FAP; a left FAP uses no right-side shape and vice versa;
// the eyeLook and pupil shapes are left to the eye FAPs); the amplitude is as far as the
// combination goes with every weight <= 1 (a shape that reaches 1 stays there while the
// others carry on, as long as that stays clean). Eyeball rotations 23..26 from the eyeLook
// shapes when the eyeball is a mesh under its own Transform (Kabsch fit of the shape's
// motion, else ARKit's nominal angle); pupils 29 / 30 from pupilDilate. Everything else is
// listed in `missed` with the reason. Rules and thresholds in docs/arkit.md.
ArkitMapping mapArkitToFaps(const FaceModel& head, const ArkitShapes& shapes,
                            const FapuMeasurement& fapu);

// --- The keys --------------------------------------------------------------------------------
struct ArkitKeysOptions {
  bool visemes = true;      // viseme1..14 from the viseme FIT preset
  bool expressions = true;  // expression1..6 from the expression FIT preset
};
struct ArkitKeys {
  FaceModel head;        // the input with its keys
  ArkitShapes shapes;    // findArkitShapes(head)
  ArkitMapping mapping;  // mapArkitToFaps on it, keys past their siblings' reach brought to it
  std::vector<std::string> warnings;
};
// The head with a morph target fap<N>_<name>@<amplitude> per key of the mapping (eyeball
// rotations as poses: animations of that name rotating the eye's Transform) with the copies
// that hold it past its reach (_reach, _held: docs/arkit.md, "Held keys"), and viseme<N> and
// expression<N>_<name> keys (and poses where a Transform moves) evaluated each alone
// from the neutral face with the FAPs the viseme and expression FIT presets give it. Keys
// and poses already named in the grammar are replaced. Ready for faceFromShapeKeys / `fat
// generate`. Throws mpeg4face::Error as findArkitShapes, and when the FAPU cannot be measured.
ArkitKeys arkitFapKeys(const FaceModel& head, const ArkitKeysOptions& options = {});

}  // namespace mpeg4face
