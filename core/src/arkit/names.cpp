// SPDX-License-Identifier: GPL-3.0-or-later
// ARKit shape names, which of a head's morph targets are ARKit shapes, and their motion at
// the feature points. docs/arkit.md.
#include <algorithm>
#include <array>
#include <cctype>
#include <map>
#include <string>

#include "mpeg4face/arkit/shapes.hpp"
#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

constexpr std::array<std::string_view, kArkitShapeCount + 4> kKnownNames{
    "eyeBlinkLeft", "eyeLookDownLeft", "eyeLookInLeft", "eyeLookOutLeft", "eyeLookUpLeft",
    "eyeSquintLeft", "eyeWideLeft", "eyeBlinkRight", "eyeLookDownRight", "eyeLookInRight",
    "eyeLookOutRight", "eyeLookUpRight", "eyeSquintRight", "eyeWideRight", "jawForward", "jawRight",
    "jawLeft", "jawOpen", "mouthClose", "mouthFunnel", "mouthPucker", "mouthRight", "mouthLeft",
    "mouthSmileLeft", "mouthSmileRight", "mouthFrownLeft", "mouthFrownRight", "mouthDimpleLeft",
    "mouthDimpleRight", "mouthStretchLeft", "mouthStretchRight", "mouthRollLower", "mouthRollUpper",
    "mouthShrugLower", "mouthShrugUpper", "mouthPressLeft", "mouthPressRight", "mouthLowerDownLeft",
    "mouthLowerDownRight", "mouthUpperUpLeft", "mouthUpperUpRight", "browDownLeft", "browDownRight",
    "browInnerUp", "browOuterUpLeft", "browOuterUpRight", "cheekPuff", "cheekSquintLeft",
    "cheekSquintRight", "noseSneerLeft", "noseSneerRight", "tongueOut",
    // ICT-FaceKit's additions
    "cheekRaiserLeft", "cheekRaiserRight", "pupilDilateLeft", "pupilDilateRight"};

std::string lowerLetters(std::string_view text) {
  std::string out;
  for (char c : text) {
    if (c == '_' || c == '-' || c == ' ') continue;
    out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return out;
}

bool endsWith(std::string_view text, std::string_view end) {
  return text.size() >= end.size() && text.substr(text.size() - end.size()) == end;
}

// The side a name's own suffix says (eyeBlinkLeft: Left), without the exceptions.
FaceSide nameSide(std::string_view name) {
  if (endsWith(name, "Left")) return FaceSide::Left;
  if (endsWith(name, "Right")) return FaceSide::Right;
  return FaceSide::Centre;
}

std::optional<int> knownIndex(const std::string& normalised) {
  for (std::size_t i = 0; i < kKnownNames.size(); ++i) {
    if (lowerLetters(kKnownNames[i]) == normalised) return static_cast<int>(i);
  }
  return std::nullopt;
}

}  // namespace

std::span<const std::string_view> arkitShapeNames() {
  return std::span(kKnownNames).first(kArkitShapeCount);
}

std::span<const std::string_view> arkitKnownShapeNames() { return kKnownNames; }

bool isArkitEyeShape(int shape) {
  const std::string_view name = kKnownNames[static_cast<std::size_t>(shape)];
  return name.starts_with("eyeLook") || name.starts_with("pupilDilate");
}

std::optional<ArkitShapeRef> arkitShapeIndex(std::string_view targetName) {
  // A side suffix after a separator: _L, .R, -Left, " right".
  FaceSide side = FaceSide::Centre;
  std::string lower;
  for (char c : targetName) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const auto& [suffix, s] : {std::pair{std::string_view("left"), FaceSide::Left},
                                  {"right", FaceSide::Right},
                                  {"l", FaceSide::Left},
                                  {"r", FaceSide::Right}}) {
    if (lower.size() <= suffix.size() + 1 || !endsWith(lower, suffix)) continue;
    const char separator = lower[lower.size() - suffix.size() - 1];
    if (separator == '_' || separator == '.' || separator == '-' || separator == ' ') {
      side = s;
      targetName.remove_suffix(suffix.size() + 1);
      break;
    }
  }
  if (const std::size_t cut = targetName.find_last_of(".:|"); cut != std::string_view::npos) {
    targetName.remove_prefix(cut + 1);
  }
  const std::string base = lowerLetters(targetName);
  if (base.empty()) return std::nullopt;
  if (side == FaceSide::Centre) {
    if (auto i = knownIndex(base)) return ArkitShapeRef{*i, FaceSide::Centre};
    return std::nullopt;
  }
  if (auto i = knownIndex(base + (side == FaceSide::Left ? "left" : "right"))) {
    return ArkitShapeRef{*i, FaceSide::Centre};
  }
  // A half of a shape ARKit has whole (browInnerUp_L).
  if (auto i = knownIndex(base);
      i && nameSide(kKnownNames[static_cast<std::size_t>(*i)]) == FaceSide::Centre) {
    return ArkitShapeRef{*i, side};
  }
  return std::nullopt;
}

