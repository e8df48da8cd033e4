// SPDX-License-Identifier: GPL-3.0-or-later
#include "codec/bit_io.hpp"

#include <cstdio>

#include "mpeg4face/error.hpp"

namespace mpeg4face {

void BitWriter::nextStartCode() {
  writeBit(false);
  while (bitCount_ & 7) writeBit(true);
}

void BitWriter::writeStartCode(uint32_t code) {
  nextStartCode();
  writeBits(code, 32);
}

void BitWriter::truncate(uint64_t count) {
  bitCount_ = count;
  bytes_.resize(static_cast<size_t>((count + 7) / 8));
  // The dropped bits of a partial last byte go back to 0, as writeBits expects them.
  if (count & 7) bytes_.back() &= static_cast<uint8_t>(0xFF00 >> (count & 7));
}

BitWriter BitWriter::slice(uint64_t from, uint64_t to) const {
  BitWriter out;
  for (uint64_t i = from; i < to; ++i) out.writeBit(bitAt(i));
  return out;
}

void BitWriter::append(const BitWriter& bits) {
  for (uint64_t i = 0; i < bits.bitCount_; ++i) writeBit(bits.bitAt(i));
}

BitReader::BitReader(std::span<const uint8_t> data, std::string source)
    : data_(data), source_(std::move(source)), size_(uint64_t{data.size()} * 8) {}

uint32_t BitReader::readBits(int count, std::string_view element) {
  if (static_cast<uint64_t>(count) > bitsLeft()) {
    fail(element, "needs " + std::to_string(count) + " bits but the data ends (" +
                      std::to_string(bitsLeft()) + " bits left)");
  }
  const uint32_t value = peekBitsOrZero(count);
  position_ += static_cast<uint64_t>(count);
  return value;
}

bool BitReader::readBit(std::string_view element) { return readBits(1, element) != 0; }

bool BitReader::nextIsStartCode(uint32_t code) const {
  // The stuffing is 1..8 bits: a 0 then 1s to the boundary (8 bits when already aligned).
  const uint64_t stuffing = 8 - (position_ & 7);
  if (position_ + stuffing + 32 > size_) return false;
  if (bitAt(position_)) return false;
  for (uint64_t i = 1; i < stuffing; ++i) {
    if (!bitAt(position_ + i)) return false;
  }
  const uint64_t byte = (position_ + stuffing) >> 3;
  const uint32_t found = (uint32_t{data_[byte]} << 24) | (uint32_t{data_[byte + 1]} << 16) |
                         (uint32_t{data_[byte + 2]} << 8) | uint32_t{data_[byte + 3]};
  return found == code;
}

void BitReader::readStartCode(uint32_t code, std::string_view element) {
  if (!nextIsStartCode(code)) {
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%08X", code);
    fail(element, std::string("expected next_start_code() stuffing and the start code ") + hex);
  }
  position_ += 8 - (position_ & 7);
  noteStartCode(position_);
  position_ += 32;
}

uint64_t BitReader::nextBytealigned() const {
  if (position_ & 7) return (position_ | 7) + 1;
  return bitsAtOrZero(position_, 8) == 0x7F && position_ + 8 <= size_ ? position_ + 8 : position_;
}

void BitReader::fail(std::string_view element, const std::string& message) const {
  failAt(position_, element, message);
}

void BitReader::failAt(uint64_t position, std::string_view element,
                       const std::string& message) const {
  throw Error(source_, 0, std::string(element),
              "at bit " + std::to_string(position) + " (byte " + std::to_string(position >> 3) +
                  ", bit " + std::to_string(position & 7) + "): " + message);
}

}  // namespace mpeg4face
