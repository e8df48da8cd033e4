// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face rd`: the rate-distortion curve of a .fap stream, every coding mode swept over its
// fap_quant range, as CSV and optionally a plot (scripts/rd_plot.py, matplotlib).
#include "mpeg4face/codec/rd.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "arguments.hpp"
#include "commands.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/files.hpp"
#include "quality.hpp"

namespace mpeg4face::cli {
namespace {

struct RdArgs {
  std::string input;
  std::string csv;
  std::string plot;
  FapQuality quality = FapQuality::Robust;
};

RdArgs parseArgs(const std::vector<std::string>& args) {
  RdArgs out;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--csv" || a == "--plot") {
      (a == "--csv" ? out.csv : out.plot) = optionValue(args, i, "a file name");
    } else if (a == "--quality") {
      out.quality = qualityArgument(args, i);
    } else if (a.starts_with("-")) {
      throw UsageError("unknown option '" + a + "'");
    } else if (out.input.empty()) {
      out.input = a;
    } else {
      throw UsageError("more than one input given ('" + out.input + "' and '" + a + "')");
    }
  }
  if (out.input.empty()) throw UsageError("no input .fap file given");
  if (out.csv.empty()) throw UsageError("no output given (--csv OUT.csv)");
  return out;
}

// PSNR as the CSV carries it: "inf" for +inf (a FAP reproduced exactly), empty when undefined.
std::string psnrField(const std::optional<double>& db) {
  if (!db) return "";
  if (std::isinf(*db)) return "inf";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4f", *db);
  return buffer;
}

std::string csvText(const std::vector<RdPoint>& points) {
  std::string text = "mode,fap_quant,bits,bits_per_sample,bits_per_second,psnr_db,robust_psnr_db\n";
  for (const RdPoint& p : points) {
    char buffer[128];
    std::snprintf(buffer, sizeof buffer, "%s,%d,%llu,%.6f,%.3f,", rdModeName(p).c_str(), p.fapQuant,
                  static_cast<unsigned long long>(p.bits), p.bitsPerSample, p.bitsPerSecond);
    text += buffer + psnrField(p.psnr) + "," + psnrField(p.robustPsnr) + "\n";
  }
  return text;
}

// For each mode, the fewest bits per FAP sample that reach 20, 25, 30 and 35 dB by `quality`.
void printCheapest(const std::vector<RdPoint>& points, FapQuality quality) {
  constexpr std::array kTargets{20.0, 25.0, 30.0, 35.0};
  std::printf("bits per FAP sample of the cheapest encoding reaching the %s:\n%-16s",
              qualityLabel(quality).c_str(), "mode");
  for (const double t : kTargets) std::printf("  %5.0f dB", t);
  std::printf("\n");
  std::vector<std::string> names;
  for (const RdPoint& p : points) {
    if (std::find(names.begin(), names.end(), rdModeName(p)) == names.end()) {
      names.push_back(rdModeName(p));
    }
  }
  for (const std::string& name : names) {
    std::vector<RdPoint> ofMode;
    for (const RdPoint& p : points) {
      if (rdModeName(p) == name) ofMode.push_back(p);
    }
    std::printf("%-16s", name.c_str());
    for (const double t : kTargets) {
      const std::optional<RdPoint> best = cheapestMeeting(ofMode, t, quality);
      if (best) {
        std::printf("  %8.3f", best->bitsPerSample);
      } else {
        std::printf("  %8s", "-");
      }
    }
    std::printf("\n");
  }
}

// Runs /usr/bin/python3 rd_plot.py CSV PNG TITLE COLUMN (no shell, so names need no quoting). The
// script is found through MPEG4FACE_RD_PLOT, else in the source tree's scripts/.
void plot(const std::string& csv, const std::string& png, const std::string& title,
          const std::string& column) {
  const char* env = std::getenv("MPEG4FACE_RD_PLOT");
  const std::string script = env ? env : MPEG4FACE_SCRIPTS_DIR "/rd_plot.py";
  std::fflush(stdout);
  const pid_t pid = fork();
  if (pid < 0) throw Error(png, 0, "plot", "cannot start /usr/bin/python3");
  if (pid == 0) {
    const char* argv[] = {"/usr/bin/python3", script.c_str(), csv.c_str(), png.c_str(),
                          title.c_str(),      column.c_str(), nullptr};
    execv(argv[0], const_cast<char* const*>(argv));
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  if (code == 0) return;
  if (code == 3) {
    throw Error(png, 0, "plot",
                "matplotlib is missing: install python3-matplotlib (scripts/setup.sh); the CSV "
                "was written");
  }
  if (code == 127) throw Error(png, 0, "plot", "cannot run /usr/bin/python3 " + script);
  throw Error(png, 0, "plot", script + " failed (exit status " + std::to_string(code) + ")");
}

}  // namespace

int runRd(const std::vector<std::string>& rawArgs) {
  const RdArgs args = parseArgs(rawArgs);
  const FapStream input = readFapFile(args.input);
  std::vector<RdPoint> points;
  try {
    points = sweepRateDistortion(input, allCodingModes());
  } catch (const Error& e) {
    throw Error(args.input, 0, e.field(), e.reason());
  }
  writeFileAtomically(args.csv, csvText(points));
  std::printf("%s: %zu frames at %g Hz, %zu FAP samples; %zu encodings written to %s\n",
              args.input.c_str(), input.frames.size(), input.frameRate, fapSampleCount(input),
              points.size(), args.csv.c_str());
  printCheapest(points, args.quality);
  if (!args.plot.empty()) {
    plot(args.csv, args.plot, std::filesystem::path(args.input).filename().string(),
         args.quality == FapQuality::Robust ? "robust_psnr_db" : "psnr_db");
    std::printf("plot written to %s\n", args.plot.c_str());
  }
  return 0;
}

}  // namespace mpeg4face::cli
