// SPDX-License-Identifier: GPL-3.0-or-later
// The .fap reader and writer: the nine Xface streams, the quirks of other writers, and errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/files.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::Error;
using mpeg4face::FapFrame;
using mpeg4face::FapStream;
using mpeg4face::parseFap;
using mpeg4face::test::errorOf;
using mpeg4face::test::kData;

const std::vector<std::string> kXface = {"anger", "beg", "disgust", "fear", "happy-for",
                                         "hate",  "joy", "pride",   "test"};

bool contains(const Error& e, const std::string& text) {
  return std::string(e.what()).find(text) != std::string::npos;
}

// A 68-token mask line with the given FAPs set.
std::string maskLine(std::initializer_list<int> faps) {
  std::string tokens(2 * 68, ' ');
  for (int i = 0; i < 68; ++i) tokens[2 * i] = '0';
  for (int fap : faps) tokens[2 * (fap - 1)] = '1';
  tokens.back() = '\n';
  return tokens;
}

TEST(FapFile, XfaceTestStreamHeaderMaskAndValues) {
  const FapStream s = mpeg4face::readFapFile(kData / "xface-fap" / "test.fap");
  EXPECT_EQ(s.version, "2.1");
  EXPECT_EQ(s.name, "C:\\Users\\balci\\Work\\FACE\\exml2fap\\files\\TempFile");
  EXPECT_EQ(s.frameRate, 25.0);
  EXPECT_TRUE(s.headerLine);
  ASSERT_EQ(s.frames.size(), 43u);
  // Line 2 of the file, read by eye: FAPs 3-20, 23-26, 31-42, 48-60 and 63 are sent.
  std::vector<int> sent;
  for (int fap = 1; fap <= 68; ++fap) {
    if (s.frames[1].has(fap)) sent.push_back(fap);
  }
  std::vector<int> expected;
  for (int fap = 3; fap <= 20; ++fap) expected.push_back(fap);
  for (int fap : {23, 24, 25, 26}) expected.push_back(fap);
  for (int fap = 31; fap <= 42; ++fap) expected.push_back(fap);
  for (int fap = 48; fap <= 60; ++fap) expected.push_back(fap);
  expected.push_back(63);
  EXPECT_EQ(sent, expected);
  // Line 5: "1 0 8 10 1 1 8 8 10 10 0 0 0 0 0 0 0 -2 -2 1 1 -1 -1 -1 -1 0 0 0 0 1 1 0 0 0 0
  // 2 -5 -2 8 10 1 1 8 8 10 10 0 0 0".
  const FapFrame& f = s.frames[1];
  EXPECT_EQ(f.number, 1);
  EXPECT_EQ(f.value(3), 0);
  EXPECT_EQ(f.value(4), 8);
  EXPECT_EQ(f.value(5), 10);
  EXPECT_EQ(f.value(19), -2);
  EXPECT_EQ(f.value(23), 1);
  EXPECT_EQ(f.value(25), -1);
  EXPECT_EQ(f.value(31), -1);
  EXPECT_EQ(f.value(37), 1);
  EXPECT_EQ(f.value(48), 2);
  EXPECT_EQ(f.value(49), -5);
  EXPECT_EQ(f.value(50), -2);
  EXPECT_EQ(f.value(52), 10);
  EXPECT_EQ(f.value(63), 0);
  EXPECT_FALSE(f.has(1));
  EXPECT_FALSE(f.has(21));
  for (size_t i = 0; i < s.frames.size(); ++i) EXPECT_EQ(s.frames[i].number, int(i));
}

TEST(FapFile, AllNineXfaceStreamsRoundTripByteIdentical) {
  for (const std::string& name : kXface) {
    const auto path = kData / "xface-fap" / (name + ".fap");
    const std::string original = mpeg4face::readFile(path);
    const FapStream s = mpeg4face::readFapFile(path);
    EXPECT_GE(s.frames.size(), 43u) << name;
    EXPECT_EQ(mpeg4face::fapText(s), original) << name;
    const auto copy = mpeg4face::test::scratchDir() / (name + ".fap");
    mpeg4face::writeFapFile(copy, s);
    EXPECT_EQ(mpeg4face::readFile(copy), original) << name;
    EXPECT_FALSE(std::filesystem::exists(copy.string() + ".part")) << name;
  }
}

