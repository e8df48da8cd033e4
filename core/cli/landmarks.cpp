// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face landmarks`: a head's MPEG-4 feature points found by registering a template head
// onto it (model/landmarks.hpp), written as CSV or as the head in glTF with its points.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "commands.hpp"
#include "feature_points.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/gltf.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/model/landmarks.hpp"
#include "mpeg4face/spec.hpp"
#include "paths.hpp"
#include "steps.hpp"

namespace mpeg4face::cli {
namespace {

struct LandmarksArgs : LandmarkArgs {
  std::string head;
  std::string output;
};

LandmarksArgs parseArgs(const std::vector<std::string>& args) {
  LandmarksArgs out;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (takeLandmarkOption(args, i, out)) continue;
    if (a == "-o") {
      out.output = optionValue(args, i, "an output file (.csv, .glb or .gltf)");
    } else if (a.starts_with("-")) {
      throw UsageError("unknown option '" + a + "'");
    } else if (out.head.empty()) {
      out.head = a;
    } else {
      throw UsageError("more than one HEAD given ('" + out.head + "' and '" + a + "')");
    }
  }
  if (out.head.empty()) throw UsageError("no HEAD given");
  if (out.output.empty()) throw UsageError("no output given (-o OUT.csv or -o OUT.glb)");
  const std::string ext = extensionOf(out.output);
  if (ext != ".csv" && !isGltf(out.output)) {
    throw UsageError("-o takes a .csv, .glb or .gltf file, not '" + out.output + "'");
  }
  return out;
}

}  // namespace

std::string sampleIctHead(const char* option) {
  const std::filesystem::path sample =
      std::filesystem::path(MPEG4FACE_SAMPLES_DIR) / "build" / "ict_head.glb";
  if (!std::filesystem::exists(sample)) {
    throw UsageError(std::string("no ") + option + " given and no ICT sample head: run " +
                     "samples/build.sh (it makes " + sample.string() + ") or pass " + option);
  }
  return sample.string();
}

namespace {

// One --pin: FP=VERTEX (of the face mesh), FP=MESH:VERTEX or FP=x,y,z (model space).
std::pair<std::string, FeaturePointBinding> parsePin(const std::string& text,
                                                     const FaceModel& model) {
  const auto bad = [&](const std::string& why) {
    return UsageError("--pin '" + text + "': " + why);
  };
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos) throw bad("expected FP=VERTEX, FP=MESH:VERTEX or FP=x,y,z");
  const std::string id = text.substr(0, eq), where = text.substr(eq + 1);
  if (!findFeaturePoint(id)) throw bad("'" + id + "' is not an MPEG-4 feature point");
  FeaturePointBinding b;
  if (where.find(',') != std::string::npos) {
    std::stringstream in(where);
    std::string part;
    int k = 0;
    while (std::getline(in, part, ',')) {
      const std::optional<double> value = parseNumber(part);
      if (!value || k > 2) throw bad("a position is three numbers x,y,z");
      b.position[k++] = *value;
    }
    if (k != 3) throw bad("a position is three numbers x,y,z");
    return {id, b};
  }
  const std::size_t colon = where.rfind(':');
  if (colon != std::string::npos) {
    const std::string mesh = where.substr(0, colon);
    const std::optional<int> found = model.findMesh(mesh);
    if (!found) throw bad("the head has no mesh '" + mesh + "'");
    b.mesh = *found;
  } else {
    b.mesh = landmarkFaceMesh(model);
  }
  const std::optional<int> vertex =
      parseInt(colon == std::string::npos ? where : where.substr(colon + 1));
  if (!vertex || b.mesh < 0 || *vertex < 0 ||
      *vertex >= model.meshes[static_cast<std::size_t>(b.mesh)].vertexCount()) {
    throw bad("not a vertex of the head's mesh");
  }
  b.vertex = *vertex;
  return {id, b};
}

