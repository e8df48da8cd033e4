// SPDX-License-Identifier: GPL-3.0-or-later
// CANDIDE-3 .wfm reading (J. Ahlberg, LiTH-ISY-R-2326).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "mpeg4face/face_model.hpp"

namespace mpeg4face {

// A CANDIDE .wfm file: one mesh named "candide3" plus its units.
struct CandideUnit {
  std::string name;        // the comment line: "FAP 3 open_jaw", "Jaw drop", "Head height"
  int fap = 0;             // FAP number for MPEG-4 units, else 0
  std::string fapu;        // "MNS", "ES", ... for MPEG-4 units (from the second comment line)
  std::vector<int> vertices;
  Points3 displacements;   // one row per entry of `vertices`
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

}  // namespace mpeg4face
