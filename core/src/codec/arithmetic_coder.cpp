// SPDX-License-Identifier: GPL-3.0-or-later
#include "codec/arithmetic_coder.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <string>

#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

constexpr uint32_t kQ1 = 16384;
constexpr uint32_t kQ2 = 32768;
constexpr uint32_t kTop = 65535;
// Inside a segment a 1 is stuffed after this many consecutive 0 bits, so no segment can
// emulate a start code (23 zeros and a 1).
constexpr int kMaxZeroRun = 22;

// narrow()'s scaling of length * bound by the total: a division, or a shift for 2^count.
auto dividedBy(uint32_t total) {
  return [total](uint32_t x) { return x / total; };
}
auto shiftedBy(int count) {
  return [count](uint32_t x) { return x >> count; };
}

}  // namespace

AdaptiveModel::AdaptiveModel(int symbolCount) : symbolCount_(symbolCount) {
  if (symbolCount < 1 || symbolCount > kMaxSymbols) {
    throw Error("adaptive model size " + std::to_string(symbolCount) + " is not in 1.." +
                std::to_string(kMaxSymbols));
  }
  while (topBit_ * 2 <= static_cast<size_t>(symbolCount)) topBit_ *= 2;
}

void AdaptiveModel::rebuild() {
  const size_t n = counts_.size();
  std::fill(tree_.begin(), tree_.end(), 0u);
  total_ = 0;
  for (size_t i = 1; i <= n; ++i) {
    tree_[i] += counts_[i - 1];
    total_ += counts_[i - 1];
    const size_t parent = i + (i & (~i + 1));
    if (parent <= n) tree_[parent] += tree_[i];
  }
}

int AdaptiveModel::find(uint32_t target) const {
  uint32_t below = 0;
  return find(target, below);
}

int AdaptiveModel::find(uint32_t target, uint32_t& below) const {
  if (fresh_) {
    below = target;
    return static_cast<int>(target);
  }
  size_t pos = 0;
  below = 0;
  for (size_t step = topBit_; step > 0; step >>= 1) {
    if (pos + step < tree_.size() && below + tree_[pos + step] <= target) {
      pos += step;
      below += tree_[pos];
    }
  }
  return static_cast<int>(pos);
}

void AdaptiveModel::prepareUpdate() {
  if (fresh_) {
    // All counts 1: a Fenwick node holds as many counts as the lowest set bit of its index.
    counts_.assign(static_cast<size_t>(symbolCount_), 1u);
    tree_.resize(counts_.size() + 1);
    for (size_t i = 1; i < tree_.size(); ++i) tree_[i] = static_cast<uint32_t>(i & (~i + 1));
    total_ = static_cast<uint32_t>(symbolCount_);
    fresh_ = false;
  }
  if (total_ == kMaxTotal) {
    for (uint32_t& c : counts_) c = (c + 1) / 2;
    rebuild();
  }
}

double AdaptiveModel::idealBits(int symbol) const {
  return -std::log2(static_cast<double>(count(symbol)) / static_cast<double>(total()));
}

void ArithmeticEncoder::encode(int symbol, AdaptiveModel& model) {
  // The reference's cumulative table counts from the top: symbol s spans
  // [cumul(s + 1), cumul(s)) with cumul(s) = total - countBelow(s).
  const uint32_t total = model.total();
  const uint32_t upper = total - model.countBelow(symbol);
  narrow(upper - model.count(symbol), upper, dividedBy(total));
  model.update(symbol);
}

void ArithmeticEncoder::encodeUniform(int symbol, int symbolCount) {
  const auto upper = static_cast<uint32_t>(symbolCount - symbol);
  const auto total = static_cast<uint32_t>(symbolCount);
  narrow(upper - 1, upper, dividedBy(total));
}

void ArithmeticEncoder::encodeBits(uint32_t bits, int count) {
  const uint32_t upper = (1u << count) - bits;
  narrow(upper - 1, upper, shiftedBy(count));
}

// A 0 spans the top `zero` of 4096, as symbol 0 of a model does.
void ArithmeticEncoder::encodeBit(bool bit, BinaryContext& context) {
  const uint32_t split = BinaryContext::kOne - context.zero;
  if (bit)
    narrow(0, split, shiftedBy(BinaryContext::kBits));
  else
    narrow(split, BinaryContext::kOne, shiftedBy(BinaryContext::kBits));
  context.update(bit);
}

