// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/livelink.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::Error;
using mpeg4face::LiveLinkCapture;
using mpeg4face::test::errorOf;
using mpeg4face::test::kData;

const std::filesystem::path kCapture =
    kData / "livelink-face" / "MySlate_3_Jason_Millers_iPhone.csv";

std::string header() {
  std::string h = "Timecode,BlendShapeCount";
  for (std::string_view name : mpeg4face::liveLinkChannelNames()) (h += ',') += name;
  return h + "\n";
}

// A row with the timecode, 61 and every channel at `value` (its text), `channel` set apart.
std::string row(const std::string& timecode, const std::string& value = "0.5", int channel = -1,
                const std::string& special = "") {
  std::string r = timecode + ",61";
  for (int k = 0; k < mpeg4face::kLiveLinkChannelCount; ++k)
    r += "," + (k == channel ? special : value);
  return r + "\n";
}

LiveLinkCapture parse(const std::string& text) {
  return mpeg4face::parseLiveLinkCsv(text, "t.csv");
}

Error parseError(const std::string& text) {
  return errorOf([&] { parse(text); });
}

TEST(LiveLink, RealCapture) {
  const LiveLinkCapture c = mpeg4face::readLiveLinkCsv(kCapture);
  EXPECT_EQ(c.frameCount(), 328);
  EXPECT_EQ(c.frameRate, 60);
  ASSERT_EQ(c.values.rows(), 328);
  ASSERT_EQ(c.values.cols(), 61);
  EXPECT_EQ(c.channels[17], "JawOpen");
  // 00:32:09:07.867 at 60 fps.
  EXPECT_NEAR(c.times[0], 32 * 60 + 9 + 7.867 / 60, 1e-9);
  EXPECT_NEAR(c.times[1] - c.times[0], 1.001 / 60, 1e-9);
  EXPECT_NEAR(c.values(0, 0), 0.0491091609, 1e-12);  // EyeBlinkLeft
  EXPECT_EQ(c.clampedWeights, 0);
  EXPECT_TRUE(c.warnings.empty());
  for (int k = 0; k < 52; ++k) {
    EXPECT_GE(c.values.col(k).minCoeff(), 0);
    EXPECT_LE(c.values.col(k).maxCoeff(), 1);
  }
}

TEST(LiveLink, FrameRateFromTheTimecodes) {
  // Crossing a second shows the rate: frames up to 29 -> 30 fps, up to 24 -> 25.
  EXPECT_EQ(
      parse(header() + row("00:00:00:28.000") + row("00:00:00:29.000") + row("00:00:01:00.000"))
          .frameRate,
      30);
  EXPECT_EQ(
      parse(header() + row("00:00:00:23.500") + row("00:00:00:24.500") + row("00:00:01:00.500"))
          .frameRate,
      25);
  EXPECT_EQ(parse(header() + row("00:00:00:58.000") + row("00:00:01:00.000")).frameRate, 60);
  // Within one second the rate cannot show: 60 in doubt, unless a frame number says more.
  EXPECT_EQ(parse(header() + row("00:00:05:01.000") + row("00:00:05:02.000")).frameRate, 60);
  EXPECT_EQ(parse(header() + row("00:00:05:97.000")).frameRate, 100);
  const LiveLinkCapture c = parse(header() + row("00:00:00:29.000") + row("00:00:01:00.000"));
  EXPECT_NEAR(c.times[1] - c.times[0], 1.0 / 30, 1e-12);
}

TEST(LiveLink, ColumnsByNameAndIgnoredColumns) {
  // Two channels swapped and an extra column: found by name, the extra one named in a warning.
  std::string h = header();
  h.replace(h.find("EyeBlinkLeft"), 12, "EYEBLINKRIGHT");
  h.replace(h.find("EyeBlinkRight"), 13, "EyeBlinkLeft");
  h.insert(h.size() - 1, ",Extra");
  std::string r = row("00:00:00:00.000", "0.25");
  r.replace(r.find(",0.25"), 5, ",0.75");  // the file's first channel column: EyeBlinkRight
  r.insert(r.size() - 1, ",7");
  const LiveLinkCapture c = parse(h + r);
  EXPECT_EQ(c.values(0, 7), 0.75);  // EyeBlinkRight
  EXPECT_EQ(c.values(0, 0), 0.25);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_NE(c.warnings[0].find("'Extra'"), std::string::npos) << c.warnings[0];
}

