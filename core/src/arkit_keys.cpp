// SPDX-License-Identifier: GPL-3.0-or-later
// A head's FAP, viseme and expression keys made from its ARKit shapes. docs/arkit.md.
#include <algorithm>
#include <map>

#include "mpeg4face/arkit.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fap_stream.hpp"
#include "mpeg4face/fat_evaluate.hpp"
#include "mpeg4face/fat_names.hpp"
#include "mpeg4face/fit.hpp"
#include "mpeg4face/fit_presets.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

bool inGrammar(const std::string& name) { return parseShapeKeyName(name).has_value(); }

// Keeps the morph targets of mesh `m` that `keep` says and appends `added`, with each
// animation channel of the mesh following (its kept targets' weights, 0 for the added).
void replaceMorphTargets(FaceModel& head, int m, const std::vector<bool>& keep,
                         std::vector<MorphTarget> added) {
  IndexedFaceSet& mesh = head.meshes[static_cast<std::size_t>(m)];
  const std::size_t before = mesh.morphTargets.size();
  std::vector<MorphTarget> targets;
  std::vector<double> weights;
  for (std::size_t t = 0; t < before; ++t) {
    if (!keep[t]) continue;
    targets.push_back(std::move(mesh.morphTargets[t]));
    if (!mesh.weights.empty()) weights.push_back(mesh.weights[t]);
  }
  for (MorphTarget& target : added) {
    targets.push_back(std::move(target));
    if (!mesh.weights.empty()) weights.push_back(0);
  }
  const std::size_t after = targets.size();
  mesh.morphTargets = std::move(targets);
  mesh.weights = std::move(weights);
  if (before == 0) return;
  for (MorphWeightAnimation& animation : head.animations) {
    for (MorphWeightChannel& channel : animation.channels) {
      if (channel.mesh != m) continue;
      std::vector<double> values;
      for (std::size_t k = 0; k < channel.weights.size() / before; ++k) {
        for (std::size_t t = 0; t < before; ++t) {
          if (keep[t]) values.push_back(channel.weights[k * before + t]);
        }
        values.resize((k + 1) * after, 0.0);
      }
      channel.weights = std::move(values);
    }
  }
}

// Every morph target and animation named in the shape-key grammar goes; `added` (per mesh)
// comes in.
void setKeys(FaceModel& head, std::vector<std::vector<MorphTarget>> added,
             std::vector<MorphWeightAnimation> poses, bool dropGrammar) {
  for (std::size_t m = 0; m < head.meshes.size(); ++m) {
    std::vector<bool> keep;
    for (const MorphTarget& t : head.meshes[m].morphTargets) {
      keep.push_back(!dropGrammar || !inGrammar(t.name));
    }
    replaceMorphTargets(head, static_cast<int>(m), keep, std::move(added[m]));
  }
  if (dropGrammar) {
    std::erase_if(head.animations, [](const MorphWeightAnimation& a) { return inGrammar(a.name); });
  }
  for (MorphWeightAnimation& pose : poses) head.animations.push_back(std::move(pose));
}

// A pose's channel: the Transform's field at one key.
TransformChannel poseChannel(int transform, TransformChannel::Path path,
                             std::vector<double> values) {
  return {transform, path, MorphWeightChannel::Interpolation::Linear, {0.0}, std::move(values)};
}
TransformChannel rotationChannel(int transform, const Eigen::Quaterniond& q) {
  return poseChannel(transform, TransformChannel::Path::Rotation, {q.x(), q.y(), q.z(), q.w()});
}

