// SPDX-License-Identifier: GPL-3.0-or-later
// CANDIDE-3 .wfm reading (J. Ahlberg, LiTH-ISY-R-2326).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face {

// A CANDIDE .wfm file: one mesh named "candide3" plus its units.
struct CandideUnit {
  std::string name;  // the comment line: "FAP 3 open_jaw", "Jaw drop", "Head height"
  int fap = 0;       // FAP number for MPEG-4 units, else 0
  std::string fapu;  // "MNS", "ES", ... for MPEG-4 units (from the second comment line)
  std::vector<int> vertices;
  Points3 displacements;  // one row per entry of `vertices`
};
struct CandideModel {
  FaceModel model;  // one mesh, triangles
  std::vector<CandideUnit> animationUnits;
  std::vector<CandideUnit> shapeUnits;
};
CandideModel readWfm(const std::filesystem::path& path);
CandideModel parseWfm(std::string_view text, const std::string& fileName);
// The same file as a FaceModel whose mesh carries every animation unit as a morph target
// named after the unit (dense displacements at unit value 1); readModel uses this.
FaceModel candideToFaceModel(const CandideModel& candide);

// The model's morph targets of CANDIDE's MPEG-4 animation units (candideToFaceModel's, on a
// model with its feature points bound) renamed and scaled into the shape-key grammar
// (fat/names.hpp), so that the FaceDefTables generator and Blender read them: unit FAP N at
// value a moves its vertices by a * FAPU * displacement (docs/fat.md, "CANDIDE-3
// convention"; the FAPU the unit names, else FAP N's), which is the target
// fap<N>_<name>@1000, and fap<N>_<name>@-1000 too for a bidirectional FAP. Other targets
// stay. Throws Error naming the unit whose FAPU the feature points do not give.
void nameCandideFapUnits(FaceModel& model, const CandideModel& candide);
inline constexpr int kCandideUnitAmplitude = 1000;

}  // namespace mpeg4face
