// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face info`: what a user needs to know about a head before animating it, or about a FAP
// stream (.fap, .fba) before decoding or playing it.
#include <algorithm>
#include <array>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>

#include "arguments.hpp"
#include "commands.hpp"
#include "feature_points.hpp"
#include "paths.hpp"
#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/codec/measure.hpp"
#include "mpeg4face/io/fap_file.hpp"
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

// What every frame of a stream sends, gathered once for the text and the JSON.
struct StreamSummary {
  struct Range {
    int frames = 0;
    int min = 0;
    int max = 0;
  };
  std::array<Range, kFapCount + 1> faps{};  // [3..68]; frames 0 where never sent
  int visemeFrames = 0;
  int expressionFrames = 0;
  std::set<int> visemes;      // viseme_select1 and 2 as sent
  std::set<int> expressions;  // expression_select1 and 2 as sent
  int emptyFrames = 0;        // frames that send nothing
};

StreamSummary summarise(const FapStream& stream) {
  StreamSummary out;
  for (const FapFrame& f : stream.frames) {
    if (f.mask.none()) ++out.emptyFrames;
    if (f.has(1)) {
      ++out.visemeFrames;
      out.visemes.insert({f.viseme.select1, f.viseme.select2});
    }
    if (f.has(2)) {
      ++out.expressionFrames;
      out.expressions.insert({f.expression.select1, f.expression.select2});
    }
    for (int fap = 3; fap <= kFapCount; ++fap) {
      if (!f.has(fap)) continue;
      StreamSummary::Range& r = out.faps[static_cast<size_t>(fap)];
      const int v = f.value(fap);
      r.min = r.frames == 0 ? v : std::min(r.min, v);
      r.max = r.frames == 0 ? v : std::max(r.max, v);
      ++r.frames;
    }
  }
  return out;
}

// The coding mode as the planes say it: "predictive", "dct", "pca (predictive components)".
std::string fbaModeName(const FbaStreamInfo& info) {
  std::string temporal = info.dctPlanes == 0          ? "predictive"
                         : info.predictivePlanes == 0 ? "dct"
                                                      : "predictive and dct";
  if (info.pca) return "pca (" + temporal + " components)";
  return temporal;
}

// The longest run of frames from an intra plane to the next one or to the end (a decoder can
// join within that many frames); nullopt with fewer than two intra planes.
std::optional<size_t> intraPeriod(const FbaStreamInfo& info, size_t frames) {
  const std::vector<size_t>& at = info.intraFrameIndices;
  if (at.size() < 2) return std::nullopt;
  size_t period = 0;
  for (size_t i = 0; i < at.size(); ++i) {
    period = std::max(period, (i + 1 < at.size() ? at[i + 1] : frames) - at[i]);
  }
  return period;
}

