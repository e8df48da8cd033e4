// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/fat_names.hpp"

#include <map>
#include <set>

#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"
#include "text_reader.hpp"

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

ShapeKeyCopies deformedCopiesFromShapeKeys(const FaceModel& model) {
  model.validate();
  const FaceModel basis = neutralFaceModel(model);
  ShapeKeyCopies out;
  std::map<std::string, std::size_t> copyOf;
  std::set<std::string> ignored;
  for (std::size_t m = 0; m < model.meshes.size(); ++m) {
    const IndexedFaceSet& mesh = model.meshes[m];
    std::set<std::string> onThisMesh;
    for (const MorphTarget& target : mesh.morphTargets) {
      const std::string field = "mesh '" + mesh.name + "' morph target " + text::quote(target.name);
      std::optional<ShapeKeyName> key;
      try {
        key = parseShapeKeyName(target.name);
      } catch (const Error& e) {
        throw Error({}, 0, field, e.reason());
      }
      if (!key) {
        if (ignored.insert(target.name).second) out.ignored.push_back(target.name);
        continue;
      }
      if (!onThisMesh.insert(target.name).second) {
        throw Error({}, 0, field, "appears twice on this mesh");
      }
      auto [it, added] = copyOf.try_emplace(target.name, out.copies.size());
      if (added) {
        DeformedCopy& copy = out.copies.emplace_back();
        copy.name = target.name;
        copy.fapID = key->fapID;
        copy.highLevelSelect = key->highLevelSelect;
        copy.amplitude = key->amplitude;
        copy.model = basis;
      }
      out.copies[it->second].model.meshes[m].coord += target.displacements;
    }
  }
  return out;
}

ShapeKeyFace faceFromShapeKeys(const FaceModel& model, const GeneratorOptions& options) {
  ShapeKeyCopies keys = deformedCopiesFromShapeKeys(model);
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
