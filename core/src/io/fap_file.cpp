// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/io/fap_file.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdlib>
#include <vector>

#include "io/text_reader.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"

namespace mpeg4face {
namespace {

// The fields of FAP 1 and FAP 2 in file order, with their largest value (the smallest is 0).
struct HighLevelField {
  const char* name;
  int max;
};
constexpr std::array<HighLevelField, 4> kVisemeFields{{
    {"viseme_select1", 14},
    {"viseme_select2", 14},
    {"viseme_blend", 63},
    {"viseme_def", 1},
}};
constexpr std::array<HighLevelField, 6> kExpressionFields{{
    {"expression_select1", 6},
    {"expression_intensity1", 63},
    {"expression_select2", 6},
    {"expression_intensity2", 63},
    {"init_face", 1},
    {"expression_def", 1},
}};

std::array<int, 4> visemeFields(const Viseme& v) {
  return {v.select1, v.select2, v.blend, v.def ? 1 : 0};
}
std::array<int, 6> expressionFields(const Expression& e) {
  return {e.select1, e.intensity1, e.select2, e.intensity2, e.initFace ? 1 : 0, e.def ? 1 : 0};
}

// How many integers FAP `fap` takes on a values line.
size_t valueCount(int fap) {
  if (fap == 1) return kVisemeFields.size();
  if (fap == 2) return kExpressionFields.size();
  return 1;
}

// Built once: the reader names a field with each value it parses.
const std::string& fapField(int fap) {
  static const auto names = [] {
    std::array<std::string, kFapCount> n;
    for (int f = 1; f <= kFapCount; ++f)
      n[static_cast<size_t>(f - 1)] =
          "FAP " + std::to_string(f) + " " + std::string(fapInfo(f).name);
    return n;
  }();
  return names[static_cast<size_t>(fap - 1)];
}
std::string fapField(int fap, const HighLevelField& f) {
  return "FAP " + std::to_string(fap) + " " + f.name;
}

bool isSupportedVersion(std::string_view v) { return v == "2.0" || v == "2.1" || v == "2.2"; }

// Version 2.0 units to FAPU, to the nearest (halves away from zero).
int fromVersion20(int raw) {
  const int half = kFapVersion20Scale / 2;
  return raw >= 0 ? (raw + half) / kFapVersion20Scale : -((-raw + half) / kFapVersion20Scale);
}

std::string highLevelRangeProblem(int value, const HighLevelField& f) {
  if (value >= 0 && value <= f.max) return {};
  return std::to_string(value) + " is out of range 0.." + std::to_string(f.max);
}

std::string magnitudeProblem(long long value) {
  if (std::llabs(value) <= kMaxFapMagnitude) return {};
  return std::to_string(value) + " is out of range: |value| must be at most " +
         std::to_string(kMaxFapMagnitude) + " FAPU";
}

class FapParser {
 public:
  FapParser(std::string_view text, const std::string& fileName) : lines_(text, fileName) {}

  FapStream parse() {
    std::string_view line;
    bool first = true;
    while (lines_.next(line)) {
      const std::string_view content = text::trim(line);
      if (content.empty() || content.front() == '#') continue;
      text::splitWhitespace(content, tokens_);
      // A header starts with its version (2.x); a mask line with 0 or 1.
      if (first && tokens_[0] != "0" && tokens_[0] != "1") {
        parseHeader(content);
      } else if (!maskPending_) {
        if (first) stream_.headerLine = false;
        parseMask();
      } else {
        parseValues();
      }
      first = false;
    }
    finish(first);
    return std::move(stream_);
  }

 private:
  [[noreturn]] void fail(std::string_view field, const std::string& message) const {
    lines_.fail(field, message);
  }

