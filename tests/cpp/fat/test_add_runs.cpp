// SPDX-License-Identifier: GPL-3.0-or-later
// The FAT evaluator's inner loop (core/src/fat/add_runs.hpp): each kernel gives, bit for bit,
// what a plain loop over the entries gives, for runs of every length (so every tail after the
// 8-vertex blocks), with and without a base, in float and 16-bit storage.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <random>
#include <type_traits>
#include <vector>

#include "fat/add_runs.hpp"

using namespace mpeg4face::fat;

namespace {

template <typename Stored>
std::vector<Stored> randomValues(std::size_t n, std::mt19937& rng) {
  std::vector<Stored> v(n);
  std::uniform_int_distribution<int> i16(-32767, 32767);
  std::uniform_real_distribution<float> f(-3, 3);
  for (Stored& x : v) {
    if constexpr (std::is_same_v<Stored, float>) {
      x = f(rng);
    } else {
      x = static_cast<Stored>(i16(rng));
    }
  }
  return v;
}

// What addRuns promises, one entry at a time.
template <typename Stored>
void plainLoop(const std::vector<Run>& runs, std::vector<float>& work, const Stored* base,
               const Stored* slope, const float* B, const float* C) {
  std::size_t e = 0;
  for (const auto& [first, length] : runs) {
    for (std::uint32_t v = 0; v < length; ++v, ++e) {
      for (std::size_t axis = 0; axis < 3; ++axis) {
        const std::size_t i = 3 * e + axis;
        const float motion =
            base ? B[axis] * static_cast<float>(base[i]) + C[axis] * static_cast<float>(slope[i])
                 : C[axis] * static_cast<float>(slope[i]);
        work[3 * (first + v) + axis] += motion;
      }
    }
  }
}

template <typename Stored>
void expectTheKernelIsThePlainLoop(RunsKernel kernel) {
  std::mt19937 rng(11);
  // Runs of 1..60 vertices (tails of 0..23 floats after the 24-float blocks), with gaps.
  std::vector<Run> runs;
  std::uint32_t slot = 5, entries = 0;
  for (std::uint32_t length = 1; length <= 60; ++length) {
    runs.emplace_back(slot, length);
    slot += length + length % 7;
    entries += length;
  }
  const std::vector<Stored> base = randomValues<Stored>(3 * entries, rng);
  const std::vector<Stored> slope = randomValues<Stored>(3 * entries, rng);
  const float B[3] = {1.5e-4f, -3.0e-5f, 7.0e-4f}, C[3] = {-2.5e-3f, 6.1e-5f, 1.0e-4f};
  const std::vector<float> start = randomValues<float>(3 * std::size_t(slot) + 3, rng);
  for (const Stored* b : {base.data(), static_cast<const Stored*>(nullptr)}) {
    std::vector<float> expected = start;
    plainLoop(runs, expected, b, slope.data(), B, C);
    std::vector<float> work = start;
    addRuns(runs.data(), runs.size(), work.data(), b, slope.data(), B, C, kernel);
    for (std::size_t i = 0; i < work.size(); ++i) {
      ASSERT_EQ(std::memcmp(&work[i], &expected[i], sizeof(float)), 0)
          << (b ? "with" : "without") << " base, " << sizeof(Stored) << "-byte tables, float " << i
          << ": " << work[i] << " instead of " << expected[i];
    }
  }
}

}  // namespace

TEST(AddRuns, ThePortableKernelIsThePlainLoopBitForBit) {
  expectTheKernelIsThePlainLoop<float>(RunsKernel::Portable);
  expectTheKernelIsThePlainLoop<std::int16_t>(RunsKernel::Portable);
}

TEST(AddRuns, TheAvx2KernelIsThePlainLoopBitForBit) {
  if (bestRunsKernel() != RunsKernel::Avx2) GTEST_SKIP() << "this CPU or build has no AVX2";
  expectTheKernelIsThePlainLoop<float>(RunsKernel::Avx2);
  expectTheKernelIsThePlainLoop<std::int16_t>(RunsKernel::Avx2);
}
