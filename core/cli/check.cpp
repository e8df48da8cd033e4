// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face check`: the motion check (fat/motion_check.hpp) of a head's shape keys and of FAP
// streams played on it, as a summary a person reads at a glance or as JSON.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "commands.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/motion_check.hpp"
#include "mpeg4face/io/fat_gltf.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "mpeg4face/io/vrml.hpp"
#include "paths.hpp"
#include "steps.hpp"

namespace mpeg4face::cli {
namespace {

struct Args {
  std::string head;
  std::vector<std::string> streams;
  bool json = false;
  MotionLimits limits;
};

Args parseArgs(const std::vector<std::string>& args) {
  Args out;
  std::vector<std::string> files;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--stream") {
      out.streams.push_back(optionValue(args, i, "a .fap or .fba file"));
    } else if (a == "--json") {
      out.json = true;
    } else if (a == "--no-own-shapes") {
      out.limits.ownShapes = false;
    } else if (a == "--max-edge-ratio") {
      out.limits.edgeRatioP99 = numberArgument(args, i, "a ratio", 1);
    } else if (a == "--flip-degrees") {
      out.limits.flipDegrees = numberArgument(args, i, "an angle in degrees", 0);
    } else if (a == "--max-flips") {
      out.limits.normalFlips = intArgument(args, i, 0, 1 << 30);
    } else if (a == "--max-intersections") {
      out.limits.newIntersections = intArgument(args, i, 0, 1 << 30);
    } else if (a == "--max-spikes") {
      out.limits.spikeVertices = intArgument(args, i, 0, 1 << 30);
    } else if (a == "--spike-ratio") {
      out.limits.bumpOfLocalMotion = numberArgument(args, i, "a ratio", 0);
    } else if (a == "--spike-of-peak") {
      out.limits.bumpOfPeak = numberArgument(args, i, "a percentage of the peak", 0) / 100;
    } else if (a == "--max-lip-corner") {
      out.limits.lipCornerOutside = numberArgument(args, i, "a percentage of MW0", 0) / 100;
    } else if (a == "--min-lower-lip") {
      out.limits.lowerLipShare = numberArgument(args, i, "a percentage", 0) / 100;
    } else if (a.starts_with("-") && a != "-") {
      throw UsageError("unknown option '" + a + "'");
    } else {
      files.push_back(a);
    }
  }
  if (files.size() != 1) throw UsageError("check takes one HEAD.glb or FACE.wrl");
  out.head = files[0];
  if (!isGltf(out.head) && extensionOf(out.head) != ".wrl") {
    throw UsageError("HEAD must be .glb, .gltf or .wrl, not '" + out.head + "'");
  }
  return out;
}