double BinaryContext::idealBits(bool bit) const {
  // Indexed by the probability in 1/256: the encoder asks often, and 1/256 is close enough.
  static const auto table = [] {
    std::array<double, 257> t{};
    for (size_t i = 0; i < t.size(); ++i)
      t[i] = -std::log2(std::max(static_cast<double>(i), 0.5) / 256.0);
    return t;
  }();
  const uint32_t p = bit ? kOne - zero : zero;
  return table[(p + 8) >> 4];
}

// Writes `count` (1..16) bits with the stuffing rule. Where no 1 needs stuffing (the zero run
// before every bit stays below 22) they go out in one write; runs after a 1 inside the chunk
// are shorter than 16, so only the leading zeros can reach 22.
void ArithmeticEncoder::put(uint32_t bits, int count) {
  const int leadingZeros = count - std::bit_width(bits);
  if (zeroRun_ + std::min(leadingZeros, count - 1) < kMaxZeroRun) [[likely]] {
    out_.writeBits(bits, count);
    zeroRun_ = bits == 0 ? zeroRun_ + count : std::countr_zero(bits);
    return;
  }
  for (int i = count - 1; i >= 0; --i) {
    if (zeroRun_ == kMaxZeroRun) {
      out_.writeBit(true);
      zeroRun_ = 0;
    }
    const bool bit = (bits >> i) & 1;
    out_.writeBit(bit);
    zeroRun_ = bit ? 0 : zeroRun_ + 1;
  }
}

// The settled bits (1..16, most significant first): the first one followed by the pending bits
// (its opposite), then the rest.
void ArithmeticEncoder::emit(uint32_t bits, int count) {
  if (pending_ == 0) [[likely]] {
    put(bits, count);
    return;
  }
  const uint32_t first = bits >> (count - 1);
  put(first, 1);
  for (; pending_ > 0;) {
    const int run = static_cast<int>(std::min<uint32_t>(pending_, 16));
    put(first ? 0u : (1u << run) - 1, run);
    pending_ -= static_cast<uint32_t>(run);
  }
  if (count > 1) put(bits & ((1u << (count - 1)) - 1), count - 1);
}

// The renormalisation of the reference coder (while high < q2 or low >= q2: send the top bit
// and double; while q1 <= low and high < q3: one more pending bit, subtract q1 and double)
// done a run at a time. The first loop sends exactly the leading bits low and high share. After
// it low < q2 <= high, and each step of the second (x -> 2x - q2 mod 2^16) drops bit 14 of
// both, so it runs while low has a 1 and high a 0 there, and leaves bit 15 toggled.
template <typename Scale>
void ArithmeticEncoder::narrow(uint32_t lower, uint32_t upper, Scale scale) {
  uint32_t low = low_, high = high_;
  const uint32_t length = high - low + 1;
  high = low - 1 + scale(length * upper);
  low += scale(length * lower);
  const int settled = std::countl_zero(static_cast<uint16_t>(low ^ high));
  if (settled > 0) {
    emit(low >> (16 - settled), settled);
    low = (low << settled) & kTop;
    high = ((high << settled) | ((1u << settled) - 1)) & kTop;
  }
  const int straddling = std::countl_one(static_cast<uint16_t>((low & ~high) << 1));
  if (straddling > 0) {
    pending_ += static_cast<uint32_t>(straddling);
    low = ((low << straddling) & kTop) ^ kQ2;
    high = (((high << straddling) | ((1u << straddling) - 1)) & kTop) ^ kQ2;
  }
  low_ = low;
  high_ = high;
}

void ArithmeticEncoder::flush() {
  ++pending_;
  emit(low_ >= kQ1 ? 1 : 0, 1);
  low_ = 0;
  high_ = kTop;
  zeroRun_ = 0;
}

// `count` (0..31) coder bits, stuffing removed. Without a stuffed 1 among them (the zero run
// before every bit stays below 22; runs after a 1 are shorter than 22 when count <= 23) they
// are taken in one read; otherwise bit by bit, the rare case kept out of line.
inline uint32_t ArithmeticDecoder::get(int count) {
  const uint32_t bits = in_.peekBitsOrZero(count);
  const int leadingZeros = count - std::bit_width(bits);
  if (count <= 23 && zeroRun_ + std::min(leadingZeros, count - 1) < kMaxZeroRun) [[likely]] {
    in_.skip(count);
    bitsRead_ += static_cast<uint64_t>(count);
    zeroRun_ = bits == 0 ? zeroRun_ + count : std::countr_zero(bits);
    return bits;
  }
  return getSlowly(count);
}

