// SPDX-License-Identifier: GPL-3.0-or-later
// The FAP stream model: times, left/right pairs, and resolution (hold and mirroring).
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <utility>
#include <vector>

#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/stream/fap_stream.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::FapFrame;
using mpeg4face::fapInfo;
using mpeg4face::fapMirror;
using mpeg4face::FapState;
using mpeg4face::FapStream;

FapFrame frame(int number, std::initializer_list<std::pair<int, int>> values) {
  FapFrame f;
  f.number = number;
  for (auto [fap, v] : values) f.set(fap, v);
  return f;
}

TEST(FapStream, TimesAndDuration) {
  FapStream s;
  s.frameRate = 25;
  s.frames = {frame(0, {}), frame(5, {}), frame(12, {})};
  EXPECT_DOUBLE_EQ(mpeg4face::frameTime(s, s.frames[1]), 0.2);
  EXPECT_DOUBLE_EQ(mpeg4face::frameTime(s, s.frames[2]), 0.48);
  EXPECT_DOUBLE_EQ(mpeg4face::streamDuration(s), 13 / 25.0);  // frames 0..12
  s.frames.clear();
  EXPECT_EQ(mpeg4face::streamDuration(s), 0.0);
}

TEST(FapStream, TheTwentyThreeLeftRightPairs) {
  // Read off the FAP table by hand. Tao et al. (III-C) count 23 FAPs per side.
  const std::vector<std::pair<int, int>> expected = {
      {6, 7},   {8, 9},   {10, 11}, {12, 13}, {19, 20}, {21, 22}, {23, 24}, {25, 26},
      {27, 28}, {29, 30}, {31, 32}, {33, 34}, {35, 36}, {37, 38}, {39, 40}, {41, 42},
      {53, 54}, {55, 56}, {57, 58}, {59, 60}, {61, 62}, {65, 66}, {67, 68}};
  std::vector<std::pair<int, int>> found;
  for (int fap = 1; fap <= 68; ++fap) {
    const int other = fapMirror(fap);
    if (other == 0) continue;
    EXPECT_EQ(fapMirror(other), fap) << fap;
    if (fap < other) found.emplace_back(fap, other);
  }
  EXPECT_EQ(found, expected);
  EXPECT_EQ(fapMirror(0), 0);
  EXPECT_EQ(fapMirror(69), 0);
  EXPECT_EQ(fapMirror(3), 0);
  // Copying a value is symmetric motion: each pair shares FAPU and group, and its positive
  // directions are the same or mirror images (left <-> right).
  for (auto [l, r] : expected) {
    EXPECT_EQ(fapInfo(l).fapu, fapInfo(r).fapu) << l;
    EXPECT_EQ(fapInfo(l).group, fapInfo(r).group) << l;
    const std::string a(fapInfo(l).positiveMotion), b(fapInfo(r).positiveMotion);
    const bool mirrored = (a == "left" && b == "right") || (a == "right" && b == "left");
    EXPECT_TRUE(a == b || mirrored) << l << " " << a << " / " << b;
  }
}

TEST(FapStream, UnsentFapsKeepTheirLastValue) {
  FapStream s;
  s.frames = {frame(0, {{3, 100}}), frame(1, {{4, 5}}), frame(2, {{3, -20}})};
  const std::vector<FapState> r = mpeg4face::resolveFapStream(s);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_TRUE(r[0].has(3));
  EXPECT_FALSE(r[0].has(4));
  EXPECT_EQ(r[0].value(4), 0);
  EXPECT_EQ(r[1].number, 1);
  EXPECT_EQ(r[1].value(3), 100);
  EXPECT_EQ(r[1].value(4), 5);
  EXPECT_TRUE(r[1].sent(3));
  EXPECT_EQ(r[2].value(3), -20);
  EXPECT_EQ(r[2].value(4), 5);
  EXPECT_EQ(r[2].mask.count(), 2u);
  EXPECT_FALSE(r[2].has(5));
}

TEST(FapStream, AnUnsentSideMirrorsTheSentOneUntilItIsSent) {
  FapStream s;
  s.frames = {frame(0, {{19, 300}}), frame(1, {{19, 400}}), frame(2, {{20, -50}}),
              frame(3, {{19, 10}})};
  const std::vector<FapState> r = mpeg4face::resolveFapStream(s);
  EXPECT_TRUE(r[0].has(20));
  EXPECT_FALSE(r[0].sent(20));
  EXPECT_TRUE(r[0].mirrored[19]);
  EXPECT_EQ(r[0].value(20), 300);
  EXPECT_EQ(r[1].value(20), 400);
  // Once the right side is sent it holds its own value.
  EXPECT_TRUE(r[2].sent(20));
  EXPECT_EQ(r[2].value(20), -50);
  EXPECT_EQ(r[2].value(19), 400);
  EXPECT_EQ(r[3].value(19), 10);
  EXPECT_EQ(r[3].value(20), -50);
  EXPECT_EQ(r[3].mirrored.count(), 0u);
  // FAPs without a sent partner stay inactive.
  EXPECT_FALSE(r[3].has(21));
  EXPECT_FALSE(r[3].has(22));
}

TEST(FapStream, VisemeAndExpressionHold) {
  FapFrame first = frame(0, {{3, 1}});
  first.mask.set(0);
  first.viseme = {5, 7, 20, false};
  first.mask.set(1);
  first.expression = {1, 40, 0, 0, true, false};
  FapState state;
  mpeg4face::applyFrame(state, first);
  mpeg4face::applyFrame(state, frame(4, {{3, 2}}));
  EXPECT_EQ(state.number, 4);
  EXPECT_TRUE(state.has(1));
  EXPECT_TRUE(state.has(2));
  EXPECT_EQ(state.viseme, (mpeg4face::Viseme{5, 7, 20, false}));
  EXPECT_EQ(state.expression, (mpeg4face::Expression{1, 40, 0, 0, true, false}));
  EXPECT_EQ(state.value(3), 2);
}

TEST(FapStream, XfaceStreamsSendBothSidesOrNeither) {
  // Every Xface frame repeats one mask, so each resolved state is exactly that frame.
  const FapStream s = mpeg4face::readFapFile(mpeg4face::test::kData / "xface-fap" / "joy.fap");
  const std::vector<FapState> r = mpeg4face::resolveFapStream(s);
  ASSERT_EQ(r.size(), s.frames.size());
  for (size_t i = 0; i < r.size(); ++i) {
    EXPECT_EQ(r[i].mask, s.frames[i].mask) << i;
    EXPECT_EQ(r[i].mirrored.count(), 0u) << i;
    for (int fap = 3; fap <= 68; ++fap) {
      if (s.frames[i].has(fap)) {
        EXPECT_EQ(r[i].value(fap), s.frames[i].value(fap)) << i;
      }
    }
  }
}

}  // namespace
