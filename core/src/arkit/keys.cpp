// SPDX-License-Identifier: GPL-3.0-or-later
// A head's FAP, viseme and expression keys made from its ARKit shapes. docs/arkit.md.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string_view>

#include "arkit/arkit_internal.hpp"
#include "mpeg4face/arkit/capture.hpp"
#include "mpeg4face/arkit/shapes.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/fit/fit.hpp"
#include "mpeg4face/fit/presets.hpp"
#include "mpeg4face/spec.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

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

// FAPs sent together to move one part of the face: a lip (inner and outer contour), a
// mouth corner, both lips forwards, a brow, the brows squeezed, both cheeks or nose wings.
// ARKit shapes move a whole lip or brow, so the key of FAP 10 (2.8) made from them moves
// the whole lower lip, and a stream that sends 5, 10, 11, 52, 57 and 58 together (as the
// Xface streams do) would lower it six times over. docs/arkit.md, "Localised keys".
constexpr std::array<std::array<int, 6>, 11> kSiblingFaps{{
    {5, 10, 11, 52, 57, 58},
    {4, 8, 9, 51, 55, 56},
    {6, 12, 53, 59},
    {7, 13, 54, 60},
    {16, 17},
    {31, 33, 35},
    {32, 34, 36},
    {37, 38},
    {39, 40},
    {41, 42},
    {61, 62},
}};

}  // namespace

namespace arkit {

std::span<const int> siblingFaps(int fap) {
  for (const auto& group : kSiblingFaps) {
    const auto end = std::find(group.begin(), group.end(), 0);
    if (std::find(group.begin(), end, fap) != end) return {group.begin(), end};
  }
  return {};
}

Points3 jawOpenCoord(const FaceModel& head, const ArkitShapes& shapes, int mesh) {
  const IndexedFaceSet& geometry = head.meshes[static_cast<std::size_t>(mesh)];
  Points3 coord = geometry.coord;
  if (const std::optional<int> jawOpen = shapes.find({arkitShapeIndex("jawOpen")->shape})) {
    for (const ArkitTarget& t : shapes.shapes[static_cast<std::size_t>(*jawOpen)].targets) {
      if (t.mesh == mesh)
        coord += geometry.morphTargets[static_cast<std::size_t>(t.target)].displacements;
    }
  }
  return coord;
}

}  // namespace arkit

