// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/arithmetic_coder.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

constexpr uint32_t kQ1 = 16384;
constexpr uint32_t kQ2 = 32768;
constexpr uint32_t kQ3 = 49152;
constexpr uint32_t kTop = 65535;
// Inside a segment a 1 is stuffed after this many consecutive 0 bits, so no segment can
// emulate a start code (23 zeros and a 1).
constexpr int kMaxZeroRun = 22;

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

uint32_t AdaptiveModel::countBelow(int symbol) const {
  if (fresh_) return static_cast<uint32_t>(symbol);
  uint32_t sum = 0;
  for (size_t i = static_cast<size_t>(symbol); i > 0; i &= i - 1) sum += tree_[i];
  return sum;
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

void AdaptiveModel::update(int symbol) {
  if (fresh_) {
    counts_.assign(static_cast<size_t>(symbolCount_), 1u);
    tree_.resize(counts_.size() + 1);
    rebuild();
    fresh_ = false;
  } else if (total_ == kMaxTotal) {
    for (uint32_t& c : counts_) c = (c + 1) / 2;
    rebuild();
  }
  ++counts_[static_cast<size_t>(symbol)];
  ++total_;
  for (size_t i = static_cast<size_t>(symbol) + 1; i < tree_.size(); i += i & (~i + 1)) {
    ++tree_[i];
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
  narrow(upper - model.count(symbol), upper, total);
  model.update(symbol);
}

void ArithmeticEncoder::encodeUniform(int symbol, int symbolCount) {
  const auto upper = static_cast<uint32_t>(symbolCount - symbol);
  narrow(upper - 1, upper, static_cast<uint32_t>(symbolCount));
}

inline void ArithmeticEncoder::put(bool bit) {
  if (zeroRun_ == kMaxZeroRun) [[unlikely]] {
    out_.writeBit(true);
    zeroRun_ = 0;
  }
  out_.writeBit(bit);
  zeroRun_ = bit ? 0 : zeroRun_ + 1;
}

inline void ArithmeticEncoder::emit(bool bit) {
  put(bit);
  for (; pending_ > 0; --pending_) put(!bit);
}

void ArithmeticEncoder::narrow(uint32_t lower, uint32_t upper, uint32_t total) {
  uint32_t low = low_,
           high = high_;  // locals: emit() writes memory the compiler cannot see through
  const uint32_t length = high - low + 1;
  high = low - 1 + length * upper / total;
  low += length * lower / total;
  for (;;) {
    if (high < kQ2) {
      emit(false);
    } else if (low >= kQ2) {
      emit(true);
      low -= kQ2;
      high -= kQ2;
    } else if (low >= kQ1 && high < kQ3) {
      ++pending_;
      low -= kQ1;
      high -= kQ1;
    } else {
      break;
    }
    low *= 2;
    high = 2 * high + 1;
  }
  low_ = low;
  high_ = high;
}

void ArithmeticEncoder::flush() {
  ++pending_;
  emit(low_ >= kQ1);
  low_ = 0;
  high_ = kTop;
  zeroRun_ = 0;
}

// Called per coder bit, so the rare case is kept out of line.
inline bool ArithmeticDecoder::get() {
  const bool bit = in_.readBitOrZero();
  if (zeroRun_ == kMaxZeroRun) [[unlikely]] {
    return afterZeroRun(bit);
  }
  zeroRun_ = bit ? 0 : zeroRun_ + 1;
  ++bitsRead_;
  return bit;
}

bool ArithmeticDecoder::afterZeroRun(bool bit) {
  if (bit) {
    stuffedAfter_.push_back(bitsRead_);
    bit = in_.readBitOrZero();  // the stuffed 1 is not a coder bit
  } else if (badStuffing_ == UINT64_MAX) {
    // Legal only past the segment's end (where plain fields follow); finish() decides.
    badStuffing_ = in_.position() - 1;
  }
  zeroRun_ = bit ? 0 : 1;
  ++bitsRead_;
  return bit;
}

ArithmeticDecoder::ArithmeticDecoder(BitReader& in) : in_(in), start_(in.position()) {
  for (int i = 0; i < 16; ++i) value_ = 2 * value_ + (get() ? 1 : 0);
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
  narrow(upper - model.count(symbol), upper, total);
  model.update(symbol);
  return symbol;
}

int ArithmeticDecoder::decodeUniform(int symbolCount) {
  const auto total = static_cast<uint32_t>(symbolCount);
  const uint32_t symbol = target(total);
  narrow(total - symbol - 1, total - symbol, total);
  return static_cast<int>(symbol);
}

void ArithmeticDecoder::narrow(uint32_t lower, uint32_t upper, uint32_t total) {
  uint32_t low = low_, high = high_, value = value_;
  const uint32_t length = high - low + 1;
  high = low - 1 + length * upper / total;
  low += length * lower / total;
  for (;;) {
    if (high < kQ2) {
      // nothing to subtract
    } else if (low >= kQ2) {
      value -= kQ2;
      low -= kQ2;
      high -= kQ2;
    } else if (low >= kQ1 && high < kQ3) {
      value -= kQ1;
      low -= kQ1;
      high -= kQ1;
    } else {
      break;
    }
    low *= 2;
    high = 2 * high + 1;
    value = 2 * value + (get() ? 1 : 0);
  }
  low_ = low;
  high_ = high;
  value_ = value;
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
