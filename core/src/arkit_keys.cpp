// SPDX-License-Identifier: GPL-3.0-or-later
// A head's FAP, viseme and expression keys made from its ARKit shapes. docs/arkit.md.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>

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

// The FAPs of an area of the skin that several FAPs share (the lips, chin, cheeks, brows and
// nose): ARKit shapes move a whole lip or brow, so the key of FAP 10 (2.8) made from them
// moves the whole lower lip, and a viseme that sends 5, 10, 11, 52, 57 and 58 together
// would lower it six times over. Their keys are localised instead (docs/arkit.md).
bool isAreaFap(int fap) {
  return (fap >= 4 && fap <= 13) || (fap >= 16 && fap <= 18) || (fap >= 31 && fap <= 42) ||
         (fap >= 51 && fap <= 64);
}

// Shepard's partition of unity over the area FAPs' feature points on a mesh: a point's share
// at each vertex, 1 at its own vertex and 0 at every other such point's,
// inverse-square distance weighted between. The shares of all the mesh's points add to 1,
// so the localised keys of neighbouring FAPs sent at one value move the area as the shapes
// do, and each key leaves every other feature point where it was.
class FeaturePointShares {
 public:
  FeaturePointShares(const FaceModel& head, int mesh) : mesh_(mesh) {
    const IndexedFaceSet& m = head.meshes[static_cast<std::size_t>(mesh)];
    std::set<std::string, std::less<>> areaPoints;
    for (const FapInfo& fap : fapTable()) {
      if (isAreaFap(fap.number)) areaPoints.emplace(fap.featurePoint);
    }
    for (const auto& [id, binding] : head.featurePoints) {
      if (!areaPoints.contains(id) || binding.mesh != mesh || binding.vertex < 0 ||
          binding.vertex >= m.vertexCount()) {
        continue;
      }
      index_[id] = static_cast<int>(points_.size());
      points_.push_back(m.coord.row(binding.vertex));
    }
    total_.resize(m.vertexCount());
    for (int v = 0; v < m.vertexCount(); ++v) {
      double sum = 0;
      for (std::size_t p = 0; p < points_.size(); ++p) sum += weight(m.coord.row(v), p);
      total_[static_cast<std::size_t>(v)] = sum;
    }
  }
  int mesh() const { return mesh_; }
  // Multiplies each row of `d` (this mesh's displacements) by the point's share.
  void localise(const std::string& id, const IndexedFaceSet& m, Points3& d) const {
    const auto it = index_.find(id);
    if (it == index_.end()) return;
    const std::size_t p = static_cast<std::size_t>(it->second);
    for (int v = 0; v < m.vertexCount(); ++v) {
      if (d.row(v).isZero()) continue;
      const double w = weight(m.coord.row(v), p);
      const double total = total_[static_cast<std::size_t>(v)];
      // At a feature point's own vertex the weights are infinite: all of it, or none.
      d.row(v) *= std::isinf(w) ? 1.0 : std::isinf(total) ? 0.0 : w / total;
    }
  }

 private:
  double weight(const Eigen::RowVector3d& x, std::size_t p) const {
    const double d2 = (x - points_[p]).squaredNorm();
    return d2 == 0 ? std::numeric_limits<double>::infinity() : 1.0 / d2;
  }
  int mesh_;
  std::map<std::string, int> index_;
  std::vector<Eigen::RowVector3d> points_;
  std::vector<double> total_;
};

// viseme1..14 and expression1..6: each alone from the neutral face, with the FAPs the FIT
// preset gives it (its own frame: nothing held from another), as keys and poses.
void addHighLevelKeys(ArkitKeys& out, const FaceModel& localised, const ArkitKeysOptions& options) {
  const ShapeKeyFace generated = faceFromShapeKeys(localised);
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
  std::vector<std::vector<MorphTarget>> localisedAdded(out.head.meshes.size());
  std::vector<MorphWeightAnimation> poses;
  std::optional<FeaturePointShares> shares;  // of the mesh the last area FAP's point is on
  // The viseme and expression keys are evaluated through the keys localised (addHighLevelKeys).
  const bool highLevel = (options.visemes || options.expressions) && !out.mapping.keys.empty();
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
    std::map<int, Points3> area;  // the same key localised, for the viseme and expression keys
    if (highLevel && isAreaFap(key.fap)) {
      const std::string point(fapInfo(key.fap).featurePoint);
      const auto binding = out.head.featurePoints.find(point);
      const auto found = binding == out.head.featurePoints.end()
                             ? meshes.end()
                             : meshes.find(binding->second.mesh);
      if (found != meshes.end()) {
        if (!shares || shares->mesh() != found->first) shares.emplace(out.head, found->first);
        Points3 d = found->second;
        shares->localise(point, out.head.meshes[static_cast<std::size_t>(found->first)], d);
        area.emplace(found->first, std::move(d));
      }
    }
    for (auto& [m, d] : meshes) {
      if (highLevel) {
        const auto it = area.find(m);
        localisedAdded[static_cast<std::size_t>(m)].push_back(
            {name, it == area.end() ? d : std::move(it->second)});
      }
      added[static_cast<std::size_t>(m)].push_back({name, std::move(d)});
    }
  }
  if (!highLevel) {
    setKeys(out.head, std::move(added), std::move(poses), false);
    return out;
  }
  FaceModel localised = out.head;  // a copy of a whole head: only when it is evaluated
  setKeys(localised, std::move(localisedAdded), poses, false);
  setKeys(out.head, std::move(added), std::move(poses), false);
  addHighLevelKeys(out, localised, options);
  return out;
}

}  // namespace mpeg4face
