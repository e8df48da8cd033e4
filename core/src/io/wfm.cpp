// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/io/wfm.hpp"

#include <algorithm>
#include <cstddef>
#include <optional>
#include <string>

#include "io/text_reader.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

enum class Section {
  None,  // an ordinary comment
  Vertices,
  Faces,
  AnimationUnits,
  ShapeUnits,
  Skipped,  // ANIMATION PARAMETERS, SHAPE PARAMETERS, TEXTURE, GLOBAL MOTION, END OF FILE
  Unknown,  // another header-like comment: its data is skipped too
};

// The text of a comment line without '#' and the spaces around it; nullopt if not a comment.
std::optional<std::string_view> commentText(std::string_view line) {
  line = text::trim(line);
  if (line.empty() || line.front() != '#') return std::nullopt;
  return text::trim(line.substr(1));
}

// Section headers are upper-case comments ending in ':' ("# VERTEX LIST:"). Version notes
// ("# 3.1.5: * AUV14 ... changed:") and "# FAPs not implemented:" have lower case, so they
// stay comments.
Section sectionOf(std::string_view comment) {
  if (comment.empty() || comment.back() != ':') return Section::None;
  if (std::any_of(comment.begin(), comment.end(), [](char c) { return c >= 'a' && c <= 'z'; })) {
    return Section::None;
  }
  const std::string_view name = text::trim(comment.substr(0, comment.size() - 1));
  if (name == "VERTEX LIST") return Section::Vertices;
  if (name == "FACE LIST") return Section::Faces;
  if (name == "ANIMATION UNITS LIST") return Section::AnimationUnits;
  if (name == "SHAPE UNITS LIST") return Section::ShapeUnits;
  if (name == "ANIMATION PARAMETERS" || name == "SHAPE PARAMETERS" || name == "TEXTURE" ||
      name == "GLOBAL MOTION" || name == "END OF FILE") {
    return Section::Skipped;
  }
  return Section::Unknown;
}

bool isFapuName(std::string_view s) {
  const auto table = fapuTable();
  return std::any_of(table.begin(), table.end(), [&](const FapuInfo& f) { return f.name == s; });
}

class WfmParser {
 public:
  WfmParser(std::string_view text, const std::string& fileName) : reader_(text, fileName) {}

  CandideModel parse() {
    enum class State { Preamble, AfterList, Skipping } state = State::Preamble;
    std::string_view line;
    while (reader_.next(line)) {
      if (text::trim(line).empty()) continue;
      const std::optional<std::string_view> comment = commentText(line);
      if (!comment) {
        if (state == State::Skipping) continue;
        if (state == State::Preamble) {
          reader_.fail({}, "'# VERTEX LIST:' expected, found " + text::quote(line));
        }
        reader_.fail(section_, "unexpected line after the last row of the list: " +
                                   text::quote(line) + " (does the count match?)");
      }
      const Section section = sectionOf(*comment);
      if (section == Section::None) continue;
      state = State::AfterList;
      switch (section) {
        case Section::Vertices:
          parseVertices();
          break;
        case Section::Faces:
          parseFaces();
          break;
        case Section::AnimationUnits:
          parseUnits(result_.animationUnits, haveAnimationUnits_, "ANIMATION UNITS LIST");
          break;
        case Section::ShapeUnits:
          parseUnits(result_.shapeUnits, haveShapeUnits_, "SHAPE UNITS LIST");
          break;
        default:
          state = State::Skipping;
      }
    }
    if (!haveVertices_) {
      throw Error(reader_.fileName(), 0, "VERTEX LIST", "no '# VERTEX LIST:' section");
    }
    if (!haveFaces_) throw Error(reader_.fileName(), 0, "FACE LIST", "no '# FACE LIST:' section");
    result_.model.addMeshWithTransform(std::move(mesh_));
    return std::move(result_);
  }

 private:
  // Called with the header as the current line: fails if that section came already.
  void startSection(bool& seen, std::string_view name, bool needsVertices) {
    section_ = name;
    if (seen) reader_.fail(name, "second '# " + std::string(name) + ":' section");
    if (needsVertices && !haveVertices_) {
      reader_.fail(name, "comes before '# VERTEX LIST:', which its indices refer to");
    }
    seen = true;
  }

  bool nextNonBlank(std::string_view& line) {
    while (reader_.next(line)) {
      if (!text::trim(line).empty()) return true;
    }
    return false;
  }

  // A count line: one non-negative integer.
  int parseCount(std::string_view line, std::string_view section) {
    text::splitWhitespace(line, tokens_);
    if (tokens_.size() != 1) {
      reader_.fail(section, "a count expected, found " + text::quote(text::trim(line)));
    }
    const int count = reader_.toInt(tokens_[0], section);
    if (count < 0) reader_.fail(section, "negative count " + std::to_string(count));
    return count;
  }

