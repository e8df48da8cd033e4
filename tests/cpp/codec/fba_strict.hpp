// SPDX-License-Identifier: GPL-3.0-or-later
// What the codec tests share to check an encoding as a standard decoder reads it: decodeFba
// both ways, as this project reads and strictly as 14496-2's syntax reads
// (FbaDecodeLimits::strict), and the two must agree (issue 44: the encoder emulates no start
// code and hides no plane before one).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <span>
#include <string>

#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/error.hpp"

namespace mpeg4face::test {

// The strict reading of `bytes`, or the error it gives as text (so a test can print it).
inline std::string strictDifference(std::span<const uint8_t> bytes, const FapStream& expected) {
  try {
    FbaDecodeLimits strict;
    strict.strict = true;
    if (decodeFba(bytes, {}, strict) != expected) return "the strict reading differs";
  } catch (const Error& e) {
    return std::string("the strict reading fails: ") + e.what();
  }
  return {};
}

// decodeFba(bytes); the test fails unless the strict reading gives the same.
inline FapStream decodeBothWays(std::span<const uint8_t> bytes) {
  FapStream decoded = decodeFba(bytes);
  EXPECT_EQ(strictDifference(bytes, decoded), "");
  return decoded;
}

}  // namespace mpeg4face::test
