// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: the planes an encoder writes kept from misleading a standard decoder, one that
// reads fba_object as 14496-2's syntax is written (nextbits_bytealigned()): the predictive and
// DCT encoders (codec/fba_predictive.cpp, codec/fba_dct.cpp). docs/bitstream.md, "Start codes
// the encoder never emulates".
#pragma once

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "codec/bit_io.hpp"

namespace mpeg4face {

// The planes an encoder writes into `out`, one after the other, each made safe for a standard
// decoder once the bits after it are known (secure()): the predictive encoder's planes of a
// group, the DCT encoder's planes of a stream. docs/bitstream.md, "Start codes the encoder
// never emulates".
class PlaneGuard {
 public:
  struct Span {
    uint64_t start = 0;  // its first bit (of the start code's stuffing, if it has one)
    uint64_t body = 0;   // its first bit after the start code
    uint64_t end = 0;
    bool startCode = false;
  };

  explicit PlaneGuard(BitWriter& out) : out_(out) {}

  // A plane starts at out's end, with fba_object_plane_start_code if `startCode`.
  void open(bool startCode);
  // The plane opened last ends at out's end.
  void close() { planes_.back().end = out_.bitCount(); }
  // Makes plane j safe given the bits after it (or, if `codeFollows` and there are none yet,
  // the start code to come): first with a plane start code after it (its stuffing ends the
  // runs the plane's tail and the next header make), then with one before it (the syntax
  // allows it before any plane: it aligns the plane anew and nothing before it can be taken
  // for stuffing); the plane before is then checked again. The coded bits stay as they are,
  // the planes after a new start code move. False if j stays unsafe.
  // A plane is unsafe if a standard decoder misreads it: a byte-aligned 0x000001 that is no
  // start code, where a run of zeros reaches across fields and segments (each coder
  // segment's stuffing counts only its own zeros); or, for a plane without a start code, 23
  // zero bits where nextbits_bytealigned() looks from its first bit, which takes the plane
  // for stuffing before a start code.
  bool secure(size_t j, bool codeFollows);
  // Drops planes j.. and their bits.
  void rollBack(size_t j);
  void clear() { planes_.clear(); }

  const std::vector<Span>& planes() const { return planes_; }
  // The first plane a start code moved since the last call, if any (its bits and those after
  // it changed places).
  std::optional<size_t> takeMoved() {
    return std::exchange(moved_, std::nullopt);
  }

 private:
  bool violates(size_t j, bool codeFollows) const;
  void insertStartCode(size_t j);

  BitWriter& out_;
  std::vector<Span> planes_;
  std::optional<size_t> moved_;
  mutable std::vector<bool> bits_;  // violates()'s, kept to spare allocations
  mutable std::vector<uint64_t> codes_;
};

}  // namespace mpeg4face
