// SPDX-License-Identifier: GPL-3.0-or-later
// The FAP Interpolation Table: model, authoring, validation, Tao's interpolation loop, the
// presets and what an encoder may leave out.
#include <gtest/gtest.h>

#include <cmath>

#include "mpeg4face/error.hpp"
#include "mpeg4face/fit.hpp"
#include "mpeg4face/fit_json.hpp"
#include "mpeg4face/fit_node.hpp"
#include "mpeg4face/fit_presets.hpp"
#include "test_support.hpp"

using namespace mpeg4face;
using mpeg4face::test::errorOf;

namespace {

bool mentions(const std::vector<std::string>& problems, const std::string& text) {
  for (const std::string& p : problems) {
    if (p.find(text) != std::string::npos) return true;
  }
  return false;
}

// A stream whose left and right FAPs are equal and whose outer lips follow the lip preset.
FapStream symmetricStream() {
  FapStream s;
  for (int n = 0; n < 40; ++n) {
    FapFrame& f = s.frames.emplace_back();
    f.number = n;
    for (int fap = 3; fap <= kFapCount; ++fap) {
      const int mirror = fapMirror(fap);
      const int base = mirror != 0 ? std::min(fap, mirror) : fap;
      f.set(fap, static_cast<int>(std::lround(300 * std::sin(0.1 * n + base))));
    }
  }
  return s;
}

FapStream without(FapStream s, const std::bitset<kFapCount>& drop) {
  for (FapFrame& f : s.frames) {
    for (std::size_t i = 0; i < drop.size(); ++i) {
      if (drop[i]) f.mask.reset(i), f.values[i] = 0;
    }
  }
  return s;
}

}  // namespace

TEST(Fit, LeftRightPresetReproducesASymmetricStreamFromHalfItsFaps) {
  const FapStream full = symmetricStream();
  const FitTable table = leftRightFitTable();
  EXPECT_TRUE(fitProblems(table).empty());
  EXPECT_EQ(table.nodes.size(), 46u);
  std::bitset<kFapCount> right;
  for (int fap = 3; fap <= kFapCount; ++fap) {
    if (fapMirror(fap) != 0 && fapInfo(fap).name.find("_r") != std::string_view::npos) {
      right.set(static_cast<std::size_t>(fap - 1));
    }
  }
  ASSERT_EQ(right.count(), 23u);
  FapStream half = without(full, right);
  EXPECT_EQ(interpolateFitStream(table, half), 23 * 40);
  EXPECT_EQ(half, full);
  // The encoder's side: of a frame that sends everything, exactly one of each pair can go.
  const std::bitset<kFapCount> derived = fitDerivedFaps(table, full.frames[0].mask);
  EXPECT_EQ(derived.count(), 23u);
  for (int fap = 3; fap <= kFapCount; ++fap) {
    if (fapMirror(fap) != 0) {
      EXPECT_NE(derived[static_cast<std::size_t>(fap - 1)],
                derived[static_cast<std::size_t>(fapMirror(fap) - 1)])
          << fap;
    }
  }
}

TEST(Fit, LipPresetThinsTheUpperLipAndReproducesTheOuterLip) {
  const double fmax = 1000;
  const FitTable table = innerOuterLipFitTable(fmax);
  EXPECT_TRUE(fitProblems(table).empty());
  FapStream full;
  for (int n = 0; n < 30; ++n) {
    FapFrame& f = full.frames.emplace_back();
    f.number = n;
    for (int inner = 4; inner <= 13; ++inner) {
      const int value = 20 * n - 300 + inner;
      f.set(inner, value);
      // Tao's f = F (1 - (F / Fmax)^2) for lower_t_midlip_o, f = F for the others.
      const double outer = inner == 4 ? value * (1 - (value / fmax) * (value / fmax)) : value;
      f.set(inner + 47, static_cast<int>(std::lround(outer)));
    }
  }
  std::bitset<kFapCount> outer;
  for (int fap = 51; fap <= 60; ++fap) outer.set(static_cast<std::size_t>(fap - 1));
  FapStream half = without(full, outer);
  EXPECT_EQ(interpolateFitStream(table, half), 10 * 30);
  EXPECT_EQ(half, full);
  // At F = 500 the outer lip moves 375: thinner than the inner.
  FapFrame f;
  f.set(4, 500);
  interpolateFitFrame(table, f);
  EXPECT_EQ(f.value(51), 375);
  EXPECT_EQ(fitDerivedFaps(table, full.frames[0].mask), outer);
}

