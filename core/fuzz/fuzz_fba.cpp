// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the FBA bitstream decoder. mpeg4face::Error is the expected outcome for
// broken input; any other exception, a crash, a hang or a sanitizer report is a bug. A stream
// the decoder accepts is coded again losslessly (fap_quant 0): that must decode to the
// encoder's reconstruction, and give back the stream itself unless values had to be clipped;
// and again with RDO quantisation (issue 20), which must decode to its reconstruction too.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mpeg4face::FapStream stream;
  try {
    stream = mpeg4face::decodeFba(std::span(data, size), "fuzz.fba");
  } catch (const mpeg4face::Error&) {
    return 0;
  }
  mpeg4face::FbaEncoding again;
  try {
    again = mpeg4face::encodeFba(stream, {.fapQuant = 0});
  } catch (const mpeg4face::Error&) {
    return 0;  // a reconstruction beyond kMaxFbaValue, which the encoder refuses
  }
  if (mpeg4face::decodeFba(again.bytes) != again.reconstruction) std::abort();
  if (again.stats.clippedValues == 0 && again.reconstruction != stream) std::abort();
  const auto rdo = mpeg4face::encodeFba(stream, {.fapQuant = 2, .rdoLambda = 2e-3});
  if (mpeg4face::decodeFba(rdo.bytes) != rdo.reconstruction) std::abort();
  return 0;
}
