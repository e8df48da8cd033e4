// SPDX-License-Identifier: GPL-3.0-or-later
// Shape-key (morph target) names that say which FAP, viseme or expression a target shows, so
// that a model sculpted in Blender or exported as glTF can feed the FaceDefTables generator:
//
//   fap<N>[_<name>]@<amplitude>            N 3..68, amplitude a non-zero integer FAP value
//   viseme<N>[_<label>]                    N 1..14, shown fully (amount 63)
//   expression<N>[_<label>][@<intensity>]  N 1..6, intensity 1..63 (default 63)
//
// e.g. fap3_open_jaw@512, fap6@-300, viseme1_p_b_m, expression1_joy@40. <name> and <label>
// are letters, digits, '_' and '-'. A <name> that is a standard FAP name (or BIFS field
// name) must be FAP N's; a <label> that is a standard expression name must be expression
// N's. The prefixes fap, viseme, expression are matched without regard to case; a name is
// ours when one of them is followed by a digit, '_', '@' or the end. Grammar in docs/fat.md.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mpeg4face/fat/generate.hpp"
#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/model/face_shape.hpp"

namespace mpeg4face {

struct ShapeKeyName {
  int fapID = 3;            // 3..68, 1 viseme, 2 expression
  int highLevelSelect = 0;  // viseme / expression number; 0 for FAPs 3..68
  int amplitude = 0;        // FAP value; the viseme / expression amount 1..63
  std::string label;        // <name> / <label>, "" if none
};

// nullopt for a name that is not ours (does not start as the grammar says); throws
// mpeg4face::Error (field: the name in quotes) with the grammar in its message for a name
// that starts so but is malformed.
std::optional<ShapeKeyName> parseShapeKeyName(std::string_view name);

// The name in the grammar: fap<N>[_<label>]@<amplitude>, viseme<N>[_<label>],
// expression<N>[_<label>][@<intensity>] (the intensity written unless it is 63).
std::string formatShapeKeyName(const ShapeKeyName& key);

struct ShapeKeyCopies {
  std::vector<FaceShape> copies;     // in order of first appearance
  std::vector<std::string> ignored;  // target and animation names not ours, once each
};

// The morph targets of `model` as shapes of its basis (the model's own positions): each of
// our names becomes one shape (the same name on several meshes moves each of them), named
// after the target, listing the vertices its morph targets move (non-zero rows). An
// animation of our name with transform channels is a pose: the shape of that name (made if
// no morph target has it) takes the transforms' values at each channel's last key, so eyes,
// jaw and head modelled as transforms get FaceDefTransforms. Throws mpeg4face::Error for a
// malformed name (see parseShapeKeyName), naming the mesh or the animation.
ShapeKeyCopies shapesFromShapeKeys(const FaceModel& model);

// A face from a model with shape keys: its neutral (neutralFaceModel) with the FaceDefTables
// generateFaceDefTables makes from its shape keys in the grammar, the FAPU measured on it.
struct ShapeKeyFace {
  MpegFace face;
  std::size_t copies = 0;             // the shape keys in the grammar, made into tables
  std::vector<std::string> warnings;  // generateFaceDefTables'
  std::vector<std::string> ignored;   // shape keys not in the grammar
};
ShapeKeyFace faceFromShapeKeys(const FaceModel& model, const GeneratorOptions& options = {});

}  // namespace mpeg4face
