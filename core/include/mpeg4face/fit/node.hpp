// SPDX-License-Identifier: GPL-3.0-or-later
// The BIFS FIT node's fields (ISO/IEC 14496-1; field names as the standard's) and a FAP
// Interpolation Table in them. Where the standard's exact layout is not public, ours is
// (docs/fit.md, "The FIT node"):
//   FAPs              each node's FAPs, then -1
//   Graph             each link, in priority order: parent node, child node
//   numeratorTerms    per link, per child FAP (node order): K;  denominatorTerms: P
//   numeratorExp      per numerator term: one exponent per parent variable (fit/fit.hpp);
//   denominatorExp    likewise
//   numeratorImpulse  per numerator term: the select (0 none; 69, 70 viseme_select1/2;
//                     72, 73 expression_select1/2) and the value a_i
//   numeratorCoefs    per numerator term: c_i;  denominatorCoefs: b_i
#pragma once

#include <string>
#include <vector>

#include "mpeg4face/fit/fit.hpp"

namespace mpeg4face {

struct FitNodeFields {
  std::vector<int> FAPs, Graph, numeratorExp, denominatorExp, numeratorImpulse, numeratorTerms,
      denominatorTerms;
  std::vector<double> numeratorCoefs, denominatorCoefs;
  bool operator==(const FitNodeFields&) const = default;
};

// Throws mpeg4face::Error (validateFitTable) for an invalid table.
FitNodeFields fitNodeFields(const FitTable& table);
// Throws mpeg4face::Error naming `source` and the field (e.g. "FIT.numeratorExp") whose
// length does not fit the rest, then validates the table.
FitTable fitTableFromNode(const FitNodeFields& fields, const std::string& source = "FIT");

}  // namespace mpeg4face
