// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: trellis quantisation for the predictive encoder (FbaEncodeOptions::rdoTrellis).
// Predictive coding is DPCM, so a level chosen at one frame moves every later residual; a
// per-value choice misses that. For one low-level FAP over one group of planes (an intra plane
// and the inter planes after it) this chooses every level at once, by dynamic programming over
// the reconstructions near the signal, minimising weight * sum e^2 + lambda * bits, where bits
// is what the FAP's adaptive model spends on the inter levels (a function of their histogram
// and the inter range alone: codec/fba_trellis.cpp) and the inter range is chosen too.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace mpeg4face::fba {

struct TrellisProblem {
  std::span<const int64_t> values;  // the FAP in each frame of the group, FAP units
  int64_t step = 0;                 // QP * fap_quant; 0: no quantisation
  double weight = 1;                // of a squared error (the robust PSNR's 1 / R^2)
  double lambda = 0;                // > 0
  int64_t cap = 0;                  // the largest |level| a range code reaches
  // The sizes a side of a range can take (levels of the range codes 0..31), increasing.
  std::span<const int> sides;
};

struct TrellisLevels {
  std::vector<int64_t> levels;         // levels[0] the intra level, then the inter levels
  int64_t interMin = 0, interMax = 0;  // the inter levels' extent
};

TrellisLevels trellisQuantise(const TrellisProblem& problem);

}  // namespace mpeg4face::fba