std::string number(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

// How bad a pose is, for "worst": the number of limits it passes, then how far past the
// edge-ratio limit, then flips, intersections and spikes.
bool worse(const PoseMotion& a, const PoseMotion& b) {
  if (a.failures.size() != b.failures.size()) return a.failures.size() > b.failures.size();
  if (a.edgeRatioP99 != b.edgeRatioP99) return a.edgeRatioP99 > b.edgeRatioP99;
  return a.normalFlips + a.newIntersections + a.spikes >
         b.normalFlips + b.newIntersections + b.spikes;
}

struct Measure {
  const char* label;
  double still;  // the value of a pose that does not move: no "worst at" for it
  std::function<double(const PoseMotion&)> value;
  std::function<std::string(double)> show;
};


nlohmann::ordered_json poseJson(const PoseMotion& p, const FaceModel& model) {
  nlohmann::ordered_json j;
  j["name"] = p.name;
  if (p.stream >= 0) {
    j["stream"] = p.stream;
    j["frame"] = p.frame;
  }
  j["edge_ratio_max"] = p.edgeRatioMax;
  j["edge_ratio_p99"] = p.edgeRatioP99;
  j["normal_flips"] = p.normalFlips;
  j["contact_folds"] = p.contactFolds;
  j["new_self_intersections"] = p.newIntersections;
  j["touching_self_intersections"] = p.touchingIntersections;
  j["spikes"] = p.spikes;
  j["own_shape_faults"] = p.ownShapeFaults;
  j["bump_p99_of_peak"] = p.bumpP99;
  j["bump_ratio_max"] = p.bumpRatioMax;
  j["lip_corner_outside_mw0"] = p.lipCornerOutside ? nlohmann::json(*p.lipCornerOutside) : nullptr;
  j["inner_lip_gap_mns0"] = p.innerLipGap ? nlohmann::json(*p.innerLipGap) : nullptr;
  j["failures"] = p.failures;
  // The offending elements only where a limit is passed: a long stream stays readable.
  j["meshes"] = nlohmann::json::array();
  if (p.failures.empty()) return j;
  for (const MeshMotion& m : p.meshes) {
    if (m.offendingVertices.empty()) continue;
    nlohmann::ordered_json mj;
    mj["mesh"] = model.meshes[m.mesh].name;
    mj["edge_ratio_p99"] = m.edgeRatioP99;
    mj["offending_vertices"] = m.offendingVertices;
    mj["flipped_triangles"] = m.flippedTriangles;
    mj["new_intersections"] = m.newIntersections;
    mj["spike_vertices"] = m.spikeVertices;
    mj["bump_p99_of_peak"] = m.bumpP99;
    mj["bump_ratio_max"] = m.bumpRatioMax;
    j["meshes"].push_back(mj);
  }
  return j;
}

void printJson(const std::string& head, const MotionCheck& check, const FaceModel& model) {
  nlohmann::ordered_json j;
  j["file"] = head;
  j["passed"] = check.passed();
  const MotionLimits& l = check.limits;
  j["limits"] = {{"edge_ratio_p99", l.edgeRatioP99},
                 {"flip_degrees", l.flipDegrees},
                 {"normal_flips", l.normalFlips},
                 {"new_self_intersections", l.newIntersections},
                 {"spike_vertices", l.spikeVertices},
                 {"bump_of_peak", l.bumpOfPeak},
                 {"bump_of_local_motion", l.bumpOfLocalMotion},
                 {"bump_mesh_share", l.bumpMeshShare},
                 {"lip_corner_outside_mw0", l.lipCornerOutside},
                 {"lower_lip_share", l.lowerLipShare},
                 {"lip_region_mw0", l.lipRegion},
                 {"lid_region_es0", l.lidRegion},
                 {"own_shapes", l.ownShapes}};
  j["neutral_self_intersections"] = check.neutralIntersections;
  j["own_shapes"] = check.ownShapes;
  j["neutral_lip_gap_mns0"] = check.neutralLipGap ? nlohmann::json(*check.neutralLipGap) : nullptr;
  j["lower_lip_share"] = check.lowerLipShare ? nlohmann::json(*check.lowerLipShare) : nullptr;
  j["failures"] = check.failures;
  j["notes"] = check.notes;
  j["streams"] = nlohmann::json::array();
  for (const StreamMotion& s : check.streams) {
    j["streams"].push_back({{"name", s.name},
                            {"frames", s.frames},
                            {"inner_lip_gap_min_mns0", s.innerLipGapMin},
                            {"inner_lip_gap_max_mns0", s.innerLipGapMax}});
  }
  j["keys"] = nlohmann::json::array();
  for (const PoseMotion& p : check.keys) j["keys"].push_back(poseJson(p, model));
  j["frames"] = nlohmann::json::array();
  for (const PoseMotion& p : check.frames) j["frames"].push_back(poseJson(p, model));
  std::printf("%s\n", j.dump(1).c_str());
}

}  // namespace