std::string csvText(const FaceModel& head, const LandmarkResult& found) {
  std::string out = "fp,mesh,vertex,x,y,z,confidence\n";
  for (const auto& [id, p] : found.points) {
    char line[256];
    const std::string mesh =
        p.binding.mesh >= 0 ? head.meshes[static_cast<std::size_t>(p.binding.mesh)].name : "";
    const std::string vertex = p.binding.mesh >= 0 ? std::to_string(p.binding.vertex) : "";
    const Eigen::Vector3d at = *head.featurePointPosition(id);
    std::snprintf(line, sizeof line, "%s,%s,%s,%.9g,%.9g,%.9g,%.3f\n", id.c_str(), mesh.c_str(),
                  vertex.c_str(), at.x(), at.y(), at.z(), p.confidence);
    out += line;
  }
  return out;
}

}  // namespace

bool takeLandmarkOption(const std::vector<std::string>& args, std::size_t& i,
                        LandmarkArgs& out) {
  const std::string& a = args[i];
  if (a == "--pin") {
    out.pins.push_back(optionValue(args, i, "FP=VERTEX, FP=MESH:VERTEX or FP=x,y,z"));
  } else if (a == "--feature-points") {
    out.featurePoints = optionValue(args, i, "a CSV file");
  } else if (a == "--template") {
    out.templateHead = optionValue(args, i, "a head with feature points");
  } else {
    return false;
  }
  return true;
}

LandmarkResult placeFeaturePoints(FaceModel& head, const FaceModel& templateHead,
                                  const std::vector<std::string>& pins,
                                  std::vector<std::string>& warnings) {
  LandmarkOptions options;
  options.pins = head.featurePoints;  // the head's own points are kept
  for (const std::string& pin : pins) {
    auto [id, binding] = parsePin(pin, head);
    options.pins[id] = binding;
  }
  LandmarkResult found = findFeaturePoints(head, templateHead, options);
  head.featurePoints.clear();
  for (const auto& [id, p] : found.points) head.featurePoints[id] = p.binding;
  // Pins given as positions on the surface are bound to their vertices, as every command does.
  const FeaturePointSnap snap = snapFeaturePointsToVertices(head);
  warnings.insert(warnings.end(), snap.notes.begin(), snap.notes.end());
  for (auto& [id, p] : found.points) p.binding = head.featurePoints.at(id);
  return found;
}

int runLandmarks(const std::vector<std::string>& args) {
  const LandmarksArgs a = parseArgs(args);
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  FaceModel head = readModel(a.head);
  std::vector<std::string> warnings;
  bindFeaturePoints(a.featurePoints, head, warnings);
  const std::size_t pins = head.featurePoints.size() + a.pins.size();
  const FaceModel templateHead =
      readModel(a.templateHead ? *a.templateHead : sampleIctHead("--template"));
  const LandmarkResult found = placeFeaturePoints(head, templateHead, a.pins, warnings);
  if (isGltf(a.output)) {
    writeGltf(head, a.output);
  } else {
    writeFileAtomically(a.output, csvText(head, found));
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("%zu feature points placed (%zu pins) on mesh '%s' in %.1f s; fit residual "
              "%.1f%% of ES0 (median; alignment %.1f%% of the head's size)\n",
              found.points.size(), pins,
              head.meshes[static_cast<std::size_t>(found.faceMesh)].name.c_str(), seconds,
              100 * found.fitResidual, 100 * found.alignmentResidual);
  for (const std::string& why : found.notPlaced) std::printf("not placed: %s\n", why.c_str());
  const FapuMeasurement fapu = measureFapu(head);
  for (const auto& [name, d] : fapu.distances()) {
    if (d->measured) {
      std::printf("  %-6.*s = %g\n", static_cast<int>(name.size()), name.data(), d->value);
    } else {
      std::printf("  %-6.*s not measured: %s\n", static_cast<int>(name.size()), name.data(),
                  d->method.c_str());
    }
  }
  for (const ConstraintWarning& w : checkLocationConstraints(head, fapu)) {
    warnings.push_back((w.advisory ? "Table 6 (advice): " : "Table 6: ") + w.message);
  }
  for (const std::string& w : warnings) std::printf("warning: %s\n", w.c_str());
  std::printf("wrote %s\n", a.output.c_str());
  return 0;
}

}  // namespace mpeg4face::cli
