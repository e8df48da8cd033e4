// SPDX-License-Identifier: GPL-3.0-or-later
// The corners an independent decoder written from the standard found (issue 20, part 4), each
// shown on a stream written here element by element from the syntax tables of ISO/IEC
// 14496-2 (docs/bitstream.md), not by encodeFba: (a) FAP 4's intra range [0, 0] restores the
// default ranges; (b) visual_object_sequence and visual_object headers before fba_object;
// (c) a PCA stream has its own object start code, and user data after fba_object_start_code
// is skipped; (d) encode reports clipping; (e) a damaged stream's error says so and names
// the bit, and names body animation only where fba_paramset_mask reads 2 or 3; (f) a plane at
// fap_quant 0 keeps the blend bound of the plane before it (issue 44).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "codec/arithmetic_coder.hpp"
#include "codec/bit_io.hpp"
#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/spec.hpp"
#include "fba_strict.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::ArithmeticEncoder;
using mpeg4face::BitWriter;
using mpeg4face::test::decodeBothWays;
using mpeg4face::FapStream;

// The FAP groups of the syntax (first FAP of groups 1..10, and one past the last).
constexpr int kGroupStart[11] = {1, 3, 19, 31, 39, 43, 48, 51, 61, 65, 69};

// Default range in levels at fap_quant 1: whole units of 60, rounded up (as the reference).
int defaultLevels(int range) { return (range + 59) / 60 * 60; }

void startCode(BitWriter& out, uint32_t code) {  // next_start_code() then the code
  out.writeBit(false);
  while (out.bitCount() % 8 != 0) out.writeBit(true);
  out.writeBits(code, 32);
}

// fba_object_plane_start_code and the header of an intra FAP plane at 25 Hz, no time code, no
// skip, up to fap_quant.
void intraPlaneHeader(BitWriter& out, int fapQuant) {
  startCode(out, 0x000001BB);
  out.writeBit(true);    // is_intra_frame
  out.writeBits(1, 2);   // fba_paramset_mask: FAPs
  out.writeBit(true);    // is_frame_rate
  out.writeBits(25, 8);  // frame_rate
  out.writeBits(0, 4);   // seconds
  out.writeBit(false);   // frequency_offset
  out.writeBit(false);   // is_time_code
  out.writeBit(false);   // skip_frames
  out.writeBits(static_cast<uint32_t>(fapQuant), 5);
}

// intraPlaneHeader, then the masks of FAPs 3 and 4 (group 2, type 1: one bit per FAP),
// gender 0, coding_type 0.
void intraPlaneStart(BitWriter& out, int fapQuant) {
  intraPlaneHeader(out, fapQuant);
  for (int g = 0; g < 10; ++g) {
    out.writeBit(true);  // marker_bit
    if (g != 1) {
      out.writeBits(0, 2);  // fap_mask_type: none of the group
      continue;
    }
    out.writeBits(1, 2);  // one bit per FAP 3..18
    for (int fap = 3; fap <= 18; ++fap) out.writeBit(fap <= 4);
  }
  out.writeBit(false);  // suggested_gender
  out.writeBit(false);  // coding_type: predictive
}

// One flag's range codes: a marker bit before every 4th FAP from each group start (groups
// 2..10), a 5-bit code for FAPs 3 and 4 (the masked ones).
void rangeCodes(BitWriter& out, uint32_t fap3, uint32_t fap4) {
  for (int g = 1; g < 10; ++g) {
    for (int fap = kGroupStart[g]; fap < kGroupStart[g + 1]; ++fap) {
      if ((fap - kGroupStart[g]) % 4 == 0) out.writeBit(true);
      if (fap == 3) out.writeBits(fap3, 5);
      if (fap == 4) out.writeBits(fap4, 5);
    }
  }
}

std::vector<uint8_t> bytesOf(BitWriter& out) { return out.take(); }

int qp(int fap) { return mpeg4face::fapInfo(fap).quantStep; }

