// SPDX-License-Identifier: GPL-3.0-or-later
// Bits at equal robust PSNR, predictive mode, before and after its encoder-side rate-distortion
// work (issue 20 part 2), in one process on the nine Xface streams: "before" is today's
// encoder swept over fap_quant 0..31, "after" the same with RDO quantisation over a grid of
// lambda (FbaEncodeOptions::rdoLambda). For each target, the cheapest encoding of each stream
// reaching it; the sums over the nine streams are printed as bits per FAP sample. Every
// "after" encoding chosen is decoded again and must equal the encoder's reconstruction.
// "trellis" is trellis quantisation (FbaEncodeOptions::rdoTrellis) with the FAPs that are
// always 0 left out of the mask (maskZeroFaps), swept over a finer lambda grid and fap_quant
// 0..12 (the trellis is slower; the cheapest choices lie at fap_quant <= 10, and a smaller
// search can only cost it bits); its chosen encodings are decoded again too.
// Then what masks and an intra period chosen by cost would save at 25 dB, and encode speed with
// and without RDO (medians of several runs, thread CPU time).
#include <algorithm>
#include <array>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/codec/rd.hpp"
#include "mpeg4face/io/fap_file.hpp"

namespace {

using mpeg4face::FapStream;
using mpeg4face::FbaEncodeOptions;
using mpeg4face::RdPoint;

constexpr std::array kTargets{20.0, 25.0, 30.0, 35.0};
constexpr std::array kLambdas{0.0, 2e-4, 5e-4, 1e-3, 2e-3, 5e-3, 1e-2, 2e-2};
constexpr std::array kTrellisLambdas{1e-4, 2e-4, 5e-4, 1e-3, 1.5e-3, 2e-3,   2.5e-3, 3e-3, 3.5e-3,
                                     4e-3, 5e-3, 6e-3, 7e-3, 1e-2,   1.5e-2, 2e-2,   3e-2};
constexpr int kTrellisMaxQuant = 12;

double cpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

struct Choice {
  RdPoint point;
  double lambda = 0;
};

// The cheapest of `points` (with their lambdas) reaching `target` by the robust PSNR.
std::optional<Choice> cheapest(const std::vector<Choice>& points, double target) {
  std::optional<Choice> best;
  for (const Choice& c : points) {
    if (mpeg4face::meetsPsnr(c.point, target, mpeg4face::FapQuality::Robust) &&
        (!best || c.point.bits < best->point.bits)) {
      best = c;
    }
  }
  return best;
}

// `stream` with the low-level FAPs whose value never changes left out of every frame's mask
// (what an encoder-side mask would do at no intra cost: the mask is the same in every frame).
FapStream withoutConstantFaps(const FapStream& stream) {
  FapStream out = stream;
  for (int fap = 3; fap <= mpeg4face::kFapCount; ++fap) {
    const auto& first = stream.frames.front();
    const bool constant = std::all_of(stream.frames.begin(), stream.frames.end(), [&](auto& f) {
      return f.has(fap) && first.has(fap) && f.value(fap) == first.value(fap);
    });
    if (constant) {
      for (auto& f : out.frames) f.mask.reset(static_cast<size_t>(fap - 1));
    }
  }
  return out;
}

}  // namespace

