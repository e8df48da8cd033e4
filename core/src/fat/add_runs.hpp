// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: the FAT evaluator's inner loop (FatEvaluator::evaluate). Not installed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>

namespace mpeg4face::fat {

// Entries of a table whose vertex slots follow one another: (first slot, length).
using Run = std::pair<std::uint32_t, std::uint32_t>;

// Portable: what the compiler vectorises for any CPU. Avx2: written with AVX2 intrinsics,
// x86-64 only; 8 floats a step through the whole run (the portable loop does its last < 24
// floats one by one, which costs as much as the rest of a 100-vertex run).
enum class RunsKernel { Portable, Avx2 };

// Avx2 where this build and CPU have it, else Portable.
RunsKernel bestRunsKernel();

// For each run in turn, work[3 * slot + axis] += B[axis] * base[e] + C[axis] * slope[e] over
// its slots, e counting on from the previous run's end in `base` and `slope` (x, y, z
// interleaved); a null `base` adds nothing. Every kernel rounds exactly alike: one float
// multiply each, the two products added, then added to work.
void addRuns(const Run* runs, std::size_t runCount, float* work, const float* base,
             const float* slope, const float* B, const float* C, RunsKernel kernel);
void addRuns(const Run* runs, std::size_t runCount, float* work, const std::int16_t* base,
             const std::int16_t* slope, const float* B, const float* C, RunsKernel kernel);

}  // namespace mpeg4face::fat
