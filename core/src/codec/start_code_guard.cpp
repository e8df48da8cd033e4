// SPDX-License-Identifier: GPL-3.0-or-later
#include "codec/start_code_guard.hpp"

#include <algorithm>
#include <optional>

namespace mpeg4face {
namespace {

// Where BitWriter::writeStartCode(), called at `position`, puts the code: after a 0 and 1s to
// the byte boundary, or a whole 0111 1111 byte when aligned.
uint64_t startCodeAfter(uint64_t position) { return (position | 7) + 1; }

// Whether a standard decoder misreads `plane` (PlaneGuard::secure), the start codes being at
// `codes` (bit positions). The bits after the plane are `out`'s, or, if `codeFollows` and none
// are written yet, the start code that will follow. `bits` is scratch.
bool misreadByStandardDecoder(const BitWriter& out, const PlaneGuard::Span& plane,
                              const std::vector<uint64_t>& codes, bool codeFollows,
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

}  // namespace

void PlaneGuard::open(bool startCode) {
  const uint64_t start = out_.bitCount();
  planes_.push_back({start, start, start, startCode});
  if (startCode) {
    out_.writeStartCode(kFbaObjectPlaneStartCode);
    planes_.back().body = out_.bitCount();
  }
}

bool PlaneGuard::violates(size_t j, bool codeFollows) const {
  codes_.clear();
  for (const Span& p : planes_) {
    if (p.startCode) codes_.push_back(startCodeAfter(p.start));
  }
  return misreadByStandardDecoder(out_, planes_[j], codes_, codeFollows, bits_);
}

bool PlaneGuard::secure(size_t j, bool codeFollows) {
  if (!violates(j, codeFollows)) return true;
  if (j + 1 < planes_.size() && !planes_[j + 1].startCode) {
    insertStartCode(j + 1);
    if (!violates(j, true)) return true;
    codeFollows = true;
  }
  if (planes_[j].startCode) return false;
  insertStartCode(j);
  // The start code moved what follows plane j - 1, so that plane is checked again.
  return !violates(j, codeFollows) && (j == 0 || secure(j - 1, true));
}

// The planes after the new start code move along; those with a start code get their stuffing
// anew, since it depends on where they now start.
void PlaneGuard::insertStartCode(size_t j) {
  std::vector<BitWriter> bodies;
  for (size_t m = j; m < planes_.size(); ++m) {
    bodies.push_back(out_.slice(planes_[m].body, planes_[m].end));
  }
  out_.truncate(planes_[j].start);
  planes_[j].startCode = true;
  for (size_t m = j; m < planes_.size(); ++m) {
    Span& plane = planes_[m];
    plane.start = out_.bitCount();
    if (plane.startCode) out_.writeStartCode(kFbaObjectPlaneStartCode);
    plane.body = out_.bitCount();
    out_.append(bodies[m - j]);
    plane.end = out_.bitCount();
  }
  moved_ = std::min(moved_.value_or(j), j);
}

void PlaneGuard::rollBack(size_t j) {
  out_.truncate(planes_[j].start);
  planes_.resize(j);
  if (moved_ && *moved_ >= j) moved_.reset();
}

}  // namespace mpeg4face
