// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face encode`: a .fap stream to an FBA bitstream, with what it costs and how close the
// decoder will get.
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "arguments.hpp"
#include "commands.hpp"
#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/codec/measure.hpp"
#include "mpeg4face/codec/rd.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fit/learn.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/spec.hpp"
#include "quality.hpp"

namespace mpeg4face::cli {
namespace {

struct EncodeArgs {
  std::string input;
  std::string output;
  FbaEncodeOptions options;
  // --mode auto: the fewest-bit mode and fap_quant that reaches psnrTarget by `quality`
  // (codec/rd.hpp).
  bool autoMode = false;
  std::optional<double> psnrTarget;
  FapQuality quality = FapQuality::Robust;
  bool fapQuantGiven = false;
  bool pcaTemporalGiven = false;
  bool json = false;
  std::string fit;  // a FAP Interpolation Table: leave out the FAPs it derives
};

EncodeArgs parseArgs(const std::vector<std::string>& args) {
  EncodeArgs out;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-o") {
      out.output = optionValue(args, i, "an output file");
    } else if (a == "--mode") {
      const std::optional<FapCodingMode> mode = parseCodingMode(optionValue(args, i, "a mode"));
      out.autoMode = args[i] == "auto";
      if (!mode && !out.autoMode) {
        throw UsageError("unknown mode '" + args[i] + "' (modes: predictive, dct, pca, auto)");
      }
      if (mode) out.options.mode = *mode;
    } else if (a == "--psnr") {
      const std::string& text = optionValue(args, i, "a target in dB");
      out.psnrTarget = parseNumber(text);
      if (!out.psnrTarget) throw UsageError("--psnr takes a number of dB, not '" + text + "'");
    } else if (a == "--quality") {
      out.quality = qualityArgument(args, i);
    } else if (a == "--fap-quant") {
      out.options.fapQuant = intArgument(args, i, 0, 31);
      out.fapQuantGiven = true;
    } else if (a == "--pca-temporal") {
      const std::optional<FapCodingMode> mode = parseCodingMode(optionValue(args, i, "a mode"));
      if (!mode || *mode == FapCodingMode::Pca) {
        throw UsageError("--pca-temporal takes predictive or dct, not '" + args[i] + "'");
      }
      out.options.pcaTemporal = *mode;
      out.pcaTemporalGiven = true;
    } else if (a == "--pca-basis-bits") {
      out.options.pcaBasisBits = intArgument(args, i, 1, 15);
    } else if (a == "--intra-period") {
      out.options.intraPeriod = intArgument(args, i, 0, 1 << 30);
    } else if (a == "--rdo-lambda") {
      out.options.rdoLambda = numberArgument(args, i, "a lambda", 0.0);
    } else if (a == "--rdo-trellis") {
      out.options.rdoTrellis = true;
    } else if (a == "--mask-zero-faps") {
      out.options.maskZeroFaps = true;
    } else if (a == "--vos") {
      out.options.visualObjectSequence = true;
    } else if (a == "--json") {
      out.json = true;
    } else if (a == "--fit") {
      out.fit = optionValue(args, i, "a FAP Interpolation Table (.json)");
    } else if (a.starts_with("-")) {
      throw UsageError("unknown option '" + a + "'");
    } else if (out.input.empty()) {
      out.input = a;
    } else {
      throw UsageError("more than one input given ('" + out.input + "' and '" + a + "')");
    }
  }
  if (out.input.empty()) throw UsageError("no input .fap file given");
  if (out.output.empty()) throw UsageError("no output given (-o OUT.fba)");
  if (out.autoMode != out.psnrTarget.has_value()) {
    throw UsageError("--mode auto and --psnr DB go together");
  }
  if (out.autoMode && out.fapQuantGiven) {
    throw UsageError("--mode auto chooses fap_quant itself; drop --fap-quant");
  }
  if (out.pcaTemporalGiven && out.options.mode != FapCodingMode::Pca) {
    throw UsageError("--pca-temporal goes with --mode pca (auto chooses it itself)");
  }
  return out;
}

std::string decibels(const std::optional<double>& db) {
  if (!db) return "undefined (no FAP varies)";
  if (std::isinf(*db)) return "inf dB";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2f dB", *db);
  return buffer;
}

}  // namespace