TEST(FbaConformance, A_IntraRangeZeroOfFap4RestoresTheDefaultRanges) {
  BitWriter out;
  out.writeBits(0x000001BA, 32);  // fba_object_start_code
  // Plane 0: new intra ranges FAP 3 [-60, 60] (code 1), FAP 4 [0, 0] (code 0 both ways).
  intraPlaneStart(out, 1);
  for (const bool flag : {true, true, false, false}) out.writeBit(flag);  // is_i_new_max/min
  rangeCodes(out, 1, 0);                                                  // i_new_max
  rangeCodes(out, 1, 0);                                                  // i_new_min
  {
    ArithmeticEncoder coder(out);
    coder.encodeUniform(50 + 60, 121);  // FAP 3 level 50
    coder.encodeUniform(0, 1);          // FAP 4 level 0
    coder.flush();
  }
  // Plane 1: no new ranges. FAP 4 had [0, 0], so the defaults are back: FAP 3 level 500
  // (beyond the 60 of plane 0), FAP 4 level -100.
  intraPlaneStart(out, 1);
  for (int flag = 0; flag < 4; ++flag) out.writeBit(false);
  const int r3 = defaultLevels(mpeg4face::fapInfo(3).intraRange);
  const int r4 = defaultLevels(mpeg4face::fapInfo(4).intraRange);
  ASSERT_GT(r3, 500);
  ASSERT_GT(r4, 100);
  {
    ArithmeticEncoder coder(out);
    coder.encodeUniform(500 + r3, 2 * r3 + 1);
    coder.encodeUniform(-100 + r4, 2 * r4 + 1);
    coder.flush();
  }
  startCode(out, 0x000001B1);
  const FapStream s = decodeBothWays(bytesOf(out));
  ASSERT_EQ(s.frames.size(), 2u);
  EXPECT_EQ(s.frames[0].value(3), 50 * qp(3));
  EXPECT_EQ(s.frames[0].value(4), 0);
  EXPECT_EQ(s.frames[1].value(3), 500 * qp(3));
  EXPECT_EQ(s.frames[1].value(4), -100 * qp(4));
}

// One intra plane sending FAP 3 = level 2 and FAP 4 = level -3 under the default ranges.
void plainPlane(BitWriter& out) {
  intraPlaneStart(out, 1);
  for (int flag = 0; flag < 4; ++flag) out.writeBit(false);
  const int r3 = defaultLevels(mpeg4face::fapInfo(3).intraRange);
  const int r4 = defaultLevels(mpeg4face::fapInfo(4).intraRange);
  ArithmeticEncoder coder(out);
  coder.encodeUniform(2 + r3, 2 * r3 + 1);
  coder.encodeUniform(-3 + r4, 2 * r4 + 1);
  coder.flush();
}

void userData(BitWriter& out, const std::string& text) {
  out.writeBits(0x000001B2, 32);  // user_data_start_code, byte-aligned
  for (const char c : text) out.writeBits(static_cast<uint8_t>(c), 8);
}

void expectPlainPlane(const FapStream& s) {
  ASSERT_EQ(s.frames.size(), 1u);
  EXPECT_EQ(s.frames[0].value(3), 2 * qp(3));
  EXPECT_EQ(s.frames[0].value(4), -3 * qp(4));
}

TEST(FbaConformance, B_VisualObjectSequenceAndVisualObjectHeaders) {
  const auto stream = [](uint32_t visualObjectType) {
    BitWriter out;
    out.writeBits(0x000001B0, 32);  // visual_object_sequence_start_code
    out.writeBits(0x61, 8);         // profile_and_level_indication: Simple Face Animation L1
    userData(out, "made by hand");
    out.writeBits(0x000001B5, 32);  // visual_object_start_code
    out.writeBit(true);             // is_visual_object_identifier
    out.writeBits(1, 4);            // visual_object_verid
    out.writeBits(1, 3);            // visual_object_priority
    out.writeBits(visualObjectType, 4);
    startCode(out, 0x000001B2);  // next_start_code(), then user data
    for (const char c : std::string("face")) out.writeBits(static_cast<uint8_t>(c), 8);
    out.writeBits(0x000001BA, 32);  // fba_object_start_code
    plainPlane(out);
    startCode(out, 0x000001B1);  // visual_object_sequence_end_code
    return out.take();
  };
  expectPlainPlane(decodeBothWays(stream(4)));  // 4: FBA ID
  try {
    mpeg4face::decodeFba(stream(1), "video.m4v");  // 1: video ID
    ADD_FAILURE() << "a video object decoded as FBA";
  } catch (const mpeg4face::Error& e) {
    EXPECT_EQ(e.field(), "visual_object_type");
    EXPECT_NE(std::string(e.what()).find("not an FBA object"), std::string::npos) << e.what();
  }

  // encode --vos: the same headers in front (no identifier, no user data), decoded alike.
  const FapStream joy = mpeg4face::readFapFile(mpeg4face::test::kData / "xface-fap/joy.fap");
  for (const auto mode : {mpeg4face::FapCodingMode::Predictive, mpeg4face::FapCodingMode::Pca}) {
    const auto plain = mpeg4face::encodeFba(joy, {.mode = mode, .fapQuant = 4});
    const auto vos =
        mpeg4face::encodeFba(joy, {.mode = mode, .fapQuant = 4, .visualObjectSequence = true});
    const std::vector<uint8_t> head(vos.bytes.begin(), vos.bytes.begin() + 10);
    // 0x23: is_visual_object_identifier 0, visual_object_type 0100, next_start_code() 011.
    EXPECT_EQ(head, (std::vector<uint8_t>{0, 0, 1, 0xB0, 0x61, 0, 0, 1, 0xB5, 0x23}));
    EXPECT_EQ(vos.reconstruction, plain.reconstruction);
    EXPECT_EQ(decodeBothWays(vos.bytes), vos.reconstruction);
    EXPECT_EQ(std::vector<uint8_t>(vos.bytes.begin() + 10, vos.bytes.end()), plain.bytes);
  }
}