// viseme1..14 and expression1..6: each alone from the neutral face, with the FAPs the FIT
// preset gives it (its own frame: nothing held from another), as keys and poses.
void addHighLevelKeys(ArkitKeys& out, const ArkitKeysOptions& options) {
  const ShapeKeyFace generated = faceFromShapeKeys(out.head);
  for (const std::string& w : generated.warnings) out.warnings.push_back("tables: " + w);
  const FatEvaluator evaluator(generated.face, measureFapu(generated.face.faceSceneGraph));
  const FatState neutral = evaluator.neutralState();
  std::vector<std::pair<std::string, FapFrame>> frames;
  if (options.visemes) {
    const FitTable fit = visemeFitTable();
    for (const VisemeInfo& v : visemeTable()) {
      if (v.number == 0) continue;
      FapFrame frame;
      frame.mask.set(0);
      frame.viseme = {v.number, 0, 63, false};
      interpolateFitFrame(fit, frame);
      frames.emplace_back(formatShapeKeyName({1, v.number, 63, ""}), frame);
    }
  }
  if (options.expressions) {
    const FitTable fit = expressionFitTable();
    for (const ExpressionInfo& e : expressionTable()) {
      if (e.number == 0) continue;
      FapFrame frame;
      frame.mask.set(1);
      frame.expression = {e.number, 63, 0, 0, false, false};
      interpolateFitFrame(fit, frame);
      frames.emplace_back(formatShapeKeyName({2, e.number, 63, std::string(e.name)}), frame);
    }
  }
  std::vector<std::pair<int, int>> reach(kFapCount, {0, 0});  // per FAP: the keys' amplitudes
  for (const ArkitFapKey& key : out.mapping.keys) {
    auto& [low, high] = reach[static_cast<std::size_t>(key.fap - 1)];
    low = std::min(low, key.amplitude);
    high = std::max(high, key.amplitude);
  }
  std::vector<std::vector<MorphTarget>> added(out.head.meshes.size());
  std::vector<MorphWeightAnimation> poses;
  for (auto& [name, frame] : frames) {
    FapState state;
    applyFrame(state, frame);  // the left/right partners of what the preset gives
    FapFrame resolved = resolvedFrame(state);
    // The shapes reach no further than the keys: a value past a key's amplitude is held at
    // it, and one of a sign without a key is 0 (its table would run the shapes backwards).
    for (int f = 3; f <= kFapCount; ++f) {
      if (!resolved.has(f)) continue;
      const int value = resolved.value(f);
      const auto& [low, high] = reach[static_cast<std::size_t>(f - 1)];
      resolved.set(f, std::clamp(value, low, high));
    }
    const FatState shown = evaluator.evaluate(resolved);
    for (std::size_t m = 0; m < added.size(); ++m) {
      Points3 d = shown.coord[m] - neutral.coord[m];
      if ((d.array() != 0).any()) added[m].push_back({name, std::move(d)});
    }
    MorphWeightAnimation pose{name, {}, {}};
    for (std::size_t t = 0; t < shown.transforms.size(); ++t) {
      const Transform& a = shown.transforms[t];
      const Transform& n = neutral.transforms[t];
      if (a.translation != n.translation) {
        pose.transformChannels.push_back(
            poseChannel(static_cast<int>(t), TransformChannel::Path::Translation,
                        {a.translation.x(), a.translation.y(), a.translation.z()}));
      }
      if (a.rotation.coeffs() != n.rotation.coeffs()) {
        pose.transformChannels.push_back(rotationChannel(static_cast<int>(t), a.rotation));
      }
    }
    if (!pose.transformChannels.empty()) poses.push_back(std::move(pose));
  }
  setKeys(out.head, std::move(added), std::move(poses), false);
}

}  // namespace

ArkitKeys arkitFapKeys(const FaceModel& head, const ArkitKeysOptions& options) {
  ArkitKeys out;
  out.head = head;
  setKeys(out.head, std::vector<std::vector<MorphTarget>>(head.meshes.size()), {}, true);
  out.shapes = findArkitShapes(out.head);
  const FapuMeasurement fapu = measureFapu(out.head);
  if (!fapu.ES0.measured) {
    throw Error(
        {}, 0, "feature points",
        "ES0 cannot be measured (" + fapu.ES0.method + "): the FAP keys' amplitudes need the FAPU");
  }
  for (const std::string& name : fapu.missing()) {
    out.warnings.push_back(name + " is not measured: the FAPs in its unit get no keys");
  }
  out.mapping = mapArkitToFaps(out.head, out.shapes, fapu);

  std::vector<std::vector<MorphTarget>> added(out.head.meshes.size());
  std::vector<MorphWeightAnimation> poses;
  for (const ArkitFapKey& key : out.mapping.keys) {
    const std::string name =
        formatShapeKeyName({key.fap, 0, key.amplitude, std::string(fapInfo(key.fap).name)});
    // An eyeball turn: the eye's Transform turns; the shape still moves the lids.
    std::vector<int> turned;
    if (key.transform >= 0) {
      poses.push_back({name, {}, {rotationChannel(key.transform, key.rotation)}});
      turned = out.head.transforms[static_cast<std::size_t>(key.transform)].meshes;
    }
    std::map<int, Points3> meshes;
    for (const auto& [shape, weight] : key.weights) {
      for (const ArkitTarget& t : out.shapes.shapes[static_cast<std::size_t>(shape)].targets) {
        if (std::find(turned.begin(), turned.end(), t.mesh) != turned.end()) continue;
        const IndexedFaceSet& mesh = out.head.meshes[static_cast<std::size_t>(t.mesh)];
        auto [it, made] = meshes.try_emplace(t.mesh, Points3::Zero(mesh.vertexCount(), 3));
        it->second += weight * mesh.morphTargets[static_cast<std::size_t>(t.target)].displacements;
      }
    }
    for (auto& [m, d] : meshes) added[static_cast<std::size_t>(m)].push_back({name, std::move(d)});
  }
  setKeys(out.head, std::move(added), std::move(poses), false);
  if ((options.visemes || options.expressions) && !out.mapping.keys.empty()) {
    addHighLevelKeys(out, options);
  }
  return out;
}

}  // namespace mpeg4face