TEST(FapFile, HighLevelFapsTakeFourAndSixFields) {
  const std::string text = "2.2 talk 30 2\n" + maskLine({1, 2, 3}) +
                           "0 3 11 40 1 1 50 4 10 0 1 -120\n" + maskLine({1}) + "1 14 0 63 0\n";
  const FapStream s = parseFap(text, "hl.fap");
  EXPECT_EQ(s.version, "2.2");
  EXPECT_EQ(s.frameRate, 30.0);
  ASSERT_EQ(s.frames.size(), 2u);
  EXPECT_EQ(s.frames[0].viseme, (mpeg4face::Viseme{3, 11, 40, true}));
  EXPECT_EQ(s.frames[0].expression, (mpeg4face::Expression{1, 50, 4, 10, false, true}));
  EXPECT_EQ(s.frames[0].value(3), -120);
  EXPECT_EQ(s.frames[1].viseme, (mpeg4face::Viseme{14, 0, 63, false}));
  EXPECT_FALSE(s.frames[1].has(2));
  // Written back in the file's own layout.
  EXPECT_EQ(mpeg4face::fapText(s), "2.2 talk 30 2\n" + maskLine({1, 2, 3}).replace(135, 1, " \n") +
                                       "0 3 11 40 1 1 50 4 10 0 1 -120 \n" +
                                       maskLine({1}).replace(135, 1, " \n") + "1 14 0 63 0 \n");
}

TEST(FapFile, QuirksCommentsCrlfBlankLinesSkippedNumbersNoHeaderGreta69) {
  // Headerless, CRLF, comments and blank lines between records (Greta writes those), frame
  // numbers that skip, and Greta's 69-token masks (slot 0 first).
  std::string mask69 = "0 " + maskLine({3, 48});
  std::string text = "# made by hand\r\n" + mask69 + "\r\n" + "0 100 -7\r\n\r\n# between\r\n" +
                     maskLine({3}) + "5 90\r\n" + mask69 + "12 80 -6";
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n' && (i == 0 || text[i - 1] != '\r')) text.insert(i++, "\r");
  }
  const FapStream s = parseFap(text, "quirks.fap");
  EXPECT_FALSE(s.headerLine);
  EXPECT_EQ(s.frameRate, 25.0);
  EXPECT_EQ(s.version, "2.1");
  ASSERT_EQ(s.frames.size(), 3u);
  EXPECT_EQ(s.frames[0].number, 0);
  EXPECT_EQ(s.frames[1].number, 5);
  EXPECT_EQ(s.frames[2].number, 12);
  EXPECT_TRUE(s.frames[0].has(3));
  EXPECT_TRUE(s.frames[0].has(48));
  EXPECT_FALSE(s.frames[0].has(2));
  EXPECT_EQ(s.frames[0].value(48), -7);
  EXPECT_FALSE(s.frames[1].has(48));
  EXPECT_EQ(s.frames[2].value(3), 80);
  // Written back without header, LF, 68-token masks; reads back to the same stream.
  const std::string written = mpeg4face::fapText(s);
  EXPECT_EQ(written.find('\r'), std::string::npos);
  EXPECT_EQ(written.substr(0, 2 * 68 + 1), maskLine({3, 48}).replace(135, 1, " \n"));
  EXPECT_EQ(parseFap(written, "again.fap"), s);
}

TEST(FapFile, Version20ValuesAreTwentiethsOfFapu) {
  // 2.0 low-level values are divided by 20 to the nearest (halves away from zero); FAP 1 and
  // 2 fields are indices and stay as they are.
  const std::string text =
      "2.0 old 25 1\n" + maskLine({1, 3, 4, 5, 6, 7}) + "0 2 3 10 0 200 -30 10 -10 7\n";
  const FapStream s = parseFap(text, "old.fap");
  EXPECT_EQ(s.version, "2.0");
  const FapFrame& f = s.frames.at(0);
  EXPECT_EQ(f.viseme, (mpeg4face::Viseme{2, 3, 10, false}));
  EXPECT_EQ(f.value(3), 10);
  EXPECT_EQ(f.value(4), -2);  // -1.5
  EXPECT_EQ(f.value(5), 1);   // 0.5
  EXPECT_EQ(f.value(6), -1);  // -0.5
  EXPECT_EQ(f.value(7), 0);   // 0.35
  // Written back in 2.0 units: exact where the 2.0 value was a multiple of 20.
  const std::string written = mpeg4face::fapText(s);
  EXPECT_NE(written.find("\n0 2 3 10 0 200 -40 20 -20 0 \n"), std::string::npos) << written;
  EXPECT_EQ(parseFap(written, "again.fap"), s);
}