int main() {
  const std::filesystem::path dir = std::filesystem::path(MPEG4FACE_TEST_DATA) / "xface-fap";
  std::vector<FapStream> streams;
  std::vector<std::string> names;
  for (const char* name :
       {"anger", "beg", "disgust", "fear", "happy-for", "hate", "joy", "pride", "test"}) {
    streams.push_back(mpeg4face::readFapFile(dir / (std::string(name) + ".fap")));
    names.emplace_back(name);
  }
  std::array<double, kTargets.size()> before{}, after{}, trellis{};
  double samples = 0;
  bool allReached = true, decodedAlike = true;
  // What masks could save (issue 20 part 2): inter values of low-level FAPs equal to the
  // previous frame's ("still"), of FAPs constant over the whole stream, and the bits of the
  // 25 dB "after" encodings with those constant FAPs left out of the mask.
  double interValues = 0, stillValues = 0, constantValues = 0, bits25 = 0, bits25Masked = 0,
         bits25Period = 0;
  std::printf(
      "stream      target  before bits (q)   after bits (q, lambda)   trellis (q, lambda)\n");
  for (size_t s = 0; s < streams.size(); ++s) {
    const FapStream& stream = streams[s];
    samples += static_cast<double>(mpeg4face::fapSampleCount(stream));
    const FapStream masked = withoutConstantFaps(stream);
    for (size_t f = 1; f < stream.frames.size(); ++f) {
      for (int fap = 3; fap <= mpeg4face::kFapCount; ++fap) {
        if (!stream.frames[f].has(fap) || !stream.frames[f - 1].has(fap)) continue;
        interValues += 1;
        stillValues += stream.frames[f].value(fap) == stream.frames[f - 1].value(fap) ? 1 : 0;
        constantValues += masked.frames[f].has(fap) ? 0 : 1;
      }
    }
    std::vector<Choice> plain, rdo, trellisPoints;
    for (const double lambda : kTrellisLambdas) {
      for (int q = 0; q <= kTrellisMaxQuant; ++q) {
        const FbaEncodeOptions options{
            .fapQuant = q, .rdoLambda = lambda, .rdoTrellis = true, .maskZeroFaps = true};
        trellisPoints.push_back({measureEncoding(stream, options), lambda});
      }
    }
    for (const double lambda : kLambdas) {
      for (int q = 0; q <= 31; ++q) {
        const FbaEncodeOptions options{.fapQuant = q, .rdoLambda = lambda};
        const Choice c{mpeg4face::measureEncoding(stream, options), lambda};
        if (lambda == 0) plain.push_back(c);
        rdo.push_back(c);
      }
    }
    for (size_t t = 0; t < kTargets.size(); ++t) {
      const auto b = cheapest(plain, kTargets[t]);
      const auto a = cheapest(rdo, kTargets[t]);
      const auto tr = cheapest(trellisPoints, kTargets[t]);
      if (!b || !a || !tr) {
        std::printf("%-10s %4.0f dB  %s\n", names[s].c_str(), kTargets[t],
                    !b   ? "before: not reached"
                    : !a ? "after: not reached"
                         : "trellis: not reached");
        allReached = false;
        continue;
      }
      before[t] += static_cast<double>(b->point.bits);
      after[t] += static_cast<double>(a->point.bits);
      trellis[t] += static_cast<double>(tr->point.bits);
      const FbaEncodeOptions options{.fapQuant = a->point.fapQuant, .rdoLambda = a->lambda};
      const auto enc = mpeg4face::encodeFba(stream, options);
      decodedAlike &= mpeg4face::decodeFba(enc.bytes) == enc.reconstruction;
      const auto trellisEnc = mpeg4face::encodeFba(stream, {.fapQuant = tr->point.fapQuant,
                                                            .rdoLambda = tr->lambda,
                                                            .rdoTrellis = true,
                                                            .maskZeroFaps = true});
      decodedAlike &= mpeg4face::decodeFba(trellisEnc.bytes) == trellisEnc.reconstruction;
      if (t == 1) {
        bits25 += static_cast<double>(a->point.bits);
        bits25Masked += static_cast<double>(mpeg4face::measureEncoding(masked, options).bits);
        // Intra period chosen by cost: the cheapest period still reaching 25 dB.
        uint64_t best = a->point.bits;
        for (const int period : {8, 16, 32, 64}) {
          FbaEncodeOptions o = options;
          o.intraPeriod = period;
          const RdPoint p = mpeg4face::measureEncoding(stream, o);
          if (mpeg4face::meetsPsnr(p, 25.0, mpeg4face::FapQuality::Robust)) {
            best = std::min(best, p.bits);
          }
        }
        bits25Period += static_cast<double>(best);
      }
      std::printf("%-10s %4.0f dB  %7llu (q%2d)     %7llu (q%2d, %-6g)    %7llu (q%2d, %g)\n",
                  names[s].c_str(), kTargets[t], static_cast<unsigned long long>(b->point.bits),
                  b->point.fapQuant, static_cast<unsigned long long>(a->point.bits),
                  a->point.fapQuant, a->lambda, static_cast<unsigned long long>(tr->point.bits),
                  tr->point.fapQuant, tr->lambda);
    }
  }
  std::printf(
      "\nnine Xface streams, %.0f FAP samples; bits per FAP sample of the cheapest\n"
      "predictive encoding reaching the robust PSNR:\n",
      samples);
  std::printf("target   before   after   saving   trellis  saving\n");
  for (size_t t = 0; t < kTargets.size(); ++t) {
    std::printf("%4.0f dB  %6.3f  %6.3f  %5.1f %%  %6.3f   %5.1f %%\n", kTargets[t],
                before[t] / samples, after[t] / samples, 100.0 * (1.0 - after[t] / before[t]),
                trellis[t] / samples, 100.0 * (1.0 - trellis[t] / before[t]));
  }
  std::printf(
      "sums over the streams where all three reach the target%s; every chosen RDO encoding "
      "decodes to its reconstruction: %s\n",
      allReached ? " (all do)" : " (see above)", decodedAlike ? "yes" : "NO");

  std::printf(
      "\ninter values of low-level FAPs: %.0f, still (same as the frame before) %.1f %%, of FAPs "
      "constant over the stream %.1f %%\n25 dB after-encodings with those constant FAPs left out "
      "of the mask: %.3f -> %.3f bits/sample (%.1f %%)\n",
      interValues, 100.0 * stillValues / interValues, 100.0 * constantValues / interValues,
      bits25 / samples, bits25Masked / samples, 100.0 * (1.0 - bits25Masked / bits25));

  std::printf(
      "25 dB after-encodings with the intra period (0, 8, 16, 32, 64) chosen by cost: "
      "%.3f -> %.3f bits/sample (%.1f %%)\n",
      bits25 / samples, bits25Period / samples, 100.0 * (1.0 - bits25Period / bits25));

  // Encode speed on all nine streams, fap_quant 4, without and with RDO.
  double values = 0;
  for (const FapStream& s : streams) values += static_cast<double>(mpeg4face::fapSampleCount(s));
  for (const auto& [lambda, useTrellis] :
       {std::pair{0.0, false}, std::pair{1e-3, false}, std::pair{3e-3, true}}) {
    const int repeats = useTrellis ? 1 : 20;
    std::vector<double> seconds;
    for (int run = 0; run < 7; ++run) {
      const double start = cpuSeconds();
      for (int repeat = 0; repeat < repeats; ++repeat) {
        for (const FapStream& s : streams) {
          mpeg4face::encodeFba(s, {.fapQuant = 4, .rdoLambda = lambda, .rdoTrellis = useTrellis});
        }
      }
      seconds.push_back(cpuSeconds() - start);
    }
    std::nth_element(seconds.begin(), seconds.begin() + 3, seconds.end());
    std::printf("encode, lambda %g%s: %.2f M FAP values/s (median of 7)\n", lambda,
                useTrellis ? ", trellis" : "", repeats * values / seconds[3] / 1e6);
  }
  return decodedAlike ? 0 : 1;
}
