// SPDX-License-Identifier: GPL-3.0-or-later
// The FBA bitstream of ISO/IEC 14496-2 for face animation: a FapStream in, bytes out, and back.
// The syntax as implemented, element by element, is in docs/bitstream.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face {

// How the encoder codes FAPs. Predictive is the standard's coding_type 0 (quantised values and
// frame-to-frame differences, adaptive arithmetic coding). Dct is coding_type 1: 16-frame
// segments, DCT per FAP (docs/dct-mode.md; its syntax is the project's own). Pca: the KLT of
// each FAP group, basis in a stream header, components coded by the predictive or DCT mode
// (docs/pca-mode.md, the project's own syntax).
enum class FapCodingMode { Predictive, Dct, Pca };
std::string_view codingModeName(FapCodingMode mode);  // "predictive", "dct", "pca"
std::optional<FapCodingMode> parseCodingMode(std::string_view name);

struct FbaEncodeOptions {
  FapCodingMode mode = FapCodingMode::Predictive;
  // 0..31; the quantiser step of FAP n is FapInfo::quantStep * fapQuant. 0 = no quantisation
  // (lossless within the codable range, |value| <= 1860).
  int fapQuant = 1;
  // An intra frame at least every intraPeriod frames sent (a decoder can join there); 0 =
  // intra frames only where needed: the first frame and wherever the FAP mask changes.
  int intraPeriod = 0;
  // Dct mode: fapQuant 1..31 is the AC step's factor; the DC step is the AC step / dcDivisor
  // (1..15; Tekalp-Ostermann 2.2.2 gives the ratio 1/4). intraPeriod counts frames too: a
  // segment is intra when intraPeriod frames have been sent since the last intra segment began.
  int dcDivisor = 4;
  // Pca mode: the coder of the components (Predictive or Dct; fapQuant is its factor), the
  // energy fraction the kept components of a group hold (Tao et al.: 0.98), and the fraction
  // bits of the basis carried in the header (1..15).
  FapCodingMode pcaTemporal = FapCodingMode::Predictive;
  double pcaEnergy = 0.98;
  int pcaBasisBits = 4;
  // Predictive mode (and PCA's predictive components), encoder side only: rate-distortion
  // optimised quantisation. 0 (default) codes each value at the nearest level. lambda > 0
  // lets each inter value take the nearest level, one step nearer zero, or zero, whichever
  // minimises e^2 / R^2 + lambda * bits, e the reconstruction error, R the FAP's range over
  // the stream (the robust PSNR's normalisation) and bits what the FAP's adaptive model would
  // spend on it now (docs/rate-distortion.md, "Predictive mode: RDO quantisation").
  double rdoLambda = 0.0;
  // With rdoLambda > 0: choose each FAP's levels over a whole group of planes at once (a
  // trellis: a level moves every later residual) together with its inter range, by the same
  // cost with bits the adaptive model's code length for the levels (docs/rate-distortion.md,
  // "Predictive mode: trellis quantisation"). Slower; the syntax is the same.
  bool rdoTrellis = false;
  // Predictive mode: leave out of the FAP mask the low-level FAPs that are 0 in every frame
  // that sends them. A FAP never sent is the neutral face's, 0, so a decoder shows the same
  // face; the reconstruction lacks those FAPs (they were only ever 0).
  bool maskZeroFaps = false;
  // Wrap fba_object in visual_object_sequence and visual_object headers (profile Simple Face
  // Animation level 1, visual_object_type FBA), as a 14496-2 elementary stream starts.
  bool visualObjectSequence = false;
};

struct FbaEncodeStats {
  uint64_t bits = 0;                // the whole stream, start and end codes included
  std::vector<uint64_t> frameBits;  // per frame sent (reconstruction.frames), headers included
  int intraFrames = 0;
  // Values whose quantised value or difference lies outside what the syntax can code (range
  // codes are 5 bits: at most 1860 steps of QP * fapQuant) are sent clipped; the prediction
  // loop catches up on the following frames. Counted as without RDO: a lag RDO's coarse
  // levels leave is distortion, not clipping.
  int clippedValues = 0;
};

struct FbaEncoding {
  std::vector<uint8_t> bytes;
  FbaEncodeStats stats;
  // Exactly what decodeFba(bytes) returns: the quantised values, FAP 1/2 fields clamped to
  // their ranges, and no name (the bitstream has none). A stream whose first frame number is
  // not 0 gets an empty frame 0 in front, since frame numbers count from the first plane.
  FapStream reconstruction;
};

// Throws mpeg4face::Error for a stream the syntax cannot carry (frame numbers not increasing,
// negative, FAP 1/2 fields outside their ranges, |value| > kMaxFbaValue, frame rate not in
// (0, 255.9375]) or bad options.
FbaEncoding encodeFba(const FapStream& stream, const FbaEncodeOptions& options = {});

// Largest |FAP value| the codec accepts or reconstructs.
inline constexpr int kMaxFbaValue = 1 << 24;

// Bounds a decoder enforces so that a hostile stream cannot make it allocate without limit.
struct FbaDecodeLimits {
  size_t maxFrames = size_t{1} << 20;  // about 11.6 hours at 25 frames per second
  int maxFrameNumber = 1 << 30;        // skipped frames count too
  // Read as 14496-2's syntax reads, as a standard decoder does (docs/bitstream.md, "Strict
  // decoding"): a start code before a plane and the end of the object wherever
  // nextbits_bytealigned() shows 23 zero bits, the stuffing before them not checked; and a
  // byte-aligned 0x000001 that is not a start code the syntax reads is an error (start code
  // emulation: a standard decoder would end the object there). The default instead takes a
  // start code only behind exact next_start_code() stuffing.
  bool strict = false;
};

// Accepts visual_object_sequence and visual_object headers (and user data) before fba_object.
// Throws mpeg4face::Error naming `source` (a file name, may be empty), the syntax element and
// the bit offset for any stream that does not follow the syntax, is truncated, or exceeds the
// limits; past the object's start, the message says the stream is damaged there.
FapStream decodeFba(std::span<const uint8_t> bytes, std::string_view source = {},
                    const FbaDecodeLimits& limits = {});
// A .fba file decoded (errors name the file); the stream is named after the file, since the
// bitstream carries no name.
FapStream readFbaFile(const std::filesystem::path& path);

// What a bitstream's headers say besides its frames (`mpeg4face info`), filled in by the
// decoders below as they read.
struct FbaStreamInfo {
  uint64_t bits = 0;                  // the whole stream
  bool visualObjectSequence = false;  // visual_object_sequence and visual_object headers
  bool pca = false;                   // the PCA mode's object (its components coded below)
  int pcaComponents = 0;              // components over all groups of the PCA header
  int pcaBasisBits = 0;
  int planes = 0;
  int predictivePlanes = 0;  // intra planes whose coding_type is 0 ...
  int dctPlanes = 0;         // ... and 1 (the planes after one share its type)
  // Index in FapStream::frames of each intra plane's first frame, in order (one per intra
  // plane).
  std::vector<size_t> intraFrameIndices;
  std::vector<int> fapQuants;  // the fap_quant values of the intra planes, ascending, distinct
};
FapStream decodeFba(std::span<const uint8_t> bytes, std::string_view source,
                    const FbaDecodeLimits& limits, FbaStreamInfo& info);
FapStream readFbaFile(const std::filesystem::path& path, FbaStreamInfo& info);

}  // namespace mpeg4face