uint32_t ArithmeticDecoder::getSlowly(int count) {
  uint32_t bits = 0;
  for (int i = 0; i < count; ++i) {
    bool bit = in_.readBitOrZero();
    if (zeroRun_ == kMaxZeroRun) {
      if (bit) {
        stuffedAfter_.push_back(bitsRead_);
        bit = in_.readBitOrZero();  // the stuffed 1 is not a coder bit
      } else if (badStuffing_ == UINT64_MAX) {
        // Legal only past the segment's end (where plain fields follow); finish() decides.
        badStuffing_ = in_.position() - 1;
      }
      zeroRun_ = 0;
    }
    zeroRun_ = bit ? 0 : zeroRun_ + 1;
    ++bitsRead_;
    bits = 2 * bits + (bit ? 1 : 0);
  }
  return bits;
}

ArithmeticDecoder::ArithmeticDecoder(BitReader& in) : in_(in), start_(in.position()) {
  value_ = get(16);
}

uint32_t ArithmeticDecoder::target(uint32_t total) const {
  // value_ stays within [low_, high_] whatever the input bits, so cum < total.
  const uint32_t length = high_ - low_ + 1;
  const uint32_t cum = ((value_ - low_ + 1) * total - 1) / length;
  return total - 1 - cum;
}

int ArithmeticDecoder::decode(AdaptiveModel& model) {
  const uint32_t total = model.total();
  uint32_t below = 0;
  const int symbol = model.find(target(total), below);
  const uint32_t upper = total - below;
  narrow(upper - model.count(symbol), upper, dividedBy(total));
  model.update(symbol);
  return symbol;
}

int ArithmeticDecoder::decodeUniform(int symbolCount) {
  const auto total = static_cast<uint32_t>(symbolCount);
  const uint32_t symbol = target(total);
  narrow(total - symbol - 1, total - symbol, dividedBy(total));
  return static_cast<int>(symbol);
}

uint32_t ArithmeticDecoder::decodeBits(int count) {
  const uint32_t total = 1u << count;
  const uint32_t bits = target(total);
  narrow(total - bits - 1, total - bits, shiftedBy(count));
  return bits;
}

bool ArithmeticDecoder::decodeBit(BinaryContext& context) {
  const bool bit = target(BinaryContext::kOne) >= context.zero;
  const uint32_t split = BinaryContext::kOne - context.zero;
  if (bit)
    narrow(0, split, shiftedBy(BinaryContext::kBits));
  else
    narrow(split, BinaryContext::kOne, shiftedBy(BinaryContext::kBits));
  context.update(bit);
  return bit;
}

// ArithmeticEncoder::narrow's runs; the code value follows low and high, taking in a coder
// bit per doubling.
template <typename Scale>
void ArithmeticDecoder::narrow(uint32_t lower, uint32_t upper, Scale scale) {
  uint32_t low = low_, high = high_;
  const uint32_t length = high - low + 1;
  high = low - 1 + scale(length * upper);
  low += scale(length * lower);
  const int settled = std::countl_zero(static_cast<uint16_t>(low ^ high));
  if (settled > 0) {
    low = (low << settled) & kTop;
    high = ((high << settled) | ((1u << settled) - 1)) & kTop;
  }
  const int straddling = std::countl_one(static_cast<uint16_t>((low & ~high) << 1));
  const uint32_t toggle = straddling > 0 ? kQ2 : 0;
  if (straddling > 0) {
    low = ((low << straddling) & kTop) ^ kQ2;
    high = (((high << straddling) | ((1u << straddling) - 1)) & kTop) ^ kQ2;
  }
  const int shift = settled + straddling;
  if (shift > 0) {
    value_ = ((static_cast<uint32_t>(uint64_t{value_} << shift) | get(shift)) & kTop) ^ toggle;
  }
  low_ = low;
  high_ = high;
}

void ArithmeticDecoder::finish(std::string_view element) {
  // The encoder wrote one bit per renormalisation plus 2 at the flush; the decoder read 16
  // ahead plus one per renormalisation: the segment holds all but the last 14 coder bits read,
  // and the stuffed 1s before them.
  const uint64_t coderBits = bitsRead_ - 14;
  uint64_t end = start_ + coderBits;
  for (uint64_t before : stuffedAfter_) end += before < coderBits ? 1 : 0;
  if (end > in_.size()) {
    in_.failAt(start_, element,
               "the arithmetic-coded segment starting here runs past the end of the data");
  }
  if (badStuffing_ < end) {
    in_.failAt(badStuffing_, element, "22 zero bits not followed by a stuffed 1");
  }
  in_.seek(end);
}

}  // namespace mpeg4face
