// SPDX-License-Identifier: GPL-3.0-or-later
// fba_object(): the start code, planes until the end code. Each intra plane names its
// coding_type; this file checks the input, writes and reads the object level and hands every
// plane to its mode (fba_predictive.cpp).
#include "mpeg4face/fba_codec.hpp"

#include <cstdio>
#include <string>

#include "fba_dct.hpp"
#include "fba_pca.hpp"
#include "fba_predictive.hpp"
#include "fba_syntax.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/file_io.hpp"

namespace mpeg4face {
namespace {

constexpr std::array<std::pair<FapCodingMode, std::string_view>, 3> kModeNames{{
    {FapCodingMode::Predictive, "predictive"},
    {FapCodingMode::Dct, "dct"},
    {FapCodingMode::Pca, "pca"},
}};

std::string hertz(double fps) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", fps);
  return text;
}

std::string frameName(const FapFrame& frame, size_t index) {
  return "frame " + std::to_string(index) + " (number " + std::to_string(frame.number) + ")";
}

void checkRange(int value, int max, const std::string& where, const char* field) {
  if (value < 0 || value > max) {
    throw Error({}, 0, field,
                where + ": " + std::to_string(value) + " is outside 0.." + std::to_string(max));
  }
}

void checkInput(const FapStream& stream, const FbaEncodeOptions& options) {
  if (options.fapQuant < 0 || options.fapQuant > 31) {
    throw Error({}, 0, "fapQuant", std::to_string(options.fapQuant) + " is outside 0..31");
  }
  if (options.intraPeriod < 0) {
    throw Error({}, 0, "intraPeriod", std::to_string(options.intraPeriod) + " is negative");
  }
  for (size_t k = 0; k < stream.frames.size(); ++k) {
    const FapFrame& f = stream.frames[k];
    const std::string where = frameName(f, k);
    if (f.number < 0) throw Error({}, 0, "number", where + ": frame numbers start at 0");
    if (k > 0 && f.number <= stream.frames[k - 1].number) {
      throw Error({}, 0, "number", where + ": frame numbers must increase");
    }
    if (f.has(1)) {
      checkRange(f.viseme.select1, 14, where, "viseme_select1");
      checkRange(f.viseme.select2, 14, where, "viseme_select2");
      checkRange(f.viseme.blend, 63, where, "viseme_blend");
    }
    if (f.has(2)) {
      checkRange(f.expression.select1, 6, where, "expression_select1");
      checkRange(f.expression.intensity1, 63, where, "expression_intensity1");
      checkRange(f.expression.select2, 6, where, "expression_select2");
      checkRange(f.expression.intensity2, 63, where, "expression_intensity2");
    }
    for (int fap = 3; fap <= kFapCount; ++fap) {
      if (f.has(fap) && (f.value(fap) < -kMaxFbaValue || f.value(fap) > kMaxFbaValue)) {
        throw Error({}, 0, "FAP " + std::to_string(fap),
                    where + ": " + std::to_string(f.value(fap)) + " is beyond +-" +
                        std::to_string(kMaxFbaValue));
      }
    }
  }
}

}  // namespace

std::string_view codingModeName(FapCodingMode mode) {
  for (const auto& [m, name] : kModeNames) {
    if (m == mode) return name;
  }
  return "unknown";
}

std::optional<FapCodingMode> parseCodingMode(std::string_view name) {
  for (const auto& [m, n] : kModeNames) {
    if (n == name) return m;
  }
  return std::nullopt;
}

FbaEncoding encodeFba(const FapStream& stream, const FbaEncodeOptions& options) {
  checkInput(stream, options);
  const fba::FrameRateCode rate = fba::frameRateCode(stream.frameRate);

  // Frame numbers count from the first plane, so a stream that starts later gets an empty
  // frame 0 whose skip reaches the first real frame.
  std::vector<FapFrame> withFrameZero;
  std::span<const FapFrame> frames = stream.frames;
  if (!frames.empty() && frames.front().number > 0) {
    withFrameZero.reserve(frames.size() + 1);
    withFrameZero.emplace_back();
    withFrameZero.insert(withFrameZero.end(), frames.begin(), frames.end());
    frames = withFrameZero;
  }

  FbaEncoding result;
  result.reconstruction.frameRate =
      frames.empty() ? FapStream{}.frameRate : fba::framesPerSecond(rate);
  BitWriter out;
  out.writeBits(kFbaObjectStartCode, 32);
  result.reconstruction.frames.reserve(frames.size());
  result.stats.frameBits.reserve(frames.size());
  fba::EncodeOutput output{out, result.stats, result.reconstruction};
  switch (options.mode) {
    case FapCodingMode::Predictive:
      fba::encodePredictive(frames, options, rate, output);
      break;
    case FapCodingMode::Dct:
      fba::encodeDct(frames, options, rate, output);
      break;
    case FapCodingMode::Pca:
      fba::encodePca(frames, options, rate, output);
      break;
  }
  out.writeStartCode(kFbaObjectEndCode);
  result.stats.bits = out.bitCount();
  result.bytes = out.take();
  return result;
}

