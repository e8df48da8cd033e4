// SPDX-License-Identifier: GPL-3.0-or-later
#include "codec/start_code_guard.hpp"

#include <algorithm>
#include <optional>

namespace mpeg4face {

bool misreadByStandardDecoder(const BitWriter& out, PlaneBits plane,
                              std::span<const uint64_t> codes, bool codeFollows,
                              std::vector<bool>& bits) {
  const uint64_t from = plane.start >= 24 ? (plane.start - 24) & ~uint64_t{7} : 0;
  bits.clear();
  for (uint64_t x = from; x < std::min(out.bitCount(), plane.end + 64); ++x) {
    bits.push_back(out.bitAt(x));
  }
  std::optional<uint64_t> following;
  if (codeFollows && plane.end == out.bitCount()) {
    following = startCodeAfter(plane.end);
    bits.push_back(false);
    while (from + bits.size() < *following) bits.push_back(true);
    bits.insert(bits.end(), 23, false);
    bits.insert(bits.end(), 2, true);  // 0x000001 and the first bit of 0xBB or 0xB1
  }
  const uint64_t known = from + bits.size();
  const auto zeros = [&](uint64_t x) {  // 23 zero bits at x, as far as they are known
    for (uint64_t i = x; i < std::min(x + 23, known); ++i) {
      if (bits[i - from]) return false;
    }
    return true;
  };
  // The prefixes whose 1 lies in the plane or after it (those before are the previous
  // plane's, or a header's outside this mode).
  for (uint64_t b = from; b < plane.end && b + 24 <= known; b += 8) {
    if (b + 23 < plane.start || !zeros(b) || !bits[b + 23 - from]) continue;
    if (b != following && std::find(codes.begin(), codes.end(), b) == codes.end()) return true;
  }
  // An inter plane starts with a 0 bit, so nextbits_bytealigned() skips no stuffing byte.
  return !plane.startCode && zeros((plane.start + 7) & ~uint64_t{7});
}

}  // namespace mpeg4face
