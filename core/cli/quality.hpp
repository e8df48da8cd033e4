// SPDX-License-Identifier: GPL-3.0-or-later
// The --quality option of psnr, rd and encode: which PSNR judges an encoding (codec/measure.hpp).
#pragma once

#include <string>
#include <vector>

#include "arguments.hpp"
#include "mpeg4face/codec/measure.hpp"

namespace mpeg4face::cli {

// The value after --quality (args[i]) as a measure; moves i onto it.
inline FapQuality qualityArgument(const std::vector<std::string>& args, size_t& i) {
  const std::string& text = optionValue(args, i, "robust or tao");
  const std::optional<FapQuality> quality = parseFapQuality(text);
  if (!quality) throw UsageError("--quality takes robust or tao, not '" + text + "'");
  return *quality;
}

// How a measure is named where a PSNR is printed.
inline std::string qualityLabel(FapQuality quality) {
  return quality == FapQuality::Robust ? "robust PSNR, 10 log10(1 / mean MSE_i/R_i^2)"
                                       : "PSNR of Tao et al. 1999, eq. 8";
}

}  // namespace mpeg4face::cli