TEST(Fit, FirstAvailableParentInPriorityOrderAndSentFapsKept) {
  FitTable table;
  const int a = addFitNode(table, {33});
  const int b = addFitNode(table, {34});
  const int child = addFitNode(table, {31});
  const int fromA = addFitLink(table, a, child);
  const int fromB = addFitLink(table, b, child);
  setFitFunction(table, fromA, 31, linearFitFunction({33}, 33, 2.0));
  setFitFunction(table, fromB, 31, linearFitFunction({34}, 34, 3.0));
  FapFrame both;
  both.set(33, 10);
  both.set(34, 10);
  EXPECT_EQ(interpolateFitFrame(table, both), 1);
  EXPECT_EQ(both.value(31), 20);  // the first link wins
  FapFrame onlyB;
  onlyB.set(34, 10);
  interpolateFitFrame(table, onlyB);
  EXPECT_EQ(onlyB.value(31), 30);
  FapFrame sent = both;
  sent.set(31, -7);
  EXPECT_EQ(interpolateFitFrame(table, sent), 0);
  EXPECT_EQ(sent.value(31), -7);
  FapFrame none;
  none.set(3, 1);
  EXPECT_EQ(interpolateFitFrame(table, none), 0);
  EXPECT_FALSE(none.has(31));
}

TEST(Fit, ChainsAcrossPassesAndStopsOnCycles) {
  // 3 -> 4 -> 5 in one pass's order 5, 4: the chain needs two passes.
  FitTable table;
  const int n5 = addFitNode(table, {5});
  const int n4 = addFitNode(table, {4});
  const int n3 = addFitNode(table, {3});
  setFitFunction(table, addFitLink(table, n4, n5), 5, linearFitFunction({4}, 4, 2));
  setFitFunction(table, addFitLink(table, n3, n4), 4, linearFitFunction({3}, 3, 3));
  // And a cycle 4 <-> 5 (5 -> 4), which must not loop.
  setFitFunction(table, addFitLink(table, n5, n4), 4, linearFitFunction({5}, 5, 1));
  FapFrame f;
  f.set(3, 7);
  EXPECT_EQ(interpolateFitFrame(table, f), 2);
  EXPECT_EQ(f.value(4), 21);
  EXPECT_EQ(f.value(5), 42);
  FapFrame nothing;
  EXPECT_EQ(interpolateFitFrame(table, nothing), 0);
}

TEST(Fit, ZeroDenominatorIsAnErrorNamingTheLinkAndFap) {
  FitTable table;
  const int p = addFitNode(table, {33});
  const int c = addFitNode(table, {31});
  const int link = addFitLink(table, p, c);
  // f = 1 / F: fine at F = 4, a division by zero at F = 0.
  setFitFunction(table, link, 31, {{FitTerm{100, {0}}}, {FitTerm{1, {1}}}});
  FapFrame f;
  f.number = 12;
  f.set(33, 4);
  interpolateFitFrame(table, f);
  EXPECT_EQ(f.value(31), 25);
  FapFrame zero;
  zero.number = 13;
  zero.set(33, 0);
  const Error e = errorOf([&] { interpolateFitFrame(table, zero); });
  EXPECT_NE(std::string(e.what()).find("frame 13 link 0 (node 0 -> node 1) FAP 31"),
            std::string::npos)
      << e.what();
  EXPECT_NE(std::string(e.what()).find("denominator is 0"), std::string::npos) << e.what();
  EXPECT_FALSE(zero.has(31));
}