TEST(FapFile, HeaderNameMayHoldSpacesOrBeEmpty) {
  FapStream s = parseFap("2.1 my talking head 12.5 0\n", "n.fap");
  EXPECT_EQ(s.name, "my talking head");
  EXPECT_EQ(s.frameRate, 12.5);
  EXPECT_TRUE(s.frames.empty());
  EXPECT_EQ(mpeg4face::fapText(s), "2.1 my talking head 12.5 0\n");
  s = parseFap("2.1 29.97 0\n", "n.fap");
  EXPECT_EQ(s.name, "");
  EXPECT_EQ(s.frameRate, 29.97);
  EXPECT_EQ(mpeg4face::fapText(s), "2.1 29.97 0\n");
}

TEST(FapFile, WriterRefusesWhatCannotReadBack) {
  FapStream s;
  s.frames.resize(2);
  s.frames[0].number = 3;
  s.frames[1].number = 3;
  Error e = errorOf([&] { mpeg4face::fapText(s); });
  EXPECT_EQ(e.field(), "frame 1 (number 3) frame number");
  EXPECT_TRUE(contains(e, "must increase")) << e.what();

  s.frames[1].number = 4;
  s.frames[1].set(5, 2'000'000);
  e = errorOf([&] { mpeg4face::fapText(s); });
  EXPECT_EQ(e.field(), "frame 1 (number 4) FAP 5 raise_b_midlip");

  s.frames[1].set(5, 0);
  s.frames[0].mask.set(0);
  s.frames[0].viseme.blend = 64;
  e = errorOf([&] { mpeg4face::fapText(s); });
  EXPECT_EQ(e.field(), "frame 0 (number 3) FAP 1 viseme_blend");
  EXPECT_TRUE(contains(e, "64 is out of range 0..63")) << e.what();

  s.frames[0].viseme.blend = 0;
  s.name = "two\nlines";
  EXPECT_EQ(errorOf([&] { mpeg4face::fapText(s); }).field(), "name");
  s.name = "ok";
  s.version = "3.0";
  EXPECT_EQ(errorOf([&] { mpeg4face::fapText(s); }).field(), "version");
  s.version = "2.1";
  s.headerLine = false;
  s.frameRate = 30;
  EXPECT_EQ(errorOf([&] { mpeg4face::fapText(s); }).field(), "header");
  s.frameRate = 25;
  EXPECT_EQ(parseFap(mpeg4face::fapText(s), "x.fap").frames, s.frames);

  // A failed write leaves nothing behind.
  const auto dir = mpeg4face::test::scratchDir();
  s.frames[0].number = 9;
  e = errorOf([&] { mpeg4face::writeFapFile(dir / "bad.fap", s); });
  EXPECT_EQ(e.file(), (dir / "bad.fap").string());
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.fap"));
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.fap.part"));
}

TEST(FapFile, ErrorsNameFileLineAndField) {
  const std::string head = "2.1 x 25 1\n";
  Error e = errorOf([&] { parseFap(head + maskLine({3, 4}) + "0 12\n", "a.fap"); });
  EXPECT_EQ(e.file(), "a.fap");
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.field(), "FAP 4 lower_t_midlip");
  EXPECT_TRUE(contains(e,
                       "value missing: the mask on line 2 sends 2 FAPs, 2 values, this line "
                       "has 1"))
      << e.what();

  e = errorOf([&] { parseFap(head + maskLine({1}) + "0 1 2 3\n", "a.fap"); });
  EXPECT_EQ(e.field(), "FAP 1 viseme_def");

  e = errorOf([&] { parseFap(head + maskLine({2}) + "0 7 1 2 3 0 0\n", "a.fap"); });
  EXPECT_EQ(e.field(), "FAP 2 expression_select1");
  EXPECT_TRUE(contains(e, "7 is out of range 0..6")) << e.what();

  e = errorOf([&] { parseFap(head + maskLine({3}) + "0 1 2\n", "a.fap"); });
  EXPECT_EQ(e.field(), "values");
  EXPECT_TRUE(contains(e, "too many values")) << e.what();

  e = errorOf([&] {
    parseFap("2.1 x 25 2\n" + maskLine({3}) + "4 1\n" + maskLine({3}) + "4 2\n", "a.fap");
  });
  EXPECT_EQ(e.line(), 5);
  EXPECT_EQ(e.field(), "frame number");

  e = errorOf([&] { parseFap("", "empty.fap"); });
  EXPECT_TRUE(contains(e, "empty.fap: no FAP header or frames")) << e.what();
}

