// SPDX-License-Identifier: GPL-3.0-or-later
// Quality and rate measures for FAP coding: the PSNR of Tao et al. (1999) eq. (8), a robust
// PSNR that the worst-coded FAPs dominate, per-FAP errors, and bit rates. The exact definitions and
// how edge cases are handled are in docs/fap-format.md ("Measures").
#pragma once

#include <cstddef>
#include <optional>
#include <string_view>
#include <vector>

#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face {

// Which PSNR a rate-distortion choice is judged by (docs/rate-distortion.md, "Two measures").
// Tao: eq. (8), the mean of R_i^2 / MSE_i, which the best-coded FAP dominates (one exact FAP
// makes it +inf). Robust: 10 log10(1 / mean_i(MSE_i / R_i^2)), which the worst-coded FAPs
// dominate and which is +inf only when every FAP is exact.
enum class FapQuality { Robust, Tao };

// "robust" / "tao", and back (nullopt for another name).
std::string_view fapQualityName(FapQuality quality);
std::optional<FapQuality> parseFapQuality(std::string_view name);

// The error of one low-level FAP (3..68) over the frames where the original has sent it.
struct FapError {
  int fap = 0;
  int frames = 0;        // frames compared: from the original's first sending of this FAP on
  int missing = 0;       // of those, frames where the decoded stream has no value (counted as 0)
  long long range = 0;   // R_i: max - min of the original's values over those frames
  long long maxAbs = 0;  // largest |original - decoded|
  double rms = 0;        // sqrt(mean (original - decoded)^2)
  // 10 log10(R_i^2 / rms^2) in dB: +inf when exact, nullopt when R_i = 0.
  std::optional<double> psnr;
};

struct FapComparison {
  int frames = 0;
  std::vector<FapError> faps;  // every low-level FAP the original sends, in FAP order
  // Tao et al. eq. (8), 10 log10((1/N) sum_i R_i^2 / rms_i^2), over the N FAPs of `faps` with
  // R_i > 0: +inf if one of them is exact, nullopt if N = 0.
  std::optional<double> psnr;
  // The robust PSNR, 10 log10(N / sum_i rms_i^2 / R_i^2) over the same N FAPs: +inf only when
  // all of them are exact, nullopt if N = 0.
  std::optional<double> robustPsnr;
  int psnrFaps = 0;            // N
  std::vector<int> extraFaps;  // low-level FAPs the decoded stream has and the original never sends
  int visemeMismatches = 0;    // frames where the original has FAP 1 and the decoded differs
  int expressionMismatches = 0;  // likewise for FAP 2
};

// Compares a decoded stream with its original, frame by frame on resolved states
// (applyFrame): the original's sent FAPs against everything the decoded stream resolves to,
// mirrored FAPs included. Both must have the same frame rate and frame numbers; throws
// mpeg4face::Error (field "frame rate" / "frame number") naming the first difference.
FapComparison compareFapStreams(const FapStream& original, const FapStream& decoded);

// `decoded` aligned with `original` by frame number for compareFapStreams: the frames at its
// front that are numbered below the original's first frame and send nothing are dropped. The
// FBA bitstream numbers its first plane 0, so a stream that starts at frame n > 0 decodes
// with an empty frame 0 in front (docs/bitstream.md, "Frame numbers"); an empty frame is the
// neutral face a decoder shows before the first frame anyway. Anything else is left for
// compareFapStreams to report.
FapStream alignByFrameNumber(const FapStream& original, FapStream decoded);

// The comparison's PSNR by `quality`: robustPsnr or psnr.
std::optional<double> psnrBy(const FapComparison& comparison, FapQuality quality);

// Bit rates. `bits` spread over `frameCount` frames at `frameRate` Hz: bits * frameRate /
// frameCount; over a stream: bits / streamDuration (skipped frame numbers count as time).
double bitsPerFrame(double bits, std::size_t frameCount);
double bitsPerSecond(double bits, std::size_t frameCount, double frameRate);
double bitsPerSecond(double bits, const FapStream& stream);

}  // namespace mpeg4face
