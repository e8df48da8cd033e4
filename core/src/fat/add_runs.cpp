// SPDX-License-Identifier: GPL-3.0-or-later
#include "fat/add_runs.hpp"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define MPEG4FACE_HAS_AVX2_KERNEL 1
#endif

namespace mpeg4face::fat {
namespace {

// A block is 8 vertices: 24 interleaved x, y, z floats, three AVX registers.
constexpr std::size_t kFloats = 24;

// The factors of each axis repeated over a block, so that float k of a block has axis k % 3.
struct BlockFactors {
  float B[kFloats], C[kFloats];
  BlockFactors(const float* b, const float* c, bool withBase) {
    for (std::size_t k = 0; k < kFloats; ++k) B[k] = withBase ? b[k % 3] : 0.0f, C[k] = c[k % 3];
  }
};

// Float k of a block's motion from its stored base and slope: the rounding every kernel keeps.
template <bool withBase, typename Stored>
[[gnu::always_inline]] inline float motion(const BlockFactors& f, std::size_t k, Stored b,
                                           Stored s) {
  return withBase ? f.B[k] * float(b) + f.C[k] * float(s) : f.C[k] * float(s);
}

// Portable: blocks as flat loops the compiler vectorises, the rest one by one.
template <bool withBase, typename Stored>
void addRunsPortable(const Run* runs, std::size_t runCount, float* __restrict work,
                     const Stored* __restrict base, const Stored* __restrict slope,
                     const BlockFactors& f) {
  // w[0 .. n) += the motion of n floats from the start of a block (n <= kFloats).
  const auto add = [&](float* __restrict w, const Stored* __restrict b, const Stored* __restrict s,
                       std::size_t n) {
    for (std::size_t k = 0; k < n; ++k) w[k] += motion<withBase>(f, k, b[k], s[k]);
  };
  for (std::size_t r = 0; r < runCount; ++r) {
    float* __restrict w = work + 3 * std::size_t(runs[r].first);
    const std::size_t floats = 3 * std::size_t(runs[r].second);
    std::size_t i = 0;
    for (; i + kFloats <= floats; i += kFloats) add(w + i, base + i, slope + i, kFloats);
    add(w + i, base + i, slope + i, floats - i);
    if (withBase) base += floats;
    slope += floats;
  }
}

#ifdef MPEG4FACE_HAS_AVX2_KERNEL
[[gnu::target("avx2"), gnu::always_inline]] inline __m256 load8(const float* p) {
  return _mm256_loadu_ps(p);
}
[[gnu::target("avx2"), gnu::always_inline]] inline __m256 load8(const std::int16_t* p) {
  return _mm256_cvtepi32_ps(
      _mm256_cvtepi16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p))));
}

// w[0 .. 8) += B * b + C * s, rounded as the portable loop rounds (no fused multiply-add).
template <bool withBase, typename Stored>
[[gnu::target("avx2"), gnu::always_inline]] inline void add8(float* w, const Stored* b,
                                                             const Stored* s, __m256 B, __m256 C) {
  __m256 motion = _mm256_mul_ps(C, load8(s));
  if constexpr (withBase) motion = _mm256_add_ps(_mm256_mul_ps(B, load8(b)), motion);
  _mm256_storeu_ps(w, _mm256_add_ps(_mm256_loadu_ps(w), motion));
}

template <bool withBase, typename Stored>
[[gnu::target("avx2")]] void addRunsAvx2(const Run* runs, std::size_t runCount, float* work,
                                         const Stored* base, const Stored* slope,
                                         const BlockFactors& f) {
  const __m256 B[3] = {_mm256_loadu_ps(f.B), _mm256_loadu_ps(f.B + 8), _mm256_loadu_ps(f.B + 16)};
  const __m256 C[3] = {_mm256_loadu_ps(f.C), _mm256_loadu_ps(f.C + 8), _mm256_loadu_ps(f.C + 16)};
  for (std::size_t r = 0; r < runCount; ++r) {
    float* w = work + 3 * std::size_t(runs[r].first);
    const std::size_t floats = 3 * std::size_t(runs[r].second);
    std::size_t i = 0;
    for (; i + kFloats <= floats; i += kFloats) {
      add8<withBase>(w + i, base + i, slope + i, B[0], C[0]);
      add8<withBase>(w + i + 8, base + i + 8, slope + i + 8, B[1], C[1]);
      add8<withBase>(w + i + 16, base + i + 16, slope + i + 16, B[2], C[2]);
    }
    std::size_t k = 0;  // the register of the block that comes next
    for (; i + 8 <= floats; i += 8, ++k) add8<withBase>(w + i, base + i, slope + i, B[k], C[k]);
    for (k *= 8; i < floats; ++i, ++k) w[i] += motion<withBase>(f, k, base[i], slope[i]);
    if (withBase) base += floats;
    slope += floats;
  }
}
#endif

template <typename Stored>
void addRunsOf(const Run* runs, std::size_t runCount, float* work, const Stored* base,
               const Stored* slope, const float* B, const float* C, RunsKernel kernel) {
  const BlockFactors f(B, C, base != nullptr);
#ifdef MPEG4FACE_HAS_AVX2_KERNEL
  if (kernel == RunsKernel::Avx2) {
    if (base) return addRunsAvx2<true>(runs, runCount, work, base, slope, f);
    // Without a base the loops still step a base pointer, never read: the slopes serve.
    return addRunsAvx2<false>(runs, runCount, work, slope, slope, f);
  }
#else
  (void)kernel;
#endif
  if (base) return addRunsPortable<true>(runs, runCount, work, base, slope, f);
  addRunsPortable<false>(runs, runCount, work, slope, slope, f);
}

}  // namespace

RunsKernel bestRunsKernel() {
#ifdef MPEG4FACE_HAS_AVX2_KERNEL
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2) return RunsKernel::Avx2;
#endif
  return RunsKernel::Portable;
}

void addRuns(const Run* runs, std::size_t runCount, float* work, const float* base,
             const float* slope, const float* B, const float* C, RunsKernel kernel) {
  addRunsOf(runs, runCount, work, base, slope, B, C, kernel);
}

void addRuns(const Run* runs, std::size_t runCount, float* work, const std::int16_t* base,
             const std::int16_t* slope, const float* B, const float* C, RunsKernel kernel) {
  addRunsOf(runs, runCount, work, base, slope, B, C, kernel);
}

}  // namespace mpeg4face::fat