TEST(FbaConformance, C_PcaStreamsHaveTheirOwnObjectStartCode) {
  const FapStream joy = mpeg4face::readFapFile(mpeg4face::test::kData / "xface-fap/joy.fap");
  const auto pca = mpeg4face::encodeFba(joy, {.mode = mpeg4face::FapCodingMode::Pca});
  // 0x000001B9 is reserved in 14496-2: a standard decoder, which needs 0x000001BA, refuses it.
  EXPECT_EQ(std::vector<uint8_t>(pca.bytes.begin(), pca.bytes.begin() + 4),
            (std::vector<uint8_t>{0, 0, 1, 0xB9}));
  EXPECT_EQ(decodeBothWays(pca.bytes), pca.reconstruction);

  // A standard stream with user data after fba_object_start_code is decoded, the user data
  // skipped (it used to be read as a PCA header).
  BitWriter standard;
  standard.writeBits(0x000001BA, 32);
  startCode(standard, 0x000001B2);
  for (const char c : std::string("not a PCA header")) standard.writeBits(uint8_t(c), 8);
  plainPlane(standard);
  startCode(standard, 0x000001B1);
  expectPlainPlane(decodeBothWays(standard.take()));

  // The PCA start code without the PCA header is refused.
  BitWriter bare;
  bare.writeBits(0x000001B9, 32);
  plainPlane(bare);
  startCode(bare, 0x000001B1);
  try {
    mpeg4face::decodeFba(bare.take());
    ADD_FAILURE() << "a PCA object without its header decoded";
  } catch (const mpeg4face::Error& e) {
    EXPECT_EQ(e.field(), "pca_header_start_code") << e.what();
  }
}

TEST(FbaConformance, D_EncodeReportsClippedValuesAndTheLargestError) {
  // FAP 3 at 3000 with fap_quant 0: beyond the largest intra range a 5-bit range code gives
  // (31 x 60 = 1860 levels), so the intra plane sends it clipped to 1860 and the inter plane
  // catches up (1140 lies inside the inter range the encoder sends); FAP 4 moves and is
  // exact, so eq. (8) says inf.
  const int clipped = 1;
  const int largestError = 3000 - 31 * 60;
  std::string mask(68 * 2, ' ');
  for (int i = 0; i < 68; ++i) mask[static_cast<size_t>(2 * i)] = i < 4 && i >= 2 ? '1' : '0';
  mask.pop_back();
  const std::string fap = mpeg4face::test::writeScratchFile(
      "clip.fap", "2.1 clip 25 2\n" + mask + "\n0 3000 10\n" + mask + "\n1 3000 20\n");
  const std::string fba = (mpeg4face::test::scratchDir() / "clip.fba").string();
  const auto r = mpeg4face::test::runCli("encode " + fap + " -o " + fba + " --fap-quant 0");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("PSNR inf"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("clipped: " + std::to_string(clipped) + " values, largest error " +
                       std::to_string(largestError) + " FAP units (FAP 3 open_jaw)"),
            std::string::npos)
      << r.out;
}

