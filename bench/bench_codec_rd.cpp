// SPDX-License-Identifier: GPL-3.0-or-later
// The rate-distortion figures of issue [codec-rd]: for each coding mode and the cheapest of all,
// the fewest bits per FAP sample (bits of the whole stream / low-level FAP values sent) whose
// robust PSNR reaches 20, 25, 30 and 35 dB, and the same for Tao et al.'s eq. (8), on the nine
// Xface streams (tests/data/xface-fap, pooled: their bits summed over their samples summed)
// and on the two long 30 Hz streams (tests/data/long-30hz). Each mode is swept over its whole
// fap_quant range, as `mpeg4face rd` does (codec/rd.hpp). The figures before this work
// (cheapest at 25 dB robust: 2.09 on Xface, 1.62 on a long stream) are printed beside them.
#include <array>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "mpeg4face/codec/measure.hpp"
#include "mpeg4face/codec/rd.hpp"
#include "mpeg4face/io/fap_file.hpp"

namespace {

using namespace mpeg4face;

constexpr double kInf = std::numeric_limits<double>::infinity();

constexpr std::array kTargets{20.0, 25.0, 30.0, 35.0};

// The fewest bits of `mode` ("" = any) reaching `target` by `quality`; +inf if none does.
double cheapest(const std::vector<RdPoint>& points, const std::string& mode, double target,
                FapQuality quality) {
  std::vector<RdPoint> of;
  for (const RdPoint& p : points) {
    if (mode.empty() || rdModeName(p) == mode) of.push_back(p);
  }
  const auto best = cheapestMeeting(of, target, quality);
  return best ? static_cast<double>(best->bits) : kInf;
}

struct Set {
  std::string name;
  std::vector<std::filesystem::path> files;
  std::string target;  // the acceptance at 25 dB robust, and the figure before
};

}  // namespace

int main() {
  const std::filesystem::path data = MPEG4FACE_TEST_DATA;
  std::vector<Set> sets{
      {"xface (9 streams, pooled)", {}, "target <= 1.05; before: 2.09"},
      {"xface-30hz", {data / "long-30hz" / "xface-30hz.fap"}, "goal <= 0.8"},
      {"xface-30hz-tracked", {data / "long-30hz" / "xface-30hz-tracked.fap"}, "goal <= 0.8"}};
  for (const char* name :
       {"anger", "beg", "disgust", "fear", "happy-for", "hate", "joy", "pride", "test"})
    sets[0].files.push_back(data / "xface-fap" / (std::string(name) + ".fap"));
  const std::vector<std::string> modes{"", "predictive", "dct", "pca+predictive", "pca+dct"};
  for (const Set& set : sets) {
    std::vector<std::vector<RdPoint>> sweeps;
    double samples = 0;
    for (const auto& file : set.files) {
      const FapStream stream = readFapFile(file);
      samples += static_cast<double>(fapSampleCount(stream));
      sweeps.push_back(sweepRateDistortion(stream, allCodingModes()));
    }
    std::printf("\n%s: %.0f FAP samples; bits per FAP sample at each target (- none reaches)\n",
                set.name.c_str(), samples);
    std::printf("%-16s %-7s %8s %8s %8s %8s\n", "mode", "measure", "20 dB", "25 dB", "30 dB",
                "35 dB");
    for (const FapQuality quality : {FapQuality::Robust, FapQuality::Tao}) {
      for (const std::string& mode : modes) {
        std::printf("%-16s %-7s", mode.empty() ? "cheapest" : mode.c_str(),
                    std::string(fapQualityName(quality)).c_str());
        for (const double target : kTargets) {
          double bits = 0;
          for (const auto& points : sweeps) bits += cheapest(points, mode, target, quality);
          if (bits == kInf)
            std::printf(" %8s", "-");
          else
            std::printf(" %8.3f", bits / samples);
        }
        std::printf("\n");
      }
    }
    double bits = 0;
    for (const auto& points : sweeps) bits += cheapest(points, "", 25.0, FapQuality::Robust);
    std::printf("cheapest at 25 dB robust: %.3f bits per FAP sample (%s)\n", bits / samples,
                set.target.c_str());
  }
}
