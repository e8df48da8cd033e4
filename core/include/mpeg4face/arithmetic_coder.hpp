// SPDX-License-Identifier: GPL-3.0-or-later
// The adaptive arithmetic coder of the FBA bitstream: a 16-bit multi-symbol coder of the
// H.263 Annex E family (q1 = 16384, q2 = 32768, q3 = 49152, top = 65535) with adaptive
// cumulative-frequency models, and the start-code emulation prevention of the FBA syntax (a 1
// stuffed after 22 consecutive 0 bits inside a coder segment). A segment is the bits between
// a coder's start and its flush; plain fields may follow a flushed segment directly.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "mpeg4face/bit_io.hpp"

namespace mpeg4face {

// Symbols 0..n-1 with adaptive counts, the reference's rules: every count starts at 1, a coded
// symbol's count grows by 1, and when the total has reached 16383 all counts are first halved
// (rounding up). The coder maps symbol 0 to the top of the interval, symbol n-1 to the bottom
// (the reference's descending cumulative table). Counts are kept in a Fenwick tree so a symbol
// costs O(log n) even for the large default FAP ranges.
class AdaptiveModel {
 public:
  static constexpr uint32_t kMaxTotal = 16383;
  // Halving must bring the total below kMaxTotal again, and every symbol needs a count.
  static constexpr int kMaxSymbols = 16382;

  // Throws mpeg4face::Error if symbolCount is not in 1..kMaxSymbols.
  explicit AdaptiveModel(int symbolCount = 1);

  int symbolCount() const { return static_cast<int>(counts_.size()); }
  // Back to all counts 1.
  void reset();
  uint32_t total() const { return total_; }
  uint32_t count(int symbol) const { return counts_[static_cast<size_t>(symbol)]; }
  // Sum of the counts of the symbols below `symbol`.
  uint32_t countBelow(int symbol) const;
  // The symbol s with countBelow(s) <= target < countBelow(s) + count(s); target < total().
  int find(uint32_t target) const;
  // Adds the coded symbol (halving first when the total has reached kMaxTotal).
  void update(int symbol);
  // -log2(count / total): what an ideal coder would spend on `symbol` now, in bits.
  double idealBits(int symbol) const;

 private:
  void rebuild();

  std::vector<uint32_t> counts_;
  std::vector<uint32_t> tree_;  // Fenwick tree over counts_, 1-based
  uint32_t total_ = 0;
  size_t topBit_ = 1;  // highest power of two <= symbolCount
};

class ArithmeticEncoder {
 public:
  // Starts a segment at the writer's current position.
  explicit ArithmeticEncoder(BitWriter& out) : out_(out) {}
  // Codes `symbol` (0..model.symbolCount()-1) and then adapts the model to it.
  void encode(int symbol, AdaptiveModel& model);
  // Ends the segment with the 2 (+ pending) bits that pin the code value down, so the decoder
  // needs nothing after them; the next encode() starts a new segment.
  void flush();

 private:
  void emit(bool bit);  // one coder bit with its pending opposite bits
  void put(bool bit);   // one bit with the stuffing rule

  BitWriter& out_;
  uint32_t low_ = 0;
  uint32_t high_ = 65535;
  uint32_t pending_ = 0;
  int zeroRun_ = 0;
};

class ArithmeticDecoder {
 public:
  // Starts a segment at the reader's current position (reads 16 bits ahead).
  explicit ArithmeticDecoder(BitReader& in);
  // Decodes a symbol and adapts the model to it, as the encoder did.
  int decode(AdaptiveModel& model);
  // Ends the segment: moves the reader to just after the encoder's flush bits. Throws
  // mpeg4face::Error naming `element` if the segment runs past the data or breaks the
  // stuffing rule.
  void finish(std::string_view element);

 private:
  bool get();  // one coder bit, stuffing removed

  BitReader& in_;
  uint64_t start_;
  uint32_t low_ = 0;
  uint32_t high_ = 65535;
  uint32_t value_ = 0;
  int zeroRun_ = 0;
  uint64_t bitsRead_ = 0;              // coder bits, stuffing not counted
  uint64_t ends_[16] = {};             // reader position after each of the last 16 coder bits
  uint64_t badStuffing_ = UINT64_MAX;  // first stuffing violation, if any
};

}  // namespace mpeg4face
