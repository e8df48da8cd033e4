// SPDX-License-Identifier: GPL-3.0-or-later
// The 16-point DCT of the FBA bitstream's DCT coding mode (coding_type 1; Tekalp-Ostermann
// 2.2.2, Tao et al. V-B): a double-precision forward transform for the encoder and an exact
// integer inverse that defines what every decoder outputs. The mode itself is reached through
// codec/fba_codec.hpp (FapCodingMode::Dct); its syntax, the project's own, is in docs/dct-mode.md.
#pragma once

#include <array>
#include <cstdint>

namespace mpeg4face {

inline constexpr int kDctSegmentLength = 16;
// The largest |low-level FAP value| the DCT mode encodes: 2^20 - 1 FAPU (10 rad in AU), so
// that every coefficient stays within the decoder's integer arithmetic (|level * step| <=
// 2^24). The .fap reader's limit (1,000,000) is below it.
inline constexpr int kDctMaxValue = (1 << 20) - 1;

// Orthonormal DCT-II: X[k] = c(k) sum_n x[n] cos(pi (2n + 1) k / 32), c(0) = sqrt(1/16),
// c(k > 0) = sqrt(2/16).
std::array<double, kDctSegmentLength> forwardDct16(const std::array<double, kDctSegmentLength>& x);

// B[k][n] = round(2^28 c(k) cos(pi (2n + 1) k / 32)), k the row; B[0][n] = 2^26 exactly.
const std::array<std::array<std::int64_t, kDctSegmentLength>, kDctSegmentLength>& dctBasis();

// The decoder's reconstruction of one segment from its levels (levels[0] the DC level), in
// integer arithmetic so that every decoder agrees bit for bit. The AC step is
// acStep / 2^stepFractionBits (a fixed-point step: the DCT mode sends steps in 1/64):
//   S[n] = acStep * (levels[0] B[0][n] + dcDivisor sum_{k>0} levels[k] B[k][n])
//   x[n] = S[n] / (dcDivisor 2^(28 + stepFractionBits)), rounded to nearest, halves away from 0.
// The DC step is the AC step / dcDivisor. Needs |levels[0] * acStep / dcDivisor| and
// |levels[k] * acStep| <= 2^(24 + stepFractionBits) (decoders check this before calling),
// dcDivisor in 1..15, stepFractionBits in 0..8; S is summed in 128 bits.
std::array<int, kDctSegmentLength> reconstructDctSegment(
    const std::array<std::int64_t, kDctSegmentLength>& levels, std::int64_t acStep, int dcDivisor,
    int stepFractionBits = 0);

}  // namespace mpeg4face
