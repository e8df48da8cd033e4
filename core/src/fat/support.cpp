// SPDX-License-Identifier: GPL-3.0-or-later
#include "fat/support.hpp"

#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/tables.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face::fat {

std::string fapLabel(int fapID, int highLevelSelect) {
  std::string label = "FAP " + std::to_string(fapID);
  if (fapID == 1) label += " viseme " + std::to_string(highLevelSelect);
  if (fapID == 2) label += " expression " + std::to_string(highLevelSelect);
  return label;
}

double requireFapScale(const FapuMeasurement& fapu, int fapID, const std::string& field) {
  const double scale = fapScale(fapu, fapID);
  if (scale > 0) return scale;
  const FapuKind kind = fapInfo(fapID).fapu;
  std::string neutralName;
  for (const FapuInfo& info : fapuTable()) {
    if (info.kind == kind) neutralName = info.neutralName;
  }
  std::string why = "not measured";
  for (auto [name, distance] : fapu.distances()) {
    if (name == neutralName && !distance->method.empty()) why = distance->method;
  }
  throw Error({}, 0, field,
              "FAP " + std::to_string(fapID) + " (" + std::string(fapInfo(fapID).name) +
                  ") is in " + std::string(fapuName(kind)) + " units, but " + neutralName +
                  " is not measured: " + why);
}

}  // namespace mpeg4face::fat
