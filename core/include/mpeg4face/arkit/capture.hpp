// SPDX-License-Identifier: GPL-3.0-or-later
// Face captures (ARKit blendshape weights, io/livelink.hpp) to FAP streams and back, through a
// face that carries ARKit shapes as morph targets (and, for the best fit, FAP keys in the
// shape-key grammar, fat/names.hpp). Solvers and sign conventions in docs/arkit.md
// ("Captures").
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "mpeg4face/fat/tables.hpp"
#include "mpeg4face/io/livelink.hpp"
#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face {

// One face prepared for both directions, built once (the solves are precomputed here) and
// used for any number of frames. The face's motion is compared over its "face area": the
// vertices that its ARKit shapes or its FAP tables move, on meshes that no FaceDefTransform
// animates (eyeballs, a jaw or head modelled as Transforms are left to FAPs 23-26, 48-50).
struct ArkitCaptureFace {
  // Per Live Link weight channel (0..51): whether the face has that ARKit shape.
  std::vector<bool> hasShape;
  // The face area as (mesh, vertex) pairs, and the ARKit shapes' motion there: 3 rows per
  // vertex (model space x y z), one column per ARKit shape (zero for missing shapes).
  std::vector<std::pair<int, int>> area;
  Eigen::MatrixXd shapeMotion;
  // The low-level FAPs (not 23-26, 48-50) as columns of their motion per FAPU over the area,
  // one column per FAP and side: `columnFap[c]` the FAP, `columnSign[c]` +1 or -1.
  Eigen::MatrixXd fapMotion;
  std::vector<int> columnFap;
  std::vector<int> columnSign;
  // How far each column's FAP value (in FAPU) keeps its motion linear, +inf without end: the
  // solver's upper bound (a FAP key held past its amplitude moves no further).
  std::vector<double> columnReach;
  // True when the columns come from the face's FaceDefTables (FAP keys); false when the face
  // has none and each FAP moves its own feature point along its direction (the definition).
  bool fromTables = false;
  MpegFace face;  // the tables (or none), with the neutral face and feature points
  FapuMeasurement fapu;
  // ARKit -> FAP: the normal equations of the FAP columns (with a small ridge) and their
  // right-hand side per ARKit weight: per frame b = fapRhs * w, then bounded least squares.
  Eigen::MatrixXd fapGram;
  Eigen::MatrixXd fapRhs;
  // The angle FAPs' (23-26, 48-50) tables move the area too (eyelids riding along with the
  // eyes): their columns' pull K' K_angle, taken off b for the frame's angle values.
  Eigen::MatrixXd angleRhs;
  std::vector<int> angleColumnFap;
  std::vector<int> angleColumnSign;
  // FAP 3 follows JawOpen as the angle FAPs follow their channels: its column (+ side), -1
  // without a jaw table or shape, and its value per unit weight (the FAP 3 that best
  // reproduces jawOpen's motion alone). The others fit what the jaw leaves (a mouth held
  // closed while the jaw opens is the lips' doing, not a smaller jaw).
  int jawColumn = -1;
  double jawPerWeight = 0;
  // FAP -> ARKit: the normal equations of the ARKit shapes over the area.
  Eigen::MatrixXd shapeGram;
  std::vector<std::string> warnings;  // e.g. the ARKit shapes the face lacks, once
};

// Prepares a face: its ARKit shapes are morph targets named as ARKit's blendshapes
// (eyeBlinkLeft, EyeBlinkLeft, eyeBlink_L, blendShape1.eyeBlinkLeft, eye_blink_left; ICT's
// halves browInnerUp_L / _R and cheekPuff_L / _R add up to one shape); its FAP keys, if any,
// are morph targets / poses in the shape-key grammar. Throws mpeg4face::Error listing the
// names looked for if the face has no ARKit shape, and if no FAPU can be measured.
ArkitCaptureFace prepareArkitCaptureFace(const FaceModel& head);

