// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: what the ARKit mapping and the keys made from it share (docs/arkit.md). Not
// installed.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string_view>

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

}  // namespace mpeg4face::arkit