  void parseHeader(std::string_view content) {
    const size_t n = tokens_.size();
    if (n < 3) {
      fail("header",
           "expected 'version name frame_rate frame_count', found " + text::quote(content));
    }
    if (!isSupportedVersion(tokens_[0])) {
      fail("version",
           "unsupported .fap version " + text::quote(tokens_[0]) + " (expected 2.0, 2.1 or 2.2)");
    }
    stream_.version = std::string(tokens_[0]);
    version20_ = stream_.version == "2.0";
    if (n > 3) {
      const char* begin = tokens_[1].data();
      const char* end = tokens_[n - 3].data() + tokens_[n - 3].size();
      stream_.name.assign(begin, end);
    }
    const double rate = lines_.toDouble(tokens_[n - 2], "frame rate");
    if (!(rate > 0.0 && rate <= kMaxFapFrameRate)) {
      fail("frame rate", text::quote(tokens_[n - 2]) + " is out of range (0, " +
                             std::to_string(static_cast<int>(kMaxFapFrameRate)) + "] Hz");
    }
    stream_.frameRate = rate;
    declaredFrames_ = lines_.toInt(tokens_[n - 1], "frame count");
    if (declaredFrames_ < 0 || declaredFrames_ > kMaxFapFrames) {
      fail("frame count",
           text::quote(tokens_[n - 1]) + " is out of range 0.." + std::to_string(kMaxFapFrames));
    }
    headerLine_ = lines_.lineNumber();
    // Each frame takes at least two lines of 68 and 2 bytes: cap what the count may reserve.
    const size_t fit = lines_.remainingBytes() / (2 * kFapCount + 2) + 1;
    stream_.frames.reserve(std::min(static_cast<size_t>(declaredFrames_), fit));
  }

  void parseMask() {
    if (declaredFrames_ >= 0 && stream_.frames.size() == static_cast<size_t>(declaredFrames_)) {
      fail("frame count", "more frames than the " + std::to_string(declaredFrames_) +
                              " the header (line " + std::to_string(headerLine_) + ") announces");
    }
    size_t offset = 0;
    if (tokens_.size() == kFapCount + 1) {
      // Greta indexed its arrays by FAP number and once wrote slot 0 (unused) first.
      if (tokens_[0] != "0") {
        fail("mask", "a 69-token mask (Greta) must start with its unused slot 0, found " +
                         text::quote(tokens_[0]));
      }
      offset = 1;
    } else if (tokens_.size() != kFapCount) {
      fail("mask", "expected 68 tokens of 0 or 1 (69 with Greta's leading slot 0), found " +
                       std::to_string(tokens_.size()));
    }
    mask_.reset();
    for (int fap = 1; fap <= kFapCount; ++fap) {
      const std::string_view t = tokens_[offset + static_cast<size_t>(fap - 1)];
      if (t == "1") {
        mask_.set(static_cast<size_t>(fap - 1));
      } else if (t != "0") {
        fail("mask", fapField(fap) + " must be 0 or 1, found " + text::quote(t));
      }
    }
    maskPending_ = true;
    maskLine_ = lines_.lineNumber();
  }

