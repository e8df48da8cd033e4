// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face info`: what a user needs to know about a head before animating it.
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "arguments.hpp"
#include "commands.hpp"
#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face::cli {
namespace {

struct InfoArgs {
  std::string file;
  std::optional<std::string> featurePoints;
  bool json = false;
};

InfoArgs parseArgs(const std::vector<std::string>& args) {
  InfoArgs out;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--json") {
      out.json = true;
    } else if (a == "--feature-points") {
      out.featurePoints = optionValue(args, i, "a CSV file");
    } else if (a.starts_with("-")) {
      throw UsageError("unknown option '" + a + "'");
    } else if (out.file.empty()) {
      out.file = a;
    } else {
      throw UsageError("more than one FILE given ('" + out.file + "' and '" + a + "')");
    }
  }
  if (out.file.empty()) throw UsageError("no FILE given");
  return out;
}

}  // namespace

int runInfo(const std::vector<std::string>& rawArgs) {
  const InfoArgs args = parseArgs(rawArgs);
  FaceModel model = readModel(args.file);
  std::vector<std::string> warnings;
  if (args.featurePoints) {
    FeaturePointCsv csv = readFeaturePointCsv(*args.featurePoints, model);
    for (auto& [id, binding] : csv.featurePoints) model.featurePoints[id] = binding;
    warnings = std::move(csv.warnings);
  }
  const FapuMeasurement fapu = measureFapu(model);
  for (auto [name, d] : fapu.distances()) {
    if (!d->measured) warnings.push_back(std::string(name) + " not measured: " + d->method);
  }
  for (const ConstraintWarning& w : checkLocationConstraints(model, fapu)) {
    warnings.push_back((w.advisory ? "Table 6 (advice): " : "Table 6: ") + w.message);
  }

  std::vector<std::string> present, missing;
  for (const FeaturePointInfo& fp : featurePointTable()) {
    (model.featurePoints.contains(std::string(fp.id)) ? present : missing).emplace_back(fp.id);
  }

  if (args.json) {
    nlohmann::ordered_json j;
    j["file"] = args.file;
    j["meshes"] = nlohmann::json::array();
    for (const IndexedFaceSet& mesh : model.meshes) {
      nlohmann::ordered_json m;
      m["name"] = mesh.name;
      m["vertices"] = mesh.vertexCount();
      m["faces"] = mesh.faceCount();
      m["morph_targets"] = nlohmann::json::array();
      for (const MorphTarget& t : mesh.morphTargets) m["morph_targets"].push_back(t.name);
      j["meshes"].push_back(std::move(m));
    }
    j["transforms"] = model.transforms.size();
    j["animations"] = model.animations.size();
    j["feature_points"] = {{"present", present}, {"missing", missing}};
    nlohmann::ordered_json f, used;
    for (auto [name, d] : fapu.distances()) {
      const std::string key(name);
      f[key] = d->measured ? nlohmann::json(d->value) : nlohmann::json(nullptr);
      used[key] = {{"points", d->pointsUsed}, {"method", d->method}};
    }
    j["fapu"] = f;
    j["fapu_points_used"] = used;
    j["warnings"] = warnings;
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }

  std::printf("%s\n", args.file.c_str());
  std::printf("meshes (%zu):\n", model.meshes.size());
  for (const IndexedFaceSet& mesh : model.meshes) {
    std::printf("  %-24s %7d vertices %7d faces %4zu morph targets\n", mesh.name.c_str(),
                mesh.vertexCount(), mesh.faceCount(), mesh.morphTargets.size());
  }
  for (const IndexedFaceSet& mesh : model.meshes) {
    if (mesh.morphTargets.empty()) continue;
    std::printf("morph targets of %s:\n", mesh.name.c_str());
    for (const MorphTarget& t : mesh.morphTargets) std::printf("  %s\n", t.name.c_str());
  }
  if (!model.animations.empty()) std::printf("animations: %zu\n", model.animations.size());
  std::printf("feature points: %zu present, %zu missing\n", present.size(), missing.size());
  auto printList = [](const char* label, const std::vector<std::string>& ids) {
    if (ids.empty()) return;
    std::printf("  %s:", label);
    for (const std::string& id : ids) std::printf(" %s", id.c_str());
    std::printf("\n");
  };
  printList("present", present);
  printList("missing", missing);
  std::printf("FAPU (model units; the unit is the distance / 1024, AU = 1e-5 rad):\n");
  for (auto [name, d] : fapu.distances()) {
    const std::string label(name);
    if (d->measured) {
      std::printf("  %-6s = %-12.6g from %s\n", label.c_str(), d->value, d->method.c_str());
    } else {
      std::printf("  %-6s   not measured (%s)\n", label.c_str(), d->method.c_str());
    }
  }
  std::printf("warnings (%zu):\n", warnings.size());
  for (const std::string& w : warnings) std::printf("  %s\n", w.c_str());
  return 0;
}

}  // namespace mpeg4face::cli