int runEncode(const std::vector<std::string>& rawArgs) {
  EncodeArgs args = parseArgs(rawArgs);
  const FapStream input = readFapFile(args.input);
  std::optional<FitTable> table;
  FapStream sent = input;
  int leftOut = 0;
  if (!args.fit.empty()) {
    table = readFitTableFile(args.fit);
    sent = withoutDerivedFaps(*table, input);
    for (std::size_t f = 0; f < input.frames.size(); ++f) {
      leftOut += static_cast<int>(input.frames[f].mask.count() - sent.frames[f].mask.count());
    }
  }
  FbaEncoding enc;
  try {
    if (args.autoMode) {
      const std::optional<RdPoint> best =
          cheapestEncoding(sent, *args.psnrTarget, allCodingModes(), args.options, args.quality);
      if (!best) {
        throw Error({}, 0, "PSNR target",
                    "no mode and fap_quant reaches " + decibels(args.psnrTarget) + " of " +
                        qualityLabel(args.quality));
      }
      args.options.mode = best->mode;
      args.options.pcaTemporal = best->pcaTemporal;
      args.options.fapQuant = best->fapQuant;
    }
    enc = encodeFba(sent, args.options);
  } catch (const Error& e) {
    throw Error(args.input, 0, e.field(), e.reason());
  }
  // The decoder's view: with a table, what it interpolates counts against the original.
  FapStream decoded = comparableReconstruction(input, enc.reconstruction);
  if (table) interpolateFitStream(*table, decoded);
  writeFileAtomically(args.output, std::string(enc.bytes.begin(), enc.bytes.end()));

  const FapComparison quality = compareFapStreams(input, decoded);
  bool lossless = quality.visemeMismatches == 0 && quality.expressionMismatches == 0;
  for (const FapError& e : quality.faps) lossless &= e.maxAbs == 0;
  const FapError* worst = nullptr;  // the FAP with the largest error
  for (const FapError& e : quality.faps) {
    if (!worst || e.maxAbs > worst->maxAbs) worst = &e;
  }
  const auto bits = static_cast<double>(enc.stats.bits);
  const double rate = input.frames.empty() ? 0.0 : bitsPerSecond(bits, input);

  if (args.json) {
    nlohmann::ordered_json j;
    j["input"] = args.input;
    j["output"] = args.output;
    j["mode"] = codingModeName(args.options.mode);
    if (args.options.mode == FapCodingMode::Pca) {
      j["pca_temporal"] = codingModeName(args.options.pcaTemporal);
    }
    if (args.autoMode) {
      j["psnr_target_db"] = *args.psnrTarget;
      j["quality"] = fapQualityName(args.quality);
    }
    j["fap_quant"] = args.options.fapQuant;
    j["intra_period"] = args.options.intraPeriod;
    j["rdo_lambda"] = args.options.rdoLambda;
    j["rdo_trellis"] = args.options.rdoTrellis;
    j["mask_zero_faps"] = args.options.maskZeroFaps;
    if (table) {
      j["fit"] = args.fit;
      j["fit_values_left_out"] = leftOut;
    }
    j["frames"] = input.frames.size();
    j["frame_rate"] = input.frameRate;
    j["bits"] = enc.stats.bits;
    j["bits_per_second"] = rate;
    j["intra_frames"] = enc.stats.intraFrames;
    j["clipped_values"] = enc.stats.clippedValues;
    j["largest_error"] = worst ? worst->maxAbs : 0;
    j["lossless"] = lossless;
    for (const auto& [key, db] :
         {std::pair{"psnr_db", quality.psnr}, std::pair{"robust_psnr_db", quality.robustPsnr}}) {
      if (!db) {
        j[key] = nullptr;
      } else if (std::isinf(*db)) {
        j[key] = "inf";
      } else {
        j[key] = *db;
      }
    }
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  std::printf("%s: %zu frames at %g Hz\n", args.input.c_str(), input.frames.size(),
              input.frameRate);
  std::string mode(codingModeName(args.options.mode));
  if (args.options.mode == FapCodingMode::Pca) {
    mode += " (components coded " + std::string(codingModeName(args.options.pcaTemporal)) + ")";
  }
  std::printf("%s: %s, fap_quant %d, intra frames: %d\n", args.output.c_str(), mode.c_str(),
              args.options.fapQuant, enc.stats.intraFrames);
  if (table) {
    std::printf("%s: %d values left out, the decoder derives them\n", args.fit.c_str(), leftOut);
  }
  if (args.autoMode) {
    std::printf("auto: the fewest bits of every mode and fap_quant reaching %s of %s\n",
                decibels(args.psnrTarget).c_str(), qualityLabel(args.quality).c_str());
  }
  std::printf("bits %llu (%zu bytes), %.1f bits/s\n",
              static_cast<unsigned long long>(enc.stats.bits), enc.bytes.size(), rate);
  std::printf("PSNR %s over %d FAPs (Tao et al. 1999, eq. 8)%s\n", decibels(quality.psnr).c_str(),
              quality.psnrFaps, lossless ? "; lossless" : "");
  std::printf("robust PSNR %s (10 log10(1 / mean MSE_i/R_i^2), the worst FAPs count)\n",
              decibels(quality.robustPsnr).c_str());
  if (enc.stats.clippedValues > 0) {
    // Eq. (8) can still say inf here (one FAP exact): the clipping is what the user must see.
    std::printf("clipped: %d values, largest error %lld FAP units (FAP %d %s)\n",
                enc.stats.clippedValues, worst->maxAbs, worst->fap,
                std::string(fapInfo(worst->fap).name).c_str());
    std::fprintf(stderr,
                 "warning: %d values lay outside the codable range and were sent clipped "
                 "(the prediction catches up on later frames)%s\n",
                 enc.stats.clippedValues,
                 args.options.fapQuant == 0 ? "; fap_quant 0 codes |value| <= 1860 only" : "");
  }
  return 0;
}

}  // namespace mpeg4face::cli