int describeStream(const InfoArgs& args, bool fba) {
  if (args.featurePoints) throw UsageError("--feature-points applies to a face model, not a stream");
  FbaStreamInfo info;
  const FapStream stream = fba ? readFbaFile(args.file, info) : readFapFile(args.file);
  const StreamSummary sum = summarise(stream);
  const double duration = streamDuration(stream);
  const bool hasRate = fba && duration > 0;  // bits/s
  const double rate = hasRate ? bitsPerSecond(static_cast<double>(info.bits), stream) : 0.0;
  const std::optional<size_t> period = intraPeriod(info, stream.frames.size());

  if (args.json) {
    nlohmann::ordered_json j;
    j["file"] = args.file;
    j["format"] = fba ? "fba" : "fap";
    if (fba) {
      nlohmann::ordered_json c;
      c["mode"] = fbaModeName(info);
      c["fap_quant"] = info.fapQuants;
      c["planes"] = info.planes;
      c["intra_planes"] = info.intraFrameIndices.size();
      c["intra_period"] = period ? nlohmann::json(*period) : nlohmann::json(nullptr);
      c["visual_object_sequence"] = info.visualObjectSequence;
      if (info.pca) {
        c["pca_components"] = info.pcaComponents;
        c["pca_basis_bits"] = info.pcaBasisBits;
      }
      c["bits"] = info.bits;
      c["bits_per_second"] = hasRate ? nlohmann::json(rate) : nlohmann::json(nullptr);
      j["coding"] = c;
    } else {
      j["version"] = stream.version;
      j["name"] = stream.name;
      j["header_line"] = stream.headerLine;
    }
    j["frames"] = stream.frames.size();
    j["frame_rate"] = stream.frameRate;
    j["duration_s"] = duration;
    j["first_frame"] = stream.frames.empty() ? nlohmann::json(nullptr)
                                             : nlohmann::json(stream.frames.front().number);
    j["last_frame"] = stream.frames.empty() ? nlohmann::json(nullptr)
                                            : nlohmann::json(stream.frames.back().number);
    j["empty_frames"] = sum.emptyFrames;
    j["faps"] = nlohmann::json::array();
    for (int fap = 3; fap <= kFapCount; ++fap) {
      const StreamSummary::Range& r = sum.faps[static_cast<size_t>(fap)];
      if (r.frames == 0) continue;
      j["faps"].push_back(nlohmann::ordered_json{{"fap", fap},
                                                 {"name", fapInfo(fap).name},
                                                 {"frames", r.frames},
                                                 {"min", r.min},
                                                 {"max", r.max}});
    }
    j["viseme"] = {{"frames", sum.visemeFrames}, {"visemes", sum.visemes}};
    j["expression"] = {{"frames", sum.expressionFrames}, {"expressions", sum.expressions}};
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }

  std::printf("%s\n", args.file.c_str());
  if (fba) {
    std::printf("format: FBA bitstream (%s), %s coding\n",
                info.visualObjectSequence ? "with visual object sequence header" : "fba_object",
                fbaModeName(info).c_str());
    std::string quants;
    for (int q : info.fapQuants) quants += (quants.empty() ? "" : ", ") + std::to_string(q);
    std::printf("fap_quant: %s\n", quants.empty() ? "-" : quants.c_str());
    std::printf("planes: %d, %zu intra", info.planes, info.intraFrameIndices.size());
    if (period) std::printf(" (intra period: at most %zu frames from one to the next)", *period);
    std::printf("\n");
    if (info.pca) {
      std::printf("PCA: %d components, basis in 2^-%d\n", info.pcaComponents, info.pcaBasisBits);
    }
    std::printf("bits: %llu", static_cast<unsigned long long>(info.bits));
    if (hasRate) std::printf(", %.1f bits/s", rate);
    std::printf("\n");
  } else {
    std::printf("format: FAP file version %s%s, name '%s'\n", stream.version.c_str(),
                stream.headerLine ? "" : " (no header line)", stream.name.c_str());
  }
  std::printf("frames: %zu at %g Hz, %.3f s", stream.frames.size(), stream.frameRate, duration);
  if (!stream.frames.empty()) {
    std::printf(", numbers %d..%d", stream.frames.front().number, stream.frames.back().number);
  }
  if (sum.emptyFrames > 0) std::printf(", %d sending nothing", sum.emptyFrames);
  std::printf("\n");
  int present = 0;
  for (int fap = 3; fap <= kFapCount; ++fap) present += sum.faps[static_cast<size_t>(fap)].frames > 0;
  std::printf("low-level FAPs present (%d):\n", present);
  if (present > 0) std::printf("  FAP name                     frames      min      max\n");
  for (int fap = 3; fap <= kFapCount; ++fap) {
    const StreamSummary::Range& r = sum.faps[static_cast<size_t>(fap)];
    if (r.frames == 0) continue;
    std::printf("  %3d %-24s %6d %8d %8d\n", fap, std::string(fapInfo(fap).name).c_str(), r.frames,
                r.min, r.max);
  }
  auto printSet = [](const char* label, int frames, const std::set<int>& values) {
    if (frames == 0) return;
    std::printf("%s: %d frames, values", label, frames);
    for (int v : values) std::printf(" %d", v);
    std::printf("\n");
  };
  printSet("visemes (FAP 1)", sum.visemeFrames, sum.visemes);
  printSet("expressions (FAP 2)", sum.expressionFrames, sum.expressions);
  return 0;
}

}  // namespace

int runInfo(const std::vector<std::string>& rawArgs) {
  const InfoArgs args = parseArgs(rawArgs);
  const std::string ext = extensionOf(args.file);
  if (ext == ".fap" || ext == ".fba") return describeStream(args, ext == ".fba");
  FaceModel model = readModel(args.file);
  std::vector<std::string> warnings;
  bindFeaturePoints(args.featurePoints, model, warnings);
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