FaceSide arkitShapeSide(const ArkitShapeRef& ref) {
  if (ref.half != FaceSide::Centre) return ref.half;
  const std::string_view name = kKnownNames.at(static_cast<std::size_t>(ref.shape));
  if (name == "jawLeft" || name == "jawRight" || name == "mouthLeft" || name == "mouthRight") {
    return FaceSide::Centre;
  }
  return nameSide(name);
}

std::string arkitShapeLabel(const ArkitShapeRef& ref) {
  std::string label(kKnownNames.at(static_cast<std::size_t>(ref.shape)));
  if (ref.half == FaceSide::Left) label += " (left half)";
  if (ref.half == FaceSide::Right) label += " (right half)";
  return label;
}

std::optional<int> ArkitShapes::find(const ArkitShapeRef& ref) const {
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    if (shapes[i].ref == ref) return static_cast<int>(i);
  }
  return std::nullopt;
}

ArkitShapes findArkitShapes(const FaceModel& head) {
  // (shape, half) -> the shape; ordered as arkitKnownShapeNames, whole before left before right.
  std::map<std::pair<int, int>, ArkitShape> found;
  for (std::size_t m = 0; m < head.meshes.size(); ++m) {
    const IndexedFaceSet& mesh = head.meshes[m];
    for (std::size_t t = 0; t < mesh.morphTargets.size(); ++t) {
      const std::string& name = mesh.morphTargets[t].name;
      const std::optional<ArkitShapeRef> ref = arkitShapeIndex(name);
      if (!ref) continue;
      ArkitShape& shape = found[{ref->shape, static_cast<int>(ref->half)}];
      if (shape.targets.empty()) {
        shape.ref = *ref;
        shape.name = name;
      } else if (shape.name != name) {
        throw Error({}, 0, "morph targets",
                    "'" + shape.name + "' and '" + name + "' are both ARKit's " +
                        arkitShapeLabel(*ref) + ": rename or remove one");
      }
      shape.targets.push_back({static_cast<int>(m), static_cast<int>(t)});
    }
  }
  if (found.empty()) {
    std::string names;
    for (std::string_view n : kKnownNames) names += (names.empty() ? "" : ", ") + std::string(n);
    throw Error({}, 0, "morph targets",
                "no morph target is an ARKit blendshape; looked for " + names +
                    " (case, '_' and prefixes like 'blendShape1.' ignored; eyeBlink_L, "
                    "EyeBlinkLeft and eye_blink_left are eyeBlinkLeft)");
  }
  ArkitShapes out;
  for (auto& [key, shape] : found) out.shapes.push_back(std::move(shape));
  return out;
}

ArkitPointMotion arkitFeaturePointMotion(const FaceModel& head, const ArkitShapes& shapes,
                                         std::span<const std::string> ids) {
  const std::vector<Eigen::Affine3d> world = head.meshWorldMatrices();
  ArkitPointMotion out;
  std::vector<FeaturePointBinding> bindings;
  for (const std::string& id : ids) {
    auto it = head.featurePoints.find(id);
    if (it == head.featurePoints.end() || it->second.mesh < 0) continue;
    const FeaturePointBinding& b = it->second;
    if (b.mesh >= static_cast<int>(head.meshes.size()) || b.vertex < 0 ||
        b.vertex >= head.meshes[static_cast<std::size_t>(b.mesh)].vertexCount()) {
      throw Error({}, 0, "feature point " + id, "bound to a vertex the head does not have");
    }
    out.points.push_back(id);
    bindings.push_back(b);
  }
  out.motion = Eigen::MatrixXd::Zero(3 * static_cast<Eigen::Index>(out.points.size()),
                                     static_cast<Eigen::Index>(shapes.shapes.size()));
  for (std::size_t s = 0; s < shapes.shapes.size(); ++s) {
    for (const ArkitTarget& t : shapes.shapes[s].targets) {
      const IndexedFaceSet& mesh = head.meshes[static_cast<std::size_t>(t.mesh)];
      const Points3& d = mesh.morphTargets[static_cast<std::size_t>(t.target)].displacements;
      for (std::size_t p = 0; p < bindings.size(); ++p) {
        if (bindings[p].mesh != t.mesh) continue;
        out.motion.block<3, 1>(3 * static_cast<Eigen::Index>(p), static_cast<Eigen::Index>(s)) +=
            world[static_cast<std::size_t>(t.mesh)].linear() *
            d.row(bindings[p].vertex).transpose();
      }
    }
  }
  return out;
}

}  // namespace mpeg4face
