// SPDX-License-Identifier: GPL-3.0-or-later
// Rate-distortion of FAP coding: one encoding measured (bits, bits per FAP sample, bits/s,
// PSNR by both measures of codec/measure.hpp), sweeps over coding modes and fap_quant, and the
// cheapest encoding that meets a PSNR target by either measure. Definitions and choices are in
// docs/rate-distortion.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/codec/measure.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face {

struct RdPoint {
  FapCodingMode mode = FapCodingMode::Predictive;
  FapCodingMode pcaTemporal = FapCodingMode::Predictive;  // the component coder, mode Pca only
  int fapQuant = 0;
  uint64_t bits = 0;
  double bitsPerSample = 0;  // bits / fapSampleCount(stream)
  double bitsPerSecond = 0;  // bits / streamDuration(stream)
  // Tao et al. eq. (8) as compareFapStreams gives it: +inf when a FAP is reproduced exactly,
  // nullopt when no FAP varies.
  std::optional<double> psnr;
  // The robust PSNR (FapComparison::robustPsnr): +inf only when every FAP is exact.
  std::optional<double> robustPsnr;
};

// The point's PSNR by `quality`: robustPsnr or psnr.
std::optional<double> psnrBy(const RdPoint& point, FapQuality quality);

// The low-level FAP values (FAPs 3..68) the stream sends, summed over its frames: the "FAP
// samples" a rate is normalised by (Tao et al. give kbit/s for a number of FAPs at 30 Hz).
std::size_t fapSampleCount(const FapStream& stream);

// The reconstruction on the input's frames and rate, for compareFapStreams: without the empty
// frame 0 the bitstream needs when the input starts later, and with the input's exact rate
// (the bitstream codes it in 1/16 Hz, times 1000/1001).
FapStream comparableReconstruction(const FapStream& input, FapStream reconstruction);

// The fap_quant values a mode accepts: predictive 0..31, dct and pca 1..31 (PCA is lossy
// anyway; its components coded with fap_quant 0 would cost without gain).
std::vector<int> fapQuantRange(FapCodingMode mode);

// Encodes `stream` with `options` and measures it. Throws what encodeFba throws, and
// mpeg4face::Error for a stream with no frames or no FAP samples.
RdPoint measureEncoding(const FapStream& stream, const FbaEncodeOptions& options);

// measureEncoding for every mode in `modes` and every fap_quant of fapQuantRange(mode), in
// that order; the other options are taken from `base`. Pca is swept with each component coder
// (pcaTemporal predictive, then dct).
std::vector<RdPoint> sweepRateDistortion(const FapStream& stream,
                                         std::span<const FapCodingMode> modes,
                                         const FbaEncodeOptions& base = {});

// Whether a point reaches `targetDb` by `quality`: that PSNR is defined and >= targetDb (+inf
// reaches all).
bool meetsPsnr(const RdPoint& point, double targetDb, FapQuality quality = FapQuality::Robust);

// Of `points`, the one with the fewest bits that meets `targetDb` by `quality` (ties: the
// earlier one); nullopt if none does.
std::optional<RdPoint> cheapestMeeting(std::span<const RdPoint> points, double targetDb,
                                       FapQuality quality = FapQuality::Robust);

// The fewest-bit (mode, fap_quant) over all modes of `modes` and their whole fap_quant range
// that meets `targetDb` by `quality`: an exhaustive search, so never worse than the best single
// mode at that target. nullopt if no encoding reaches it.
std::optional<RdPoint> cheapestEncoding(const FapStream& stream, double targetDb,
                                        std::span<const FapCodingMode> modes,
                                        const FbaEncodeOptions& base = {},
                                        FapQuality quality = FapQuality::Robust);

// A point's mode as tables and the rd CSV name it: "predictive", "dct", "pca+predictive",
// "pca+dct" (Tao et al.'s PCA+PC and PCA+DCT).
std::string rdModeName(const RdPoint& point);

// Every coding mode the codec has, for the sweeps above.
std::span<const FapCodingMode> allCodingModes();

}  // namespace mpeg4face