TEST(FbaConformance, E_ADamagedStreamSaysSoAndNamesTheBit) {
  // Two planes by hand; the second's fba_paramset_mask flipped to 3 (FAPs and BAPs).
  BitWriter out;
  out.writeBits(0x000001BA, 32);
  plainPlane(out);
  startCode(out, 0x000001BB);
  const uint64_t paramset = out.bitCount() + 1;  // after is_intra_frame
  out.writeBit(true);
  out.writeBits(3, 2);
  const std::vector<uint8_t> bytes = out.take();
  try {
    mpeg4face::decodeFba(bytes, "flipped.fba");
    ADD_FAILURE() << "decoded";
  } catch (const mpeg4face::Error& e) {
    EXPECT_EQ(e.field(), "fba_paramset_mask");
    // A mask of 3 may be body animation as well as damage: the message says both.
    EXPECT_EQ(e.reason().rfind(
                  "the stream carries body animation or is damaged at bit " +
                      std::to_string(paramset),
                  0),
              0u)
        << e.what();
    EXPECT_NE(e.reason().find("is 3 (FAPs and BAPs): body animation is not supported"),
              std::string::npos)
        << e.what();
  }

  // Every 37th bit of an encoding flipped in turn (bounded): whatever fails says "damaged"
  // and where, never only "body animation".
  const FapStream joy = mpeg4face::readFapFile(mpeg4face::test::kData / "xface-fap/joy.fap");
  const auto enc = mpeg4face::encodeFba(joy, {.fapQuant = 8});
  int failures = 0;
  for (size_t bit = 40; bit < enc.bytes.size() * 8; bit += 37) {
    std::vector<uint8_t> damaged = enc.bytes;
    damaged[bit / 8] ^= static_cast<uint8_t>(0x80 >> (bit % 8));
    try {
      mpeg4face::decodeFba(damaged);
    } catch (const mpeg4face::Error& e) {
      ++failures;
      EXPECT_TRUE(
          e.reason().rfind("the stream is damaged at bit ", 0) == 0 ||
          e.reason().rfind("the stream carries body animation or is damaged at bit ", 0) == 0)
          << e.what();
    }
  }
  EXPECT_GT(failures, 0);
}

// The 2 bits at `bit` (most significant first).
uint32_t twoBitsAt(const std::vector<uint8_t>& bytes, uint64_t bit) {
  uint32_t value = 0;
  for (uint64_t b = bit; b < bit + 2; ++b) {
    value = value << 1 | ((bytes[b / 8] >> (7 - b % 8)) & 1u);
  }
  return value;
}

// Issue 44: a damaged stream's error names body animation only when the plane header's
// fba_paramset_mask really reads 2 or 3 (a 0 there is damage, nothing else).
TEST(FbaConformance, E_DamageMentionsBodyAnimationOnlyWhenTheMaskSaysSo) {
  const FapStream joy = mpeg4face::readFapFile(mpeg4face::test::kData / "xface-fap/joy.fap");
  const auto enc = mpeg4face::encodeFba(joy);
  const uint64_t totalBits = enc.bytes.size() * 8;
  ASSERT_GT(totalBits, 3000u);
  // 300 bits spread over the stream, each flipped in turn; then both bits of the first plane's
  // fba_paramset_mask (01 after is_intra_frame, after the object and plane start codes), which
  // make 00 and 11.
  std::vector<uint64_t> flips;
  for (uint64_t i = 0; i < 300; ++i) flips.push_back(i * totalBits / 300 + i % 8);
  const std::vector<uint8_t> planeStart{0x00, 0x00, 0x01, 0xBB};
  const auto at = std::search(enc.bytes.begin(), enc.bytes.end(), planeStart.begin(),
                              planeStart.end());
  ASSERT_NE(at, enc.bytes.end());
  const auto mask = static_cast<uint64_t>(at - enc.bytes.begin() + 4) * 8 + 1;
  ASSERT_EQ(twoBitsAt(enc.bytes, mask), 1u);
  flips.push_back(mask);
  flips.push_back(mask + 1);

  int refused = 0, maskZero = 0, maskBody = 0;
  for (const uint64_t bit : flips) {
    std::vector<uint8_t> damaged = enc.bytes;
    damaged[bit / 8] ^= static_cast<uint8_t>(0x80 >> (bit % 8));
    try {
      mpeg4face::decodeFba(damaged, "joy.fba");
      continue;
    } catch (const mpeg4face::Error& e) {
      ++refused;
      const std::string& reason = e.reason();
      const bool body = reason.find("body animation") != std::string::npos ||
                        reason.find("BAP") != std::string::npos;
      if (e.field() != "fba_paramset_mask") {
        EXPECT_FALSE(body) << "flip of bit " << bit << ": " << e.what();
        continue;
      }
      // "... at bit N (byte ...": the mask's first bit.
      const std::string key = "at bit ";
      const size_t p = reason.find(key);
      ASSERT_NE(p, std::string::npos) << e.what();
      const uint64_t maskBit = std::stoull(reason.substr(p + key.size()));
      const uint32_t value = twoBitsAt(damaged, maskBit);
      if (body) {
        EXPECT_TRUE(value == 2 || value == 3) << "flip of bit " << bit << ": " << e.what();
        ++maskBody;
      } else {
        EXPECT_EQ(value, 0u) << "flip of bit " << bit << ": " << e.what();
        EXPECT_NE(reason.find("is 0"), std::string::npos) << e.what();
        ++maskZero;
      }
    }
  }
  EXPECT_GT(refused, 30);
  EXPECT_GT(maskZero, 0);
  EXPECT_GT(maskBody, 0);
  std::printf("%d of %zu flips refused; %d at a mask of 0, %d at a mask of 2 or 3\n", refused,
              flips.size(), maskZero, maskBody);
}

