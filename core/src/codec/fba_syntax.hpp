// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: the parts of the FBA syntax every FAP coding mode shares (plane header, the common
// start of an intra plane's data, the quantiser), so that a mode (codec/fba_predictive.cpp, DCT
// next) only writes and reads its own plane data. codec/fba_codec.cpp dispatches on coding_type.
#pragma once

#include <bitset>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "codec/bit_io.hpp"
#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face::fba {

// ISO/IEC 14496-2 start codes and values around fba_object (docs/bitstream.md, "Object
// level").
inline constexpr uint32_t kVisualObjectSequenceStartCode = 0x000001B0;
inline constexpr uint32_t kUserDataStartCode = 0x000001B2;
inline constexpr uint32_t kVisualObjectStartCode = 0x000001B5;
inline constexpr uint32_t kFbaVisualObjectType = 4;           // visual_object_type "FBA ID"
inline constexpr uint32_t kSimpleFaceAnimationLevel1 = 0x61;  // profile_and_level_indication
// The PCA mode's object start code, a start code 14496-2 reserves, so that a standard decoder
// refuses a PCA stream instead of decoding its components as FAPs (docs/pca-mode.md).
inline constexpr uint32_t kPcaObjectStartCode = 0x000001B9;

inline constexpr int kCodingTypePredictive = 0;
inline constexpr int kCodingTypeDct = 1;
// fba_paramset_mask: bit 0 FAPs, bit 1 BAPs (body animation, not supported).
inline constexpr uint32_t kParamsetFap = 1;
// In the error of a plane header whose fba_paramset_mask reads 2 or 3 (and only there), so
// that decodeFba tells "body animation or damage" apart from plain damage.
inline constexpr std::string_view kBodyAnimationNotSupported = "body animation is not supported";
inline constexpr int kGroupCount = 10;

// frame_rate(8), seconds(4), frequency_offset(1): (frame_rate + seconds / 16) frames per
// second, times 1000 / 1001 with the offset.
struct FrameRateCode {
  uint32_t frameRate = 25;
  uint32_t seconds = 0;
  bool frequencyOffset = false;
};
// The closest code; throws Error if framesPerSecond is not in (0, 255.9375].
FrameRateCode frameRateCode(double framesPerSecond);
double framesPerSecond(const FrameRateCode& code);

struct TimeCode {
  uint32_t hours = 0;
  uint32_t minutes = 0;
  uint32_t seconds = 0;
};

struct PlaneHeader {
  bool isIntra = false;
  std::optional<FrameRateCode> frameRate;  // intra planes only
  std::optional<TimeCode> timeCode;        // intra planes only; read, not used for numbering
  int framesToSkip = 0;                    // frames not sent between this plane and the next
};
// fba_object_plane_header() without the optional start code (the caller writes that).
void writePlaneHeader(BitWriter& out, const PlaneHeader& header);
// Throws Error if the paramset is not FAPs only (naming body animation only when it reads 2
// or 3) or framesToSkip exceeds maxSkip.
PlaneHeader readPlaneHeader(BitReader& in, int maxSkip);

// The start of every intra plane's FAP data: fap_quant, the group masks, suggested_gender,
// coding_type.
struct IntraSettings {
  int fapQuant = 1;
  std::bitset<kFapCount> mask;
  bool suggestedGender = false;
  int codingType = kCodingTypePredictive;
};
void writeIntraSettings(BitWriter& out, const IntraSettings& settings);
IntraSettings readIntraSettings(BitReader& in);

// The reference quantiser: level 0 if |x| <= step/2, else (|x| + step/2) / step with the sign
// of x; step 0 means no quantisation.
inline int64_t quantise(int64_t x, int64_t step) {
  if (step == 0) return x;
  const uint64_t a = static_cast<uint64_t>(x < 0 ? -x : x);
  const auto half = static_cast<uint64_t>(step / 2);
  // Values are bounded (kMaxFbaValue), so a 32-bit division does; it is the faster one.
  const uint64_t level = a <= half ? 0
                         : a < (uint64_t{1} << 31)
                             ? static_cast<uint32_t>(a + half) / static_cast<uint32_t>(step)
                             : (a + half) / static_cast<uint64_t>(step);
  return x < 0 ? -static_cast<int64_t>(level) : static_cast<int64_t>(level);
}
inline int64_t dequantise(int64_t level, int64_t step) { return step == 0 ? level : level * step; }

// Frames not sent between frames[i] and the next frame (0 after the last).
int framesToSkipAfter(std::span<const FapFrame> frames, size_t i);

// What a mode's encoder fills in besides the bytes: FbaEncodeStats and the reconstruction.
struct EncodeOutput {
  BitWriter& out;
  FbaEncodeStats& stats;
  FapStream& reconstruction;
};

}  // namespace mpeg4face::fba
