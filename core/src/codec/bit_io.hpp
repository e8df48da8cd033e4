// SPDX-License-Identifier: GPL-3.0-or-later
// Bit-level reading and writing for the FBA bitstream (ISO/IEC 14496-2): most significant bit
// first, 32-bit start codes after next_start_code() stuffing. The arithmetic coder
// (codec/arithmetic_coder.hpp) writes through a BitWriter and reads through a BitReader, so plain
// fields and coder segments interleave in one stream.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace mpeg4face {

// The FBA start codes (32 bits, byte aligned).
inline constexpr uint32_t kFbaObjectStartCode = 0x000001BA;
inline constexpr uint32_t kFbaObjectPlaneStartCode = 0x000001BB;
inline constexpr uint32_t kFbaObjectEndCode = 0x000001B1;

class BitWriter {
 public:
  // The low `count` bits of `value` (count 0..32), most significant first. Inline and a byte
  // at a time: the arithmetic coder writes its bits in runs through here.
  void writeBits(uint32_t value, int count) {
    if (count <= 0) return;
    uint64_t v = value & ((uint64_t{1} << count) - 1);
    const auto offset = static_cast<int>(bitCount_ & 7);
    bitCount_ += static_cast<uint64_t>(count);
    if (offset != 0) {
      const int free = 8 - offset;
      if (count <= free) {
        bytes_.back() |= static_cast<uint8_t>(v << (free - count));
        return;
      }
      count -= free;
      bytes_.back() |= static_cast<uint8_t>(v >> count);
    }
    for (; count >= 8; count -= 8) bytes_.push_back(static_cast<uint8_t>(v >> (count - 8)));
    if (count > 0) bytes_.push_back(static_cast<uint8_t>(v << (8 - count)));
  }
  void writeBit(bool bit) { writeBits(bit ? 1u : 0u, 1); }
  // next_start_code(): a 0 then 1s up to the byte boundary; a whole 0111 1111 byte when the
  // writer is already aligned, so a reader can always find and strip it.
  void nextStartCode();
  // nextStartCode() then the 32-bit code.
  void writeStartCode(uint32_t code);

  uint64_t bitCount() const { return bitCount_; }
  bool bitAt(uint64_t position) const {
    return (bytes_[position >> 3] >> (7 - (position & 7))) & 1;
  }
  // Drops the bits from `count` on (count <= bitCount()), so an encoder can write a part again.
  void truncate(uint64_t count);
  // The bits [from, to), as a writer of their own (append() puts them back).
  BitWriter slice(uint64_t from, uint64_t to) const;
  void append(const BitWriter& bits);
  // The bytes written so far; a partial last byte is padded with 0 bits.
  const std::vector<uint8_t>& bytes() const { return bytes_; }
  std::vector<uint8_t> take() { return std::move(bytes_); }

 private:
  std::vector<uint8_t> bytes_;
  uint64_t bitCount_ = 0;
};

// Reads a byte buffer it does not own. Every failing read throws mpeg4face::Error whose field
// is the syntax element being read and whose message gives the bit offset (and byte, bit).
class BitReader {
 public:
  // `source` names the input (a file name) in errors; may be empty.
  explicit BitReader(std::span<const uint8_t> data, std::string source = {});

  uint32_t readBits(int count, std::string_view element);  // count 0..32
  bool readBit(std::string_view element);
  // The arithmetic decoder reads ahead of the data it needs: past the end it gets 0 bits and
  // the position still advances; ArithmeticDecoder::finish checks where the segment ended.
  bool readBitOrZero() {
    const bool bit = position_ < size_ && bitAt(position_);
    ++position_;
    return bit;
  }
  // The next `count` bits (0..32) without moving, 0 bits past the end; skip() moves on.
  uint32_t peekBitsOrZero(int count) const { return bitsAtOrZero(position_, count); }
  void skip(int count) { position_ += static_cast<uint64_t>(count); }

  uint64_t position() const { return position_; }  // in bits from the start
  uint64_t size() const { return size_; }          // in bits
  uint64_t bitsLeft() const { return position_ < size_ ? size_ - position_ : 0; }
  // Moves to any bit position (past the end is allowed; the next read then fails).
  void seek(uint64_t position) { position_ = position; }

  // True if next_start_code() stuffing (see BitWriter) followed by `code` starts here.
  bool nextIsStartCode(uint32_t code) const;
  // Reads the stuffing and `code`; throws naming `element` if they are not there.
  void readStartCode(uint32_t code, std::string_view element);

  // Where 14496-2's nextbits_bytealigned() looks from here: the next byte boundary, or this
  // one if aligned, past a 0111 1111 byte (next_start_code() stuffing) if one is there.
  uint64_t nextBytealigned() const;
  // The `count` bits (0..32) at `position`, 0 bits past the end.
  uint32_t bitsAtOrZero(uint64_t position, int count) const;
  // True if the 23 bits at `position` are in the data and all 0: a start code prefix to a
  // standard decoder's nextbits_bytealigned() == '000 0000 0000 0000 0000 0000'.
  bool startCodePrefixAt(uint64_t position) const {
    return position + 23 <= size_ && bitsAtOrZero(position, 23) == 0;
  }
  // The positions of the start codes read (readStartCode and noteStartCode), in order; a
  // strict decoder checks that the data holds no other byte-aligned 0x000001.
  void noteStartCode(uint64_t position) { startCodes_.push_back(position); }
  const std::vector<uint64_t>& startCodes() const { return startCodes_; }
  std::span<const uint8_t> data() const { return data_; }

  // Throws Error naming `element` at bit `position` (the current one by default).
  [[noreturn]] void fail(std::string_view element, const std::string& message) const;
  [[noreturn]] void failAt(uint64_t position, std::string_view element,
                           const std::string& message) const;

 private:
  bool bitAt(uint64_t position) const { return (data_[position >> 3] >> (7 - (position & 7))) & 1; }

  std::span<const uint8_t> data_;
  std::string source_;
  uint64_t size_;
  uint64_t position_ = 0;
  std::vector<uint64_t> startCodes_;
};

inline uint32_t BitReader::bitsAtOrZero(uint64_t position, int count) const {
  if (count == 0) return 0;
  const uint64_t byte = position >> 3;
  uint64_t window = 0;  // 40 bits from `byte` on: room for 32 bits at any bit offset
  if (position < size_ && byte + 5 <= data_.size()) {
    for (uint64_t i = 0; i < 5; ++i) window = (window << 8) | data_[byte + i];
  } else {
    for (uint64_t i = 0; i < 5; ++i)
      window = (window << 8) | (position < size_ && byte + i < data_.size() ? data_[byte + i] : 0);
  }
  const int shift = 40 - static_cast<int>(position & 7) - count;
  return static_cast<uint32_t>((window >> shift) & ((uint64_t{1} << count) - 1));
}

}  // namespace mpeg4face