  void parseValues() {
    size_t expected = 0;
    for (int fap = 1; fap <= kFapCount; ++fap) {
      if (mask_[static_cast<size_t>(fap - 1)]) expected += valueCount(fap);
    }
    const auto maskNote = [&] {
      return "the mask on line " + std::to_string(maskLine_) + " sends " +
             std::to_string(mask_.count()) + " FAPs, " + std::to_string(expected) + " values";
    };
    const size_t found = tokens_.size() - 1;
    if (found < expected) {
      // Name the first FAP (and field of FAP 1 / 2) whose value is missing.
      size_t at = 0;
      int fap = 1;
      for (; fap <= kFapCount; ++fap) {
        if (!mask_[static_cast<size_t>(fap - 1)]) continue;
        if (at + valueCount(fap) > found) break;
        at += valueCount(fap);
      }
      const size_t k = found - at;  // fields of `fap` present
      const std::string field = fap == 1   ? fapField(fap, kVisemeFields[k])
                                : fap == 2 ? fapField(fap, kExpressionFields[k])
                                           : fapField(fap);
      fail(field, "value missing: " + maskNote() + ", this line has " + std::to_string(found) +
                      " after the frame number");
    }
    if (found > expected) {
      fail("values", "too many values: " + maskNote() + ", this line has " + std::to_string(found) +
                         " after the frame number");
    }

    FapFrame frame;
    frame.number = lines_.toInt(tokens_[0], "frame number");
    if (frame.number < 0)
      fail("frame number", "must not be negative, found " + text::quote(tokens_[0]));
    if (!stream_.frames.empty() && frame.number <= stream_.frames.back().number) {
      fail("frame number", std::to_string(frame.number) + " does not follow frame " +
                               std::to_string(stream_.frames.back().number) +
                               ": frame numbers must increase");
    }
    frame.mask = mask_;
    size_t next = 1;
    for (int fap = 1; fap <= kFapCount; ++fap) {
      if (!mask_[static_cast<size_t>(fap - 1)]) continue;
      if (fap == 1) {
        const auto v = readHighLevel<4>(fap, kVisemeFields, next);
        frame.viseme = {v[0], v[1], v[2], v[3] == 1};
      } else if (fap == 2) {
        const auto e = readHighLevel<6>(fap, kExpressionFields, next);
        frame.expression = {e[0], e[1], e[2], e[3], e[4] == 1, e[5] == 1};
      } else {
        const std::string_view t = tokens_[next++];
        const int raw = lines_.toInt(t, fapField(fap));
        const int value = version20_ ? fromVersion20(raw) : raw;
        const std::string problem = magnitudeProblem(value);
        if (!problem.empty()) {
          fail(fapField(fap), version20_ ? text::quote(t) + " in 2.0 units: " + problem : problem);
        }
        frame.values[static_cast<size_t>(fap - 1)] = value;
      }
    }
    stream_.frames.push_back(frame);
    maskPending_ = false;
  }

  template <size_t N>
  std::array<int, N> readHighLevel(int fap, const std::array<HighLevelField, N>& fields,
                                   size_t& next) const {
    std::array<int, N> out{};
    for (size_t k = 0; k < N; ++k) {
      const std::string_view t = tokens_[next++];
      out[k] = lines_.toInt(t, fapField(fap, fields[k]));
      const std::string problem = highLevelRangeProblem(out[k], fields[k]);
      if (!problem.empty()) fail(fapField(fap, fields[k]), problem);
    }
    return out;
  }

  void finish(bool empty) {
    if (empty) throw Error(lines_.fileName(), 0, {}, "no FAP header or frames (empty file)");
    if (maskPending_) {
      throw Error(lines_.fileName(), maskLine_, "values",
                  "the file ends after this mask line: its values line is missing");
    }
    if (declaredFrames_ >= 0 && stream_.frames.size() < static_cast<size_t>(declaredFrames_)) {
      fail("frame count", "the file ends after " + std::to_string(stream_.frames.size()) +
                              " frames, but the header (line " + std::to_string(headerLine_) +
                              ") announces " + std::to_string(declaredFrames_));
    }
  }

  text::LineReader lines_;
  FapStream stream_;
  std::vector<std::string_view> tokens_;
  std::bitset<kFapCount> mask_;
  bool maskPending_ = false;
  bool version20_ = false;
  int maskLine_ = 0;
  int headerLine_ = 0;
  int declaredFrames_ = -1;  // -1: no header
};

template <typename T>
void appendNumber(std::string& out, T value) {
  std::array<char, 32> buffer{};
  const auto [end, ec] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out.append(buffer.data(), end);
}

class FapWriter {
 public:
  FapWriter(const FapStream& stream, std::string fileName)
      : stream_(stream), file_(std::move(fileName)) {}