// An intra plane sending FAP 1 only (group 1, type 1: FAP 1's bit set, FAP 2's not): the
// selects and blend level as intra symbols (every count 1) over 0..14 and 0..blendTop, then
// viseme_def 0, then the always-present low-level segment with no FAP in it.
void visemePlane(BitWriter& out, int fapQuant, int select1, int select2, int blend,
                 int blendTop) {
  intraPlaneHeader(out, fapQuant);
  for (int g = 0; g < 10; ++g) {
    out.writeBit(true);  // marker_bit
    out.writeBits(g == 0 ? 1 : 0, 2);
    if (g == 0) {
      out.writeBit(true);   // FAP 1
      out.writeBit(false);  // FAP 2
    }
  }
  out.writeBit(false);                                // suggested_gender
  out.writeBit(false);                                // coding_type: predictive
  for (int flag = 0; flag < 4; ++flag) out.writeBit(false);  // no new ranges
  {
    ArithmeticEncoder coder(out);
    coder.encodeUniform(select1, 15);
    coder.encodeUniform(select2, 15);
    coder.encodeUniform(blend, blendTop + 1);
    coder.flush();
  }
  out.writeBit(false);  // viseme_def
  ArithmeticEncoder(out).flush();
}

// Why 8 of issue 44: a plane at fap_quant 0 after one at 5 codes its blend in 0..13, the bound
// the plane at 5 set (B = (63 + 2) / 5), as the reference decoders read it; a first plane at
// fap_quant 0 has 0..63.
TEST(FbaConformance, F_FapQuantZeroKeepsTheBlendBound) {
  BitWriter out;
  out.writeBits(0x000001BA, 32);
  visemePlane(out, 5, 3, 7, 10, 13);  // blend level 10 at fap_quant 5: 50
  visemePlane(out, 0, 4, 8, 12, 13);  // blend 12, unquantised, in 0..13
  startCode(out, 0x000001B1);
  const FapStream kept = decodeBothWays(bytesOf(out));
  ASSERT_EQ(kept.frames.size(), 2u);
  EXPECT_EQ(kept.frames[0].viseme.select1, 3);
  EXPECT_EQ(kept.frames[0].viseme.select2, 7);
  EXPECT_EQ(kept.frames[0].viseme.blend, 50);
  EXPECT_EQ(kept.frames[1].viseme.select1, 4);
  EXPECT_EQ(kept.frames[1].viseme.select2, 8);
  EXPECT_EQ(kept.frames[1].viseme.blend, 12);

  BitWriter first;
  first.writeBits(0x000001BA, 32);
  visemePlane(first, 0, 4, 8, 40, 63);
  startCode(first, 0x000001B1);
  const FapStream fresh = decodeBothWays(bytesOf(first));
  ASSERT_EQ(fresh.frames.size(), 1u);
  EXPECT_EQ(fresh.frames[0].viseme.blend, 40);
}

}  // namespace
