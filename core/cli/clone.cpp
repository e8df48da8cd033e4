// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face clone`: Facial Motion Cloning (Pandzic 2003) from a face with tables or named
// shape keys to a neutral face with feature points; the result is the target with its own
// FaceDefTables.
#include "mpeg4face/clone/clone.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include "arguments.hpp"
#include "commands.hpp"
#include "feature_points.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/io/fat_gltf.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "mpeg4face/io/vrml.hpp"
#include "paths.hpp"
#include "steps.hpp"

namespace mpeg4face::cli {
namespace {

struct Args {
  std::string source, target, output;
  std::optional<std::string> sourceFeaturePoints, targetFeaturePoints;
  CloneOptions options;
};

Args parseArgs(const std::vector<std::string>& args) {
  Args out;
  std::vector<std::string> files;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-o") {
      out.output = optionValue(args, i, "an output file");
    } else if (a == "--source-feature-points") {
      out.sourceFeaturePoints = optionValue(args, i, "a CSV file");
    } else if (a == "--target-feature-points") {
      out.targetFeaturePoints = optionValue(args, i, "a CSV file");
    } else if (a == "--filter-support") {
      out.options.filterSupport = numberArgument(args, i, "a number", 0);
    } else if (a == "--fixed-filter") {
      out.options.adaptiveFilter = false;
    } else if (a == "--no-rigid") {
      out.options.rigidParts = false;
    } else if (a.starts_with("-") && a != "-") {
      throw UsageError("unknown option '" + a + "'");
    } else {
      files.push_back(a);
    }
  }
  if (files.size() != 2) throw UsageError("clone takes SOURCE and TARGET");
  out.source = files[0];
  out.target = files[1];
  if (out.output.empty()) throw UsageError("no output file given (-o)");
  if (!isGltf(out.output) && extensionOf(out.output) != ".wrl") {
    throw UsageError("-o must name a .glb, .gltf or .wrl file");
  }
  if (!isGltf(out.source) && extensionOf(out.source) != ".wrl") {
    throw UsageError(
        "SOURCE must be a face with tables (.wrl, .glb, .gltf) or a glTF head with "
        "named shape keys, not '" +
        out.source + "'");
  }
  return out;
}

CloneSource tablesSource(MpegFace face, const FapuMeasurement& fapu, const std::string& path) {
  if (face.faceDefTables.empty()) {
    throw Error(path, 0, "faceDefTables",
                "the face has no Face Animation Tables: nothing to clone");
  }
  CloneSource out;
  out.copies = shapesFromFaceDefTables(face, fapu);
  out.neutral = std::move(face.faceSceneGraph);
  out.neutral = neutralFaceModel(std::move(out.neutral));
  out.kind = "tables";
  return out;
}

}  // namespace

CloneSource readCloneSource(const std::string& path,
                            const std::optional<std::string>& featurePoints,
                            std::vector<std::string>& warnings) {
  if (!isGltf(path)) {
    MpegFace face = readVrml(path);
    bindFeaturePoints(featurePoints, face.faceSceneGraph, warnings);
    const FapuMeasurement fapu = measureFapu(face.faceSceneGraph);
    return tablesSource(std::move(face), fapu, path);
  }
  // Only "no tables at all" sends us to the shape keys; broken tables are an error.
  if (std::optional<FatGltf> fat = readFatGltfIfAny(path)) {
    bindFeaturePoints(featurePoints, fat->face.faceSceneGraph, warnings);
    // The file's own FAPU: the one its targets were scaled with.
    return tablesSource(std::move(fat->face), fat->fapu, path);
  }
  FaceModel model = readModel(path);
  bindFeaturePoints(featurePoints, model, warnings);
  ShapeKeyCopies keys = shapesFromShapeKeys(model);
  if (keys.copies.empty()) {
    throw Error(path, 0, "morph targets",
                "neither Face Animation Tables nor a shape key named as a FAP, viseme or "
                "expression (e.g. fap3_open_jaw@512; grammar in docs/fat.md)");
  }
  CloneSource out{std::move(model), std::move(keys.copies), "shape keys",
                  std::move(keys.ignored)};
  out.neutral = neutralFaceModel(std::move(out.neutral));
  return out;
}

void requireCloneFeaturePoints(const FaceModel& model, const std::string& path,
                               const char* option) {
  const std::vector<std::string> missing = missingCloneFeaturePoints(model);
  if (missing.empty()) return;
  std::string list;
  for (const std::string& id : missing) list += (list.empty() ? "" : " ") + id;
  throw Error(path, 0, "feature points",
              "missing feature points that cloning needs: " + list + " (bind them with " + option +
                  " CSV)");
}

namespace {

// The target with its tables, plus each cloned copy's vertex motion as a shape key named
// like the copy (Transform motion is in the tables only), so that the file can be edited
// and fed to `fat generate` again.
MpegFace withCopiesAsShapeKeys(const ClonedFace& cloned) {
  MpegFace out = cloned.face;
  FaceModel& model = out.faceSceneGraph;
  for (const FaceShape& copy : cloned.copies) {
    for (const MeshDisplacement& d : copy.meshes) {
      IndexedFaceSet& mesh = model.meshes[static_cast<std::size_t>(d.mesh)];
      mesh.morphTargets.push_back({copy.name, denseDisplacement(copy, d.mesh, mesh.vertexCount())});
      mesh.weights.resize(mesh.morphTargets.size(), 0.0);
    }
  }
  return out;
}

}  // namespace

void writeClonedFace(const ClonedFace& cloned, const std::string& path) {
  if (isGltf(path)) {
    writeFatGltf(withCopiesAsShapeKeys(cloned), measureFapu(cloned.face.faceSceneGraph), {},
                 path);
  } else {
    writeVrml(cloned.face, path);
  }
}

int runClone(const std::vector<std::string>& rawArgs) {
  Args args = parseArgs(rawArgs);
  std::vector<std::string> warnings;
  const CloneSource source = readCloneSource(args.source, args.sourceFeaturePoints, warnings);
  for (const std::string& name : source.ignored) {
    warnings.push_back("source shape key or animation '" + name +
                       "' is not a FAP, viseme or expression: ignored");
  }

  FaceModel target = readModel(args.target);
  bindFeaturePoints(args.targetFeaturePoints, target, warnings);
  target = neutralFaceModel(std::move(target));
  requireCloneFeaturePoints(source.neutral, args.source, "--source-feature-points");
  requireCloneFeaturePoints(target, args.target, "--target-feature-points");

  ProgressPrinter printer("clone");
  args.options.progress = [&](std::string_view stage, double fraction) {
    printer(stage, fraction);
  };
  const ClonedFace cloned = cloneFace(source.neutral, source.copies, target, args.options);
  printer("writing", 1.0);
  writeClonedFace(cloned, args.output);
  printer.finish();

  std::printf("%s: %zu copies (from %s) -> %s: %zu copies, %zu tables\n", args.source.c_str(),
              source.copies.size(), source.kind.c_str(), args.target.c_str(), cloned.copies.size(),
              cloned.face.faceDefTables.size());
  warnings.insert(warnings.end(), cloned.warnings.begin(), cloned.warnings.end());
  for (const std::string& w : warnings) std::printf("warning: %s\n", w.c_str());
  std::printf("wrote %s\n", args.output.c_str());
  return 0;
}

}  // namespace mpeg4face::cli
