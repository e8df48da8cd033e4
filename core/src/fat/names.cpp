// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/fat/names.hpp"

#include <map>
#include <set>

#include "io/text_reader.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

constexpr std::string_view kGrammar =
    "shape keys for the FAT generator are named fap<N>[_<name>]@<amplitude> (N 3..68, amplitude "
    "a non-zero integer), viseme<N>[_<label>] (N 1..14) or "
    "expression<N>[_<label>][@<intensity>] (N 1..6, intensity 1..63, default 63); <name> and "
    "<label> are letters, digits, '_' and '-'";

char lower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

std::string lowered(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = lower(c);
  return out;
}

bool isDigit(char c) { return c >= '0' && c <= '9'; }

bool isLabelChar(char c) {
  return isDigit(c) || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || c == '-';
}

// Matches `prefix` at the start of `name` regardless of case.
bool startsWith(std::string_view name, std::string_view prefix) {
  if (name.size() < prefix.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    if (lower(name[i]) != prefix[i]) return false;
  }
  return true;
}

class NameParser {
 public:
  explicit NameParser(std::string_view name) : name_(name) {}

  std::optional<ShapeKeyName> parse() {
    ShapeKeyName key;
    std::string_view kind;
    for (std::string_view prefix : {"fap", "viseme", "expression"}) {
      if (!startsWith(name_, prefix)) continue;
      const std::string_view rest = name_.substr(prefix.size());
      if (!rest.empty() && !isDigit(rest[0]) && rest[0] != '_' && rest[0] != '@') continue;
      kind = prefix;
      pos_ = prefix.size();
    }
    if (kind.empty()) return std::nullopt;

    const int number = parseNumber(kind);
    if (pos_ < name_.size() && name_[pos_] == '_') {
      const std::size_t start = ++pos_;
      while (pos_ < name_.size() && isLabelChar(name_[pos_])) ++pos_;
      key.label = std::string(name_.substr(start, pos_ - start));
      if (key.label.empty()) fail("'_' must be followed by a name");
    }
    std::optional<int> amount;
    if (pos_ < name_.size() && name_[pos_] == '@') {
      const std::string_view digits = name_.substr(pos_ + 1);
      int value = 0;
      if (digits.empty()) fail("'@' must be followed by an integer");
      if (!text::tryParseInt(digits, value)) {
        fail(text::quote(digits) + " after '@' is not an integer");
      }
      amount = value;
      pos_ = name_.size();
    }
    if (pos_ < name_.size()) {
      fail("unexpected " + text::quote(name_.substr(pos_, 1)) + " after " +
           text::quote(name_.substr(0, pos_)));
    }

    if (kind == "fap") {
      if (number == 1 || number == 2) {
        fail("FAP 1 and 2 are named viseme<N> and expression<N>");
      }
      if (number < 3 || number > kFapCount) fail("FAP " + std::to_string(number) + " is not 3..68");
      if (!amount) fail("the amplitude '@<value>' is missing");
      if (*amount == 0) fail("amplitude 0 is the neutral face");
      if (!key.label.empty()) {
        const std::string label = lowered(key.label);
        const FapInfo& info = fapInfo(number);
        const std::optional<int> named = fapNumber(label);
        if (named && label != info.name && label != info.bifsName) {
          fail("'" + key.label + "' is the name of FAP " + std::to_string(*named) + ", not FAP " +
               std::to_string(number) + " (" + std::string(info.name) + ")");
        }
      }
      key.fapID = number;
      key.amplitude = *amount;
    } else if (kind == "viseme") {
      if (number < 1 || number > 14) fail("viseme " + std::to_string(number) + " is not 1..14");
      if (amount) fail("a viseme takes no '@' (it is shown fully)");
      key.fapID = 1;
      key.highLevelSelect = number;
      key.amplitude = 63;
    } else {
      if (number < 1 || number > 6) fail("expression " + std::to_string(number) + " is not 1..6");
      if (amount && (*amount < 1 || *amount > 63)) {
        fail("intensity " + std::to_string(*amount) + " is not 1..63");
      }
      if (!key.label.empty()) {
        const std::string label = lowered(key.label);
        for (const ExpressionInfo& e : expressionTable()) {
          if (e.name == label && e.number != number) {
            fail("'" + key.label + "' is expression " + std::to_string(e.number) +
                 ", not expression " + std::to_string(number));
          }
        }
      }
      key.fapID = 2;
      key.highLevelSelect = number;
      key.amplitude = amount.value_or(63);
    }
    return key;
  }

 private:
  int parseNumber(std::string_view kind) {
    const std::size_t start = pos_;
    while (pos_ < name_.size() && isDigit(name_[pos_])) ++pos_;
    int number = 0;
    if (pos_ == start) fail("the number after '" + std::string(kind) + "' is missing");
    if (!text::tryParseInt(name_.substr(start, pos_ - start), number)) {
      fail("the number " + text::quote(name_.substr(start, pos_ - start)) + " is too large");
    }
    return number;
  }

  [[noreturn]] void fail(const std::string& why) const {
    throw Error({}, 0, "shape key " + text::quote(name_), why + "; " + std::string(kGrammar));
  }

  std::string_view name_;
  std::size_t pos_ = 0;
};

}  // namespace

std::optional<ShapeKeyName> parseShapeKeyName(std::string_view name) {
  return NameParser(name).parse();
}

std::string formatShapeKeyName(const ShapeKeyName& key) {
  std::string out = key.fapID == 1 ? "viseme" : key.fapID == 2 ? "expression" : "fap";
  out += std::to_string(key.fapID <= 2 ? key.highLevelSelect : key.fapID);
  if (!key.label.empty()) out.append("_").append(key.label);
  if (key.fapID >= 3 || (key.fapID == 2 && key.amplitude != 63)) {
    out.append("@").append(std::to_string(key.amplitude));
  }
  return out;
}

