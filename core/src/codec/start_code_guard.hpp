// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: whether a standard decoder, reading fba_object as 14496-2's syntax is written
// (nextbits_bytealigned()), would misread a plane the predictive encoder wrote; the encoder
// then writes it otherwise (codec/fba_predictive.cpp). docs/bitstream.md, "Start codes the
// encoder never emulates".
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "codec/bit_io.hpp"

namespace mpeg4face {

// Where BitWriter::writeStartCode(), called at `position`, puts the code: after a 0 and 1s to
// the byte boundary, or a whole 0111 1111 byte when aligned.
inline uint64_t startCodeAfter(uint64_t position) { return (position | 7) + 1; }

// A plane's bits in the writer: [start, end), from its start code's stuffing if it has one.
struct PlaneBits {
  uint64_t start = 0, end = 0;
  bool startCode = false;
};

// True if the plane is misread: a byte-aligned 0x000001 that is none of the start codes at
// `codes` (bit positions), where a run of zeros reaches across fields and segments (each
// coder segment's stuffing counts only its own zeros); or, for a plane without a start code,
// 23 zero bits where nextbits_bytealigned() looks from its first bit, which takes the plane
// for stuffing before a start code. The bits after the plane are `out`'s, or, if
// `codeFollows` and none are written yet, the start code that will follow. `bits` is scratch.
bool misreadByStandardDecoder(const BitWriter& out, PlaneBits plane,
                              std::span<const uint64_t> codes, bool codeFollows,
                              std::vector<bool>& bits);

}  // namespace mpeg4face