namespace {

// The powers of the partitions: inverse-square over the area gives the viseme and expression
// keys each FAP's own motion; among siblings too, where a gentler fall-off (1/sqrt d, used
// before) has a cusp at each point that a capture's unlike sibling values stood out of the
// lips (issue 41; docs/arkit.md, "Localised keys").
constexpr double kAreaPower = 2.0;
constexpr double kSiblingPower = 2.0;

// A FAP key is made of ARKit shapes at weights up to 1, some at 1: sculpted no further. Its
// table is linear to kKeyReach times the amplitude and held there (a copy at twice that with
// the same motion), so a stream sending a FAP far past its key holds the shapes instead of
// driving them many times over: the Xface fear stream lowers the lower lip by -866 where
// FAP 10's key reaches -135, and linear tables tore the lip at the corners and through the
// chin. Siblings moving their points the same way share one reach on each side, the
// smallest of theirs: sent together at one value, as streams send them, they stop together
// (a sibling going on alone stood out of the lip in a spike). The capture's solver stops at
// the same reach: 3 keeps its round trip within bound with a margin, 4 lets fear's mouth
// corners tear again (docs/arkit.md, "Held keys").
constexpr double kKeyReach = 3;

// Each key's reach, 0 for keys not held: the eyeball turns and the jaw FAPs, whose motion
// may be a Transform's (a turned eye; a head's lower teeth following the chin) and a
// FaceDefTransform is linear. A key beyond its siblings' reach is brought back to it: its
// amplitude and weights scaled to the reach, the same table up to it.
std::vector<int> holdAtReach(ArkitMapping& mapping) {
  const auto own = [](const ArkitFapKey& k) {
    return static_cast<int>(std::lround(kKeyReach * k.amplitude));
  };
  const auto held = [](const ArkitFapKey& k) { return k.transform < 0 && !arkit::isJawFap(k.fap); };
  std::vector<int> reach;
  for (const ArkitFapKey& key : mapping.keys) {
    int r = held(key) ? own(key) : 0;
    const std::span<const int> group = arkit::siblingFaps(key.fap);
    for (const ArkitFapKey& other : mapping.keys) {
      if (r != 0 && other.amplitude * key.amplitude > 0 &&
          std::find(group.begin(), group.end(), other.fap) != group.end() &&
          fapInfo(other.fap).positiveMotion == fapInfo(key.fap).positiveMotion &&
          std::abs(own(other)) < std::abs(r)) {
        r = own(other);
      }
    }
    reach.push_back(r);
  }
  for (std::size_t k = 0; k < reach.size(); ++k) {
    ArkitFapKey& key = mapping.keys[k];
    if (reach[k] == 0 || std::abs(reach[k]) >= std::abs(key.amplitude)) continue;
    for (auto& weight : key.weights) weight.second *= static_cast<double>(reach[k]) / key.amplitude;
    key.amplitude = reach[k];
  }
  return reach;
}

// The teeth and the tongue move with the jaw FAPs (3, 14, 15) and the tongue's (43-47) only.
// A lip or cheek FAP's key fitted to the ARKit shapes takes a share of jawOpen and
// jawForward, lower teeth and gums included; the Xface fear stream sends twelve lip FAPs at
// once and their shares pulled the ICT sample's lower gums 10 mm back into the floor of the
// mouth. So where the teeth or the tongue are meshes of their own (a teeth or tongue point
// on a mesh that is not the chin's), the other FAPs' keys leave them still.
void keepTeethAndTongueToTheirFaps(const FaceModel& head, const ArkitMapping& mapping,
                                   std::vector<std::map<int, Points3>>& keyMotion) {
  const auto chin = head.featurePoints.find("2.1");
  const int face = chin == head.featurePoints.end() ? -1 : chin->second.mesh;
  std::set<int> parts;
  for (const auto& [id, binding] : head.featurePoints) {
    const bool teethOrTongue = id.starts_with("6.") || id == "9.8" || id == "9.9" ||
                               id == "9.10" || id == "9.11";
    if (teethOrTongue && binding.mesh >= 0 && binding.mesh != face) parts.insert(binding.mesh);
  }
  for (std::size_t k = 0; k < mapping.keys.size(); ++k) {
    const int fap = mapping.keys[k].fap;
    if (arkit::isJawFap(fap) || (fap >= 43 && fap <= 47)) continue;
    std::erase_if(keyMotion[k], [&](const auto& entry) { return parts.contains(entry.first); });
  }
}

// The FAPs of the areas several FAPs share (the lips, chin, cheeks, brows and nose).
std::vector<int> areaFaps() {
  std::vector<int> faps;
  for (int f = 4; f <= 64; ++f) {
    if (f <= 13 || (f >= 16 && f <= 18) || (f >= 31 && f <= 42) || f >= 51) faps.push_back(f);
  }
  return faps;
}

// Shepard's partition of unity over some FAPs' feature points on a mesh: a point's share at
// each vertex, 1 at its own vertex and 0 at every other of the points, inverse-distance
// weighted between (1/d^power). The shares add to 1 everywhere, so the FAPs' keys sent at
// one value move the area as the shapes do, and each key alone moves its own point and
// leaves the others where they were. Distances are taken on the face with its jaw open
// (`coord`): with the mouth closed the inner lips touch, and a lower-lip vertex would take
// an upper-lip point's share (a notch in the lip at 2.3 when FAPs 16 and 17 differ).
class FeaturePointShares {
 public:
  FeaturePointShares(const FaceModel& head, int mesh, const Points3& coord,
                     std::span<const int> faps, double power)
      : coord_(coord), power_(power) {
    for (int fap : faps) {
      const std::string id(fapInfo(fap).featurePoint);
      const auto it = head.featurePoints.find(id);
      if (it == head.featurePoints.end() || it->second.mesh != mesh || it->second.vertex < 0 ||
          it->second.vertex >= coord_.rows() || index_.contains(id)) {
        continue;
      }
      index_[id] = points_.size();
      points_.push_back(coord_.row(it->second.vertex));
    }
    total_.resize(static_cast<std::size_t>(coord_.rows()));
    for (Eigen::Index v = 0; v < coord_.rows(); ++v) {
      double sum = 0;
      for (std::size_t p = 0; p < points_.size(); ++p) sum += weight(v, p);
      total_[static_cast<std::size_t>(v)] = sum;
    }
  }
  // Multiplies each row of `d` (this mesh's displacements) by FAP `fap`'s share.
  void localise(int fap, Points3& d) const {
    const auto it = index_.find(std::string(fapInfo(fap).featurePoint));
    if (it == index_.end()) return;
    for (Eigen::Index v = 0; v < coord_.rows(); ++v) {
      if (d.row(v).isZero()) continue;
      const double w = weight(v, it->second);
      const double total = total_[static_cast<std::size_t>(v)];
      // At a feature point's own vertex the weights are infinite: all of it, or none.
      d.row(v) *= std::isinf(w) ? 1.0 : std::isinf(total) ? 0.0 : w / total;
    }
  }

