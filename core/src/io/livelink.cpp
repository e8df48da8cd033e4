// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/io/livelink.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "io/text_reader.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"

namespace mpeg4face {
namespace {

constexpr std::array<std::string_view, kLiveLinkChannelCount> kChannels{"EyeBlinkLeft",
                                                                        "EyeLookDownLeft",
                                                                        "EyeLookInLeft",
                                                                        "EyeLookOutLeft",
                                                                        "EyeLookUpLeft",
                                                                        "EyeSquintLeft",
                                                                        "EyeWideLeft",
                                                                        "EyeBlinkRight",
                                                                        "EyeLookDownRight",
                                                                        "EyeLookInRight",
                                                                        "EyeLookOutRight",
                                                                        "EyeLookUpRight",
                                                                        "EyeSquintRight",
                                                                        "EyeWideRight",
                                                                        "JawForward",
                                                                        "JawRight",
                                                                        "JawLeft",
                                                                        "JawOpen",
                                                                        "MouthClose",
                                                                        "MouthFunnel",
                                                                        "MouthPucker",
                                                                        "MouthRight",
                                                                        "MouthLeft",
                                                                        "MouthSmileLeft",
                                                                        "MouthSmileRight",
                                                                        "MouthFrownLeft",
                                                                        "MouthFrownRight",
                                                                        "MouthDimpleLeft",
                                                                        "MouthDimpleRight",
                                                                        "MouthStretchLeft",
                                                                        "MouthStretchRight",
                                                                        "MouthRollLower",
                                                                        "MouthRollUpper",
                                                                        "MouthShrugLower",
                                                                        "MouthShrugUpper",
                                                                        "MouthPressLeft",
                                                                        "MouthPressRight",
                                                                        "MouthLowerDownLeft",
                                                                        "MouthLowerDownRight",
                                                                        "MouthUpperUpLeft",
                                                                        "MouthUpperUpRight",
                                                                        "BrowDownLeft",
                                                                        "BrowDownRight",
                                                                        "BrowInnerUp",
                                                                        "BrowOuterUpLeft",
                                                                        "BrowOuterUpRight",
                                                                        "CheekPuff",
                                                                        "CheekSquintLeft",
                                                                        "CheekSquintRight",
                                                                        "NoseSneerLeft",
                                                                        "NoseSneerRight",
                                                                        "TongueOut",
                                                                        "HeadYaw",
                                                                        "HeadPitch",
                                                                        "HeadRoll",
                                                                        "LeftEyeYaw",
                                                                        "LeftEyePitch",
                                                                        "LeftEyeRoll",
                                                                        "RightEyeYaw",
                                                                        "RightEyePitch",
                                                                        "RightEyeRoll"};

constexpr std::array<double, 8> kTimecodeRates{24, 25, 30, 48, 50, 60, 100, 120};

// The cells of a line split at `separator`, trimmed; an RFC 4180 quoted cell ("...", "" for a
// quote inside) is its text between the quotes, separators included.
std::vector<std::string_view> splitCells(std::string_view line, char separator = ',') {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  while (true) {
    std::size_t end = line.find(separator, start);
    std::string_view cell = text::trim(line.substr(start, end - start));
    if (!cell.empty() && cell.front() == '"') {
      const std::size_t open = line.find('"', start);
      std::size_t close = open + 1;
      while ((close = line.find('"', close)) != std::string_view::npos &&
             close + 1 < line.size() && line[close + 1] == '"') {
        close += 2;
      }
      if (close != std::string_view::npos) {
        cell = line.substr(open + 1, close - open - 1);
        end = line.find(separator, close + 1);
      }
    }
    cells.push_back(cell);
    if (end == std::string_view::npos) return cells;
    start = end + 1;
  }
}

bool allDigits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// An integer part, as a decimal comma leaves it before the comma: [+-]digits or a timecode
// hh:mm:ss:ff.
bool integerPart(std::string_view s) {
  if (!s.empty() && (s.front() == '-' || s.front() == '+')) s.remove_prefix(1);
  const std::size_t colon = s.rfind(':');
  if (colon != std::string_view::npos) s.remove_prefix(colon + 1);
  return allDigits(s);
}

// "0,5" or "00:32:09:07,867": a number or timecode written with a decimal comma.
bool hasDecimalComma(std::string_view cell) {
  const std::size_t comma = cell.find(',');
  return comma != std::string_view::npos && integerPart(cell.substr(0, comma)) &&
         allDigits(cell.substr(comma + 1));
}

// Fails at the reader's line.
[[noreturn]] void failDecimalComma(const text::LineReader& reader, std::string_view field,
                                   std::string_view example, const std::string& how = {}) {
  reader.fail(field, how + "the values use a decimal comma (" + std::string(example) +
                         "): Live Link Face writes a decimal point (0.5) and separates the "
                         "cells with commas; re-export the CSV with a decimal point (e.g. "
                         "from a spreadsheet set to an English locale)");
}

struct Timecode {
  int hours = 0, minutes = 0, seconds = 0;
  double frame = 0;  // frame.fraction
};

// hh:mm:ss:frame[.fraction]; nullopt if malformed.
std::optional<Timecode> parseTimecode(std::string_view cell) {
  std::array<std::string_view, 4> parts;
  std::size_t start = 0;
  for (int i = 0; i < 4; ++i) {
    const std::size_t colon = i < 3 ? cell.find(':', start) : cell.size();
    if (colon == std::string_view::npos) return std::nullopt;
    parts[static_cast<std::size_t>(i)] = cell.substr(start, colon - start);
    start = colon + 1;
  }
  Timecode t;
  if (!text::tryParseInt(parts[0], t.hours) || !text::tryParseInt(parts[1], t.minutes) ||
      !text::tryParseInt(parts[2], t.seconds) || !text::tryParseDouble(parts[3], t.frame)) {
    return std::nullopt;
  }
  if (t.hours < 0 || t.minutes < 0 || t.minutes > 59 || t.seconds < 0 || t.seconds > 59 ||
      t.frame < 0 || t.frame >= kTimecodeRates.back()) {
    return std::nullopt;
  }
  return t;
}

std::string lowerCase(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

std::span<const std::string_view> liveLinkChannelNames() { return kChannels; }

LiveLinkCapture parseLiveLinkCsv(std::string_view text, const std::string& fileName) {
  text::LineReader reader(text, fileName);
  std::string_view line;
  do {
    if (!reader.next(line)) {
      throw Error(fileName, std::max(reader.lineNumber(), 1), "header",
                  "empty file: a Live Link Face CSV starts with the header "
                  "'Timecode,BlendShapeCount,EyeBlinkLeft,...'");
    }
  } while (text::trim(line).empty());

  LiveLinkCapture capture;
  capture.channels.assign(kChannels.begin(), kChannels.end());
  const int headerLine = reader.lineNumber();
  const std::vector<std::string_view> header = splitCells(line);
  // For each file column: the channel it holds, -1 timecode, -2 channel count, -3 ignored.
  std::vector<int> columnChannel(header.size(), -3);
  std::optional<std::size_t> timecodeColumn;
  std::vector<std::string> ignored;
  std::array<bool, kLiveLinkChannelCount> found{};
  for (std::size_t c = 0; c < header.size(); ++c) {
    const std::string name = lowerCase(header[c]);
    const auto known = std::find_if(kChannels.begin(), kChannels.end(),
                                    [&](std::string_view k) { return lowerCase(k) == name; });
    const std::string column = "column " + std::to_string(c + 1) + " " + text::quote(header[c]);
    if (name == "timecode") {
      if (timecodeColumn) throw Error(fileName, headerLine, column, "a second Timecode column");
      timecodeColumn = c;
      columnChannel[c] = -1;
    } else if (name == "blendshapecount") {
      columnChannel[c] = -2;
    } else if (known != kChannels.end()) {
      const auto channel = static_cast<std::size_t>(known - kChannels.begin());
      if (found[channel]) throw Error(fileName, headerLine, column, "a second column of this name");
      found[channel] = true;
      columnChannel[c] = static_cast<int>(channel);
    } else {
      ignored.emplace_back(header[c]);
    }
  }
  if (!timecodeColumn && header.size() == 1 && line.find(';') != std::string_view::npos) {
    // Separated by semicolons, as a spreadsheet writes a CSV where the decimal separator is a
    // comma: name the decimal comma in the first row if it has one.
    const std::vector<std::string_view> names = splitCells(line, ';');
    text::LineReader ahead = reader;
    std::string_view next;
    while (ahead.next(next) && text::trim(next).empty()) {
    }
    const std::vector<std::string_view> cells = splitCells(next, ';');
    for (std::size_t c = 0; c < cells.size(); ++c) {
      if (!hasDecimalComma(cells[c])) continue;
      failDecimalComma(ahead,
                       "column " + std::to_string(c + 1) +
                           (c < names.size() ? " (" + std::string(names[c]) + ")" : ""),
                       cells[c], "the cells are separated by semicolons and ");
    }
    throw Error(fileName, headerLine, "header",
                "the cells are separated by semicolons (;): Live Link Face separates them with "
                "commas; re-export the CSV comma-separated");
  }
  if (!timecodeColumn) {
    throw Error(fileName, headerLine, "Timecode",
                "missing column: the header has no Timecode (is this a Live Link Face CSV?)");
  }
  std::string missing;
  for (std::size_t k = 0; k < found.size(); ++k) {
    if (!found[k]) missing += (missing.empty() ? "" : ", ") + std::string(kChannels[k]);
  }
  if (!missing.empty()) {
    throw Error(fileName, headerLine, "header", "missing column(s): " + missing);
  }
  if (!ignored.empty()) {
    std::string list;
    for (const std::string& name : ignored) list += (list.empty() ? "" : ", ") + text::quote(name);
    capture.warnings.push_back(fileName +
                               ": columns ignored (not Live Link Face channels): " + list);
  }

  struct Row {
    int line;
    Timecode timecode;
  };
  std::vector<Row> rows;
  std::vector<double> values;
  const auto columnName = [&](std::size_t c) {
    return "column " + std::to_string(c + 1) + " (" + std::string(header[c]) + ")";
  };
  while (reader.next(line)) {
    if (text::trim(line).empty()) continue;
    const std::vector<std::string_view> cells = splitCells(line);
    if (cells.size() > header.size() && line.find('.') == std::string_view::npos) {
      // More cells than the header and not one decimal point: unquoted decimal commas split
      // each value in two. The example is the last value (its two cells).
      const std::size_t n = cells.size();
      if (integerPart(cells[n - 2]) && allDigits(cells[n - 1])) {
        failDecimalComma(reader, {},
                         std::string(cells[n - 2]) + "," + std::string(cells[n - 1]),
                         std::to_string(n) + " cells where the header has " +
                             std::to_string(header.size()) + " and no decimal point: ");
      }
    }
    if (cells.size() != header.size()) {
      const std::size_t c = std::min(cells.size(), header.size());
      reader.fail(c < header.size() ? columnName(c) : "column " + std::to_string(c + 1),
                  std::to_string(cells.size()) + " cells where the header has " +
                      std::to_string(header.size()));
    }
    Row row{reader.lineNumber(), {}};
    const std::size_t first = values.size();
    values.resize(first + kLiveLinkChannelCount, 0.0);
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const int channel = columnChannel[c];
      if (channel == -3) continue;
      if (channel == -1) {
        const std::optional<Timecode> t = parseTimecode(cells[c]);
        if (!t) {
          if (hasDecimalComma(cells[c])) {
            failDecimalComma(reader, columnName(c), cells[c]);
          }
          reader.fail(columnName(c),
                      "timecode hh:mm:ss:frame.fraction expected, found " + text::quote(cells[c]));
        }
        row.timecode = *t;
        continue;
      }
      double value = 0;
      if (!text::tryParseDouble(cells[c], value)) {
        if (hasDecimalComma(cells[c])) {
          failDecimalComma(reader, columnName(c), cells[c]);
        }
        const std::string lower = lowerCase(cells[c]);
        const bool notFinite =
            lower.find("nan") != std::string::npos || lower.find("inf") != std::string::npos;
        reader.fail(columnName(c),
                    (notFinite ? "a finite number expected, found " : "a number expected, found ") +
                        text::quote(cells[c]));
      }
      if (channel >= 0) values[first + static_cast<std::size_t>(channel)] = value;
    }
    rows.push_back(row);
  }
  if (rows.empty()) {
    throw Error(fileName, headerLine, "header",
                "no frames: the file has its header but no rows of values");
  }

  // The frame rate: a capture crossing a second shows its rate by the largest frame number.
  double maxFrame = 0;
  bool crossesSecond = false;
  for (const Row& r : rows) {
    maxFrame = std::max(maxFrame, std::floor(r.timecode.frame));
    crossesSecond = crossesSecond || r.timecode.seconds != rows.front().timecode.seconds;
  }
  double rate = kTimecodeRates.back();
  for (double candidate : kTimecodeRates) {
    if (candidate > maxFrame) {
      rate = candidate;
      break;
    }
  }
  capture.frameRate = crossesSecond ? rate : std::max(rate, 60.0);

  const auto frameCount = static_cast<Eigen::Index>(rows.size());
  capture.values =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          values.data(), frameCount, kLiveLinkChannelCount);
  capture.times.reserve(rows.size());
  const std::string timecodeName = columnName(*timecodeColumn);
  for (const Row& r : rows) {
    const Timecode& t = r.timecode;
    const double time =
        t.hours * 3600.0 + t.minutes * 60.0 + t.seconds + t.frame / capture.frameRate;
    if (!capture.times.empty() && time < capture.times.back()) {
      throw Error(fileName, r.line, timecodeName,
                  "the timecode goes backwards (earlier than the row before)");
    }
    capture.times.push_back(time);
  }
  for (Eigen::Index f = 0; f < frameCount; ++f) {
    for (int k = 0; k < kLiveLinkWeightCount; ++k) {
      double& w = capture.values(f, k);
      if (w < 0 || w > 1) {
        w = std::clamp(w, 0.0, 1.0);
        ++capture.clampedWeights;
      }
    }
  }
  if (capture.clampedWeights > 0) {
    capture.warnings.push_back(fileName + ": " + std::to_string(capture.clampedWeights) +
                               " blendshape weight(s) outside 0..1 clamped");
  }
  return capture;
}

LiveLinkCapture readLiveLinkCsv(const std::filesystem::path& path) {
  return parseLiveLinkCsv(readFile(path), path.string());
}

std::string formatLiveLinkCsv(const LiveLinkCapture& capture) {
  if (capture.values.cols() != kLiveLinkChannelCount ||
      capture.values.rows() != static_cast<Eigen::Index>(capture.times.size())) {
    throw Error("Live Link capture: values must be frames x 61, one row per time");
  }
  if (!(capture.frameRate > 0) || !std::isfinite(capture.frameRate)) {
    throw Error("Live Link capture: frame rate must be positive");
  }
  std::string out = "Timecode,BlendShapeCount";
  for (std::string_view name : kChannels) (out += ',') += name;
  out += '\n';
  char cell[64];
  for (std::size_t f = 0; f < capture.times.size(); ++f) {
    const double t = capture.times[f];
    if (!(t >= 0) || !std::isfinite(t)) {
      throw Error("Live Link capture: time " + std::to_string(f) + " is negative or not finite");
    }
    // Whole seconds, then the frame with three decimals (as the app writes it), carried
    // into the next second when it rounds up to the rate.
    auto seconds = static_cast<long long>(std::floor(t));
    double frame = std::round((t - static_cast<double>(seconds)) * capture.frameRate * 1000) / 1000;
    if (frame >= capture.frameRate) {
      ++seconds;
      frame = 0;
    }
    std::snprintf(cell, sizeof cell, "%02lld:%02lld:%02lld:%06.3f,%d", seconds / 3600,
                  seconds / 60 % 60, seconds % 60, frame, kLiveLinkChannelCount);
    out += cell;
    for (int k = 0; k < kLiveLinkChannelCount; ++k) {
      std::snprintf(cell, sizeof cell, ",%.10f", capture.values(static_cast<Eigen::Index>(f), k));
      out += cell;
    }
    out += '\n';
  }
  return out;
}

void writeLiveLinkCsv(const std::filesystem::path& path, const LiveLinkCapture& capture) {
  writeFileAtomically(path, formatLiveLinkCsv(capture));
}

}  // namespace mpeg4face