  int readCount(std::string_view section) {
    std::string_view line;
    if (!nextNonBlank(line)) reader_.fail(section, "the file ends before the count");
    return parseCount(line, section);
  }

  // Counts in the input must not reserve more than the rest of the text could hold.
  std::size_t cappedReserve(int count) const {
    return std::min(static_cast<std::size_t>(count), reader_.remainingBytes() / 2);
  }

  // Row `index` of a list of `count`, split into tokens_, which must number `width`.
  void nextRow(std::string_view section, int count, int index, std::size_t width,
               std::string_view layout) {
    std::string_view line;
    const std::string shortBy = "count says " + std::to_string(count) + " rows, but ";
    if (!nextNonBlank(line)) {
      reader_.fail(section, shortBy + "the file ends after " + std::to_string(index));
    }
    if (commentText(line))
      reader_.fail(section,
                   shortBy + "only " + std::to_string(index) + " follow before this comment");
    text::splitWhitespace(line, tokens_);
    if (tokens_.size() != width) {
      reader_.fail(section, std::to_string(width) + " values (" + std::string(layout) +
                                ") expected, found " + std::to_string(tokens_.size()) + " in " +
                                text::quote(text::trim(line)));
    }
  }

  int vertexIndex(std::string_view token, std::string_view section) const {
    const int index = reader_.toInt(token, section);
    if (index < 0 || index >= mesh_.vertexCount()) {
      reader_.fail(section, "vertex " + std::to_string(index) + " out of range (the model has " +
                                std::to_string(mesh_.vertexCount()) + " vertices)");
    }
    return index;
  }

  void parseVertices() {
    constexpr std::string_view kSection = "VERTEX LIST";
    startSection(haveVertices_, kSection, false);
    const int count = readCount(kSection);
    std::vector<double> xyz;
    xyz.reserve(3 * cappedReserve(count));
    for (int i = 0; i < count; ++i) {
      nextRow(kSection, count, i, 3, "x y z");
      for (std::string_view token : tokens_) xyz.push_back(reader_.toDouble(token, kSection));
    }
    mesh_.name = "candide3";
    mesh_.coord = Eigen::Map<const Points3>(xyz.data(), count, 3);
  }

  void parseFaces() {
    constexpr std::string_view kSection = "FACE LIST";
    startSection(haveFaces_, kSection, true);
    const int count = readCount(kSection);
    mesh_.coordIndex.reserve(4 * cappedReserve(count));
    for (int i = 0; i < count; ++i) {
      nextRow(kSection, count, i, 3, "i j k");
      for (std::string_view token : tokens_) {
        mesh_.coordIndex.push_back(vertexIndex(token, kSection));
      }
      mesh_.coordIndex.push_back(-1);
    }
  }

  // "FAP 3 open_jaw" and "FAP10 raise_b_lip_lm" give 3 and 10; other names 0. A FAP name the
  // table knows must match the number; unknown spellings (CANDIDE's "strecth_l_nose") are
  // accepted, the number wins.
  int fapOf(std::string_view name, std::string_view section) const {
    if (name.substr(0, 3) != "FAP") return 0;
    std::string_view rest = text::trim(name.substr(3));
    std::size_t digits = 0;
    while (digits < rest.size() && rest[digits] >= '0' && rest[digits] <= '9') ++digits;
    if (digits == 0 || (digits < rest.size() && !text::isSpace(rest[digits]))) return 0;
    const int number = reader_.toInt(rest.substr(0, digits), section);
    if (number < 1 || number > kFapCount) {
      reader_.fail(section, "FAP " + std::to_string(number) + " does not exist (1 to 68)");
    }
    rest = text::trim(rest.substr(digits));
    const std::string_view fapName = rest.substr(0, rest.find_first_of(" \t"));
    const std::optional<int> known = fapName.empty() ? std::nullopt : fapNumber(fapName);
    if (known && *known != number) {
      reader_.fail(section, "unit named " + text::quote(name) + ", but " + std::string(fapName) +
                                " is FAP " + std::to_string(*known));
    }
    return number;
  }