 private:
  double weight(Eigen::Index v, std::size_t p) const {
    const double d2 = (coord_.row(v) - points_[p]).squaredNorm();
    return d2 == 0 ? std::numeric_limits<double>::infinity() : std::pow(d2, -power_ / 2);
  }
  const Points3& coord_;
  double power_;
  std::map<std::string, std::size_t, std::less<>> index_;
  std::vector<Eigen::RowVector3d> points_;
  std::vector<double> total_;
};

// The nearest combination of a head's ARKit shapes (weights 0..1) to a motion of its meshes:
// a viseme or expression key is made of the shapes, not of the FAP keys it was evaluated
// through (docs/arkit.md, "Viseme and expression keys"). The eye shapes are left out: an
// expression's eyeball turn is a pose.
constexpr double kProjectionWeightCost = 0.1;
class ArkitProjection {
 public:
  ArkitProjection(const FaceModel& head, const ArkitShapes& shapes) : head_(head) {
    offset_.push_back(0);
    for (const IndexedFaceSet& mesh : head.meshes)
      offset_.push_back(offset_.back() + 3 * mesh.vertexCount());
    for (const ArkitShape& shape : shapes.shapes) {
      if (!isArkitEyeShape(shape.ref.shape)) shapes_.push_back(&shape);
    }
    basis_ = Eigen::MatrixXd::Zero(offset_.back(), static_cast<Eigen::Index>(shapes_.size()));
    for (std::size_t c = 0; c < shapes_.size(); ++c) {
      for (const ArkitTarget& t : shapes_[c]->targets) {
        basis_.col(static_cast<Eigen::Index>(c))
            .segment(offset_[static_cast<std::size_t>(t.mesh)],
                     3 * head.meshes[static_cast<std::size_t>(t.mesh)].vertexCount()) =
            target(t).reshaped<Eigen::RowMajor>();
      }
    }
    gram_ = basis_.transpose() * basis_;
    // Each weight costs kProjectionWeightCost of an average shape's squared motion: shapes
    // overlap (a shape and its halves; jawOpen and mouthLowerDown), and without a cost the
    // answer is one of many, often with some shapes at 1, which a viseme and an expression
    // added push past it (a fold under the lower lip); with it the motion is shared.
    gram_.diagonal().array() += kProjectionWeightCost * gram_.trace() /
                                static_cast<double>(std::max<Eigen::Index>(1, gram_.rows()));
  }
  // `motion` per mesh (mesh space) -> the shapes' combination per mesh.
  std::vector<Points3> project(const std::vector<Points3>& motion) const {
    Eigen::VectorXd stacked(offset_.back());
    for (std::size_t m = 0; m < motion.size(); ++m)
      stacked.segment(offset_[m], offset_[m + 1] - offset_[m]) =
          motion[m].reshaped<Eigen::RowMajor>();
    const auto n = static_cast<Eigen::Index>(shapes_.size());
    Eigen::VectorXd weights = Eigen::VectorXd::Zero(n);
    boundedLeastSquares(gram_, basis_.transpose() * stacked, Eigen::VectorXd::Zero(n),
                        Eigen::VectorXd::Ones(n), weights, {});
    std::vector<Points3> out;
    for (const Points3& m : motion) out.push_back(Points3::Zero(m.rows(), 3));
    for (std::size_t c = 0; c < shapes_.size(); ++c) {
      for (const ArkitTarget& t : shapes_[c]->targets)
        out[static_cast<std::size_t>(t.mesh)] += weights[static_cast<Eigen::Index>(c)] * target(t);
    }
    return out;
  }

