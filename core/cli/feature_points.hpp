// SPDX-License-Identifier: GPL-3.0-or-later
// Feature points as every subcommand that reads a head takes them: the file's own, those of a
// --feature-points CSV over them, and free points on a surface bound to its vertices.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/model/feature_point_snap.hpp"

namespace mpeg4face::cli {

// The CSV's points (if one is given) bound over `model`'s, then free points bound to the
// vertex they lie on (model/feature_point_snap.hpp); what the CSV warns of and each point
// bound or left free are added to `warnings`, for the command to print.
inline void bindFeaturePoints(const std::optional<std::string>& csvPath, FaceModel& model,
                              std::vector<std::string>& warnings) {
  if (csvPath) {
    FeaturePointCsv csv = readFeaturePointCsv(*csvPath, model);
    for (auto& [id, binding] : csv.featurePoints) model.featurePoints[id] = binding;
    warnings.insert(warnings.end(), csv.warnings.begin(), csv.warnings.end());
  }
  const FeaturePointSnap snap = snapFeaturePointsToVertices(model);
  warnings.insert(warnings.end(), snap.notes.begin(), snap.notes.end());
  warnings.insert(warnings.end(), snap.unbound.begin(), snap.unbound.end());
}

}  // namespace mpeg4face::cli