TEST(LiveLink, WeightsOutside01AreClampedWithOneWarning) {
  const LiveLinkCapture c =
      parse(header() + row("00:00:00:00.000", "1.5") + row("00:00:00:01.000", "-0.25"));
  EXPECT_EQ(c.clampedWeights, 104);  // 52 weights per row; the angles are not weights
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_NE(c.warnings[0].find("104 blendshape weight(s) outside 0..1 clamped"), std::string::npos)
      << c.warnings[0];
  EXPECT_EQ(c.values(0, 0), 1);
  EXPECT_EQ(c.values(1, 51), 0);
  EXPECT_EQ(c.values(0, 52), 1.5);  // HeadYaw kept
  EXPECT_EQ(c.values(1, 60), -0.25);
}

TEST(LiveLink, BadInputNamesLineAndColumn) {
  const std::string h = header();
  Error e = parseError("");
  EXPECT_NE(e.reason().find("empty file"), std::string::npos) << e.what();
  e = parseError(h);
  EXPECT_EQ(e.line(), 1);
  EXPECT_NE(e.reason().find("no frames"), std::string::npos) << e.what();

  std::string noJaw = h;
  noJaw.replace(noJaw.find(",JawOpen"), 8, "");
  e = parseError(noJaw + row("00:00:00:00.000"));
  EXPECT_EQ(e.line(), 1);
  EXPECT_NE(e.reason().find("missing column(s): JawOpen"), std::string::npos) << e.what();
  e = parseError("BlendShapeCount,EyeBlinkLeft\n");
  EXPECT_EQ(e.field(), "Timecode");

  // JawOpen is channel 17, the file's column 20.
  e = parseError(h + row("00:00:00:00.000") + row("00:00:00:01.000", "0.5", 17, "abc"));
  EXPECT_EQ(e.file(), "t.csv");
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.field(), "column 20 (JawOpen)");
  EXPECT_NE(e.reason().find("a number expected, found 'abc'"), std::string::npos) << e.what();

  e = parseError(h + row("00:00:00:00.000", "0.5", 53, "nan"));
  EXPECT_EQ(e.line(), 2);
  EXPECT_EQ(e.field(), "column 56 (HeadPitch)");
  EXPECT_NE(e.reason().find("finite number expected, found 'nan'"), std::string::npos) << e.what();
  e = parseError(h + row("00:00:00:00.000", "0.5", 0, "NaN"));
  EXPECT_EQ(e.field(), "column 3 (EyeBlinkLeft)");

  e = parseError(h + row("00:00:00:05.000") + row("00:00:00:04.000"));
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.field(), "column 1 (Timecode)");
  EXPECT_NE(e.reason().find("goes backwards"), std::string::npos) << e.what();

  e = parseError(h + row("00:00:61:00.000"));
  EXPECT_EQ(e.field(), "column 1 (Timecode)");
  EXPECT_NE(e.reason().find("hh:mm:ss:frame.fraction"), std::string::npos) << e.what();
  e = parseError(h + row("12.5"));
  EXPECT_EQ(e.line(), 2);

  std::string shortRow = row("00:00:00:00.000");
  shortRow.erase(shortRow.rfind(','));
  shortRow += "\n";
  e = parseError(h + shortRow);
  EXPECT_EQ(e.line(), 2);
  EXPECT_EQ(e.field(), "column 63 (RightEyeRoll)");
  EXPECT_NE(e.reason().find("62 cells where the header has 63"), std::string::npos) << e.what();
}