void printMotionCheckSummary(const std::string& head, const MotionCheck& check) {
  const MotionLimits& l = check.limits;
  std::size_t failedKeys = 0, failedFrames = 0;
  for (const PoseMotion& p : check.keys) failedKeys += !p.failures.empty();
  for (const PoseMotion& p : check.frames) failedFrames += !p.failures.empty();
  std::printf("%s: %s - %zu of %zu keys, %zu of %zu frames past the limits\n", head.c_str(),
              check.passed() ? "PASS" : "FAIL", failedKeys, check.keys.size(), failedFrames,
              check.frames.size());

  const std::vector<Measure> measures = {
      {"edge ratio p99", 1, [](const PoseMotion& p) { return p.edgeRatioP99; },
       [](double v) { return number("%.2f", v); }},
      {"flipped triangles", 0, [](const PoseMotion& p) { return double(p.normalFlips); },
       [](double v) { return number("%.0f", v); }},
      {"new self-intersections", 0, [](const PoseMotion& p) { return double(p.newIntersections); },
       [](double v) { return number("%.0f", v); }},
      {"spike vertices", 0, [](const PoseMotion& p) { return double(p.spikes); },
       [](double v) { return number("%.0f", v); }},
      {"bump / local motion", 0, [](const PoseMotion& p) { return p.bumpRatioMax; },
       [](double v) { return number("%.2f", v); }},
      {"inner lip corner outside", -1e9,
       [](const PoseMotion& p) { return p.lipCornerOutside.value_or(-1e9); },
       [](double v) { return v < -1e8 ? std::string("-") : number("%.1f%% MW0", 100 * v); }},
  };
  const std::vector<std::string> limitText = {number("<= %g", l.edgeRatioP99),
                                              "<= " + std::to_string(l.normalFlips),
                                              "<= " + std::to_string(l.newIntersections),
                                              "<= " + std::to_string(l.spikeVertices),
                                              number("<= %g", l.bumpOfLocalMotion),
                                              number("<= %g%%", 100 * l.lipCornerOutside)};
  // The bump ratio's columns count the poses with a vertex past it among those whose bump is
  // more than bumpOfPeak of the peak: the poses with a spike.
  const std::vector<double> limitValue = {l.edgeRatioP99,          double(l.normalFlips),
                                          double(l.newIntersections), double(l.spikeVertices),
                                          l.bumpOfLocalMotion,     l.lipCornerOutside};
  std::printf("  %-26s %-9s %-12s %-7s %-7s %s\n", "measure", "limit", "worst", "keys", "frames",
              "worst at");
  for (std::size_t k = 0; k < measures.size(); ++k) {
    const Measure& m = measures[k];
    const PoseMotion* worst = nullptr;
    std::size_t keys = 0, frames = 0;
    for (const auto* poses : {&check.keys, &check.frames}) {
      for (const PoseMotion& p : *poses) {
        const double v = m.value(p);
        if (v > limitValue[k]) (poses == &check.keys ? keys : frames) += 1;
        if (!worst || v > m.value(*worst)) worst = &p;
      }
    }
    std::printf("  %-26s %-9s %-12s %-7zu %-7zu %s\n", m.label, limitText[k].c_str(),
                worst ? m.show(m.value(*worst)).c_str() : "-", keys, frames,
                worst && m.value(*worst) > m.still ? worst->name.c_str() : "-");
  }
  std::printf(
      "  %-26s %-9s %-12s\n", "lower lip 8.2 / chin 2.1",
      number(">= %g%%", 100 * l.lowerLipShare).c_str(),
      check.lowerLipShare ? number("%.0f%% (FAP 3)", 100 * *check.lowerLipShare).c_str() : "-");
  if (check.neutralLipGap) {
    std::printf("  inner-lip gap 2.2-2.3: neutral %.3f MNS0", *check.neutralLipGap);
    for (const StreamMotion& s : check.streams) {
      const bool still = s.innerLipGapMax - s.innerLipGapMin < 0.05;
      std::printf("; %s %.3f..%.3f%s", s.name.c_str(), s.innerLipGapMin, s.innerLipGapMax,
                  still ? " (lips never part)" : "");
    }
    std::printf("\n");
  }

  for (const auto& [title, poses] :
       {std::pair{"worst keys", &check.keys}, std::pair{"worst frames", &check.frames}}) {
    std::vector<const PoseMotion*> failed;
    for (const PoseMotion& p : *poses) {
      if (!p.failures.empty()) failed.push_back(&p);
    }
    if (failed.empty()) continue;
    std::stable_sort(failed.begin(), failed.end(),
                     [](const PoseMotion* a, const PoseMotion* b) { return worse(*a, *b); });
    std::printf("%s:\n", title);
    for (std::size_t i = 0; i < std::min<std::size_t>(failed.size(), 5); ++i) {
      std::string text;
      for (const std::string& f : failed[i]->failures) text += (text.empty() ? "" : "; ") + f;
      std::printf("  %-32s %s\n", failed[i]->name.c_str(), text.c_str());
    }
  }
  for (const std::string& f : check.failures) std::printf("FAIL: %s\n", f.c_str());
  for (const std::string& n : check.notes) std::printf("note: %s\n", n.c_str());
  std::printf("(%d self-intersecting triangle pairs in the neutral, not counted)\n",
              check.neutralIntersections);
  int folds = 0, own = 0;
  for (const auto* poses : {&check.keys, &check.frames}) {
    for (const PoseMotion& p : *poses) {
      folds = std::max(folds, p.contactFolds);
      own = std::max(own, p.ownShapeFaults);
    }
  }
  if (folds > 0) {
    std::printf("(up to %d triangles in a pose folded where lips or lids meet, not counted)\n",
                folds);
  }
  if (!check.ownShapes.empty()) {
    std::printf("(%zu shape keys outside the grammar measured as the head's own motion: up to %d "
                "flips, new intersections and spikes in a pose that they make too, not counted)\n",
                check.ownShapes.size(), own);
  }
}