TEST(Fit, ExpressionPresetUsesTheImpulseOnTheSelect) {
  const FitTable table = expressionFitTable();
  EXPECT_TRUE(fitProblems(table).empty()) << fitProblems(table)[0];
  ASSERT_EQ(table.nodes[1].size(), 27u);
  FapFrame surprise;
  surprise.set(2, 0);
  surprise.expression = {6, 63, 0, 0};
  EXPECT_EQ(interpolateFitFrame(table, surprise), 27);
  EXPECT_EQ(surprise.value(3), 400);  // open_jaw at full surprise
  EXPECT_EQ(surprise.value(6), 0);
  FapFrame mixed;
  mixed.set(2, 0);
  mixed.expression = {1, 63, 6, 21};  // full joy, a third of surprise
  interpolateFitFrame(table, mixed);
  EXPECT_EQ(mixed.value(6), 250);
  EXPECT_EQ(mixed.value(3), 133);
}

TEST(Fit, VisemePresetBlendsTheTwoVisemesMouths) {
  const FitTable table = visemeFitTable();
  EXPECT_TRUE(fitProblems(table).empty()) << fitProblems(table)[0];
  ASSERT_EQ(table.nodes[1].size(), visemeFitFaps().size());
  FapFrame a;  // viseme 10 (A:) shown fully, through either select
  a.set(1, 0);
  a.viseme = {10, 0, 63};
  EXPECT_EQ(interpolateFitFrame(table, a), 7);
  EXPECT_EQ(a.value(3), 380);  // the jaw wide open
  EXPECT_EQ(a.value(6), 40);
  EXPECT_EQ(a.value(16), 0);
  FapFrame same = a;
  same.viseme = {0, 10, 0};  // select2 at blend 0: all of it
  interpolateFitFrame(table, same);
  EXPECT_EQ(same.value(3), 380);
  // A third of the way from U (14) to A: (10): each mouth FAP between the two.
  FapFrame blend;
  blend.set(1, 0);
  blend.viseme = {10, 14, 21};
  interpolateFitFrame(table, blend);
  EXPECT_EQ(blend.value(3), std::lround(380 / 3.0 + 140 * 2 / 3.0));
  EXPECT_EQ(blend.value(6), std::lround(40 / 3.0 - 200 * 2 / 3.0));
  EXPECT_EQ(blend.value(17), std::lround(140 * 2 / 3.0));
  FapFrame silence;  // viseme 0: the neutral mouth
  silence.set(1, 0);
  silence.viseme = {0, 0, 63};
  interpolateFitFrame(table, silence);
  EXPECT_EQ(silence.value(3), 0);
  EXPECT_TRUE(silence.has(3));
}

TEST(Fit, EditingAndValidationNameTheProblem) {
  FitTable table = eyebrowFitTable();
  EXPECT_TRUE(fitProblems(table).empty());
  EXPECT_EQ(table.links.size(), 2u);
  table.nodes.push_back({99});
  table.nodes.push_back({});
  const int lonely = addFitNode(table, {40});
  const int high = addFitNode(table, {1});
  const int hl = addFitLink(table, 0, high);
  table.links[0].functions.pop_back();
  table.links[1].functions[0].numerator[0].exponents.push_back(1);
  table.links[1].functions[1].denominator.clear();
  const auto problems = fitProblems(table);
  EXPECT_TRUE(mentions(problems, "node 4 has unknown FAP 99"));
  EXPECT_TRUE(mentions(problems, "node 5 is empty"));
  EXPECT_TRUE(mentions(problems, "node 6 is unreachable")) << lonely;
  EXPECT_TRUE(mentions(problems, "link 2 (node 0 -> node 7): FAP 1 cannot be interpolated")) << hl;
  EXPECT_TRUE(mentions(problems, "link 0 (node 0 -> node 1): child FAP 35 has no function"));
  EXPECT_TRUE(
      mentions(problems, "link 1 (node 2 -> node 3) FAP 32 numerator term 0 has 2 exponents"));
  EXPECT_TRUE(mentions(problems, "link 1 (node 2 -> node 3) FAP 36 has no denominator term"));
  const Error e = errorOf([&] { validateFitTable(table); });
  EXPECT_EQ(e.field(), "FIT");
  // Removing node 0 removes its links and renumbers the rest.
  removeFitNode(table, 0);
  EXPECT_EQ(table.links.size(), 1u);
  EXPECT_EQ(table.links[0].parent, 1);
  EXPECT_EQ(table.links[0].child, 2);
  removeFitLink(table, 0);
  EXPECT_TRUE(table.links.empty());
  EXPECT_THROW(addFitLink(table, 0, 42), Error);
  EXPECT_THROW(setFitFunction(table, 0, 31, {}), Error);
  // Impulses only on selects the parent has.
  FitTable bad;
  addFitNode(bad, {33});
  addFitNode(bad, {31});
  addFitLink(bad, 0, 1);
  bad.links[0].functions[0].numerator.push_back({1, {1}, kExpressionSelect1, 2});
  EXPECT_TRUE(mentions(fitProblems(bad),
                       "impulse on expression_select1, which the parent node does not have"));
  EXPECT_THROW(fitPreset("nonsense"), Error);
  for (std::string_view name : fitPresetNames())
    EXPECT_TRUE(fitProblems(fitPreset(name)).empty()) << name;
}

