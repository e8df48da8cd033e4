// SPDX-License-Identifier: GPL-3.0-or-later
// Speed of the FBA codec in FAP values per second (target: 5 million each way, issue [codec]
// item 7) for every coding mode, without and with an intra frame every 25 frames, on a long
// synthetic talking-head stream, next to a plain copy of the same values (the baseline, same
// process). Medians of several runs, in CPU time of this thread so that other work on a shared
// machine counts less (it still shares caches and cores).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/spec.hpp"

namespace {

double cpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

double medianSeconds(int runs, const std::function<void()>& work) {
  std::vector<double> s;
  for (int i = 0; i < runs; ++i) {
    const double start = cpuSeconds();
    work();
    s.push_back(cpuSeconds() - start);
  }
  std::nth_element(s.begin(), s.begin() + runs / 2, s.end());
  return s[runs / 2];
}

// 50 low-level FAPs (lips, jaw, eyes, brows, head) as damped random walks, FAP 1 and 2 in
// alternating stretches so the FAP set changes every 500 frames.
mpeg4face::FapStream talkingHead(int frameCount) {
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<int> faps;
  for (int fap = 3; fap <= 50; ++fap) faps.push_back(fap);
  faps.push_back(61);
  faps.push_back(62);
  std::vector<double> walk(mpeg4face::kFapCount + 1, 0.0);
  mpeg4face::FapStream s;
  s.frameRate = 25.0;
  for (int k = 0; k < frameCount; ++k) {
    mpeg4face::FapFrame f;
    f.number = k;
    for (int fap : faps) {
      walk[fap] = 0.97 * walk[fap] + 4.0 * mpeg4face::fapInfo(fap).quantStep * noise(rng);
      f.set(fap, static_cast<int>(std::lround(walk[fap])));
    }
    if ((k / 500) % 2 == 0) {
      f.mask.set(0);
      f.viseme = {static_cast<int>(rng() % 15), static_cast<int>(rng() % 15), 63, false};
    } else {
      f.mask.set(1);
      f.expression = {1, static_cast<int>(rng() % 64), 0, 0, false, false};
    }
    s.frames.push_back(f);
  }
  return s;
}

// FAP values in the stream: one per low-level FAP sent, one per FAP 1 or 2 sent.
long valueCount(const mpeg4face::FapStream& s) {
  long n = 0;
  for (const auto& f : s.frames) n += static_cast<long>(f.mask.count());
  return n;
}

constexpr double kTargetValuesPerSecond = 5e6;

void report(const char* what, double seconds, long values, double baseline) {
  const double rate = static_cast<double>(values) / seconds;
  std::printf("%-34s %9.2f ms  %7.2f M values/s  %5.2fx the 5 M target  %6.1fx the copy's time\n",
              what, seconds * 1e3, rate / 1e6, rate / kTargetValuesPerSecond, seconds / baseline);
}

}  // namespace

int main(int argc, char** argv) {
  constexpr int kRuns = 7;
  constexpr int kFrames = 100000;  // about 67 minutes at 25 frames per second
  const mpeg4face::FapStream stream = talkingHead(kFrames);
  const long values = valueCount(stream);
  std::printf("synthetic stream: %d frames, %ld FAP values; median of %d runs\n", kFrames, values,
              kRuns);

  std::vector<int> copy;
  const double baseline = medianSeconds(kRuns, [&] {
    copy.clear();
    for (const auto& f : stream.frames) {
      for (int fap = 1; fap <= mpeg4face::kFapCount; ++fap) {
        if (f.has(fap)) copy.push_back(f.value(fap));
      }
    }
  });
  report("baseline: copy the sent values", baseline, values, baseline);

  using mpeg4face::FapCodingMode;
  using Options = mpeg4face::FbaEncodeOptions;
  const std::vector<Options> modes{
      Options{.mode = FapCodingMode::Predictive, .fapQuant = 1},
      Options{.mode = FapCodingMode::Predictive, .fapQuant = 1, .intraPeriod = 25},
      Options{.mode = FapCodingMode::Dct, .fapQuant = 1},
      Options{.mode = FapCodingMode::Dct, .fapQuant = 1, .intraPeriod = 25},
      Options{.mode = FapCodingMode::Pca, .fapQuant = 1},
      Options{.mode = FapCodingMode::Pca, .fapQuant = 1, .pcaTemporal = FapCodingMode::Dct}};
  for (const Options& options : modes) {
    const std::string name =
        std::string(mpeg4face::codingModeName(options.mode)) +
        (options.mode == FapCodingMode::Pca
             ? "+" + std::string(mpeg4face::codingModeName(options.pcaTemporal))
             : "");
    // Arguments, if any, name the modes to run (e.g. "dct pca+dct"), for profiling one.
    if (argc > 1 && std::find(argv + 1, argv + argc, name) == argv + argc) continue;
    mpeg4face::FbaEncoding enc;
    const double encode =
        medianSeconds(kRuns, [&] { enc = mpeg4face::encodeFba(stream, options); });
    mpeg4face::FapStream decoded;
    const double decode = medianSeconds(kRuns, [&] { decoded = mpeg4face::decodeFba(enc.bytes); });
    if (decoded != enc.reconstruction) {
      std::printf("decoder output differs from the encoder's reconstruction\n");
      return 1;
    }
    std::printf(
        "\n%s, fap_quant %d, intra period %d: %llu bits, %.3f bits/value, %d intra planes\n",
        name.c_str(), options.fapQuant, options.intraPeriod,
        static_cast<unsigned long long>(enc.stats.bits),
        static_cast<double>(enc.stats.bits) / static_cast<double>(values), enc.stats.intraFrames);
    report("encodeFba", encode, values, baseline);
    report("decodeFba", decode, values, baseline);
  }
}
