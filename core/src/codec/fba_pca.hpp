// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: the PCA FAP coding mode, the project's own syntax (docs/pca-mode.md). A header
// after fba_object_start_code carries per FAP group the KLT basis and mean; the planes that
// follow are an ordinary predictive or DCT stream whose FAP slots carry the components.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "codec/fba_syntax.hpp"

namespace mpeg4face::fba {

// MPEG-4's user_data_start_code: the PCA header is the object's user data.
inline constexpr uint32_t kPcaHeaderStartCode = 0x000001B2;
inline constexpr int kMaxPcaBasisBits = 15;
// Bounds of the header's integers, so that the inverse KLT stays within int64.
inline constexpr std::int64_t kMaxPcaBasisEntry = std::int64_t{1} << 24;
// The header after its start code is stuffed: a 1 after this many zeros in a row, which the
// decoder drops. With the start code's last 0 before the header and next_start_code()'s 0
// after it, no run reaches 23, so the header emulates no start code (docs/pca-mode.md).
inline constexpr int kPcaStuffingRun = 16;
// pca_header_format: the header is stuffed. A header written before issue 44 (not stuffed)
// has pca_basis_bits, 1..15, in these 4 bits instead; the decoder reads both.
inline constexpr uint32_t kPcaHeaderStuffed = 0;

struct PcaHeaderGroup {
  int group = 0;                    // 2..10
  std::vector<int> faps;            // m FAPs of the group, ascending
  int components = 0;               // k <= m; component j rides in FAP slot firstFap + j
  std::vector<std::int64_t> mean;   // m, FAPU
  std::vector<std::int64_t> basis;  // m x k, basis[i * k + j], in 2^-basisBits
};

struct PcaHeader {
  int basisBits = 10;
  std::vector<PcaHeaderGroup> groups;  // the groups with m > 0, ascending
};

// The FAP slot that carries component j of `group`.
int pcaComponentSlot(int group, int j);

// Writes the PCA header and the component planes of `frames` (numbers increasing, from 0).
// Throws mpeg4face::Error for bad PCA options.
void encodePca(std::span<const FapFrame> frames, const FbaEncodeOptions& options,
               const FrameRateCode& rate, EncodeOutput& output);

// The header after its start code, stuffed, or as written before issue 44 without stuffing.
// Throws Error for values beyond the bounds above or a stuffing bit that is 0.
PcaHeader readPcaHeader(BitReader& in);

// The FAP frames from the component frames, in integer arithmetic (docs/pca-mode.md) so that
// encoder and decoder agree bit for bit. Throws Error naming `source` if a frame lacks a
// component or sends a FAP that is no component.
std::vector<FapFrame> reconstructPca(const PcaHeader& header, std::span<const FapFrame> components,
                                     std::string_view source);

}  // namespace mpeg4face::fba
