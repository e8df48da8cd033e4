// SPDX-License-Identifier: GPL-3.0-or-later
// Issue 44, item 1: every stream the encoder writes reads the same to a standard decoder
// (FbaDecodeLimits::strict, 14496-2's syntax as written) as to this project's decoder. RDO's
// one-sided inter ranges made segments open with long zero runs, which a plain field before
// them turned into a byte-aligned 0x000001 (start code emulation), and still streams made
// 6-bit inter planes that nextbits_bytealigned() looked past into the next start code (a
// hidden plane). docs/bitstream.md, "Start codes the encoder never emulates".
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "codec/bit_io.hpp"
#include "codec/start_code_guard.hpp"
#include "fba_strict.hpp"
#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::FapFrame;
using mpeg4face::FapStream;
using mpeg4face::FbaEncodeOptions;

// Frames that hold still: `faps` low-level FAPs at fixed values (a face held in a pose).
FapStream stillStream(int frames, int faps, uint32_t seed) {
  std::mt19937 random(seed);
  FapStream s;
  FapFrame f;
  for (int fap = 3; fap < 3 + faps; ++fap) f.set(fap, static_cast<int>(random() % 801) - 400);
  for (int k = 0; k < frames; ++k) {
    f.number = k;
    s.frames.push_back(f);
  }
  return s;
}

// FAPs that move now and then and only one way (half of them down, half up): RDO gives such
// a FAP an inter range with one side 0, so level 0 is its model's first or last symbol.
FapStream oneSidedStream(int frames, int faps, uint32_t seed) {
  std::mt19937 random(seed);
  FapStream s;
  FapFrame f;
  for (int fap = 3; fap < 3 + faps; ++fap) f.set(fap, 0);
  for (int k = 0; k < frames; ++k) {
    f.number = k;
    for (int fap = 3; fap < 3 + faps; ++fap) {
      if (random() % 9 != 0) continue;
      const int step = 1 + static_cast<int>(random() % 60);
      f.set(fap, f.value(fap) + (fap % 2 ? -step : step));
    }
    s.frames.push_back(f);
  }
  return s;
}


// The encoding as the encoder wrote it before issue 44: without the plane start codes it now
// puts before an inter plane that a standard decoder would misread. Putting one there leaves
// the coded bits as they are, so dropping it (its stuffing too) and writing the stuffing of
// the start codes after it anew gives back the bits the old encoder wrote. `dropped` counts
// the start codes dropped.
std::vector<uint8_t> withoutInterPlaneStartCodes(const std::vector<uint8_t>& bytes,
                                                 int& dropped) {
  const auto bit = [&](uint64_t x) { return (bytes[x >> 3] >> (7 - (x & 7))) & 1; };
  mpeg4face::BitWriter out;
  const uint64_t size = uint64_t{bytes.size()} * 8;
  uint64_t copied = 32;  // the object start code, written at byte 0 without stuffing
  out.writeBits(0x000001BA, 32);
  dropped = 0;
  for (uint64_t at = 40; at + 32 <= size; at += 8) {
    const uint32_t code = (uint32_t{bytes[at / 8]} << 24) | (uint32_t{bytes[at / 8 + 1]} << 16) |
                          (uint32_t{bytes[at / 8 + 2]} << 8) | bytes[at / 8 + 3];
    if ((code >> 8) != 1) continue;
    uint64_t stuffing = at - 1;  // next_start_code(): a 0, then 1s up to the code
    while (bit(stuffing)) --stuffing;
    for (; copied < stuffing; ++copied) out.writeBit(bit(copied));
    const bool interPlane = code == 0x000001BB && at + 32 < size && !bit(at + 32);
    if (interPlane) {
      ++dropped;
    } else {
      out.writeStartCode(code);
    }
    copied = at + 32;
  }
  for (; copied < size; ++copied) out.writeBit(bit(copied));
  return out.take();
}

std::vector<std::pair<std::string, FapStream>> sweepStreams() {
  std::vector<std::pair<std::string, FapStream>> streams;
  for (const char* name : {"anger", "beg", "disgust", "fear", "happy-for", "hate", "joy",
                           "pride", "test"}) {
    streams.emplace_back(name, mpeg4face::readFapFile(mpeg4face::test::kData / "xface-fap" /
                                                      (std::string(name) + ".fap")));
  }
  for (uint32_t seed = 1; seed <= 3; ++seed) {
    streams.emplace_back("still" + std::to_string(seed),
                         stillStream(60 + 37 * static_cast<int>(seed), 2 + 9 * seed, seed));
    streams.emplace_back("one-sided" + std::to_string(seed),
                         oneSidedStream(80 + 20 * static_cast<int>(seed), 6 + 14 * seed, seed));
  }
  return streams;
}

