// SPDX-License-Identifier: GPL-3.0-or-later
#include "codec/fba_syntax.hpp"

#include <cmath>
#include <string>

#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face::fba {

FrameRateCode frameRateCode(double fps) {
  if (!(fps > 0.0 && fps <= 255.9375)) {
    throw Error({}, 0, "frameRate",
                std::to_string(fps) + " frames per second cannot be coded (0 < rate <= 255.9375)");
  }
  std::optional<FrameRateCode> best;
  double bestError = 0.0;
  for (bool offset : {false, true}) {
    const double nominal = offset ? fps * 1001.0 / 1000.0 : fps;
    auto whole = static_cast<uint32_t>(std::floor(nominal));
    auto sixteenths = static_cast<uint32_t>(std::lround((nominal - whole) * 16.0));
    if (sixteenths == 16) {
      ++whole;
      sixteenths = 0;
    }
    if (whole > 255 || (whole == 0 && sixteenths == 0)) continue;
    const FrameRateCode code{whole, sixteenths, offset};
    const double error = std::abs(framesPerSecond(code) - fps);
    if (!best || error < bestError) {
      best = code;
      bestError = error;
    }
  }
  return *best;  // the offset-free candidate always exists in the accepted range
}

double framesPerSecond(const FrameRateCode& code) {
  const double nominal = code.frameRate + code.seconds / 16.0;
  return code.frequencyOffset ? nominal * 1000.0 / 1001.0 : nominal;
}

void writePlaneHeader(BitWriter& out, const PlaneHeader& header) {
  out.writeBit(header.isIntra);
  out.writeBits(kParamsetFap, 2);
  if (header.isIntra) {
    out.writeBit(header.frameRate.has_value());
    if (header.frameRate) {
      out.writeBits(header.frameRate->frameRate, 8);
      out.writeBits(header.frameRate->seconds, 4);
      out.writeBit(header.frameRate->frequencyOffset);
    }
    out.writeBit(header.timeCode.has_value());
    if (header.timeCode) {
      out.writeBits(header.timeCode->hours, 5);
      out.writeBits(header.timeCode->minutes, 6);
      out.writeBit(true);  // marker_bit
      out.writeBits(header.timeCode->seconds, 6);
    }
  }
  out.writeBit(header.framesToSkip > 0);
  if (header.framesToSkip > 0) {
    int left = header.framesToSkip;
    for (; left >= 15; left -= 15) out.writeBits(15, 4);  // 15 means "more chunks follow"
    out.writeBits(static_cast<uint32_t>(left), 4);
  }
}

PlaneHeader readPlaneHeader(BitReader& in, int maxSkip) {
  PlaneHeader header;
  header.isIntra = in.readBit("is_intra_frame");
  const uint32_t paramset = in.readBits(2, "fba_paramset_mask");
  if (paramset == 0) {
    // No FAPs and no BAPs: no encoder writes an empty plane, so the header is not where the
    // reader stands (damage, not body animation).
    in.failAt(in.position() - 2, "fba_paramset_mask",
              "is 0 (no parameters at all) where a plane header has 1 (FAPs)");
  }
  if (paramset != kParamsetFap) {
    in.failAt(in.position() - 2, "fba_paramset_mask",
              "is " + std::to_string(paramset) +
                  (paramset == 2 ? " (BAPs only)" : " (FAPs and BAPs)") + ": " +
                  std::string(kBodyAnimationNotSupported) + ", only FAP planes (1)");
  }
  if (header.isIntra) {
    if (in.readBit("is_frame_rate")) {
      FrameRateCode code;
      code.frameRate = in.readBits(8, "frame_rate");
      code.seconds = in.readBits(4, "seconds");
      code.frequencyOffset = in.readBit("frequency_offset");
      if (code.frameRate == 0 && code.seconds == 0) {
        in.failAt(in.position() - 13, "frame_rate", "0 frames per second");
      }
      header.frameRate = code;
    }
    if (in.readBit("is_time_code")) {
      TimeCode tc;
      tc.hours = in.readBits(5, "time_code_hours");
      tc.minutes = in.readBits(6, "time_code_minutes");
      if (!in.readBit("marker_bit")) in.failAt(in.position() - 1, "marker_bit", "is 0");
      tc.seconds = in.readBits(6, "time_code_seconds");
      if (tc.minutes > 59 || tc.seconds > 59) {
        in.failAt(in.position() - 18, "time_code", "minutes or seconds above 59");
      }
      header.timeCode = tc;
    }
  }
  if (in.readBit("skip_frames")) {
    uint32_t chunk = 0;
    do {
      chunk = in.readBits(4, "number_of_frames_to_skip");
      header.framesToSkip += static_cast<int>(chunk);
      if (header.framesToSkip > maxSkip) {
        in.fail("number_of_frames_to_skip",
                "more than " + std::to_string(maxSkip) + " frames (FbaDecodeLimits)");
      }
    } while (chunk == 15);
  }
  return header;
}

void writeIntraSettings(BitWriter& out, const IntraSettings& settings) {
  out.writeBits(static_cast<uint32_t>(settings.fapQuant), 5);
  for (const FapGroupInfo& group : fapGroupTable()) {
    out.writeBit(true);  // marker_bit
    bool any = false, all = true;
    for (int fap = group.firstFap; fap <= group.lastFap; ++fap) {
      const bool on = settings.mask[static_cast<size_t>(fap - 1)];
      any |= on;
      all &= on;
    }
    // 0: none of the group, 3: all of it, 1: the FAPs flagged one by one. (2, a mask whose
    // unflagged FAPs a decoder may interpolate, is read like 1.)
    const uint32_t type = !any ? 0 : all ? 3 : 1;
    out.writeBits(type, 2);
    if (type == 1) {
      for (int fap = group.firstFap; fap <= group.lastFap; ++fap) {
        out.writeBit(settings.mask[static_cast<size_t>(fap - 1)]);
      }
    }
  }
  out.writeBit(settings.suggestedGender);
  out.writeBit(settings.codingType != kCodingTypePredictive);
}

IntraSettings readIntraSettings(BitReader& in) {
  IntraSettings settings;
  settings.fapQuant = static_cast<int>(in.readBits(5, "fap_quant"));
  for (const FapGroupInfo& group : fapGroupTable()) {
    const std::string where = " (FAP group " + std::to_string(group.number) + ")";
    if (!in.readBit("marker_bit")) in.failAt(in.position() - 1, "marker_bit", "is 0" + where);
    const uint32_t type = in.readBits(2, "fap_mask_type");
    for (int fap = group.firstFap; fap <= group.lastFap; ++fap) {
      const bool on = type == 3 || ((type == 1 || type == 2) && in.readBit("fap_mask" + where));
      settings.mask[static_cast<size_t>(fap - 1)] = on;
    }
  }
  settings.suggestedGender = in.readBit("suggested_gender");
  settings.codingType = in.readBit("coding_type") ? kCodingTypeDct : kCodingTypePredictive;
  return settings;
}

int framesToSkipAfter(std::span<const FapFrame> frames, size_t i) {
  return i + 1 < frames.size() ? frames[i + 1].number - frames[i].number - 1 : 0;
}

}  // namespace mpeg4face::fba
