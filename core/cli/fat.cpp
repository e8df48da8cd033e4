// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face fat generate`, `export` and `apply`: Face Animation Tables from a head's named
// morph targets, the face as glTF, and FAP streams played on it.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include "arguments.hpp"
#include "commands.hpp"
#include "feature_points.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/fat/generate.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/fit/fit.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/fat_gltf.hpp"
#include "mpeg4face/io/gltf.hpp"
#include "mpeg4face/io/obj.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "mpeg4face/io/vrml.hpp"
#include "mpeg4face/io/wfm.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/spec.hpp"
#include "mpeg4face/stream/fap_stream.hpp"
#include "paths.hpp"

namespace mpeg4face::cli {
namespace {

// Positional arguments and the options every FAT command shares.
struct Args {
  std::vector<std::string> files;
  std::string output;
  std::optional<std::string> featurePoints;
  std::optional<double> threshold;
  std::optional<int> frame;
  std::optional<std::string> fit;
};

Args parseArgs(const std::vector<std::string>& args, bool generateOptions, bool frameOption) {
  Args out;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-o") {
      out.output = optionValue(args, i, "an output file");
    } else if (generateOptions && a == "--feature-points") {
      out.featurePoints = optionValue(args, i, "a CSV file");
    } else if (generateOptions && a == "--threshold") {
      out.threshold = numberArgument(args, i, "a number of FAPU", 0);
    } else if (generateOptions && a == "--fit") {
      out.fit = optionValue(args, i, "a FAP Interpolation Table (.json or a face's .wrl)");
    } else if (frameOption && a == "--frame") {
      const std::string& text = optionValue(args, i, "a frame number");
      const std::optional<int> n = parseInt(text);
      if (!n || *n < 0) {
        throw UsageError("--frame takes a frame number >= 0, not '" + text + "'");
      }
      out.frame = *n;
    } else if (a.starts_with("-") && a != "-") {
      throw UsageError("unknown option '" + a + "'");
    } else {
      out.files.push_back(a);
    }
  }
  if (out.output.empty()) throw UsageError("no output file given (-o)");
  return out;
}

std::string fapLabel(const FaceDefTables& t) {
  if (t.fapID == 1) return "viseme " + std::to_string(t.highLevelSelect);
  if (t.fapID == 2) return "expression " + std::to_string(t.highLevelSelect);
  return "FAP " + std::to_string(t.fapID) + " " + std::string(fapInfo(t.fapID).name);
}

MpegFace readFace(const std::string& path) {
  if (extensionOf(path) != ".wrl") throw UsageError("FACE must be a .wrl file, not '" + path + "'");
  return readVrml(path);
}

}  // namespace

int runFat(const std::vector<std::string>& rawArgs) {
  if (rawArgs.empty()) throw UsageError("no subcommand given (generate)");
  if (rawArgs[0] != "generate") throw UsageError("unknown subcommand '" + rawArgs[0] + "'");
  const Args args = parseArgs({rawArgs.begin() + 1, rawArgs.end()}, true, false);
  if (args.files.size() != 1) throw UsageError("fat generate takes one HEAD file");
  const std::string& head = args.files[0];
  const bool candide = extensionOf(head) == ".wfm";
  if (!isGltf(head) && !candide) {
    throw UsageError("HEAD must be .glb, .gltf or CANDIDE's .wfm, not '" + head + "'");
  }
  if (extensionOf(args.output) != ".wrl") throw UsageError("-o must name a .wrl file");

  // Read first: a bad table stops before the work.
  const std::optional<FitTable> fit =
      args.fit ? std::optional(readFitTableFile(*args.fit)) : std::nullopt;
  const std::optional<CandideModel> units = candide ? std::optional(readWfm(head)) : std::nullopt;
  FaceModel model = units ? candideToFaceModel(*units) : readModel(head);
  std::vector<std::string> warnings;
  bindFeaturePoints(args.featurePoints, model, warnings);
  if (units) {
    try {
      nameCandideFapUnits(model, *units);  // the FAPU come from the feature points just bound
    } catch (const Error& e) {
      throw Error(head, 0, e.field(), e.reason());
    }
  }
  GeneratorOptions options;
  if (args.threshold) options.threshold = *args.threshold;
  ShapeKeyFace generated = faceFromShapeKeys(model, options);
  generated.face.fit = fit;
  if (generated.copies == 0) {
    throw Error(head, 0, "morph targets",
                "no morph target is named as a FAP, viseme or expression (e.g. "
                "fap3_open_jaw@512; grammar in docs/fat.md)");
  }
  const MpegFace& face = generated.face;
  writeVrml(face, args.output);

  std::printf("%s: %zu shape keys -> %zu tables\n", head.c_str(), generated.copies,
              face.faceDefTables.size());
  for (const FaceDefTables& t : face.faceDefTables) {
    size_t vertices = 0;
    std::string intervals;
    for (const FaceDefMesh& m : t.faceDefMesh) {
      vertices += m.coordIndex.size();
      if (!intervals.empty()) continue;
      for (size_t k = 0; k < m.intervalBorders.size(); ++k) {
        intervals += (k ? " " : "") + std::to_string(m.intervalBorders[k]);
      }
    }
    std::printf("  %-32s %zu intervals [%s], %zu vertices, %zu transforms\n", fapLabel(t).c_str(),
                t.faceDefMesh.empty() ? size_t{0} : t.faceDefMesh[0].intervalBorders.size() - 1,
                intervals.c_str(), vertices, t.faceDefTransform.size());
  }
  for (const std::string& name : generated.ignored) {
    warnings.push_back("morph target or animation '" + name +
                       "' is not a FAP, viseme or expression: ignored");
  }
  warnings.insert(warnings.end(), generated.warnings.begin(), generated.warnings.end());
  for (const std::string& w : warnings) std::printf("warning: %s\n", w.c_str());
  std::printf("wrote %s\n", args.output.c_str());
  return 0;
}