FapStream decodeFba(std::span<const uint8_t> bytes, std::string_view source,
                    const FbaDecodeLimits& limits) {
  BitReader in(bytes, std::string(source));
  if (in.readBits(32, "fba_object_start_code") != kFbaObjectStartCode) {
    in.failAt(0, "fba_object_start_code", "the data does not start with 0x000001BA");
  }
  // The PCA mode's header (docs/pca-mode.md): the planes then carry KLT components.
  std::optional<fba::PcaHeader> pca;
  if (in.nextIsStartCode(fba::kPcaHeaderStartCode)) {
    in.readStartCode(fba::kPcaHeaderStartCode, "pca_header_start_code");
    pca = fba::readPcaHeader(in);
  }
  FapStream stream;
  std::optional<double> rate;
  std::optional<int> codingType;  // of the last intra plane
  fba::PredictiveDecoder predictive;
  fba::DctDecoder dct(limits);
  int64_t number = 0;
  for (;;) {
    if (in.nextIsStartCode(kFbaObjectEndCode)) {
      in.readStartCode(kFbaObjectEndCode, "fba_object_end_code");
      break;
    }
    if (in.bitsLeft() == 0) in.fail("fba_object_end_code", "the data ends without it");
    const uint64_t planeStart = in.position();
    if (stream.frames.size() >= limits.maxFrames) {
      in.fail("fba_object_plane",
              "more than " + std::to_string(limits.maxFrames) + " frames (FbaDecodeLimits)");
    }
    if (in.nextIsStartCode(kFbaObjectPlaneStartCode)) {
      in.readStartCode(kFbaObjectPlaneStartCode, "fba_object_plane_start_code");
    }
    const fba::PlaneHeader header = fba::readPlaneHeader(in, limits.maxFrameNumber);
    // A predictive plane is one frame; a DCT plane is a segment whose frames it appends.
    const auto newFrame = [&]() -> FapFrame& {
      FapFrame& frame = stream.frames.emplace_back();
      frame.number = static_cast<int>(number);
      return frame;
    };
    if (header.isIntra) {
      if (header.frameRate) {
        const double fps = fba::framesPerSecond(*header.frameRate);
        if (rate && *rate != fps) {
          in.failAt(planeStart, "frame_rate",
                    "changes from " + hertz(*rate) + " to " + hertz(fps) +
                        " frames per second (a FapStream has one rate)");
        }
        rate = fps;
      }
      const fba::IntraSettings settings = fba::readIntraSettings(in);
      codingType = settings.codingType;
      switch (settings.codingType) {
        case fba::kCodingTypePredictive:
          predictive.decodeIntra(in, settings, newFrame());
          break;
        case fba::kCodingTypeDct:
          dct.decodeIntra(in, settings, number, stream.frames);
          break;
      }
    } else {
      if (!codingType) {
        in.failAt(planeStart, "is_intra_frame",
                  "the first plane is an inter plane (there is nothing to predict from)");
      }
      switch (*codingType) {
        case fba::kCodingTypePredictive:
          predictive.decodeInter(in, newFrame());
          break;
        case fba::kCodingTypeDct:
          dct.decodeInter(in, number, stream.frames);
          break;
      }
    }
    number = int64_t{stream.frames.back().number} + 1 + header.framesToSkip;
    if (number > limits.maxFrameNumber) {
      in.fail("number_of_frames_to_skip",
              "frame numbers pass " + std::to_string(limits.maxFrameNumber) + " (FbaDecodeLimits)");
    }
  }
  if (in.bitsLeft() > 0) {
    in.fail("fba_object_end_code",
            std::to_string(in.bitsLeft() / 8) + " bytes follow the end of the object");
  }
  if (rate) stream.frameRate = *rate;
  if (pca) stream.frames = fba::reconstructPca(*pca, stream.frames, source);
  return stream;
}

FapStream readFbaFile(const std::filesystem::path& path) {
  const std::string bytes = readFile(path);
  FapStream stream =
      decodeFba({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, path.string());
  stream.name = path.stem().string();
  return stream;
}

}  // namespace mpeg4face