  // Each unit: one or more comment lines (the first is the name, for FAP units the second the
  // FAPU tag), a count, and `vertex dx dy dz` rows.
  void parseUnits(std::vector<CandideUnit>& units, bool& seen, std::string_view section) {
    startSection(seen, section, true);
    const int count = readCount(section);
    units.reserve(cappedReserve(count) / 8);
    const std::string shortBy = "count says " + std::to_string(count) + " units, but ";
    for (int u = 0; u < count; ++u) {
      CandideUnit unit;
      bool named = false;
      std::string_view line;
      while (true) {
        if (!nextNonBlank(line)) {
          reader_.fail(section, shortBy + "the file ends after " + std::to_string(u));
        }
        const std::optional<std::string_view> comment = commentText(line);
        if (!comment) break;
        const Section next = sectionOf(*comment);
        if (next != Section::None && next != Section::Unknown) {
          reader_.fail(section, shortBy + "only " + std::to_string(u) + " come before " +
                                    text::quote(text::trim(line)));
        }
        if (comment->empty()) continue;
        if (!named) {
          unit.name = text::toUtf8(*comment);
          unit.fap = fapOf(*comment, section);
          named = true;
        } else if (unit.fap != 0 && unit.fapu.empty() && isFapuName(*comment)) {
          unit.fapu = std::string(*comment);
        }
      }
      if (!named) reader_.fail(section, "a '# name' comment expected before the unit's count");
      const int rows = parseCount(line, section);
      std::vector<double> d;
      d.reserve(3 * cappedReserve(rows));
      unit.vertices.reserve(cappedReserve(rows));
      for (int i = 0; i < rows; ++i) {
        nextRow(section, rows, i, 4, "vertex dx dy dz");
        unit.vertices.push_back(vertexIndex(tokens_[0], section));
        for (std::size_t k = 1; k < 4; ++k) d.push_back(reader_.toDouble(tokens_[k], section));
      }
      unit.displacements = Eigen::Map<const Points3>(d.data(), rows, 3);
      units.push_back(std::move(unit));
    }
  }

  text::LineReader reader_;
  std::string_view section_;  // the list being read, or read last
  std::vector<std::string_view> tokens_;
  IndexedFaceSet mesh_;
  CandideModel result_;
  bool haveVertices_ = false;
  bool haveFaces_ = false;
  bool haveAnimationUnits_ = false;
  bool haveShapeUnits_ = false;
};

}  // namespace

CandideModel parseWfm(std::string_view text, const std::string& fileName) {
  return WfmParser(text, fileName).parse();
}

CandideModel readWfm(const std::filesystem::path& path) {
  return parseWfm(readFile(path), path.string());
}

FaceModel candideToFaceModel(const CandideModel& candide) {
  FaceModel model = candide.model;
  if (model.meshes.size() != 1) {
    throw Error({}, 0, "CANDIDE model",
                "expected exactly one mesh, found " + std::to_string(model.meshes.size()));
  }
  IndexedFaceSet& mesh = model.meshes.front();
  for (const CandideUnit& unit : candide.animationUnits) {
    if (static_cast<Eigen::Index>(unit.vertices.size()) != unit.displacements.rows()) {
      throw Error({}, 0, "animation unit '" + unit.name + "'",
                  "needs one displacement per vertex entry");
    }
    MorphTarget target{unit.name, Points3::Zero(mesh.vertexCount(), 3)};
    for (std::size_t i = 0; i < unit.vertices.size(); ++i) {
      const int v = unit.vertices[i];
      if (v < 0 || v >= mesh.vertexCount()) {
        throw Error({}, 0, "animation unit '" + unit.name + "'",
                    "vertex " + std::to_string(v) + " out of range");
      }
      // A vertex listed twice moves by the sum, as a linear unit would move it.
      target.displacements.row(v) += unit.displacements.row(static_cast<Eigen::Index>(i));
    }
    mesh.morphTargets.push_back(std::move(target));
  }
  return model;
}

void nameCandideFapUnits(FaceModel& model, const CandideModel& candide) {
  std::vector<MorphTarget>& targets = model.meshes.at(0).morphTargets;
  if (targets.size() != candide.animationUnits.size()) {
    throw Error({}, 0, "CANDIDE model", "expected candideToFaceModel's morph targets, one a unit");
  }
  const FapuMeasurement fapu = measureFapu(model);
  std::vector<MorphTarget> named;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const CandideUnit& unit = candide.animationUnits[i];
    if (unit.fap == 0) {
      named.push_back(std::move(targets[i]));
      continue;
    }
    const FapInfo& info = fapInfo(unit.fap);
    const FapuInfo* unitFapu = nullptr;
    for (const FapuInfo& f : fapuTable()) {
      if (unit.fapu.empty() ? f.kind == info.fapu : f.name == unit.fapu) unitFapu = &f;
    }
    if (unitFapu == nullptr) {
      throw Error({}, 0, "animation unit '" + unit.name + "'", "unknown FAPU '" + unit.fapu + "'");
    }
    const double scale = fapu.unit(unitFapu->kind);
    if (scale == 0) {
      throw Error({}, 0, "animation unit '" + unit.name + "'",
                  std::string(unitFapu->neutralName) +
                      " is not measured: bind the feature points it needs (mpeg4face info "
                      "names them)");
    }
    for (int sign : {1, -1}) {
      if (sign < 0 && !info.bidirectional) break;
      const int amplitude = sign * kCandideUnitAmplitude;
      named.push_back({formatShapeKeyName({unit.fap, 0, amplitude, std::string(info.name)}),
                       targets[i].displacements * (amplitude * scale)});
    }
  }
  targets = std::move(named);
  model.meshes[0].weights.clear();  // one weight a target: the old ones no longer fit
}

}  // namespace mpeg4face
