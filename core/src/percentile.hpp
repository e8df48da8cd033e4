// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: the p-th percentile of some values, the value at rank floor(p (n - 1)) (no
// interpolation), as the motion check and the fidelity report quote them. Not installed.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace mpeg4face {

// Reorders `values`; 0 for none.
inline double percentile(std::vector<double>& values, double p) {
  if (values.empty()) return 0;
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(
                                       std::floor(p * static_cast<double>(values.size() - 1)));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

}  // namespace mpeg4face