// The header and the first `rows` rows of the real capture, lines split into cells.
std::vector<std::vector<std::string>> captureCells(int rows) {
  const std::string text = mpeg4face::readFile(kCapture);
  std::vector<std::vector<std::string>> lines;
  std::size_t start = 0;
  while (static_cast<int>(lines.size()) < rows + 1) {
    const std::size_t end = text.find('\n', start);
    std::string line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::vector<std::string> cells;
    for (std::size_t s = 0;;) {
      const std::size_t comma = line.find(',', s);
      cells.push_back(line.substr(s, comma - s));
      if (comma == std::string::npos) break;
      s = comma + 1;
    }
    lines.push_back(cells);
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return lines;
}

// The cells joined by `separator`, a '.' in them made `point`, quoted (RFC 4180) when
// `quote` says so for the cell.
std::string csvText(const std::vector<std::vector<std::string>>& lines, char separator,
                    char point, bool (*quote)(const std::string&, std::size_t line)) {
  std::string out;
  for (std::size_t l = 0; l < lines.size(); ++l) {
    for (std::size_t c = 0; c < lines[l].size(); ++c) {
      std::string cell = lines[l][c];
      for (char& ch : cell) ch = ch == '.' ? point : ch;
      if (c > 0) out += separator;
      out += quote(cell, l) ? "\"" + cell + "\"" : cell;
    }
    out += '\n';
  }
  return out;
}

bool never(const std::string&, std::size_t) { return false; }
bool always(const std::string&, std::size_t) { return true; }
// As a spreadsheet writes it: the header, and every cell holding a comma.
bool whereNeeded(const std::string& cell, std::size_t line) {
  return line == 0 || cell.find(',') != std::string::npos;
}

TEST(LiveLink, ADecimalCommaIsNamedInEachForm) {
  const auto lines = captureCells(4);
  ASSERT_EQ(lines.size(), 5u);
  ASSERT_EQ(lines[0].size(), 63u);

  // A correct CSV still reads, quoted or not.
  for (const auto quote : {never, always}) {
    const LiveLinkCapture c = parse(csvText(lines, ',', '.', quote));
    EXPECT_EQ(c.frameCount(), 4);
    EXPECT_NEAR(c.values(0, 0), 0.0491091609, 1e-12);
    EXPECT_NEAR(c.times[0], 32 * 60 + 9 + 7.867 / 60, 1e-9);
  }

  const auto expectDecimalComma = [](const Error& e, const std::string& example) {
    EXPECT_EQ(e.file(), "t.csv");
    EXPECT_EQ(e.line(), 2) << e.what();
    EXPECT_NE(e.reason().find("the values use a decimal comma (" + example + ")"),
              std::string::npos)
        << e.what();
    EXPECT_NE(e.reason().find("Live Link Face writes a decimal point"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("t.csv:2: "), std::string::npos) << e.what();
  };

  // Semicolon-separated: the first decimal comma of row 1 (the timecode's fraction).
  Error e = parseError(csvText(lines, ';', ',', never));
  expectDecimalComma(e, "00:32:09:07,867");
  EXPECT_EQ(e.field(), "column 1 (Timecode)");
  EXPECT_NE(e.reason().find("separated by semicolons"), std::string::npos) << e.what();

  // Comma-separated, unquoted: every value split in two; the example is the last value.
  const std::string last = lines[1].back();
  std::string lastComma = last;
  lastComma[lastComma.find('.')] = ',';
  e = parseError(csvText(lines, ',', ',', never));
  expectDecimalComma(e, lastComma);
  EXPECT_NE(e.reason().find(" cells where the header has 63 and no decimal point"),
            std::string::npos)
      << e.what();

  // RFC 4180: the cells with a comma quoted (the header too).
  e = parseError(csvText(lines, ',', ',', whereNeeded));
  expectDecimalComma(e, "00:32:09:07,867");
  EXPECT_EQ(e.field(), "column 1 (Timecode)");
  // The same with the timecode written with a decimal point: the first value is named.
  auto pointTimecode = lines;
  for (std::size_t l = 1; l < pointTimecode.size(); ++l) {
    std::string& tc = pointTimecode[l][0];
    tc = tc.substr(0, tc.find('.'));  // 00:32:09:07, no fraction
  }
  e = parseError(csvText(pointTimecode, ',', ',', whereNeeded));
  expectDecimalComma(e, "0,0491091609");
  EXPECT_EQ(e.field(), "column 3 (EyeBlinkLeft)");

  // Semicolons without decimal commas: said at the header.
  e = parseError(csvText(lines, ';', '.', never));
  EXPECT_EQ(e.line(), 1);
  EXPECT_NE(e.reason().find("separated by semicolons (;)"), std::string::npos) << e.what();
}

TEST(LiveLink, WriteReadRoundTrip) {
  const LiveLinkCapture c = mpeg4face::readLiveLinkCsv(kCapture);
  const auto path = mpeg4face::test::scratchDir() / "capture.csv";
  mpeg4face::writeLiveLinkCsv(path, c);
  // The same text as the app wrote: timecodes, channel order, ten decimals.
  EXPECT_EQ(mpeg4face::readFile(path), mpeg4face::readFile(kCapture));
  const LiveLinkCapture back = mpeg4face::readLiveLinkCsv(path);
  EXPECT_EQ(back.frameRate, c.frameRate);
  EXPECT_EQ(back.values, c.values);
  ASSERT_EQ(back.times.size(), c.times.size());
  for (std::size_t i = 0; i < c.times.size(); ++i) EXPECT_NEAR(back.times[i], c.times[i], 1e-9);
}

TEST(LiveLink, NothingHalfWritten) {
  const auto dir = mpeg4face::test::scratchDir();
  LiveLinkCapture bad = mpeg4face::readLiveLinkCsv(kCapture);
  bad.times[3] = std::numeric_limits<double>::quiet_NaN();
  const auto path = dir / "out.csv";
  const Error e = errorOf([&] { mpeg4face::writeLiveLinkCsv(path, bad); });
  EXPECT_NE(e.reason().find("time 3"), std::string::npos) << e.what();
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_TRUE(std::filesystem::is_empty(dir));  // no .part left either
  bad.values.resize(2, 3);
  errorOf([&] { mpeg4face::writeLiveLinkCsv(path, bad); });
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
