// SPDX-License-Identifier: GPL-3.0-or-later
// The 16-point DCT of the DCT coding mode: a double-precision forward transform for the
// encoder and an integer inverse that defines the decoder's output exactly (see
// codec/dct_transform.hpp and docs/dct-mode.md).
#include "codec/dct_transform.hpp"

#include <cmath>
#include <numbers>

namespace mpeg4face {
namespace {

constexpr int kN = kDctSegmentLength;
constexpr int kBasisShift = 28;

// round(2^28 sqrt(2/16) cos(pi j / 32)) for j = 0..16: every AC basis value is one of these
// up to sign. Written out so that the decoder does not depend on the platform's cos().
constexpr std::array<std::int64_t, 17> kAcCosine = {
    94906266, 94449266, 93082668, 90819634, 87681956, 83699854, 78911676, 73363535, 67108864,
    60207898, 52727096, 44738504, 36319055, 27549835, 18515294, 9302441,  0};
constexpr std::int64_t kDcBasis = std::int64_t{1} << (kBasisShift - 2);  // 2^28 sqrt(1/16)

constexpr auto makeBasis() {
  std::array<std::array<std::int64_t, kN>, kN> b{};
  for (int n = 0; n < kN; ++n) b[0][n] = kDcBasis;
  for (int k = 1; k < kN; ++k) {
    for (int n = 0; n < kN; ++n) {
      int m = (2 * n + 1) * k % 64;                          // cos(pi m / 32) has period 64 in m
      if (m > 32) m = 64 - m;                                // cos(2 pi - a) = cos(a)
      b[k][n] = m > 16 ? -kAcCosine[32 - m] : kAcCosine[m];  // cos(pi - a) = -cos(a)
    }
  }
  return b;
}
constexpr auto kBasis = makeBasis();

__extension__ using Int128 = __int128;  // GCC and Clang; -Wpedantic knows no 128-bit type

// a / d rounded to nearest, halves away from zero; d > 0.
Int128 roundedDivide(Int128 a, Int128 d) {
  const Int128 q = ((a < 0 ? -a : a) + d / 2) / d;
  return a < 0 ? -q : q;
}

}  // namespace

const std::array<std::array<std::int64_t, kN>, kN>& dctBasis() { return kBasis; }

std::array<double, kN> forwardDct16(const std::array<double, kN>& x) {
  static const auto basis = [] {
    std::array<std::array<double, kN>, kN> b{};
    for (int k = 0; k < kN; ++k) {
      const double c = k == 0 ? std::sqrt(1.0 / kN) : std::sqrt(2.0 / kN);
      for (int n = 0; n < kN; ++n)
        b[k][n] = c * std::cos(std::numbers::pi * (2 * n + 1) * k / (2 * kN));
    }
    return b;
  }();
  std::array<double, kN> out{};
  for (int k = 0; k < kN; ++k) {
    for (int n = 0; n < kN; ++n) out[k] += basis[k][n] * x[n];
  }
  return out;
}

std::array<int, kN> reconstructDctSegment(const std::array<std::int64_t, kN>& levels,
                                          std::int64_t acStep, int dcDivisor,
                                          int stepFractionBits) {
  // Most AC levels are 0: only the others' basis rows are added (the sum is exact either way).
  std::array<Int128, kN> ac{};
  for (int k = 1; k < kN; ++k) {
    if (levels[k] == 0) continue;
    for (int n = 0; n < kN; ++n) ac[n] += Int128{levels[k]} * kBasis[k][n];
  }
  const Int128 divisor = Int128{dcDivisor} << (kBasisShift + stepFractionBits);
  std::array<int, kN> x{};
  for (int n = 0; n < kN; ++n) {
    const Int128 s = acStep * (Int128{levels[0]} * kBasis[0][n] + dcDivisor * ac[n]);
    x[n] = static_cast<int>(roundedDivide(s, divisor));
  }
  return x;
}

}  // namespace mpeg4face