 private:
  const Points3& target(const ArkitTarget& t) const {
    return head_.meshes[static_cast<std::size_t>(t.mesh)]
        .morphTargets[static_cast<std::size_t>(t.target)]
        .displacements;
  }
  const FaceModel& head_;
  std::vector<const ArkitShape*> shapes_;
  std::vector<Eigen::Index> offset_;  // of each mesh's rows in the stacked motion
  Eigen::MatrixXd basis_, gram_;
};

// viseme1..14 and expression1..6: each alone from the neutral face, with the FAPs the FIT
// preset gives it (its own frame: nothing held from another), evaluated through the FAP keys
// localised over the area and made of the ARKit shapes nearest to that motion, as keys and
// poses.
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
  const ArkitProjection projection(out.head, out.shapes);
  std::vector<std::vector<MorphTarget>> added(out.head.meshes.size());
  std::vector<MorphWeightAnimation> poses;
  for (auto& [name, frame] : frames) {
    FapState state;
    applyFrame(state, frame);   // the left/right partners of what the preset gives
    FapFrame resolved = state;  // a copy of the frame part, changed below
    // The shapes reach no further than the keys: a value past a key's amplitude is held at
    // it, and one of a sign without a key is 0 (its table would run the shapes backwards).
    for (int f = 3; f <= kFapCount; ++f) {
      if (!resolved.has(f)) continue;
      const int value = resolved.value(f);
      const auto& [low, high] = reach[static_cast<std::size_t>(f - 1)];
      resolved.set(f, std::clamp(value, low, high));
    }
    const FatState shown = evaluator.evaluate(resolved);
    std::vector<Points3> motion;
    for (std::size_t m = 0; m < added.size(); ++m)
      motion.push_back(shown.coord[m] - neutral.coord[m]);
    std::vector<Points3> made = projection.project(motion);
    for (std::size_t m = 0; m < added.size(); ++m) {
      if ((made[m].array() != 0).any()) added[m].push_back({name, std::move(made[m])});
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
  const std::vector<int> reach = holdAtReach(out.mapping);

  std::vector<std::vector<MorphTarget>> added(out.head.meshes.size());
  std::vector<std::vector<MorphTarget>> localisedAdded(out.head.meshes.size());
  std::vector<MorphWeightAnimation> poses;
  // The viseme and expression keys are evaluated through the keys localised over the area
  // (addHighLevelKeys).
  const bool highLevel = (options.visemes || options.expressions) && !out.mapping.keys.empty();
  const std::vector<int> area = areaFaps();
  // Shares per mesh and FAP set, made once: keyed by the set's storage (`area` or a group of
  // kSiblingFaps).
  std::map<std::pair<int, const int*>, FeaturePointShares> shares;
  // Siblings share on the face with its jaw open (FeaturePointShares); the area's shares,
  // which only the viseme and expression keys are evaluated through, on the neutral.
  std::map<int, Points3> opened;
  const auto sharesOf = [&](int mesh, std::span<const int> faps,
                            double power) -> const FeaturePointShares& {
    const auto key = std::make_pair(mesh, faps.data());
    auto it = shares.find(key);
    if (it != shares.end()) return it->second;
    const IndexedFaceSet& geometry = out.head.meshes[static_cast<std::size_t>(mesh)];
    auto coord = opened.find(mesh);
    if (coord == opened.end())
      coord = opened.emplace(mesh, arkit::jawOpenCoord(out.head, out.shapes, mesh)).first;
    const Points3& at = faps.data() == area.data() ? geometry.coord : coord->second;
    return shares.try_emplace(key, out.head, mesh, at, faps, power).first->second;
  };
  // Each key's motion per mesh: its shapes at their weights, on the mesh of its point shared
  // over the area (for the viseme and expression keys) and among its sibling FAPs (for the
  // key written), then refitted so that keys sent together combine as the shapes do.
  std::vector<std::map<int, Points3>> keyMotion(out.mapping.keys.size());
  std::vector<std::string> names;  // each key's shape key name
  for (const ArkitFapKey& key : out.mapping.keys) {
    names.push_back(
        formatShapeKeyName({key.fap, 0, key.amplitude, std::string(fapInfo(key.fap).name)}));
  }
  for (std::size_t k = 0; k < out.mapping.keys.size(); ++k) {
    const ArkitFapKey& key = out.mapping.keys[k];
    const std::string& name = names[k];
    // An eyeball turn: the eye's Transform turns; the shape still moves the lids.
    std::vector<int> turned;
    if (key.transform >= 0) {
      poses.push_back({name, {}, {rotationChannel(key.transform, key.rotation)}});
      turned = out.head.transforms[static_cast<std::size_t>(key.transform)].meshes;
    }
    std::map<int, Points3>& meshes = keyMotion[k];
    for (const auto& [shape, weight] : key.weights) {
      for (const ArkitTarget& t : out.shapes.shapes[static_cast<std::size_t>(shape)].targets) {
        if (std::find(turned.begin(), turned.end(), t.mesh) != turned.end()) continue;
        const IndexedFaceSet& mesh = out.head.meshes[static_cast<std::size_t>(t.mesh)];
        auto [it, made] = meshes.try_emplace(t.mesh, Points3::Zero(mesh.vertexCount(), 3));
        it->second += weight * mesh.morphTargets[static_cast<std::size_t>(t.target)].displacements;
      }
    }
    const auto binding = out.head.featurePoints.find(std::string(fapInfo(key.fap).featurePoint));
    const int pointMesh = binding == out.head.featurePoints.end() ? -1 : binding->second.mesh;
    for (auto& [m, d] : meshes) {
      if (highLevel) {
        Points3 local = d;
        if (m == pointMesh) sharesOf(m, area, kAreaPower).localise(key.fap, local);
        localisedAdded[static_cast<std::size_t>(m)].push_back({name, std::move(local)});
      }
      if (m == pointMesh) {
        sharesOf(m, arkit::siblingFaps(key.fap), kSiblingPower).localise(key.fap, d);
      }
    }
  }
  arkit::fitKeysToShapeCombinations(out.head, out.shapes, fapu, out.mapping, keyMotion);
  keepTeethAndTongueToTheirFaps(out.head, out.mapping, keyMotion);
  for (std::size_t k = 0; k < out.mapping.keys.size(); ++k) {
    const ArkitFapKey& key = out.mapping.keys[k];
    const std::string& name = names[k];
    const std::string label(fapInfo(key.fap).name);
    for (auto& [m, d] : keyMotion[k]) {
      auto& keys = added[static_cast<std::size_t>(m)];
      if (reach[k] == 0) {
        keys.push_back({name, std::move(d)});
        continue;
      }
      // Linear to the reach (a copy carrying the key on, unless the key is at it), held from
      // twice that.
      Points3 far = d * (static_cast<double>(reach[k]) / key.amplitude);
      keys.push_back({name, std::move(d)});
      if (reach[k] != key.amplitude) {
        keys.push_back({formatShapeKeyName({key.fap, 0, reach[k], label + "_reach"}), far});
      }
      keys.push_back(
          {formatShapeKeyName({key.fap, 0, 2 * reach[k], label + "_held"}), std::move(far)});
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
