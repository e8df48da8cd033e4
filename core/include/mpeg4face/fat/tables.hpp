// SPDX-License-Identifier: GPL-3.0-or-later
// Face Animation Tables (FAT): the BIFS nodes FaceDefTables, FaceDefMesh and FaceDefTransform
// (Tekalp-Ostermann 2.1.3.4), and the MPEG-4 face they belong to. Plain structs that mirror
// the nodes; the evaluator and the generator are in fat/evaluate.hpp and fat/generate.hpp.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

#include "mpeg4face/fit/fit.hpp"
#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face {

// How one FAP deforms one IndexedFaceSet: a piecewise-linear motion per affected vertex.
struct FaceDefMesh {
  int mesh = -1;                     // faceSceneGraphNode: index into FaceModel::meshes
  std::vector<int> intervalBorders;  // increasing FAP values; one is 0 (see checkIntervalBorders)
  std::vector<int> coordIndex;       // the affected vertices of the mesh
  // One row per (coordIndex entry, interval), vertex-major as in the BIFS field: the
  // displacements of coordIndex[i] are rows i * intervalCount() .. + intervalCount() - 1.
  // Model units per FAPU; on the negative side per unit of |FAP| (see intervalWeights).
  Points3 displacements;

  int intervalCount() const { return static_cast<int>(intervalBorders.size()) - 1; }
};

// How one FAP changes one field of a Transform.
struct FaceDefTransform {
  enum class Field { Rotation = 1, Scale = 2, Translation = 3 };
  int transform = -1;  // faceSceneGraphNode: index into FaceModel::transforms
  Field fieldId = Field::Rotation;
  Eigen::Vector4d rotationDef{0, 0, 1, 0};  // axis x y z, angle (radians per AU of FAP)
  Eigen::Vector3d scaleDef{1, 1, 1};
  Eigen::Vector3d translationDef{0, 0, 0};
};

// The animation rules of one FAP (fapID 3..68), or of one viseme (fapID 1) or expression
// (fapID 2) chosen by highLevelSelect. A table for FAP 1 or 2 is driven by the amount
// 0..63 of its viseme (viseme_blend for viseme_select1, 63 - viseme_blend for
// viseme_select2) or expression (its expression_intensity) in place of a FAP value, with
// unit 1: its displacements are model units per step of 1/63.
struct FaceDefTables {
  int fapID = 1;
  int highLevelSelect = 1;
  std::vector<FaceDefMesh> faceDefMesh;
  std::vector<FaceDefTransform> faceDefTransform;
};

// An animatable MPEG-4 face (BIFS FDP): the neutral scene graph with its feature points
// (faceSceneGraph, featurePointsCoord) and the tables that animate it.
struct MpegFace {
  FaceModel faceSceneGraph;
  std::vector<FaceDefTables> faceDefTables;
  std::optional<FitTable> fit =
      std::nullopt;  // the Face node's FAP Interpolation Table, if it has one
};

// The coefficient of each interval for a FAP value, so that a vertex moves by
// FAPU * sum_k weights[k] * D_k, exactly as Tekalp-Ostermann's rules 1-6 say:
// - intervals between 0 and the value get their width, the one holding the value the part
//   up to it; on the negative side these lengths are positive (0 - I, I - FAP), so a
//   negative-side displacement is motion per unit of |FAP|;
// - beyond the outermost border the outermost interval continues (rules 3 and 5); when 0 is
//   the first (last) border, a value below (above) it continues the first (last) interval
//   through 0, i.e. weight = value (-value);
// - with one interval the motion is linear and signed: weights = {value} (rule 6).
// `weights` gets intervalBorders.size() - 1 entries. Borders must be valid (see
// checkIntervalBorders).
void intervalWeights(std::span<const int> intervalBorders, double value,
                     std::vector<double>& weights);

// The same rule as weights of the motions at the borders, which is what shape keys (one per
// border, the table's motion at that value) need: a value between borders b_i <= value <=
// b_i+1 gives b_i the weight 1 - t and b_i+1 the weight t, t = (value - b_i) / (b_i+1 - b_i);
// beyond the outermost borders the outermost interval continues (t outside 0..1). `weights`
// gets intervalBorders.size() entries; a border 0's weight moves nothing (the motion there
// is 0). sum_i weights[i] * motion(b_i) is the motion intervalWeights gives, for every table.
void borderWeights(std::span<const int> intervalBorders, double value,
                   std::vector<double>& weights);

// What drives a table in `frame` (whether its FAP is present is the caller's test): the
// value of FAP fapID (3..68); for a viseme table (fapID 1) its amount viseme_blend where
// viseme_select1 names it plus 63 - viseme_blend where viseme_select2 does; for an
// expression table (fapID 2) the intensity of each expression_select that names it.
int tableInput(int fapID, int highLevelSelect, const FapFrame& frame);

// The unit a FAP's value is multiplied by: the FAPU of `fapID` in model units, AU in
// radians, 1 for FAP 1 and 2 (see FaceDefTables). 0 if that FAPU was not measured.
double fapScale(const FapuMeasurement& fapu, int fapID);

// Adds one FaceDefTransform's effect to `transform`, for a FAP value already multiplied by
// its unit (`scaledValue` = value * fapScale):
//   rotation:    rotation = rotation * R(axis, scaledValue * angle)   (about the Transform's
//                centre, in its own frame, after the rotations applied before it)
//   scale:       scale += scaledValue * scaleDef
//   translation: translation += scaledValue * translationDef
// Several FAPs on one Transform are applied in increasing fapID order.
void applyFaceDefTransform(const FaceDefTransform& def, double scaledValue, Transform& transform);

// Throws mpeg4face::Error (field "intervalBorders") unless there are at least two borders,
// strictly increasing, and (with two or more intervals) exactly one of them is 0. A single
// interval needs no 0 border: its motion is FAP * D whatever its borders.
void checkIntervalBorders(std::span<const int> intervalBorders);

}  // namespace mpeg4face
