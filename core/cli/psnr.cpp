// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face psnr`: how far a decoded FAP stream is from its original (the robust PSNR and
// Tao et al. eq. 8).
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "commands.hpp"
#include "mpeg4face/codec/measure.hpp"
#include "mpeg4face/codec/motion_error.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/vrml.hpp"
#include "mpeg4face/spec.hpp"
#include "quality.hpp"

namespace mpeg4face::cli {
namespace {

struct PsnrArgs {
  std::string original;
  std::string decoded;
  bool json = false;
  FapQuality quality = FapQuality::Robust;  // the one printed first
  std::string face;  // a face (.wrl with tables): the motion error at its feature points
};

PsnrArgs parseArgs(const std::vector<std::string>& args) {
  PsnrArgs out;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--json") {
      out.json = true;
    } else if (a == "--quality") {
      out.quality = qualityArgument(args, i);
    } else if (a == "--face") {
      out.face = optionValue(args, i, "a face (.wrl with Face Animation Tables)");
    } else if (a.starts_with("-")) {
      throw UsageError("unknown option '" + a + "'");
    } else if (out.original.empty()) {
      out.original = a;
    } else if (out.decoded.empty()) {
      out.decoded = a;
    } else {
      throw UsageError("more than two files given ('" + a + "')");
    }
  }
  if (out.decoded.empty()) throw UsageError("needs two .fap files, ORIGINAL and DECODED");
  return out;
}

// dB as text: "inf" for an exact match, "-" where undefined.
std::string decibels(const std::optional<double>& db) {
  if (!db) return "-";
  if (std::isinf(*db)) return "inf";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2f", *db);
  return buffer;
}

nlohmann::ordered_json decibelsJson(const std::optional<double>& db) {
  if (!db) return nullptr;
  if (std::isinf(*db)) return "inf";
  return *db;
}

}  // namespace

int runPsnr(const std::vector<std::string>& rawArgs) {
  const PsnrArgs args = parseArgs(rawArgs);
  const FapStream original = readFapFile(args.original);
  // A decoded stream that starts at frame 0 where the original starts later (the bitstream's
  // empty frame 0) is compared from the original's first frame.
  const FapStream decoded = alignByFrameNumber(original, readFapFile(args.decoded));
  FapComparison c;
  try {
    c = compareFapStreams(original, decoded);
  } catch (const Error& e) {
    throw Error(args.decoded, 0, e.field(), e.reason() + " (original: " + args.original + ")");
  }

  std::optional<FeaturePointMotionError> motion;
  if (!args.face.empty()) {
    const MpegFace face = readVrml(args.face);
    try {
      motion = featurePointMotionError(face, original, decoded);
    } catch (const Error& e) {
      throw Error(args.face, 0, e.field(), e.reason());
    }
  }

  if (args.json) {
    nlohmann::ordered_json j;
    j["original"] = args.original;
    j["decoded"] = args.decoded;
    j["frames"] = c.frames;
    j["frame_rate"] = original.frameRate;
    j["psnr_db"] = decibelsJson(c.psnr);
    j["robust_psnr_db"] = decibelsJson(c.robustPsnr);
    j["quality"] = fapQualityName(args.quality);
    j["quality_db"] = decibelsJson(psnrBy(c, args.quality));
    j["psnr_faps"] = c.psnrFaps;
    j["faps"] = nlohmann::json::array();
    for (const FapError& e : c.faps) {
      nlohmann::ordered_json f;
      f["fap"] = e.fap;
      f["name"] = fapInfo(e.fap).name;
      f["frames"] = e.frames;
      f["missing"] = e.missing;
      f["range"] = e.range;
      f["max_abs_error"] = e.maxAbs;
      f["rms_error"] = e.rms;
      f["psnr_db"] = decibelsJson(e.psnr);
      j["faps"].push_back(std::move(f));
    }
    if (motion) {
      j["motion_error"] = {{"face", args.face},
                           {"points", motion->points},
                           {"rms_percent_es0", motion->rmsPercentEs0},
                           {"max_percent_es0", motion->maxPercentEs0},
                           {"worst_point", motion->worstPoint},
                           {"worst_frame", motion->worstFrame}};
    }
    j["extra_faps"] = c.extraFaps;
    j["viseme_mismatches"] = c.visemeMismatches;
    j["expression_mismatches"] = c.expressionMismatches;
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }

  std::printf("original %s: %d frames at %g Hz, %zu low-level FAPs\n", args.original.c_str(),
              c.frames, original.frameRate, c.faps.size());
  std::printf("decoded  %s\n", args.decoded.c_str());
  if (c.psnr) {
    // The chosen measure first; both always, since they answer different questions.
    const std::string robust = "robust PSNR " + decibels(c.robustPsnr) + " dB over " +
                               std::to_string(c.psnrFaps) +
                               " FAPs (10 log10(1 / mean MSE_i/R_i^2): the worst FAPs count)";
    const std::string tao = "PSNR " + decibels(c.psnr) + " dB over " + std::to_string(c.psnrFaps) +
                            " FAPs (Tao et al. 1999, eq. 8; FAPs with range 0 excluded)";
    const bool robustFirst = args.quality == FapQuality::Robust;
    std::printf("%s\n%s\n", (robustFirst ? robust : tao).c_str(),
                (robustFirst ? tao : robust).c_str());
  } else {
    std::printf(
        "PSNR undefined: no FAP the original sends varies (Tao et al. eq. 8 needs a "
        "range > 0)\n");
  }
  if (motion) {
    std::printf(
        "motion error at %d feature points of %s: RMS %.3f %% of ES0, largest %.3f %% "
        "(point %s, frame %d)\n",
        motion->points, args.face.c_str(), motion->rmsPercentEs0, motion->maxPercentEs0,
        motion->worstPoint.empty() ? "-" : motion->worstPoint.c_str(), motion->worstFrame);
  }
  std::printf("\n FAP name                    frames  range  max|err|   rms err  PSNR dB\n");
  for (const FapError& e : c.faps) {
    std::printf(
        "%4d %-24s %6d %6lld %9lld %9.3f  %7s%s\n", e.fap, std::string(fapInfo(e.fap).name).c_str(),
        e.frames, e.range, e.maxAbs, e.rms, decibels(e.psnr).c_str(),
        e.missing > 0 ? ("  (missing in decoded: " + std::to_string(e.missing) + " frames)").c_str()
                      : "");
  }
  if (!c.extraFaps.empty()) {
    std::printf("\nonly in the decoded stream:");
    for (int fap : c.extraFaps) std::printf(" %d %s", fap, std::string(fapInfo(fap).name).c_str());
    std::printf("\n");
  }
  std::printf("\nviseme (FAP 1): %d frames differ; expression (FAP 2): %d frames differ\n",
              c.visemeMismatches, c.expressionMismatches);
  return 0;
}

}  // namespace mpeg4face::cli