struct CaptureOptions {
  double fps = 25;  // output frame rate; the capture's weights are interpolated linearly
  // Called now and then with (frames done, frames in all); may be empty.
  std::function<void(int, int)> progress;
};

// ARKit weights -> FAPs. Each output frame's weights (resampled to options.fps) move the face
// area by shapeMotion * w; the FAP values (FAPU, rounded) are the bounded least-squares fit
// of that motion by the FAP columns (each side >= 0, one side per FAP), warm-started from the
// previous frame. FAPs 48-50 come from the head's pitch/yaw/roll and 23-26 from the eyes'
// yaw/pitch (radians -> AU = 1e-5 rad) with the standard's signs (docs/arkit.md). Every
// frame sends the same FAPs. Throws mpeg4face::Error for a capture without frames or
// fps <= 0.
FapStream arkitCaptureToFaps(const LiveLinkCapture& capture, const ArkitCaptureFace& face,
                             const CaptureOptions& options = {});
FapStream arkitCaptureToFaps(const LiveLinkCapture& capture, const FaceModel& arkitHead,
                             const CaptureOptions& options = {});

// FAPs -> ARKit weights. Each frame's motion of the face area (through the face's
// FaceDefTables when it has them, else the FAPs' definition) is fitted by the ARKit shapes
// with weights in 0..1 (bounded least squares, warm-started); eye and head angles come back
// from FAPs 23-26, 48-50. Times are frame numbers / the stream's frame rate.
LiveLinkCapture fapsToArkit(const FapStream& stream, const ArkitCaptureFace& face,
                            const std::function<void(int, int)>& progress = {});
LiveLinkCapture fapsToArkit(const FapStream& stream, const FaceModel& arkitHead,
                            const std::function<void(int, int)>& progress = {});

// The capture's weights (all 61 channels) at `time`, linear between its frames and held
// before the first and after the last: what arkitCaptureToFaps fits at each output frame.
Eigen::VectorXd captureWeightsAt(const LiveLinkCapture& capture, double time);

// How a FAP stream made from a capture plays back through the face's FaceDefTables, frame
// by frame on the face area, against the same capture played through the face's ARKit
// shapes (the reference). Figures are relative to each frame's peak reference motion, over
// the frames that move the face (peak >= 1.5% of ES0) and each frame's moving area (the
// vertices that move at least 2% of its peak). bump = |d_i - mean of d_j over i's one-ring|
// (model/surface_bump.hpp). docs/arkit.md, "Fidelity".
struct CaptureFidelity {
  int frames = 0;  // frames compared
  double errorMean = 0, errorP95 = 0;  // |playback - reference| per vertex
  // bump's 99th percentile over the moving area, and over its vertices within 5% of ES0 of
  // a feature point; its largest; each for the playback and for the reference.
  double bumpP99 = 0, referenceBumpP99 = 0;
  double pointBumpP99 = 0, referencePointBumpP99 = 0;
  double bumpMax = 0, referenceBumpMax = 0;
  // (mesh, vertex) where some frame's playback bump is above 10% of the peak and above 3
  // times the reference's bump there; sorted.
  std::vector<std::pair<int, int>> spikes;
};
// Throws mpeg4face::Error when the stream has no frame or the face has no tables.
CaptureFidelity measureCaptureFidelity(const LiveLinkCapture& capture, const ArkitCaptureFace& face,
                                       const FapStream& stream);

// Minimises 0.5 x' G x - b' x with lower <= x <= upper (upper may be +inf), G symmetric
// positive definite: an active-set method (Stark and Parker's BVLS on the normal equations)
// started from `x` (clamped into the bounds), so that a previous frame's solution makes it
// quick. `locked` entries stay at their lower bound.
void boundedLeastSquares(const Eigen::MatrixXd& G, const Eigen::VectorXd& b,
                         const Eigen::VectorXd& lower, const Eigen::VectorXd& upper,
                         Eigen::VectorXd& x, const std::vector<bool>& locked = {});

}  // namespace mpeg4face
