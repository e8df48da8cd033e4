// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/codec/rd.hpp"

#include <array>

#include "mpeg4face/error.hpp"

namespace mpeg4face {

std::size_t fapSampleCount(const FapStream& stream) {
  std::size_t samples = 0;
  for (const FapFrame& frame : stream.frames) {
    for (int fap = 3; fap <= kFapCount; ++fap) samples += frame.has(fap) ? 1 : 0;
  }
  return samples;
}

FapStream comparableReconstruction(const FapStream& input, FapStream reconstruction) {
  if (reconstruction.frames.size() == input.frames.size() + 1) {
    reconstruction.frames.erase(reconstruction.frames.begin());
  }
  reconstruction.frameRate = input.frameRate;
  return reconstruction;
}

std::vector<int> fapQuantRange(FapCodingMode mode) {
  std::vector<int> range;
  for (int q = mode == FapCodingMode::Predictive ? 0 : 1; q <= 31; ++q) range.push_back(q);
  return range;
}

RdPoint measureEncoding(const FapStream& stream, const FbaEncodeOptions& options) {
  const std::size_t samples = fapSampleCount(stream);
  if (samples == 0) throw Error({}, 0, "FAP mask", "the stream sends no low-level FAP");
  const FbaEncoding enc = encodeFba(stream, options);
  RdPoint p;
  p.mode = options.mode;
  p.pcaTemporal = options.pcaTemporal;
  p.fapQuant = options.fapQuant;
  p.bits = enc.stats.bits;
  const auto bits = static_cast<double>(enc.stats.bits);
  p.bitsPerSample = bits / static_cast<double>(samples);
  p.bitsPerSecond = bitsPerSecond(bits, stream);
  const FapComparison c =
      compareFapStreams(stream, comparableReconstruction(stream, enc.reconstruction));
  p.psnr = c.psnr;
  p.robustPsnr = c.robustPsnr;
  return p;
}

std::vector<RdPoint> sweepRateDistortion(const FapStream& stream,
                                         std::span<const FapCodingMode> modes,
                                         const FbaEncodeOptions& base) {
  std::vector<RdPoint> points;
  for (const FapCodingMode mode : modes) {
    FbaEncodeOptions options = base;
    options.mode = mode;
    std::vector<FapCodingMode> temporals{base.pcaTemporal};
    if (mode == FapCodingMode::Pca) temporals = {FapCodingMode::Predictive, FapCodingMode::Dct};
    for (const FapCodingMode temporal : temporals) {
      options.pcaTemporal = temporal;
      for (const int q : fapQuantRange(mode)) {
        options.fapQuant = q;
        points.push_back(measureEncoding(stream, options));
      }
    }
  }
  return points;
}

std::optional<double> psnrBy(const RdPoint& point, FapQuality quality) {
  return quality == FapQuality::Robust ? point.robustPsnr : point.psnr;
}

bool meetsPsnr(const RdPoint& point, double targetDb, FapQuality quality) {
  const std::optional<double> db = psnrBy(point, quality);
  return db && *db >= targetDb;
}

std::optional<RdPoint> cheapestMeeting(std::span<const RdPoint> points, double targetDb,
                                       FapQuality quality) {
  std::optional<RdPoint> best;
  for (const RdPoint& p : points) {
    if (meetsPsnr(p, targetDb, quality) && (!best || p.bits < best->bits)) best = p;
  }
  return best;
}

std::optional<RdPoint> cheapestEncoding(const FapStream& stream, double targetDb,
                                        std::span<const FapCodingMode> modes,
                                        const FbaEncodeOptions& base, FapQuality quality) {
  const std::vector<RdPoint> points = sweepRateDistortion(stream, modes, base);
  return cheapestMeeting(points, targetDb, quality);
}

std::string rdModeName(const RdPoint& point) {
  std::string name(codingModeName(point.mode));
  if (point.mode == FapCodingMode::Pca)
    name += "+" + std::string(codingModeName(point.pcaTemporal));
  return name;
}

std::span<const FapCodingMode> allCodingModes() {
  static constexpr std::array kModes{FapCodingMode::Predictive, FapCodingMode::Dct,
                                     FapCodingMode::Pca};
  return kModes;
}

}  // namespace mpeg4face