Error malformed(const std::string& name) {
  return errorOf([&] { mpeg4face::readFapFile(kData / "malformed" / name); });
}

struct Expected {
  const char* file;
  int line;
  const char* field;
  const char* text;
};

TEST(FapFile, MalformedFilesGiveClearErrors) {
  const Expected cases[] = {
      {"fap_truncated.fap", 9, "frame count",
       "the file ends after 4 frames, but the header (line 1) announces 10"},
      {"fap_truncated_mask.fap", 8, "values", "its values line is missing"},
      {"fap_bad_mask_token.fap", 4, "mask", "FAP 23 yaw_l_eyeball must be 0 or 1, found '2'"},
      {"fap_short_mask.fap", 6, "mask", "expected 68 tokens of 0 or 1"},
      {"fap_wrong_value_count.fap", 5, "FAP 48 head_pitch", "value missing"},
      {"fap_too_many_values.fap", 3, "values", "too many values"},
      {"fap_huge_frame_count.fap", 1, "frame count", "'99999999' is out of range 0..10000000"},
      {"fap_int_overflow_count.fap", 1, "frame count", "out of range: '4000000000'"},
      {"fap_huge_value.fap", 5, "FAP 3 open_jaw", "5000000 is out of range"},
      {"fap_non_numeric.fap", 3, "FAP 23 yaw_l_eyeball", "integer expected, found '1O'"},
      {"fap_bad_version.fap", 1, "version", "unsupported .fap version '3.0'"},
      {"fap_bad_frame_rate.fap", 1, "frame rate", "'0' is out of range"},
      {"fap_frame_number_backwards.fap", 7, "frame number", "1 does not follow frame 2"},
      {"fap_garbage.fap", 1, "version", "unsupported .fap version"},
  };
  for (const Expected& c : cases) {
    const Error e = malformed(c.file);
    EXPECT_EQ(e.file(), (kData / "malformed" / c.file).string());
    EXPECT_EQ(e.line(), c.line) << c.file << ": " << e.what();
    EXPECT_EQ(e.field(), c.field) << c.file << ": " << e.what();
    EXPECT_TRUE(contains(e, c.text)) << c.file << ": " << e.what();
  }
  const Error empty = malformed("fap_empty.fap");
  EXPECT_TRUE(contains(empty, "no FAP header or frames")) << empty.what();
}

TEST(FapFile, TruncatedAnywhereFailsOrKeepsEveryFrame) {
  // A cut inside the last number still parses (nothing marks the end of a line); every other
  // cut must fail naming a line of the part that is there.
  const std::string text = mpeg4face::readFile(kData / "xface-fap" / "test.fap");
  for (size_t cut = 0; cut < text.size(); cut += 37) {
    const std::string part = text.substr(0, cut);
    try {
      EXPECT_EQ(parseFap(part, "cut.fap").frames.size(), 43u) << cut;
    } catch (const Error& e) {
      EXPECT_EQ(e.file(), "cut.fap");
      EXPECT_LE(e.line(), std::count(part.begin(), part.end(), '\n') + 1) << cut;
    }
  }
}

TEST(FapFile, Version20ValuesOutOfRangeAfterConversion) {
  const Error e =
      errorOf([] { parseFap("2.0 x 25 1\n" + maskLine({3}) + "0 -25000000\n", "v.fap"); });
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.field(), "FAP 3 open_jaw");
  EXPECT_TRUE(contains(e, "'-25000000' in 2.0 units: -1250000 is out of range")) << e.what();
}

}  // namespace
