// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: what the ARKit mapping and the keys made from it share (docs/arkit.md). Not
// installed.
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "mpeg4face/arkit/shapes.hpp"
#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/model/fapu.hpp"

namespace mpeg4face::arkit {

// A FAP's positive motion ("up", "left", ...) as a direction in the standard's axes (x the
// face's own left, y up, z forward); nullopt for motions that are not a translation.
inline std::optional<Eigen::Vector3d> fapDirection(std::string_view motion) {
  if (motion == "up") return Eigen::Vector3d::UnitY();
  if (motion == "down") return -Eigen::Vector3d::UnitY();
  if (motion == "left") return Eigen::Vector3d::UnitX();
  if (motion == "right") return -Eigen::Vector3d::UnitX();
  if (motion == "forward") return Eigen::Vector3d::UnitZ();
  return std::nullopt;
}

// The jaw FAPs (open, thrust, shift): their keys carry the lower lip, chin, mouth corners
// and tongue along, and a head may move its lower teeth with them as a Transform.
inline bool isJawFap(int fap) { return fap == 3 || fap == 14 || fap == 15; }

// The FAPs that share one part of the face with `fap` (it among them; keys.cpp): their
// keys are shared among their feature points, and sent at one value add up to the part's
// motion. Empty for a FAP that shares with none.
std::span<const int> siblingFaps(int fap);

// Mesh `mesh`'s vertices with the jaw open (its jawOpen shape added; the neutral's if the head
// has none): the inner lips touch in the neutral, so distances between sibling points and
// from them are taken here, across an open mouth (keys.cpp, combined_keys.cpp).
Points3 jawOpenCoord(const FaceModel& head, const ArkitShapes& shapes, int mesh);

// Refits the keys of `mapping` (keyMotion[k]: key k's displacement per mesh at its
// amplitude, mesh space, shared among its siblings) so that the FAP values that move the
// feature points as each ARKit shape and each pair of shapes does also reproduce their
// motion over the meshes, staying near the keys given and each moving its own point by its
// amplitude (combined_keys.cpp; docs/arkit.md, "Keys that combine"). Eyeball turns and
// keys without a bound point are left as they are.
void fitKeysToShapeCombinations(const FaceModel& head, const ArkitShapes& shapes,
                                const FapuMeasurement& fapu, const ArkitMapping& mapping,
                                std::vector<std::map<int, Points3>>& keyMotion);

}  // namespace mpeg4face::arkit
