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

#include "codec/bit_io.hpp"

namespace mpeg4face {

// Symbols 0..n-1 with adaptive counts, the reference's rules: every count starts at 1, a coded
// symbol's count grows by 1, and when the total has reached 16383 all counts are first halved
// (rounding up). The coder maps symbol 0 to the top of the interval, symbol n-1 to the bottom
// (the reference's descending cumulative table). Counts are kept in a Fenwick tree so a symbol
// costs O(log n) even for the large default FAP ranges, and only from the first update on: a
// fresh or reset model costs O(1).
class AdaptiveModel {
 public:
  static constexpr uint32_t kMaxTotal = 16383;
  // Halving must bring the total below kMaxTotal again, and every symbol needs a count.
  static constexpr int kMaxSymbols = 16382;

  // Throws mpeg4face::Error if symbolCount is not in 1..kMaxSymbols.
  explicit AdaptiveModel(int symbolCount = 1);

  int symbolCount() const { return symbolCount_; }
  // Back to all counts 1.
  void reset() { fresh_ = true; }
  uint32_t total() const { return fresh_ ? static_cast<uint32_t>(symbolCount_) : total_; }
  uint32_t count(int symbol) const { return fresh_ ? 1 : counts_[static_cast<size_t>(symbol)]; }
  // Sum of the counts of the symbols below `symbol`.
  uint32_t countBelow(int symbol) const {
    if (fresh_) return static_cast<uint32_t>(symbol);
    uint32_t sum = 0;
    for (size_t i = static_cast<size_t>(symbol); i > 0; i &= i - 1) sum += tree_[i];
    return sum;
  }
  // The symbol s with countBelow(s) <= target < countBelow(s) + count(s); target < total().
  int find(uint32_t target) const;
  // The same, also giving countBelow of the symbol found.
  int find(uint32_t target, uint32_t& below) const;
  // Adds the coded symbol (halving first when the total has reached kMaxTotal). Inline: it
  // runs once per coded symbol; the first update and halving are out of line.
  void update(int symbol) {
    if (fresh_ || total_ == kMaxTotal) [[unlikely]]
      prepareUpdate();
    ++counts_[static_cast<size_t>(symbol)];
    ++total_;
    for (size_t i = static_cast<size_t>(symbol) + 1; i < tree_.size(); i += i & (~i + 1)) {
      ++tree_[i];
    }
  }
  // -log2(count / total): what an ideal coder would spend on `symbol` now, in bits.
  double idealBits(int symbol) const;

 private:
  void rebuild();
  void prepareUpdate();  // fills in the counts of a fresh model, or halves them

  int symbolCount_;
  bool fresh_ = true;  // all counts 1; counts_ and tree_ not filled in yet
  std::vector<uint32_t> counts_;
  std::vector<uint32_t> tree_;  // Fenwick tree over counts_, 1-based
  uint32_t total_ = 0;
  size_t topBit_ = 1;  // highest power of two <= symbolCount
};

// An adaptive binary context in the manner of CABAC (the LZMA form of its state machine): the
// probability of a 0 in 1/4096, moved 1/16 of the way towards each coded bit. It starts at 1/2
// and stays within [15, 4081]/4096, so both bits keep a share of the coder's interval.
struct BinaryContext {
  static constexpr int kBits = 12;
  static constexpr uint32_t kOne = 1u << kBits;
  static constexpr int kShift = 4;
  uint16_t zero = kOne / 2;

  void update(bool bit) {
    if (bit)
      zero = static_cast<uint16_t>(zero - (zero >> kShift));
    else
      zero = static_cast<uint16_t>(zero + ((kOne - zero) >> kShift));
  }
  // -log2 P(bit) now: what coding `bit` costs, in bits (for the encoder's decisions).
  double idealBits(bool bit) const;
};

// At most this many bits per encodeBits symbol, so the interval (> 2^14 after renormalising)
// keeps >= 64 values per symbol: the rounding costs < 0.01 bit per symbol on average.
constexpr int kMaxRawBits = 8;

class ArithmeticEncoder {
 public:
  // Starts a segment at the writer's current position.
  explicit ArithmeticEncoder(BitWriter& out) : out_(out) {}
  // Codes `symbol` (0..model.symbolCount()-1) and then adapts the model to it.
  void encode(int symbol, AdaptiveModel& model);
  // Codes `symbol` as a fresh AdaptiveModel(symbolCount) would (all counts 1), for a symbol
  // that is the only one its model codes before a reset (the FAPs of an intra plane).
  void encodeUniform(int symbol, int symbolCount);
  // The same for symbolCount = 2^count (count 1..kMaxRawBits): `count` raw bits as one symbol,
  // scaled by a shift instead of a division.
  void encodeBits(uint32_t bits, int count);
  // Codes a binary decision with an adaptive context, then adapts it.
  void encodeBit(bool bit, BinaryContext& context);
  // Ends the segment with the 2 (+ pending) bits that pin the code value down, so the decoder
  // needs nothing after them; the next encode() starts a new segment.
  void flush();

 private:
  // Narrows the interval to [lower, upper) of total (scale(x) = x / total) and writes the
  // settled bits.
  template <typename Scale>
  void narrow(uint32_t lower, uint32_t upper, Scale scale);
  void emit(uint32_t bits, int count);  // settled coder bits, pending bits after the first
  void put(uint32_t bits, int count);   // bits with the stuffing rule

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
  // The counterpart of ArithmeticEncoder::encodeUniform.
  int decodeUniform(int symbolCount);
  // The counterpart of ArithmeticEncoder::encodeBits.
  uint32_t decodeBits(int count);
  // The counterpart of ArithmeticEncoder::encodeBit.
  bool decodeBit(BinaryContext& context);
  // Ends the segment: moves the reader to just after the encoder's flush bits. Throws
  // mpeg4face::Error naming `element` if the segment runs past the data or breaks the
  // stuffing rule.
  void finish(std::string_view element);

 private:
  // Where the code value lies in [0, total), counted from the bottom as AdaptiveModel::find
  // expects it.
  uint32_t target(uint32_t total) const;
  template <typename Scale>
  void narrow(uint32_t lower, uint32_t upper, Scale scale);
  uint32_t get(int count);        // coder bits, stuffing removed
  uint32_t getSlowly(int count);  // get() bit by bit, where a stuffed 1 may lie

  BitReader& in_;
  uint64_t start_;
  uint32_t low_ = 0;
  uint32_t high_ = 65535;
  uint32_t value_ = 0;
  int zeroRun_ = 0;
  uint64_t bitsRead_ = 0;  // coder bits, stuffing not counted
  // How many coder bits had been read when each stuffed 1 was skipped (rare), to find where
  // the segment ends in the data.
  std::vector<uint64_t> stuffedAfter_;
  uint64_t badStuffing_ = UINT64_MAX;  // first stuffing violation, if any
};

}  // namespace mpeg4face
