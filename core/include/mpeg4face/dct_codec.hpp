// SPDX-License-Identifier: GPL-3.0-or-later
// The DCT coding mode for FAP streams (Tekalp-Ostermann 2.2.2, Tao et al. V-B and VII-D):
// each low-level FAP is cut into 16-frame segments, each segment transformed by a 16-point
// DCT, its DC level predicted from the previous segment's and its AC levels sent as
// (zero run, amplitude) pairs, all entropy-coded with adaptive arithmetic-coder models.
// The standard's segment syntax and VLC tables are not public: the format here is the
// project's own, defined bit by bit in docs/dct-mode.md.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "mpeg4face/fap_stream.hpp"

namespace mpeg4face {

inline constexpr int kDctSegmentLength = 16;
// Low-level FAP values the encoder accepts: |value| <= kDctMaxValue (2^20 - 1 FAPU, i.e.
// 10 rad for an AU FAP), so that every coefficient fits the decoder's integer arithmetic.
inline constexpr int kDctMaxValue = (1 << 20) - 1;

struct DctOptions {
  // The AC quantiser step of FAP i is FapInfo::quantStep(i) * fapQuant, as the predictive
  // mode's fap_quant (Tekalp-Ostermann 2.2.1); 1..31.
  int fapQuant = 1;
  // The DC step is the AC step / dcDivisor; 1..15. Tekalp-Ostermann 2.2.2 gives 1/4 as the
  // standard's ratio (Tao et al. found "about three times smaller").
  int dcDivisor = 4;
  // Every intraInterval-th segment is intra (DC sent without prediction, models reset,
  // nothing refers to an earlier segment); 0: only the first segment.
  int intraInterval = 0;
};

struct DctEncoded {
  std::vector<std::uint8_t> bytes;
  // What decodeDct(bytes) returns, bit for bit: the encoder runs the decoder's
  // reconstruction (reconstructDctSegment).
  FapStream reconstruction;
  std::int64_t lowLevelSamples = 0;  // (frame, FAP 3..68) values present in the input
  // Bits of the arithmetic-coded parts (the DC and AC levels); the rest of bits() is the
  // header, frame numbers, masks, FAP 1/2, padding and the CRC.
  std::int64_t codedBits = 0;
  std::int64_t bits() const { return 8 * static_cast<std::int64_t>(bytes.size()); }
};

// Throws mpeg4face::Error naming the frame and FAP for input the format cannot carry:
// frame numbers not increasing from >= 0, |value| > kDctMaxValue, FAP 1/2 fields out of
// range, a name over 65535 bytes, a frame rate not finite and > 0, options out of range.
DctEncoded encodeDct(const FapStream& stream, const DctOptions& options = {});

// Throws mpeg4face::Error naming the byte offset and the element at fault for any input
// that is not a complete, well-formed DCT stream (truncated, corrupted, trailing bytes).
FapStream decodeDct(std::span<const std::uint8_t> bytes);

// The transform, public because the format is defined by it.
// Orthonormal DCT-II: X[k] = c(k) sum_n x[n] cos(pi (2n + 1) k / 32), c(0) = sqrt(1/16),
// c(k > 0) = sqrt(2/16). The encoder's forward transform (double precision).
std::array<double, kDctSegmentLength> forwardDct16(const std::array<double, kDctSegmentLength>& x);

// The decoder's reconstruction of one segment from its levels (levels[0] the DC level), in
// exact integer arithmetic so that every decoder agrees bit for bit: with the basis
// B[k][n] = round(2^28 c(k) cos(pi (2n + 1) k / 32)) (dctBasis),
//   S[n] = acStep * (levels[0] B[0][n] + dcDivisor sum_{k>0} levels[k] B[k][n])
//   x[n] = S[n] / (dcDivisor 2^28), rounded to nearest, halves away from zero.
// Levels must satisfy |level * step| <= 2^24 (the decoder checks this before calling).
std::array<int, kDctSegmentLength> reconstructDctSegment(
    const std::array<std::int64_t, kDctSegmentLength>& levels, int acStep, int dcDivisor);

// B[k][n] above, k the row.
const std::array<std::array<std::int64_t, kDctSegmentLength>, kDctSegmentLength>& dctBasis();

}  // namespace mpeg4face
