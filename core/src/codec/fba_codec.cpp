// SPDX-License-Identifier: GPL-3.0-or-later
// fba_object(): the start code, planes until the end code. Each intra plane names its
// coding_type; this file checks the input, writes and reads the object level and hands every
// plane to its mode (codec/fba_predictive.cpp).
#include "mpeg4face/codec/fba_codec.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "codec/fba_dct.hpp"
#include "codec/fba_pca.hpp"
#include "codec/fba_predictive.hpp"
#include "codec/fba_syntax.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"

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
  if (!(options.rdoLambda >= 0) || !std::isfinite(options.rdoLambda)) {
    throw Error({}, 0, "rdoLambda", std::to_string(options.rdoLambda) + " is not a number >= 0");
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

// `frames` without the low-level FAPs that are 0 in every frame that sends them.
std::vector<FapFrame> withoutZeroFaps(std::span<const FapFrame> frames) {
  std::vector<FapFrame> out(frames.begin(), frames.end());
  for (int fap = 3; fap <= kFapCount; ++fap) {
    const bool zero = std::all_of(frames.begin(), frames.end(), [&](const FapFrame& f) {
      return !f.has(fap) || f.value(fap) == 0;
    });
    if (!zero) continue;
    for (FapFrame& f : out) f.mask.reset(static_cast<size_t>(fap - 1));
  }
  return out;
}

// The planes up to fba_object_end_code and the end of the data.
void decodePlanes(BitReader& in, const FbaDecodeLimits& limits, FapStream& stream,
                  FbaStreamInfo& info);

// Start codes are unique in 14496-2: a standard decoder (or the system layer before it) takes
// every byte-aligned 0x000001 for one. So a strict reader refuses the data if one lies
// anywhere but at a start code the syntax read (BitReader::startCodes).
void refuseStartCodeEmulation(const BitReader& in) {
  const std::span<const uint8_t> data = in.data();
  const std::vector<uint64_t>& codes = in.startCodes();
  for (size_t i = 0; i + 3 <= data.size(); ++i) {
    if (data[i] != 0 || data[i + 1] != 0 || data[i + 2] != 1) continue;
    if (std::binary_search(codes.begin(), codes.end(), uint64_t{i} * 8)) continue;
    in.failAt(uint64_t{i} * 8, "start code emulation",
              "0x000001 at a byte boundary, which is no start code of the syntax: a standard "
              "decoder takes it for one and ends the object there");
  }
}

// `code` here, byte-aligned as 14496-2 places start codes after headers and user data, or
// after next_start_code() stuffing as this codec writes them; consumed if so.
bool acceptStartCode(BitReader& in, uint32_t code) {
  if ((in.position() & 7) == 0 && in.bitsLeft() >= 32 && in.peekBitsOrZero(32) == code) {
    in.noteStartCode(in.position());
    in.skip(32);
    return true;
  }
  if (!in.nextIsStartCode(code)) return false;
  in.readStartCode(code, "start code");
  return true;
}

// user_data(): its start code, then bytes up to the next start code prefix 0x000001 (a
// 0x7F byte just before the prefix is next_start_code() stuffing and left for the code).
void skipUserData(BitReader& in) {
  while (acceptStartCode(in, fba::kUserDataStartCode)) {
    while (in.bitsLeft() >= 24 && in.peekBitsOrZero(24) != 1) in.skip(8);
    if (in.bitsLeft() < 24) in.fail("user_data", "the data ends inside user data");
    in.seek(in.position() - 8);
    if (in.peekBitsOrZero(8) != 0x7F) in.skip(8);
  }
}

// visual_object_sequence() and visual_object() up to fba_object (14496-2 6.2.2): the profile
// is not checked, the object must be an FBA object.
void readVisualObjectHeaders(BitReader& in) {
  in.readBits(8, "profile_and_level_indication");
  skipUserData(in);
  if (!acceptStartCode(in, fba::kVisualObjectStartCode)) {
    in.fail("visual_object_start_code", "expected 0x000001B5 after the sequence header");
  }
  if (in.readBit("is_visual_object_identifier")) {
    in.readBits(4, "visual_object_verid");
    in.readBits(3, "visual_object_priority");
  }
  const uint32_t type = in.readBits(4, "visual_object_type");
  if (type != fba::kFbaVisualObjectType) {
    in.failAt(in.position() - 4, "visual_object_type",
              "is " + std::to_string(type) + ", not an FBA object (4)");
  }
  skipUserData(in);
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
  if (options.visualObjectSequence) {
    out.writeBits(fba::kVisualObjectSequenceStartCode, 32);
    out.writeBits(fba::kSimpleFaceAnimationLevel1, 8);
    out.writeBits(fba::kVisualObjectStartCode, 32);
    out.writeBit(false);  // is_visual_object_identifier
    out.writeBits(fba::kFbaVisualObjectType, 4);
    out.writeStartCode(options.mode == FapCodingMode::Pca ? fba::kPcaObjectStartCode
                                                          : kFbaObjectStartCode);
  } else {
    out.writeBits(
        options.mode == FapCodingMode::Pca ? fba::kPcaObjectStartCode : kFbaObjectStartCode, 32);
  }
  result.reconstruction.frames.reserve(frames.size());
  result.stats.frameBits.reserve(frames.size());
  fba::EncodeOutput output{out, result.stats, result.reconstruction};
  switch (options.mode) {
    case FapCodingMode::Predictive:
      if (options.maskZeroFaps) {
        const std::vector<FapFrame> masked = withoutZeroFaps(frames);
        fba::encodePredictive(masked, options, rate, output);
      } else {
        fba::encodePredictive(frames, options, rate, output);
      }
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
  FbaStreamInfo info;
  return decodeFba(bytes, source, limits, info);
}

FapStream decodeFba(std::span<const uint8_t> bytes, std::string_view source,
                    const FbaDecodeLimits& limits, FbaStreamInfo& info) {
  info = FbaStreamInfo{};
  info.bits = uint64_t{bytes.size()} * 8;
  BitReader in(bytes, std::string(source));
  if (acceptStartCode(in, fba::kVisualObjectSequenceStartCode)) {
    info.visualObjectSequence = true;
    readVisualObjectHeaders(in);
  }
  const uint64_t objectStart = in.position();
  // The PCA mode's own start code and header (docs/pca-mode.md): the planes then carry KLT
  // components. After fba_object_start_code, user data is skipped as 14496-2 says.
  std::optional<fba::PcaHeader> pca;
  if (acceptStartCode(in, fba::kPcaObjectStartCode)) {
    in.readStartCode(fba::kPcaHeaderStartCode, "pca_header_start_code");
    pca = fba::readPcaHeader(in);
    info.pca = true;
    info.pcaBasisBits = pca->basisBits;
    for (const fba::PcaHeaderGroup& g : pca->groups) info.pcaComponents += g.components;
  } else if (acceptStartCode(in, kFbaObjectStartCode)) {
    skipUserData(in);
  } else {
    if (in.bitsLeft() < 32) in.readBits(32, "fba_object_start_code");  // says the data ends
    in.failAt(objectStart, "fba_object_start_code",
              objectStart == 0 ? "the data does not start with 0x000001BA (nor 0x000001B0)"
                               : "expected 0x000001BA after the visual object header");
  }
  FapStream stream;
  try {
    decodePlanes(in, limits, stream, info);
  } catch (const Error& e) {
    // Past the object's start, a syntax error is almost always damage (a flipped bit makes
    // the arithmetic decoders and the headers after it read nonsense); limits are not.
    if (e.reason().find("FbaDecodeLimits") != std::string::npos) throw;
    // A plane header whose fba_paramset_mask reads 2 or 3 may be a stream with body
    // animation as well as damage; every other error (a mask of 0 included) is damage.
    const bool bodyAnimation =
        e.field() == "fba_paramset_mask" &&
        e.reason().find(fba::kBodyAnimationNotSupported) != std::string::npos;
    throw Error(e.file(), 0, e.field(),
                (bodyAnimation ? "the stream carries body animation or is damaged "
                               : "the stream is damaged ") +
                    e.reason());
  }
  if (limits.strict) refuseStartCodeEmulation(in);
  if (pca) stream.frames = fba::reconstructPca(*pca, stream.frames, source);
  return stream;
}

namespace {

// 14496-2 reads fba_object as
//   do { fba_object_plane() } while (!(nextbits_bytealigned() == '000 0000 0000 0000 0000 0000'
//        && nextbits_bytealigned() != fba_object_plane_start_code))
// and the plane header begins with "if (nextbits_bytealigned() == 23 zero bits) {
// next_start_code() fba_object_plane_start_code }". Strict reading does exactly that: whatever
// bits lie before the boundary nextbits_bytealigned() looks at are taken for stuffing.
// The default reads a start code only behind exact stuffing (BitReader::nextIsStartCode).
bool objectEnds(BitReader& in, bool strict) {
  if (!strict) return in.nextIsStartCode(kFbaObjectEndCode);
  const uint64_t at = in.nextBytealigned();
  return in.startCodePrefixAt(at) && in.bitsAtOrZero(at, 32) != kFbaObjectPlaneStartCode;
}

void readEndCode(BitReader& in, bool strict) {
  if (!strict) {
    in.readStartCode(kFbaObjectEndCode, "fba_object_end_code");
    return;
  }
  const uint64_t at = in.nextBytealigned();
  const uint32_t code = in.bitsAtOrZero(at, 32);
  if (at + 32 > in.size() || code != kFbaObjectEndCode) {
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%08X", code);
    in.failAt(at, "fba_object_end_code",
              std::string("the object ends here (a start code prefix), but with ") + hex);
  }
  in.noteStartCode(at);
  in.seek(at + 32);
}

void readPlaneStartCode(BitReader& in, bool strict) {
  if (!strict) {
    if (in.nextIsStartCode(kFbaObjectPlaneStartCode)) {
      in.readStartCode(kFbaObjectPlaneStartCode, "fba_object_plane_start_code");
    }
    return;
  }
  const uint64_t at = in.nextBytealigned();
  if (!in.startCodePrefixAt(at)) return;
  // objectEnds() said the 32 bits here are fba_object_plane_start_code.
  in.noteStartCode(at);
  in.seek(at + 32);
}

void decodePlanes(BitReader& in, const FbaDecodeLimits& limits, FapStream& stream,
                  FbaStreamInfo& info) {
  std::optional<double> rate;
  std::optional<int> codingType;  // of the last intra plane
  fba::PredictiveDecoder predictive;
  fba::DctDecoder dct(limits);
  int64_t number = 0;
  for (;;) {
    // The syntax's do-while reads one plane first; this encoder writes an object without
    // planes for a stream without frames, so the end is looked for before the first too.
    if (objectEnds(in, limits.strict)) {
      readEndCode(in, limits.strict);
      break;
    }
    if (in.bitsLeft() == 0) in.fail("fba_object_end_code", "the data ends without it");
    const uint64_t planeStart = in.position();
    if (stream.frames.size() >= limits.maxFrames) {
      in.fail("fba_object_plane",
              "more than " + std::to_string(limits.maxFrames) + " frames (FbaDecodeLimits)");
    }
    readPlaneStartCode(in, limits.strict);
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
      ++(settings.codingType == fba::kCodingTypeDct ? info.dctPlanes : info.predictivePlanes);
      info.intraFrameIndices.push_back(stream.frames.size());
      const auto q = std::lower_bound(info.fapQuants.begin(), info.fapQuants.end(),
                                      settings.fapQuant);
      if (q == info.fapQuants.end() || *q != settings.fapQuant) {
        info.fapQuants.insert(q, settings.fapQuant);
      }
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
    ++info.planes;
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
}

}  // namespace

FapStream readFbaFile(const std::filesystem::path& path) {
  FbaStreamInfo info;
  return readFbaFile(path, info);
}

FapStream readFbaFile(const std::filesystem::path& path, FbaStreamInfo& info) {
  const std::string bytes = readFile(path);
  FapStream stream = decodeFba({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()},
                               path.string(), {}, info);
  stream.name = path.stem().string();
  return stream;
}

}  // namespace mpeg4face
