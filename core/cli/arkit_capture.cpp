// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face arkit to-fap` and `mpeg4face arkit from-fap`: Live Link Face captures (ARKit
// weights) to FAP streams and back, through a face with ARKit shapes (docs/arkit.md).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "commands.hpp"
#include "feature_points.hpp"
#include "mpeg4face/arkit/capture.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/livelink.hpp"
#include "mpeg4face/io/read_any.hpp"

namespace mpeg4face::cli {
namespace {

struct CaptureArgs {
  std::string input;
  std::string face;
  std::string output;
  double fps = 25;
  bool report = false;  // to-fap: the playback's fidelity to the capture
};

// The ICT sample head, built by samples/build.sh.
const std::filesystem::path kDefaultFace =
    std::filesystem::path(MPEG4FACE_SAMPLES_DIR) / "build" / "ict_head.glb";

CaptureArgs parseArgs(const std::vector<std::string>& args, bool withFps, const char* inputKind) {
  CaptureArgs out;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-o") {
      out.output = optionValue(args, i, "an output file");
    } else if (a == "--face") {
      out.face = optionValue(args, i, "a head (.glb, .gltf)");
    } else if (withFps && a == "--report") {
      out.report = true;
    } else if (withFps && a == "--fps") {
      out.fps = numberArgument(args, i, "frames per second", 1e-3);
    } else if (a.starts_with("-")) {
      throw UsageError("unknown option '" + a + "'");
    } else if (out.input.empty()) {
      out.input = a;
    } else {
      throw UsageError("more than one input given ('" + a + "')");
    }
  }
  if (out.input.empty()) throw UsageError(std::string("needs ") + inputKind);
  if (out.output.empty()) throw UsageError("needs -o OUT");
  return out;
}

ArkitCaptureFace loadFace(const CaptureArgs& args) {
  std::filesystem::path path = args.face;
  if (path.empty()) {
    path = kDefaultFace;
    if (!std::filesystem::exists(path)) {
      throw Error(path.string(), 0, "--face",
                  "the default face, the ICT sample head, is not built: run samples/build.sh, "
                  "or give a head with ARKit shapes with --face HEAD.glb");
    }
  }
  std::fprintf(stderr, "face %s: preparing...\n", path.string().c_str());
  FaceModel head = readModel(path);
  std::vector<std::string> warnings;
  bindFeaturePoints(std::nullopt, head, warnings);  // free points on the skin to its vertices
  try {
    ArkitCaptureFace face = prepareArkitCaptureFace(head);
    warnings.insert(warnings.end(), face.warnings.begin(), face.warnings.end());
    for (const std::string& w : warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    std::fprintf(stderr, "face %s: %zu vertices in the face area, %zu FAP columns (%s)\n",
                 path.string().c_str(), face.area.size(), face.columnFap.size(),
                 face.fromTables ? "from its FAP keys" : "no FAP keys: the FAPs' definition");
    return face;
  } catch (const Error& e) {
    throw Error(path.string(), e.line(), e.field(), e.reason());
  }
}

void progress(int done, int total) {
  std::fprintf(stderr, "\r%d / %d frames", done, total);
  if (done == total) std::fprintf(stderr, "\n");
}

double ratio(double a, double b) { return b > 0 ? a / b : 0; }

void printFidelity(const CaptureFidelity& f, const ArkitCaptureFace& face) {
  std::printf(
      "fidelity over %d frames, against the capture through the face's ARKit shapes "
      "(relative to each frame's peak motion):\n"
      "  error: mean %.1f%%, p95 %.1f%%\n"
      "  bump p99 %.4f (shapes %.4f: x%.2f), near feature points %.4f (x%.2f), max %.4f "
      "(x%.2f)\n"
      "  spike vertices: %zu\n",
      f.frames, 100 * f.errorMean, 100 * f.errorP95, f.bumpP99, f.referenceBumpP99,
      ratio(f.bumpP99, f.referenceBumpP99), f.pointBumpP99,
      ratio(f.pointBumpP99, f.referencePointBumpP99), f.bumpMax,
      ratio(f.bumpMax, f.referenceBumpMax), f.spikes.size());
  const std::size_t shown = std::min<std::size_t>(f.spikes.size(), 10);
  for (std::size_t i = 0; i < shown; ++i) {
    const auto [m, v] = f.spikes[i];
    std::printf("    %s vertex %d\n",
                face.face.faceSceneGraph.meshes[static_cast<std::size_t>(m)].name.c_str(), v);
  }
  if (shown < f.spikes.size()) std::printf("    and %zu more\n", f.spikes.size() - shown);
}

}  // namespace

int runArkitToFap(const std::vector<std::string>& rawArgs) {
  const CaptureArgs args = parseArgs(rawArgs, true, "a Live Link Face CSV");
  const LiveLinkCapture capture = readLiveLinkCsv(args.input);
  for (const std::string& w : capture.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  const ArkitCaptureFace face = loadFace(args);
  FapStream stream = arkitCaptureToFaps(capture, face, {args.fps, progress});
  stream.name = std::filesystem::path(args.input).stem().string();
  // Measured before the stream is written: a face the report cannot measure (no FAP keys)
  // leaves nothing behind.
  std::optional<CaptureFidelity> fidelity;
  if (args.report) fidelity = measureCaptureFidelity(capture, face, stream);
  writeFapFile(args.output, stream);
  std::printf("%s: %d frames at %g fps -> %s: %zu frames at %g fps\n", args.input.c_str(),
              capture.frameCount(), capture.frameRate, args.output.c_str(), stream.frames.size(),
              stream.frameRate);
  if (fidelity) printFidelity(*fidelity, face);
  return 0;
}

int runArkitFromFap(const std::vector<std::string>& rawArgs) {
  const CaptureArgs args = parseArgs(rawArgs, false, "a FAP stream (.fap, .fba)");
  const FapStream stream = readFapStream(args.input);
  const ArkitCaptureFace face = loadFace(args);
  const LiveLinkCapture capture = fapsToArkit(stream, face, progress);
  writeLiveLinkCsv(args.output, capture);
  std::printf("%s: %zu frames at %g fps -> %s\n", args.input.c_str(), stream.frames.size(),
              stream.frameRate, args.output.c_str());
  return 0;
}

}  // namespace mpeg4face::cli
