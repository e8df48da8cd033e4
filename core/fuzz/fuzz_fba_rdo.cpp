// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the predictive encoder with its rate-distortion options (issue 44):
// the input is a recipe for a FAP stream, biased to FAPs that hold still or move one way now
// and then (what makes RDO choose inter ranges with a side, or both, at 0), and for the
// options (fap_quant 0..31, lambda, trellis, mask-zero-faps, intra period, visual object
// headers). The encoding must decode to the encoder's reconstruction both as this project
// reads and strictly, as 14496-2's syntax reads (FbaDecodeLimits::strict): a start code
// emulated or a plane hidden before one is a bug, as is any exception, a crash or a hang.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "fuzz_codec.hpp"
#include "mpeg4face/codec/fba_codec.hpp"

namespace {

using namespace mpeg4face;

constexpr std::array<double, 8> kLambdas{0, 2e-4, 5e-4, 1e-3, 2e-3, 5e-3, 1e-2, 2e-2};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::Recipe r{std::span(data, size)};
  FbaEncodeOptions options;
  const int flags = r.next();
  options.fapQuant = r.next() % 32;
  options.rdoLambda = kLambdas[static_cast<std::size_t>(flags & 7)];
  options.rdoTrellis = (flags & 8) != 0;
  options.maskZeroFaps = (flags & 16) != 0;
  options.visualObjectSequence = (flags & 32) != 0;
  options.intraPeriod = r.next() % 32;
  // The trellis costs most at small steps on long groups: fewer frames with it.
  const std::size_t maxFrames = options.rdoTrellis ? 12 : 40;

  FapStream stream;
  FapFrame f;
  int number = r.next() % 4;
  while (r.more() && stream.frames.size() < maxFrames) {
    f.number = number;
    number += 1 + (r.next() % 16 == 0 ? r.next() % 20 : 0);
    // A new mask now and then (an intra plane), else the last one.
    if (stream.frames.empty() || r.next() % 8 == 0) {
      f.mask.reset();
      for (int i = 2; i < kFapCount; i += 8) {
        const int bits = r.next();
        for (int k = 0; k < 8 && i + k < kFapCount; ++k)
          f.mask[static_cast<std::size_t>(i + k)] = (bits >> k) & 1;
      }
      f.mask[0] = r.next() % 4 == 0;
      f.mask[1] = r.next() % 4 == 0;
    }
    if (f.has(1)) f.viseme = {r.next() % 15, r.next() % 15, r.next() % 64, r.next() % 2 == 1};
    if (f.has(2))
      f.expression = {r.next() % 7,  r.next() % 64,     r.next() % 7,
                      r.next() % 64, r.next() % 2 == 1, r.next() % 2 == 1};
    // Most FAPs hold still; the others step by up to 127 either way, or by up to 63 the way
    // the FAP's number says (one-sided motion).
    for (int fap = 3; fap <= kFapCount; ++fap) {
      if (!f.has(fap)) continue;
      const int step = r.next();
      int v = f.value(fap);
      if (step >= 224) {
        v += static_cast<int8_t>(r.next());
      } else if (step >= 176) {
        v += (fap % 2 ? -1 : 1) * (r.next() % 64);
      }
      f.set(fap, std::clamp(v, -2000, 2000));
    }
    stream.frames.push_back(f);
  }
  const FbaEncoding encoded = encodeFba(stream, options);  // an Error here is a bug too
  std::size_t offset = 0;
  fuzz::decodeAsReconstructed(stream, encoded, offset);  // both ways, strictly too
  return 0;
}
