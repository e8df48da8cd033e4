// SPDX-License-Identifier: GPL-3.0-or-later
// A readable JSON form of a FAP Interpolation Table, for editing by hand (docs/fit.md):
//   {"format": "mpeg4face-fit", "version": 1,
//    "nodes": [[4], [51]],
//    "links": [{"parent": 0, "child": 1, "functions": [
//      {"fap": 51,
//       "numerator": [{"coefficient": 1, "exponents": [1]},
//                     {"coefficient": -1e-06, "exponents": [3],
//                      "impulse": {"select": "expression_select1", "value": 3}}],
//       "denominator": [{"coefficient": 1, "exponents": [0]}]}]}]}
// Each function names its child FAP; "impulse" is optional. Numbers are written so that
// they read back exactly.
#pragma once

#include <filesystem>
#include <string>

#include "mpeg4face/fit/fit.hpp"

namespace mpeg4face {

std::string fitTableToJson(const FitTable& table);
// Throws mpeg4face::Error naming `source` and the JSON path at fault (e.g.
// "links[2].functions[0].numerator[1].exponents") for malformed input, then validates the
// table (validateFitTable).
FitTable fitTableFromJson(const std::string& json, const std::string& source = "FIT JSON");

void writeFitJson(const FitTable& table, const std::filesystem::path& path);
FitTable readFitJson(const std::filesystem::path& path);

}  // namespace mpeg4face
