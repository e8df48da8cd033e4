// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: what the FAT evaluator, generator and shape-key reader share. Not installed.
#pragma once

#include <string>

#include "mpeg4face/model/fapu.hpp"

namespace mpeg4face::fat {

// "FAP 6", "FAP 1 viseme 3", "FAP 2 expression 1": how messages name a table's FAP.
std::string fapLabel(int fapID, int highLevelSelect);

// fapScale(fapu, fapID), or throws Error(field) saying which FAPU is missing and which
// feature points it needs (FapuDistance::method).
double requireFapScale(const FapuMeasurement& fapu, int fapID, const std::string& field);

}  // namespace mpeg4face::fat
