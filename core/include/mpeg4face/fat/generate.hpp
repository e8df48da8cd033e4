// SPDX-License-Identifier: GPL-3.0-or-later
// The FaceDefTables generator of Tekalp-Ostermann Fig. 8: the neutral model and the shapes a
// modeler made of it (model/face_shape.hpp: what each moves), each tagged with the FAP value it
// shows, give the tables that make the evaluator (fat/evaluate.hpp) reproduce every shape.
// Rules in docs/fat.md.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mpeg4face/fat/tables.hpp"
#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/model/face_shape.hpp"
#include "mpeg4face/model/fapu.hpp"

namespace mpeg4face {

struct GeneratorOptions {
  // A vertex is affected when some copy of its FAP moves it by more than `threshold`
  // FAPU. The FAPU is the FAP's own for FAPs in ES, IRISD, ENS, MNS, MW; ES for AU FAPs,
  // visemes and expressions (else the first measured of ENS, MNS, MW, IRISD). Transform
  // changes count when they move a point at the head's size (bounding-box diagonal) by
  // as much. 0.01 FAPU is a few millionths of a head's size: copies are reproduced within it.
  double threshold = 0.01;
  // In model units instead of FAPU, if given.
  std::optional<double> absoluteThreshold;
};

struct GeneratedTables {
  std::vector<FaceDefTables> faceDefTables;  // sorted by fapID, highLevelSelect
  // Copies that change nothing above the threshold; Transforms whose change is not
  // linear in the FAP value across a FAP's copies (a FaceDefTransform is linear).
  std::vector<std::string> warnings;
};

// Copies (shapes) of one FAP (or viseme / expression) at several amplitudes become a
// FaceDefMesh per mesh they deform, with interval borders at the amplitudes and 0 (P(a): the
// neutral moved by the copy at a; a vertex a copy does not list stays):
//   positive side  D_j = (P(I_j+1) - P(I_j)) / ((I_j+1 - I_j) * FAPU)
//   negative side  D_j = (P(I_j) - P(I_j+1)) / ((I_j+1 - I_j) * FAPU)   (per unit of |FAP|)
//   one copy at a  D   = (P(a) - P(0)) / (a * FAPU)                      (signed, rule 6)
// and a FaceDefTransform per changed Transform field (rotation: axis and angle of
// R0^-1 * R per FAP unit), taken from the copy of largest |amplitude|.
// Throws mpeg4face::Error naming the copy and the mesh or Transform for a shape that does not
// fit the neutral (checkFaceShape), the copies for a repeated amplitude, the feature points a FAP's
// unmeasured FAPU needs, and for fapID, highLevelSelect or amplitude out of range.
GeneratedTables generateFaceDefTables(const FaceModel& neutral, const FapuMeasurement& fapu,
                                      std::span<const FaceShape> copies,
                                      const GeneratorOptions& options = {});

}  // namespace mpeg4face