std::string describe(const FbaEncodeOptions& o) {
  return "fap_quant " + std::to_string(o.fapQuant) + ", lambda " + std::to_string(o.rdoLambda) +
         (o.rdoTrellis ? ", trellis" : "") + (o.maskZeroFaps ? ", mask-zero-faps" : "") +
         ", intra period " + std::to_string(o.intraPeriod);
}

// Every stream under the RDO options (lambda, trellis, mask-zero-faps, intra period, fap_quant
// 0 included): 15 streams x 24 option sets, a different slice of the option grid per stream
// so that together they cover it. Each encoding decodes strictly to the reconstruction.
TEST(FbaStartCodes, SweepDecodesTheSameStrictly) {
  const double lambdas[] = {0, 5e-4, 2e-3, 5e-3, 1e-2, 2e-2};
  const int quants[] = {0, 1, 2, 5, 16};
  const int periods[] = {0, 1, 7, 25};
  int encodings = 0, failures = 0;
  uint32_t turn = 0;
  for (const auto& [name, stream] : sweepStreams()) {
    for (int k = 0; k < 24; ++k, ++turn) {
      FbaEncodeOptions o;
      o.rdoLambda = lambdas[(turn / 2) % 6];
      o.rdoTrellis = o.rdoLambda > 0 && turn % 2 == 1;
      o.fapQuant = quants[(turn / 3 + turn) % 5];
      o.intraPeriod = periods[(turn / 5 + turn / 2) % 4];
      o.maskZeroFaps = (turn / 7) % 2 == 1;
      // The trellis is slow on long groups at small steps: its encodings take 12 frames, or 8
      // at fap_quant 0 (unit steps, the widest windows).
      FapStream part = stream;
      const size_t trellisFrames = o.fapQuant == 0 ? 8 : 12;
      if (o.rdoTrellis && part.frames.size() > trellisFrames) part.frames.resize(trellisFrames);
      const auto encoding = mpeg4face::encodeFba(part, o);
      ++encodings;
      std::string difference =
          mpeg4face::test::strictDifference(encoding.bytes, encoding.reconstruction);
      if (mpeg4face::decodeFba(encoding.bytes) != encoding.reconstruction)
        difference = "the default reading differs";
      if (!difference.empty() && ++failures <= 20) {
        ADD_FAILURE() << name << ", " << describe(o) << ": " << difference;
      }
    }
  }
  EXPECT_GE(encodings, 300);
  EXPECT_EQ(failures, 0) << "of " << encodings;
}

}  // namespace


// Whether `bytes` hold a byte-aligned 0x000001 followed by a byte that is none of the start
// codes an FBA stream has (object 0xBA, plane 0xBB, end 0xB1): a start code emulated.
bool emulatesStartCode(const std::vector<uint8_t>& bytes) {
  for (size_t i = 0; i + 3 < bytes.size(); ++i) {
    if (bytes[i] == 0 && bytes[i + 1] == 0 && bytes[i + 2] == 1 && bytes[i + 3] != 0xBA &&
        bytes[i + 3] != 0xBB && bytes[i + 3] != 0xB1)
      return true;
  }
  return false;
}

// Why 1 of issue 44: at fap_quant 0 and lambda 0.005 RDO gives joy's FAPs one-sided inter
// ranges, and a plane's skip_frames 0 and a segment opening with 22 zeros and a stuffed 1 put
// 0x000001A7 at a byte boundary. The old encoder wrote it (the bits without the start codes
// the encoder now adds, which the project's own decoder read); a standard decoder ends the
// object there. The encoder now writes a plane start code before that plane, which moves
// the plane against the byte boundaries.
TEST(FbaStartCodes, Why1EmulationIsAvoided) {
  const FapStream joy = mpeg4face::readFapFile(mpeg4face::test::kData / "xface-fap/joy.fap");
  const auto encoding =
      mpeg4face::encodeFba(joy, {.fapQuant = 0, .intraPeriod = 7, .rdoLambda = 5e-3});
  EXPECT_EQ(mpeg4face::test::decodeBothWays(encoding.bytes), encoding.reconstruction);
  EXPECT_FALSE(emulatesStartCode(encoding.bytes));

  int dropped = 0;
  const std::vector<uint8_t> old = withoutInterPlaneStartCodes(encoding.bytes, dropped);
  EXPECT_GT(dropped, 0);
  EXPECT_EQ(mpeg4face::decodeFba(old), encoding.reconstruction);
  EXPECT_TRUE(emulatesStartCode(old));
  const auto error = mpeg4face::test::errorOf([&] {
    mpeg4face::decodeFba(old, {}, {.strict = true});
  });
  EXPECT_EQ(error.field(), "fba_object_end_code") << error.what();
}