int runCheck(const std::vector<std::string>& rawArgs) {
  const Args args = parseArgs(rawArgs);
  // Read everything first: a stream that does not read stops before the work.
  // A face with tables (a .wrl, or a glTF file that mpeg4face wrote with them: fat generate,
  // clone, animate) is checked through them, as it plays; a head by its shape keys.
  std::optional<MpegFace> tables;
  if (extensionOf(args.head) == ".wrl") {
    tables = readVrml(args.head);
  } else if (isGltf(args.head)) {
    if (std::optional<FatGltf> fat = readFatGltfIfAny(args.head)) tables = std::move(fat->face);
  }
  const bool face = tables.has_value();
  const MpegFace wrl = face ? std::move(*tables) : MpegFace{};
  const FaceModel head = face ? FaceModel{} : readModel(args.head);
  std::vector<FapStream> streams;
  for (const std::string& path : args.streams) {
    streams.push_back(readFapStream(path));
    streams.back().name = std::filesystem::path(path).filename().string();
  }
  // On a terminal one line rewritten; in a log a line per tenth.
  const bool terminal = isatty(fileno(stderr));
  const MotionProgress progress = [&](std::size_t done, std::size_t total) {
    if (terminal && (done % 50 == 0 || done == total)) {
      std::fprintf(stderr, "\rcheck: %zu/%zu poses%s", done, total, done == total ? "\n" : "");
    } else if (!terminal && (done * 10 / total != (done - 1) * 10 / total || done == total)) {
      std::fprintf(stderr, "check: %zu/%zu poses\n", done, total);
    }
  };
  MotionCheck check;
  try {
    check = face ? checkMotion(wrl, streams, args.limits, progress)
                 : checkMotion(head, streams, args.limits, progress);
  } catch (const Error& e) {
    if (!e.file().empty()) throw;
    throw Error(args.head, 0, e.field(), e.reason());
  }
  if (check.keys.empty() && check.frames.empty()) {
    throw Error(args.head, 0, face ? "faceDefTables" : "morph targets",
                "no shape key named as a FAP, viseme or expression (docs/fat.md) and no "
                "--stream: nothing to check");
  }
  const FaceModel& model = face ? wrl.faceSceneGraph : head;
  if (args.json) {
    printJson(args.head, check, model);
  } else {
    printMotionCheckSummary(args.head, check);
  }
  return check.passed() ? 0 : 4;
}

}  // namespace mpeg4face::cli