namespace {

// The value a transform channel ends on: its last key (the value, for CubicSpline, between
// the in- and out-tangents). Throws naming `field` for a channel that does not fit the model.
Eigen::VectorXd finalValue(const TransformChannel& channel, const FaceModel& model,
                           const std::string& field) {
  if (channel.transform < 0 || channel.transform >= static_cast<int>(model.transforms.size())) {
    throw Error({}, 0, field,
                "transform " + std::to_string(channel.transform) + " out of range (the model has " +
                    std::to_string(model.transforms.size()) + ")");
  }
  const std::size_t width = channel.path == TransformChannel::Path::Rotation ? 4 : 3;
  const std::size_t keys = channel.times.size();
  const bool spline = channel.interpolation == MorphWeightChannel::Interpolation::CubicSpline;
  if (keys == 0 || channel.values.size() != keys * width * (spline ? 3 : 1)) {
    throw Error({}, 0, field,
                std::to_string(channel.values.size()) + " values for " + std::to_string(keys) +
                    " keys (expected " + std::to_string(width) + " a key" +
                    (spline ? ", x3 for CUBICSPLINE)" : ")"));
  }
  const std::size_t start = (spline ? 3 * (keys - 1) + 1 : keys - 1) * width;
  return Eigen::Map<const Eigen::VectorXd>(channel.values.data() + start,
                                           static_cast<Eigen::Index>(width));
}

// Our names, their copies and the names that are not ours, collected from morph targets
// and animations alike.
class CopyCollector {
 public:
  explicit CopyCollector(const FaceModel& model) : transforms_(model.transforms) {}

  // The copy named `name`, made from the basis on first use; nullptr for a name that is not
  // ours (remembered as ignored). `field` names the name's place for a malformed one.
  FaceShape* copy(const std::string& name, const std::string& field) {
    std::optional<ShapeKeyName> key;
    try {
      key = parseShapeKeyName(name);
    } catch (const Error& e) {
      throw Error({}, 0, field, e.reason());
    }
    if (!key) {
      if (ignored_.insert(name).second) out.ignored.push_back(name);
      return nullptr;
    }
    auto [it, added] = copyOf_.try_emplace(name, out.copies.size());
    if (added) {
      FaceShape& copy = out.copies.emplace_back();
      copy.name = name;
      copy.fapID = key->fapID;
      copy.highLevelSelect = key->highLevelSelect;
      copy.amplitude = key->amplitude;
    }
    return &out.copies[it->second];
  }

  // The basis's Transforms, which a pose starts from.
  const std::vector<Transform>& transforms() const { return transforms_; }

  ShapeKeyCopies out;

 private:
  std::vector<Transform> transforms_;
  std::map<std::string, std::size_t> copyOf_;
  std::set<std::string> ignored_;
};

}  // namespace

ShapeKeyCopies shapesFromShapeKeys(const FaceModel& model) {
  model.validate();
  CopyCollector collector(model);
  for (std::size_t m = 0; m < model.meshes.size(); ++m) {
    const IndexedFaceSet& mesh = model.meshes[m];
    std::set<std::string> onThisMesh;
    for (const MorphTarget& target : mesh.morphTargets) {
      const std::string field = "mesh '" + mesh.name + "' morph target " + text::quote(target.name);
      FaceShape* copy = collector.copy(target.name, field);
      if (copy == nullptr) continue;
      if (!onThisMesh.insert(target.name).second) {
        throw Error({}, 0, field, "appears twice on this mesh");
      }
      // Meshes are visited ascending, each once per name: copy->meshes stays ascending.
      MeshDisplacement d = sparseDisplacement(static_cast<int>(m), target.displacements);
      if (!d.vertices.empty()) copy->meshes.push_back(std::move(d));
    }
  }
  // A pose: the transforms an animation of our name ends on (eyes, jaw, head as objects or
  // bones), joining the copy of the morph targets of that name if there are any.
  for (const MorphWeightAnimation& animation : model.animations) {
    if (animation.transformChannels.empty()) continue;
    const std::string field = "animation " + text::quote(animation.name);
    FaceShape* copy = collector.copy(animation.name, field);
    if (copy == nullptr) continue;
    for (const TransformChannel& channel : animation.transformChannels) {
      const Eigen::VectorXd v = finalValue(channel, model, field);
      if (copy->transforms.empty()) copy->transforms = collector.transforms();
      Transform& t = copy->transforms[static_cast<std::size_t>(channel.transform)];
      switch (channel.path) {
        case TransformChannel::Path::Translation:
          t.translation = v;
          break;
        case TransformChannel::Path::Scale:
          t.scale = v;
          break;
        case TransformChannel::Path::Rotation:
          t.rotation = Eigen::Quaterniond(v[3], v[0], v[1], v[2]).normalized();
          break;
      }
    }
  }
  return std::move(collector.out);
}

ShapeKeyFace faceFromShapeKeys(const FaceModel& model, const GeneratorOptions& options) {
  ShapeKeyCopies keys = shapesFromShapeKeys(model);
  ShapeKeyFace out;
  // The basis scene graph is the neutral face: the targets are what the tables replace.
  out.face.faceSceneGraph = neutralFaceModel(model);
  GeneratedTables generated = generateFaceDefTables(
      out.face.faceSceneGraph, measureFapu(out.face.faceSceneGraph), keys.copies, options);
  out.face.faceDefTables = std::move(generated.faceDefTables);
  out.copies = keys.copies.size();
  out.warnings = std::move(generated.warnings);
  out.ignored = std::move(keys.ignored);
  return out;
}

}  // namespace mpeg4face