int runExport(const std::vector<std::string>& rawArgs) {
  const Args args = parseArgs(rawArgs, false, false);
  if (args.files.size() != 1) throw UsageError("export takes one FACE.wrl");
  if (!isGltf(args.output)) throw UsageError("-o must name a .glb or .gltf file");
  const MpegFace face = readFace(args.files[0]);
  writeFatGltf(face, measureFapu(face.faceSceneGraph), {}, args.output);
  std::printf("wrote %s\n", args.output.c_str());
  return 0;
}

int runApply(const std::vector<std::string>& rawArgs) {
  const Args args = parseArgs(rawArgs, false, true);
  if (args.files.size() != 2) throw UsageError("apply takes FACE.wrl and STREAM.fap");
  const bool obj = extensionOf(args.output) == ".obj";
  if (!obj && !isGltf(args.output)) throw UsageError("-o must name a .obj, .glb or .gltf file");
  if (obj && !args.frame) throw UsageError("an .obj holds one frame: give --frame N");
  const MpegFace face = readFace(args.files[0]);
  FapStream stream = readFapStream(args.files[1]);
  const FapuMeasurement fapu = measureFapu(face.faceSceneGraph);
  // As a decoder does: the Face node's FIT derives what the stream does not send.
  if (face.fit) {
    try {
      const int derived = interpolateFitStream(*face.fit, stream);
      std::printf("%s: the face's FIT derived %d FAP values\n", args.files[0].c_str(), derived);
    } catch (const Error& e) {
      throw Error(args.files[0], 0, "Face.fit " + e.field(), e.reason());
    }
  }

  if (!args.frame) {
    writeFatGltf(face, fapu, {&stream, 1}, args.output);
    std::printf("wrote %s: %zu frames at %g Hz\n", args.output.c_str(), stream.frames.size(),
                stream.frameRate);
    return 0;
  }
  const std::vector<FapState> states = resolveFapStream(stream);
  const FapState* state = nullptr;
  for (const FapState& s : states) {
    if (s.number == *args.frame) state = &s;
  }
  if (!state) {
    throw Error(args.files[1], 0, "frame",
                "no frame numbered " + std::to_string(*args.frame) + " in the stream");
  }
  const FatEvaluator evaluator(face, fapu);
  const FatState animated = evaluator.evaluate(*state);
  FaceModel model = face.faceSceneGraph;
  for (size_t m = 0; m < model.meshes.size(); ++m) model.meshes[m].coord = animated.coord[m];
  model.transforms = animated.transforms;
  if (obj) {
    writeObj(model, args.output);
  } else {
    writeGltf(model, args.output);
  }
  std::printf("wrote %s: frame %d\n", args.output.c_str(), *args.frame);
  return 0;
}

}  // namespace mpeg4face::cli
