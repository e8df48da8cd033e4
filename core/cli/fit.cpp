// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face fit`: FAP Interpolation Tables made from a preset, learned from streams, or
// tried on a stream. docs/fit.md.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "commands.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fit/json.hpp"
#include "mpeg4face/fit/learn.hpp"
#include "mpeg4face/fit/presets.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/vrml.hpp"

namespace mpeg4face::cli {
namespace {

std::string presetList() {
  std::string out;
  for (std::string_view n : fitPresetNames()) out += (out.empty() ? "" : ", ") + std::string(n);
  return out;
}

// "left-right,eyebrow": the presets merged in that order.
FitTable presetsByName(const std::string& names, double fmax) {
  FitTable table;
  std::size_t start = 0;
  while (start <= names.size()) {
    const std::size_t end = std::min(names.find(',', start), names.size());
    const std::string name = names.substr(start, end - start);
    bool known = false;
    for (std::string_view n : fitPresetNames()) known |= n == name;
    if (!known) throw UsageError("unknown preset '" + name + "' (presets: " + presetList() + ")");
    table = mergedFitTables(
        table, name == "inner-outer-lip" ? innerOuterLipFitTable(fmax) : fitPreset(name));
    start = end + 1;
  }
  return table;
}

std::string decibels(const std::optional<double>& db) {
  if (!db) return "undefined";
  if (std::isinf(*db)) return "inf dB";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2f dB", *db);
  return buffer;
}

int runPreset(const std::vector<std::string>& args) {
  std::string name, output;
  double fmax = kDefaultLipFmax;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "-o") {
      output = optionValue(args, i, "an output file");
    } else if (args[i] == "--fmax") {
      fmax = numberArgument(args, i, "the upper lip's Fmax in FAPU", 1);
    } else if (args[i].starts_with("-")) {
      throw UsageError("unknown option '" + args[i] + "'");
    } else if (name.empty()) {
      name = args[i];
    } else {
      throw UsageError("more than one preset given ('" + name + "' and '" + args[i] + "')");
    }
  }
  if (name.empty()) throw UsageError("no preset named (presets: " + presetList() + ")");
  if (output.empty()) throw UsageError("no output given (-o TABLE.json)");
  const FitTable table = presetsByName(name, fmax);
  writeFitJson(table, output);
  std::printf("%s: %zu nodes, %zu links -> %s\n", name.c_str(), table.nodes.size(),
              table.links.size(), output.c_str());
  return 0;
}

int runLearn(const std::vector<std::string>& args) {
  std::vector<std::string> inputs;
  std::string output, graph = "left-right,inner-outer-lip,eyebrow", start;
  int degree = 1;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "-o") {
      output = optionValue(args, i, "an output file");
    } else if (args[i] == "--graph") {
      graph = optionValue(args, i, "preset names, comma-separated");
    } else if (args[i] == "--table") {
      start = optionValue(args, i, "a table to fit (.json)");
    } else if (args[i] == "--degree") {
      degree = intArgument(args, i, 1, 15);
    } else if (args[i].starts_with("-")) {
      throw UsageError("unknown option '" + args[i] + "'");
    } else {
      inputs.push_back(args[i]);
    }
  }
  if (inputs.empty()) throw UsageError("no .fap stream given to learn from");
  if (output.empty()) throw UsageError("no output given (-o TABLE.json)");
  FitTable table = start.empty() ? presetsByName(graph, kDefaultLipFmax) : readFitJson(start);
  std::vector<FapStream> streams;
  for (const std::string& in : inputs) streams.push_back(readFapFile(in));
  const std::vector<FitFunctionFit> report = learnFitTable(table, streams, degree);
  int fitted = 0, skipped = 0;
  double worst = 0;
  for (const FitFunctionFit& f : report) {
    if (f.fitted) {
      ++fitted;
      worst = std::max(worst, f.rms);
    } else {
      ++skipped;
      if (f.samples > 0 || !f.note.starts_with("too few")) {
        std::fprintf(stderr, "link %d FAP %d kept as it was: %s\n", f.link, f.fap, f.note.c_str());
      }
    }
  }
  writeFitJson(table, output);
  std::printf(
      "%zu streams: %d functions fitted (degree %d, largest residual %.2f FAPU RMS), %d kept "
      "(no frames send both sides of their link) -> %s\n",
      streams.size(), fitted, degree, worst, skipped, output.c_str());
  return 0;
}

int runTry(const std::vector<std::string>& args) {
  std::vector<std::string> inputs;
  FbaEncodeOptions options;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--fap-quant") {
      options.fapQuant = intArgument(args, i, 0, 31);
    } else if (args[i].starts_with("-")) {
      throw UsageError("unknown option '" + args[i] + "'");
    } else {
      inputs.push_back(args[i]);
    }
  }
  if (inputs.size() != 2) throw UsageError("give a table and a .fap stream");
  const FitTable table = readFitTableFile(inputs[0]);
  const FapStream stream = readFapFile(inputs[1]);
  FitTrial t;
  try {
    t = tryFitTable(table, stream, options);
  } catch (const Error& e) {
    throw Error(inputs[1], 0, e.field(), e.reason());
  }
  std::printf("%s: %zu frames; %d FAPs derived by the table, %d values interpolated\n",
              inputs[1].c_str(), stream.frames.size(), t.derivedFaps, t.interpolated);
  std::printf(
      "bits: %llu coded whole, %llu without the derived FAPs (%.1f%% saved)\n",
      static_cast<unsigned long long>(t.bitsAll), static_cast<unsigned long long>(t.bitsSent),
      t.bitsAll ? 100.0 * (1.0 - static_cast<double>(t.bitsSent) / static_cast<double>(t.bitsAll))
                : 0.0);
  std::printf("PSNR of the derived FAPs %s, of all FAPs %s (Tao et al. 1999, eq. 8)\n",
              decibels(t.derived.psnr).c_str(), decibels(t.all.psnr).c_str());
  for (const FapError& e : t.derived.faps) {
    std::printf("  FAP %2d %-22s RMS %8.2f  max %6lld  range %6lld\n", e.fap,
                std::string(fapInfo(e.fap).name).c_str(), e.rms, e.maxAbs, e.range);
  }
  return 0;
}

}  // namespace

FitTable readFitTableFile(const std::string& path) {
  if (!std::filesystem::path(path).extension().string().ends_with(".wrl")) return readFitJson(path);
  MpegFace face = readVrml(path);
  if (!face.fit) throw Error(path, 0, "Face.fit", "the face has no FIT node");
  return std::move(*face.fit);
}

int runFit(const std::vector<std::string>& args) {
  if (args.empty()) throw UsageError("no fit command given (preset, learn, try)");
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (args[0] == "preset") return runPreset(rest);
  if (args[0] == "learn") return runLearn(rest);
  if (args[0] == "try") return runTry(rest);
  throw UsageError("unknown fit command '" + args[0] + "' (preset, learn, try)");
}

}  // namespace mpeg4face::cli