  std::string write() {
    checkHeader();
    std::string out;
    out.reserve(stream_.frames.size() * (4 * kFapCount + 16) + 256);
    if (stream_.headerLine) {
      out += stream_.version;
      if (!stream_.name.empty()) out += ' ' + stream_.name;
      out += ' ';
      appendNumber(out, stream_.frameRate);
      out += ' ';
      appendNumber(out, stream_.frames.size());
      out += '\n';
    }
    const bool version20 = stream_.version == "2.0";
    for (size_t i = 0; i < stream_.frames.size(); ++i) {
      const FapFrame& frame = stream_.frames[i];
      checkNumber(i);
      for (size_t k = 0; k < kFapCount; ++k) out += frame.mask[k] ? "1 " : "0 ";
      out += '\n';
      appendNumber(out, frame.number);
      out += ' ';
      for (int fap = 1; fap <= kFapCount; ++fap) {
        if (!frame.has(fap)) continue;
        if (fap == 1) {
          writeHighLevel(out, i, fap, kVisemeFields, visemeFields(frame.viseme));
        } else if (fap == 2) {
          writeHighLevel(out, i, fap, kExpressionFields, expressionFields(frame.expression));
        } else {
          const int value = frame.value(fap);
          const std::string problem = magnitudeProblem(value);
          if (!problem.empty()) fail(i, fapField(fap), problem);
          appendNumber(out, version20 ? value * kFapVersion20Scale : value);
          out += ' ';
        }
      }
      out += '\n';
    }
    return out;
  }

 private:
  [[noreturn]] void fail(std::string_view field, const std::string& message) const {
    throw Error(file_, 0, std::string(field), message);
  }
  [[noreturn]] void fail(size_t frame, std::string_view field, const std::string& message) const {
    fail("frame " + std::to_string(frame) + " (number " +
             std::to_string(stream_.frames[frame].number) + ") " + std::string(field),
         message);
  }

  void checkHeader() const {
    if (!isSupportedVersion(stream_.version)) {
      fail("version", "cannot write .fap version " + text::quote(stream_.version) +
                          " (expected 2.0, 2.1 or 2.2)");
    }
    if (!(stream_.frameRate > 0.0 && stream_.frameRate <= kMaxFapFrameRate)) {
      fail("frame rate", std::to_string(stream_.frameRate) + " is out of range (0, " +
                             std::to_string(static_cast<int>(kMaxFapFrameRate)) + "] Hz");
    }
    if (stream_.frames.size() > static_cast<size_t>(kMaxFapFrames)) {
      fail("frame count", std::to_string(stream_.frames.size()) + " frames, more than " +
                              std::to_string(kMaxFapFrames));
    }
    const std::string_view name = stream_.name;
    if (name.find('\n') != std::string_view::npos || text::trim(name) != name) {
      fail("name", text::quote(name) +
                       " cannot be kept in a .fap header: it holds a line break or starts or "
                       "ends with whitespace");
    }
    if (!stream_.headerLine && (stream_.version != "2.1" || stream_.frameRate != 25.0)) {
      fail("header",
           "a .fap file without header line is read as version 2.1 at 25 Hz; this "
           "stream is version " +
               stream_.version + " at " + std::to_string(stream_.frameRate) + " Hz");
    }
  }

  void checkNumber(size_t i) const {
    const int number = stream_.frames[i].number;
    if (number < 0) fail(i, "frame number", "must not be negative");
    if (i > 0 && number <= stream_.frames[i - 1].number) {
      fail(i, "frame number",
           "does not follow " + std::to_string(stream_.frames[i - 1].number) +
               ": frame numbers must increase");
    }
  }

  template <size_t N>
  void writeHighLevel(std::string& out, size_t frame, int fap,
                      const std::array<HighLevelField, N>& fields,
                      const std::array<int, N>& values) const {
    for (size_t k = 0; k < N; ++k) {
      const std::string problem = highLevelRangeProblem(values[k], fields[k]);
      if (!problem.empty()) fail(frame, fapField(fap, fields[k]), problem);
      appendNumber(out, values[k]);
      out += ' ';
    }
  }

  const FapStream& stream_;
  std::string file_;
};

}  // namespace

FapStream parseFap(std::string_view text, const std::string& fileName) {
  return FapParser(text, fileName).parse();
}

FapStream readFapFile(const std::filesystem::path& path) {
  return parseFap(readFile(path), path.string());
}

std::string fapText(const FapStream& stream) { return FapWriter(stream, {}).write(); }

void writeFapFile(const std::filesystem::path& path, const FapStream& stream) {
  writeFileAtomically(path, FapWriter(stream, path.string()).write());
}

}  // namespace mpeg4face
