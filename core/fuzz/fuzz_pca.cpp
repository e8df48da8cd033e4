// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the PCA coding mode (docs/pca-mode.md). The input is decoded as an FBA
// stream (the seeds are PCA streams, so the header parser is reached), and also read as a
// recipe for a FAP stream, built from a few hidden signals mixed into the FAPs as PCA expects,
// that is encoded in the PCA mode and decoded again. mpeg4face::Error is the expected outcome
// for broken input; any other exception, a crash, a hang, a sanitizer report or a decoder that
// disagrees with the encoder's reconstruction is a bug.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "codec/dct_transform.hpp"
#include "fuzz_codec.hpp"
#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/error.hpp"

namespace {

using namespace mpeg4face;

// Options, then a mixing weight (-8..7) of each of 3 hidden signals per FAP, then per frame a
// skip, a mask byte (bit b: FAPs 8b+1..8b+8 of a rotating window), FAP 1 and the signals' steps.
void fuzzEncoder(std::span<const uint8_t> data) {
  fuzz::Recipe r{data};
  FbaEncodeOptions options{.mode = FapCodingMode::Pca, .fapQuant = 1 + r.next() % 31};
  options.intraPeriod = r.next() % 40;
  options.pcaTemporal = r.next() % 2 == 0 ? FapCodingMode::Predictive : FapCodingMode::Dct;
  options.pcaEnergy = (1 + r.next() % 100) / 100.0;
  options.pcaBasisBits = 1 + r.next() % 15;
  std::array<std::array<int, 3>, kFapCount> weight{};
  for (auto& w : weight) {
    const int b = r.next();
    w = {b % 16 - 8, (b / 16) % 16 - 8, r.next() % 16 - 8};
  }
  FapStream stream;
  int number = r.next() % 4;
  std::array<int, 3> signal{};
  while (r.more() && stream.frames.size() < 40) {
    FapFrame f;
    f.number = number;
    number += 1 + (r.next() % 8 == 0 ? r.next() % 20 : 0);
    const int maskByte = r.next();
    const int window = r.next() % kFapCount;
    for (int b = 0; b < 8; ++b) {
      if (((maskByte >> b) & 1) == 0) continue;
      for (int i = 0; i < 8; ++i)
        f.mask.set(static_cast<std::size_t>((window + 8 * b + i) % kFapCount));
    }
    if (f.has(1)) f.viseme = {r.next() % 15, r.next() % 15, r.next() % 64, false};
    f.mask.reset(1);
    for (int& s : signal) s = std::clamp(s + static_cast<int8_t>(r.next()), -20000, 20000);
    for (int fap = 3; fap <= kFapCount; ++fap) {
      if (!f.has(fap)) continue;
      const auto& w = weight[static_cast<std::size_t>(fap - 1)];
      f.set(fap, (w[0] * signal[0] + w[1] * signal[1] + w[2] * signal[2]) / 4);
    }
    stream.frames.push_back(f);
  }
  std::size_t offset = 0;
  const FapStream decoded = fuzz::decodeAsReconstructed(
      stream, encodeFba(stream, options), offset);  // an Error in encodeFba is a bug too
  for (std::size_t t = 0; t < stream.frames.size(); ++t) {
    const FapFrame& a = stream.frames[t];
    const FapFrame& b = decoded.frames[offset + t];
    // FAP 1 passes through the component coder (whose predictive mode quantises the blend).
    if (a.number != b.number || a.has(1) != b.has(1) ||
        (a.has(1) &&
         (a.viseme.select1 != b.viseme.select1 || a.viseme.select2 != b.viseme.select2)))
      std::abort();
    for (int fap = 3; fap <= kFapCount; ++fap) {
      if (a.has(fap) && !b.has(fap)) std::abort();  // every FAP sent is in every frame
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzzEncoder(std::span(data, size));
  try {
    decodeFba(std::span(data, size), "fuzz.fba");
  } catch (const Error&) {
  }
  return 0;
}