TEST(FitJson, EveryPresetRoundTripsExactlyAndMalformedInputIsNamed) {
  for (std::string_view name : fitPresetNames()) {
    const FitTable table = fitPreset(name);
    EXPECT_EQ(fitTableFromJson(fitTableToJson(table)), table) << name;
  }
  FitTable odd = innerOuterLipFitTable(977);  // coefficients without a short decimal form
  odd.links[0].functions[0].numerator[0].coefficient = 0.1 + 0.2;
  const auto dir = mpeg4face::test::scratchDir();
  writeFitJson(odd, dir / "odd.json");
  EXPECT_EQ(readFitJson(dir / "odd.json"), odd);

  const std::string good = fitTableToJson(eyebrowFitTable());
  const auto fieldOf = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    return errorOf([&] { fitTableFromJson(text, "table.json"); });
  };
  Error e = fieldOf("\"exponents\": [1]", "\"exponents\": [\"x\"]");
  EXPECT_EQ(e.field(), "links[0].functions[0].numerator[0].exponents[0]") << e.what();
  EXPECT_EQ(e.file(), "table.json");
  e = fieldOf("\"fap\": 35", "\"fap\": 36");
  EXPECT_EQ(e.field(), "links[0].functions[1].fap") << e.what();
  e = fieldOf("\"coefficient\": 1.0", "\"coeff\": 1.0");
  EXPECT_EQ(e.field(), "links[0].functions[0].numerator[0]") << e.what();
  e = fieldOf("\"child\": 1", "\"child\": 9");
  EXPECT_EQ(e.field(), "links[0].child") << e.what();
  e = fieldOf("[33]", "[133]");
  EXPECT_EQ(e.field(), "FIT") << e.what();
  EXPECT_NE(std::string(e.what()).find("node 0 has unknown FAP 133"), std::string::npos)
      << e.what();
  e = errorOf([&] { fitTableFromJson("{\"format\": ", "t.json"); });
  EXPECT_EQ(e.field(), "JSON");
  e = fieldOf("\"coefficient\": 1.0", "\"coefficient\": 3E999999");  // found by fuzz_fit
  EXPECT_EQ(e.field(), "JSON");
  e = errorOf([&] { fitTableFromJson("{\"format\": \"other\", \"version\": 1}", "t.json"); });
  EXPECT_EQ(e.field(), "format");
}

TEST(FitNode, EveryPresetRoundTripsThroughTheBifsFields) {
  for (std::string_view name : fitPresetNames()) {
    const FitTable table = fitPreset(name);
    const FitNodeFields fields = fitNodeFields(table);
    EXPECT_EQ(fitTableFromNode(fields), table) << name;
  }
  // The layout by hand for one link {33} -> {31, 35}, f = F each.
  const FitNodeFields f = fitNodeFields(eyebrowFitTable());
  EXPECT_EQ(std::vector<int>(f.FAPs.begin(), f.FAPs.begin() + 5),
            (std::vector<int>{33, -1, 31, 35, -1}));
  EXPECT_EQ(f.Graph, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(f.numeratorTerms, (std::vector<int>{1, 1, 1, 1}));
  EXPECT_EQ(f.numeratorExp, (std::vector<int>{1, 1, 1, 1}));
  EXPECT_EQ(f.denominatorExp, (std::vector<int>{0, 0, 0, 0}));
  EXPECT_EQ(f.numeratorImpulse, (std::vector<int>(8, 0)));
  EXPECT_EQ(f.numeratorCoefs, (std::vector<double>(4, 1.0)));
}
