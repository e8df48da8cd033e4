// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the DCT coding mode of the FBA bitstream. The input is decoded as an FBA
// stream (the seeds are DCT-mode streams), and also read as a recipe for a FAP stream that is
// encoded in the DCT mode and decoded again. mpeg4face::Error is the
// expected outcome for broken input; any other exception, a crash, a hang, a sanitizer report
// or a decoder that disagrees with the encoder's reconstruction is a bug.
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

// The decoder returns the encoder's reconstruction, with the input's frame numbers, masks and
// FAP 1/2 (after the empty frame 0 the bitstream puts in front of a stream starting later).
void checkDecodes(const FapStream& stream, const FbaEncoding& encoded) {
  std::size_t offset = 0;
  const FapStream decoded = fuzz::decodeAsReconstructed(stream, encoded, offset);
  for (std::size_t t = 0; t < stream.frames.size(); ++t) {
    const FapFrame& a = stream.frames[t];
    const FapFrame& b = decoded.frames[offset + t];
    if (a.number != b.number || a.mask != b.mask || a.viseme != b.viseme ||
        a.expression != b.expression)
      std::abort();
  }
}

// Bytes to a stream the encoder must take: options, then per frame a skip, a 68-bit mask,
// FAP 1/2 fields and a step (-128..127) of each masked low-level FAP's value.
void fuzzEncoder(std::span<const uint8_t> data) {
  fuzz::Recipe r{data};
  const FbaEncodeOptions options{.mode = FapCodingMode::Dct,
                                 .fapQuant = 1 + r.next() % 31,
                                 .intraPeriod = r.next() % 64,
                                 .dcDivisor = 1 + r.next() % 15};
  FapStream stream;
  int number = r.next() % 8;
  std::array<int, kFapCount> value{};
  while (r.more() && stream.frames.size() < 48) {
    FapFrame f;
    f.number = number;
    number += 1 + (r.next() % 8 == 0 ? r.next() : 0);
    for (int i = 0; i < kFapCount; i += 8) {
      const int bits = r.next();
      for (int k = 0; k < 8 && i + k < kFapCount; ++k)
        f.mask[static_cast<std::size_t>(i + k)] = (bits >> k) & 1;
    }
    if (f.has(1)) f.viseme = {r.next() % 15, r.next() % 15, r.next() % 64, r.next() % 2 == 1};
    if (f.has(2))
      f.expression = {r.next() % 7,  r.next() % 64,     r.next() % 7,
                      r.next() % 64, r.next() % 2 == 1, r.next() % 2 == 1};
    for (int fap = 3; fap <= kFapCount; ++fap) {
      int& v = value[static_cast<std::size_t>(fap - 1)];
      if (f.has(fap))
        f.set(fap, v = std::clamp(v + static_cast<int8_t>(r.next()), -kDctMaxValue, kDctMaxValue));
    }
    stream.frames.push_back(f);
  }
  checkDecodes(stream, encodeFba(stream, options));  // an Error here is a bug too
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzzEncoder(std::span(data, size));
  FapStream stream;
  try {
    stream = decodeFba(std::span(data, size));
  } catch (const Error&) {
    return 0;
  }
  // A stream the decoder accepted re-encodes, unless its values exceed what the encoder takes.
  FbaEncoding encoded;
  try {
    encoded = encodeFba(stream, {.mode = FapCodingMode::Dct});
  } catch (const Error&) {
    return 0;
  }
  checkDecodes(stream, encoded);
  return 0;
}
