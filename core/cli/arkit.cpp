// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face arkit`: ARKit heads and captures in MPEG-4. `arkit keys` gives a head with
// ARKit blendshapes its FAP, viseme and expression keys (docs/arkit.md).
#include <cstdio>
#include <optional>
#include <set>
#include <string>

#include "arguments.hpp"
#include "commands.hpp"
#include "feature_points.hpp"
#include "mpeg4face/arkit/shapes.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/io/gltf.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "mpeg4face/spec.hpp"
#include "paths.hpp"

namespace mpeg4face::cli {
namespace {

int runArkitKeys(const std::vector<std::string>& args) {
  std::vector<std::string> files;
  std::string output;
  std::optional<std::string> featurePoints;
  ArkitKeysOptions options;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-o") {
      output = optionValue(args, i, "an output file");
    } else if (a == "--feature-points") {
      featurePoints = optionValue(args, i, "a CSV file");
    } else if (a == "--no-visemes") {
      options.visemes = false;
    } else if (a == "--no-expressions") {
      options.expressions = false;
    } else if (a.starts_with("-") && a != "-") {
      throw UsageError("unknown option '" + a + "'");
    } else {
      files.push_back(a);
    }
  }
  if (files.size() != 1) throw UsageError("arkit keys takes one HEAD file");
  if (output.empty()) throw UsageError("no output file given (-o)");
  const std::string& path = files[0];
  if (!isGltf(path)) throw UsageError("HEAD must be a .glb or .gltf file, not '" + path + "'");
  if (!isGltf(output)) throw UsageError("-o must name a .glb or .gltf file");

  FaceModel head = readModel(path);
  std::vector<std::string> warnings;
  bindFeaturePoints(featurePoints, head, warnings);
  ArkitKeys keys;
  try {
    keys = arkitFapKeys(head, options);
  } catch (const Error& e) {
    throw Error(path, 0, e.field(), e.reason());
  }
  warnings.insert(warnings.end(), keys.warnings.begin(), keys.warnings.end());
  if (keys.mapping.keys.empty()) {
    // A head without a single key is not what was asked for: say why, write nothing.
    std::string why = keys.mapping.missed.empty() ? "" : ": " + keys.mapping.missed[0].reason;
    if (keys.mapping.missed.size() > 1) {
      why += " (and " + std::to_string(keys.mapping.missed.size() - 1) + " FAPs more)";
    }
    for (const std::string& w : warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    throw Error(path, 0, "FAP keys", "no FAP key could be made" + why + "; nothing written");
  }
  writeGltf(keys.head, output);

  std::printf("%s: %zu ARKit shapes -> %zu FAP keys\n", path.c_str(), keys.shapes.shapes.size(),
              keys.mapping.keys.size());
  std::printf("  %-30s %8s %8s %10s  %s\n", "key", "reached", "residual", "worst",
              "shapes (weight)");
  for (const ArkitFapKey& key : keys.mapping.keys) {
    const std::string name =
        formatShapeKeyName({key.fap, 0, key.amplitude, std::string(fapInfo(key.fap).name)});
    std::string shapes;
    for (std::size_t k = 0; k < key.weights.size() && k < 4; ++k) {
      char text[80];
      std::snprintf(
          text, sizeof text, "%s%s %.2f", k ? ", " : "",
          arkitShapeLabel(keys.shapes.shapes[static_cast<std::size_t>(key.weights[k].first)].ref)
              .c_str(),
          key.weights[k].second);
      shapes += text;
    }
    if (key.weights.size() > 4) shapes += ", ...";
    if (key.transform >= 0) {
      shapes +=
          " (rotates " + keys.head.transforms[static_cast<std::size_t>(key.transform)].name + ")";
    }
    char worst[32] = "";
    if (!key.worstPoint.empty()) {
      std::snprintf(worst, sizeof worst, "%s %.2f", key.worstPoint.c_str(), key.worstMotion);
    }
    std::printf("  %-30s %7.0f%% %8.2f %10s  %s\n", name.c_str(), 100 * key.reached, key.residual,
                worst, shapes.c_str());
  }
  std::printf("missed:\n");
  for (const ArkitMissedFap& m : keys.mapping.missed) {
    const std::string sign = m.sign > 0 ? " +" : m.sign < 0 ? " -" : "";
    std::printf("  FAP %d %s%s: %s\n", m.fap, std::string(fapInfo(m.fap).name).c_str(),
                sign.c_str(), m.reason.c_str());
  }
  std::set<std::string> highLevel[2];  // viseme and expression keys and poses, by name
  const auto count = [&](const std::string& name) {
    if (const std::optional<ShapeKeyName> k = parseShapeKeyName(name); k && k->fapID <= 2) {
      highLevel[k->fapID - 1].insert(name);
    }
  };
  for (const IndexedFaceSet& mesh : keys.head.meshes) {
    for (const MorphTarget& t : mesh.morphTargets) count(t.name);
  }
  for (const MorphWeightAnimation& a : keys.head.animations) count(a.name);
  const std::size_t visemes = highLevel[0].size(), expressions = highLevel[1].size();
  std::printf("%zu viseme and %zu expression keys\n", visemes, expressions);
  for (const std::string& w : warnings) std::printf("warning: %s\n", w.c_str());
  std::printf("wrote %s\n", output.c_str());
  return 0;
}

}  // namespace

int runArkit(const std::vector<std::string>& args) {
  if (args.empty()) throw UsageError("no subcommand given (keys, to-fap, from-fap)");
  if (args[0] == "keys") return runArkitKeys({args.begin() + 1, args.end()});
  if (args[0] == "to-fap") return runArkitToFap({args.begin() + 1, args.end()});
  if (args[0] == "from-fap") return runArkitFromFap({args.begin() + 1, args.end()});
  throw UsageError("unknown subcommand '" + args[0] + "'");
}

}  // namespace mpeg4face::cli
