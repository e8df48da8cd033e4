// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face animate`: a head made animatable in one step. Its feature points (found from a
// template unless it has what cloning needs), the source's FAP, viseme and expression shapes
// cloned onto it, its tables, the file written, and the motion check on a stream; one line
// per step with its time.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "commands.hpp"
#include "feature_points.hpp"
#include "mpeg4face/clone/clone.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/motion_check.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "paths.hpp"
#include "steps.hpp"

namespace mpeg4face::cli {
namespace {

struct AnimateArgs : LandmarkArgs {
  std::string head, output;
  std::optional<std::string> source, stream;
};

AnimateArgs parseArgs(const std::vector<std::string>& args) {
  AnimateArgs out;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (takeLandmarkOption(args, i, out)) continue;
    if (a == "-o") {
      out.output = optionValue(args, i, "an output file (.glb, .gltf or .wrl)");
    } else if (a == "--source") {
      out.source = optionValue(args, i, "a head with FAP, viseme and expression shapes");
    } else if (a == "--stream") {
      out.stream = optionValue(args, i, "a .fap or .fba file");
    } else if (a.starts_with("-")) {
      throw UsageError("unknown option '" + a + "'");
    } else if (out.head.empty()) {
      out.head = a;
    } else {
      throw UsageError("more than one HEAD given ('" + out.head + "' and '" + a + "')");
    }
  }
  if (out.head.empty()) throw UsageError("no HEAD given");
  if (out.output.empty()) throw UsageError("no output given (-o OUT.glb or -o OUT.wrl)");
  if (!isGltf(out.output) && extensionOf(out.output) != ".wrl") {
    throw UsageError("-o takes a .glb, .gltf or .wrl file, not '" + out.output + "'");
  }
  return out;
}

// The demo's sentence, spoken by samples/build.sh.
std::string sampleSentence() {
  const std::filesystem::path hello =
      std::filesystem::path(MPEG4FACE_SAMPLES_DIR) / "build" / "streams" / "hello.fap";
  if (!std::filesystem::exists(hello)) {
    throw UsageError("no --stream given and no sample sentence: run samples/build.sh (it makes " +
                     hello.string() + ") or pass --stream");
  }
  return hello.string();
}

// Prints "name: what (1.2 s)" for a step that has just ended.
class Steps {
 public:
  template <typename... A>
  void done(const char* name, const char* format, A... args) {
    const auto now = std::chrono::steady_clock::now();
    std::printf("%-16s", (std::string(name) + ":").c_str());
    std::printf(format, args...);
    std::printf(" (%.1f s)\n", std::chrono::duration<double>(now - last_).count());
    std::fflush(stdout);
    last_ = now;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace

int runAnimate(const std::vector<std::string>& args) {
  const AnimateArgs a = parseArgs(args);
  // Everything named is read before the work: a missing file stops it at once.
  const std::string sourcePath = a.source ? *a.source : sampleIctHead("--source");
  const std::string streamPath = a.stream ? *a.stream : sampleSentence();
  Steps steps;
  std::vector<std::string> warnings;
  FaceModel head = readModel(a.head);
  bindFeaturePoints(a.featurePoints, head, warnings);
  head = neutralFaceModel(std::move(head));
  FapStream stream = readFapStream(streamPath);
  stream.name = std::filesystem::path(streamPath).filename().string();
  steps.done("read", "%s, %zu meshes; %s, %zu frames", a.head.c_str(), head.meshes.size(),
             streamPath.c_str(), stream.frames.size());

  if (!missingCloneFeaturePoints(head).empty() || !a.pins.empty()) {
    const FaceModel templateHead =
        readModel(a.templateHead ? *a.templateHead : sampleIctHead("--template"));
    const std::size_t own = head.featurePoints.size();
    const LandmarkResult found = placeFeaturePoints(head, templateHead, a.pins, warnings);
    steps.done("feature points", "%zu found, %zu of them the head's own or pins; fit residual "
               "%.1f%% of ES0", found.points.size(), own + a.pins.size(), 100 * found.fitResidual);
    for (const std::string& why : found.notPlaced) warnings.push_back("not placed: " + why);
  } else {
    steps.done("feature points", "the head's own %zu", head.featurePoints.size());
  }
  requireCloneFeaturePoints(head, a.head, "--pin or --feature-points");

  // The source's other shape keys (an ARKit head's own) are counted below, not listed.
  const CloneSource source = readCloneSource(sourcePath, std::nullopt, warnings);
  requireCloneFeaturePoints(source.neutral, sourcePath, "a source with feature points");
  CloneOptions options;
  options.relaxation = CloneRelaxation{};
  ProgressPrinter printer("animate");
  options.progress = [&](std::string_view stage, double fraction) { printer(stage, fraction); };
  const ClonedFace cloned = cloneFace(source.neutral, source.copies, head, options);
  printer.finish();
  steps.done("clone", "%zu copies of %s (%zu other shape keys left) -> %zu tables",
             cloned.copies.size(), sourcePath.c_str(), source.ignored.size(),
             cloned.face.faceDefTables.size());
  warnings.insert(warnings.end(), cloned.warnings.begin(), cloned.warnings.end());

  writeClonedFace(cloned, a.output);
  steps.done("write", "%s", a.output.c_str());

  const MotionCheck check = checkMotion(cloned.face, std::span(&stream, 1));
  std::size_t past = 0;
  for (const PoseMotion& f : check.frames) past += f.failures.empty() ? 0 : 1;
  steps.done("check", "%s: %zu of %zu frames past a limit", stream.name.c_str(), past,
             check.frames.size());
  printMotionCheckSummary(a.output, check);
  for (const std::string& w : warnings) std::printf("warning: %s\n", w.c_str());
  // The stream decides: what a key does alone at its extreme is the source's to fix.
  return past == 0 ? 0 : 4;
}

}  // namespace mpeg4face::cli
