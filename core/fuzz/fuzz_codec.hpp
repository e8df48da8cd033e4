// SPDX-License-Identifier: GPL-3.0-or-later
// What the codec fuzz targets share: fuzz bytes read as a recipe for a FAP stream, and the
// check that the decoder returns what the encoder reconstructed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "mpeg4face/codec/fba_codec.hpp"

namespace mpeg4face::fuzz {

// The bytes one at a time, 0 once they run out.
struct Recipe {
  std::span<const uint8_t> data;
  std::size_t at = 0;
  int next() { return at < data.size() ? data[at++] : 0; }
  bool more() const { return at < data.size(); }
};

// Decodes `encoded` and aborts unless the result is the encoder's reconstruction with at least
// the input's frames, read both as this project reads and strictly, as 14496-2's syntax reads
// (no start code emulated, no plane hidden before one). Returns it and, in `offset`, where the
// input's first frame is in it (the bitstream puts an empty frame 0 in front of a stream that
// starts later).
inline FapStream decodeAsReconstructed(const FapStream& stream, const FbaEncoding& encoded,
                                       std::size_t& offset) {
  FapStream decoded = decodeFba(encoded.bytes);
  if (decoded != encoded.reconstruction || decoded.frames.size() < stream.frames.size())
    std::abort();
  FbaDecodeLimits strict;
  strict.strict = true;
  if (decodeFba(encoded.bytes, {}, strict) != decoded) std::abort();
  offset = decoded.frames.size() - stream.frames.size();
  return decoded;
}

}  // namespace mpeg4face::fuzz