// Why 2 of issue 44: a stream whose FAPs hold still has every inter range [0, 0], so an inter
// plane is 6 bits (header and a 2-bit segment); where one starts at bit 1 of a byte and the
// next intra plane's start code follows, next_start_code() is a single 0 bit and
// nextbits_bytealigned() at the plane's start already sees the start code: a standard decoder
// skips the plane. The encoder now writes a plane start code before such a plane.
TEST(FbaStartCodes, Why2HiddenPlaneIsAvoided) {
  const FapStream still = stillStream(97, 11, 1);
  const auto encoding =
      mpeg4face::encodeFba(still, {.fapQuant = 0, .intraPeriod = 7, .rdoLambda = 5e-3});
  EXPECT_EQ(mpeg4face::test::decodeBothWays(encoding.bytes), encoding.reconstruction);

  int dropped = 0;
  const std::vector<uint8_t> old = withoutInterPlaneStartCodes(encoding.bytes, dropped);
  EXPECT_GT(dropped, 0);
  EXPECT_EQ(mpeg4face::decodeFba(old), encoding.reconstruction);
  // Read strictly, the old bits lose a plane for each start code the encoder now adds.
  const FapStream strict = mpeg4face::decodeFba(old, {}, {.strict = true});
  EXPECT_EQ(strict.frames.size() + static_cast<size_t>(dropped),
            encoding.reconstruction.frames.size());
}

// Step 3 of the encoder's checks: an inter plane that a plane start code after or before it
// cannot make safe ends its group, and its frame starts the next with an intra plane. This
// stream (tests/data/start-codes/README.md) has one at an intra period of 18: five intra
// planes where the period and its one mask ask for four.
TEST(FbaStartCodes, AGroupEndsWhereNoStartCodeHelps) {
  const FapStream stream = mpeg4face::readFapFile(mpeg4face::test::kData /
                                                  "start-codes/group-ends-early.fap");
  ASSERT_EQ(stream.frames.size(), 63u);
  const auto encoding =
      mpeg4face::encodeFba(stream, {.fapQuant = 0, .intraPeriod = 18, .rdoLambda = 5e-3});
  EXPECT_EQ(encoding.stats.intraFrames, 5);
  EXPECT_EQ(mpeg4face::test::decodeBothWays(encoding.bytes), encoding.reconstruction);
}

// PlaneGuard, which both the predictive and the DCT encoder use, on planes built bit by bit:
// plane 0 (after its start code) ends in 15 zeros, plane 1 opens with 15 zeros and a 1, which
// together put 0x000001 at a byte boundary; a start code before plane 1 ends the run.
TEST(FbaStartCodes, PlaneGuardEndsARunAcrossTwoPlanes) {
  mpeg4face::BitWriter out;
  mpeg4face::PlaneGuard guard(out);
  const auto bits = [&](const std::string& text) {
    for (const char c : text) out.writeBit(c == '1');
  };
  guard.open(true);
  bits("1" + std::string(15, '0'));
  guard.close();
  guard.open(false);
  bits(std::string(15, '0') + "11111");
  guard.close();
  const auto emulations = [&] {  // byte-aligned 0x000001 that are not the planes' start codes
    int n = 0;
    const std::vector<uint8_t>& b = out.bytes();
    const uint8_t plane = mpeg4face::kFbaObjectPlaneStartCode & 0xFF;
    for (size_t i = 0; i + 3 < b.size(); ++i) {
      n += b[i] == 0 && b[i + 1] == 0 && b[i + 2] == 1 && b[i + 3] != plane;
    }
    return n;
  };
  ASSERT_EQ(emulations(), 1);
  EXPECT_TRUE(guard.secure(0, false));
  EXPECT_TRUE(guard.planes()[1].startCode);
  EXPECT_EQ(guard.takeMoved(), 1U);
  EXPECT_FALSE(guard.takeMoved().has_value());
  EXPECT_EQ(emulations(), 0);
  EXPECT_TRUE(guard.secure(1, true));  // with the end code's stuffing after it
}

// A plane that emulates a start code inside itself, behind its own start code, cannot be made
// safe by start codes: secure() says so (the encoders then write it otherwise, or refuse).
TEST(FbaStartCodes, PlaneGuardReportsAPlaneNoStartCodeSaves) {
  mpeg4face::BitWriter out;
  mpeg4face::PlaneGuard guard(out);
  guard.open(true);
  for (int i = 0; i < 23; ++i) out.writeBit(false);
  for (int i = 0; i < 9; ++i) out.writeBit(true);
  guard.close();
  EXPECT_FALSE(guard.secure(0, true));
  guard.rollBack(0);
  EXPECT_EQ(out.bitCount(), 0U);
  EXPECT_TRUE(guard.planes().empty());
}
