// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/codec/measure.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>

#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

struct Accumulator {
  int frames = 0;
  int missing = 0;
  long long min = 0;
  long long max = 0;
  long long maxAbs = 0;
  double sumSquares = 0;
};

void checkFramesMatch(const FapStream& original, const FapStream& decoded) {
  if (original.frameRate != decoded.frameRate) {
    throw Error({}, 0, "frame rate",
                "the original runs at " + std::to_string(original.frameRate) +
                    " Hz, the decoded stream at " + std::to_string(decoded.frameRate) + " Hz");
  }
  const size_t n = std::min(original.frames.size(), decoded.frames.size());
  for (size_t i = 0; i < n; ++i) {
    const int a = original.frames[i].number;
    const int b = decoded.frames[i].number;
    if (a != b) {
      throw Error({}, 0, "frame number",
                  "frame " + std::to_string(i) + " is number " + std::to_string(a) +
                      " in the original but " + std::to_string(b) + " in the decoded stream");
    }
  }
  if (original.frames.size() != decoded.frames.size()) {
    throw Error({}, 0, "frame number",
                "the original has " + std::to_string(original.frames.size()) +
                    " frames, the decoded stream " + std::to_string(decoded.frames.size()));
  }
}

}  // namespace

std::string_view fapQualityName(FapQuality quality) {
  return quality == FapQuality::Robust ? "robust" : "tao";
}

std::optional<FapQuality> parseFapQuality(std::string_view name) {
  if (name == "robust") return FapQuality::Robust;
  if (name == "tao") return FapQuality::Tao;
  return std::nullopt;
}

std::optional<double> psnrBy(const FapComparison& comparison, FapQuality quality) {
  return quality == FapQuality::Robust ? comparison.robustPsnr : comparison.psnr;
}

FapComparison compareFapStreams(const FapStream& original, const FapStream& decoded) {
  checkFramesMatch(original, decoded);
  std::array<Accumulator, kFapCount + 1> acc{};
  std::bitset<kFapCount> decodedEver;
  FapState a, b;
  FapComparison out;
  out.frames = static_cast<int>(original.frames.size());
  for (size_t i = 0; i < original.frames.size(); ++i) {
    applyFrame(a, original.frames[i]);
    applyFrame(b, decoded.frames[i]);
    decodedEver |= b.mask;
    if (a.sent(1) && (!b.has(1) || b.viseme != a.viseme)) ++out.visemeMismatches;
    if (a.sent(2) && (!b.has(2) || b.expression != a.expression)) ++out.expressionMismatches;
    for (int fap = 3; fap <= kFapCount; ++fap) {
      if (!a.sent(fap)) continue;
      Accumulator& s = acc[static_cast<size_t>(fap)];
      const long long x = a.value(fap);
      const long long y = b.has(fap) ? b.value(fap) : 0;
      if (!b.has(fap)) ++s.missing;
      s.min = s.frames == 0 ? x : std::min(s.min, x);
      s.max = s.frames == 0 ? x : std::max(s.max, x);
      s.maxAbs = std::max(s.maxAbs, std::llabs(x - y));
      s.sumSquares += static_cast<double>(x - y) * static_cast<double>(x - y);
      ++s.frames;
    }
  }

  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  double sumOfRatios = 0;  // sum_i R_i^2 / mse_i
  double sumOfErrors = 0;  // sum_i mse_i / R_i^2
  for (int fap = 3; fap <= kFapCount; ++fap) {
    const Accumulator& s = acc[static_cast<size_t>(fap)];
    if (s.frames == 0) {
      if (decodedEver[static_cast<size_t>(fap - 1)]) out.extraFaps.push_back(fap);
      continue;
    }
    FapError e;
    e.fap = fap;
    e.frames = s.frames;
    e.missing = s.missing;
    e.range = s.max - s.min;
    e.maxAbs = s.maxAbs;
    const double mse = s.sumSquares / s.frames;
    e.rms = std::sqrt(mse);
    if (e.range > 0) {
      const double r2 = static_cast<double>(e.range) * static_cast<double>(e.range);
      const double ratio = mse > 0 ? r2 / mse : kInfinity;
      e.psnr = 10.0 * std::log10(ratio);
      sumOfRatios += ratio;
      sumOfErrors += mse / r2;
      ++out.psnrFaps;
    }
    out.faps.push_back(e);
  }
  if (out.psnrFaps > 0) {
    out.psnr = 10.0 * std::log10(sumOfRatios / out.psnrFaps);
    out.robustPsnr = sumOfErrors > 0 ? 10.0 * std::log10(out.psnrFaps / sumOfErrors) : kInfinity;
  }
  return out;
}

FapStream alignByFrameNumber(const FapStream& original, FapStream decoded) {
  if (original.frames.empty()) return decoded;
  const int first = original.frames.front().number;
  const auto keep =
      std::find_if(decoded.frames.begin(), decoded.frames.end(),
                   [&](const FapFrame& f) { return f.number >= first || f.mask.any(); });
  decoded.frames.erase(decoded.frames.begin(), keep);
  return decoded;
}

double bitsPerFrame(double bits, std::size_t frameCount) {
  if (frameCount == 0) throw Error({}, 0, "frame count", "no frames to spread the bits over");
  return bits / static_cast<double>(frameCount);
}

double bitsPerSecond(double bits, std::size_t frameCount, double frameRate) {
  if (!(frameRate > 0)) throw Error({}, 0, "frame rate", "must be positive");
  return bitsPerFrame(bits, frameCount) * frameRate;
}

double bitsPerSecond(double bits, const FapStream& stream) {
  const double seconds = streamDuration(stream);
  if (!(seconds > 0)) throw Error({}, 0, "frame count", "the stream spans no time");
  return bits / seconds;
}

}  // namespace mpeg4face
