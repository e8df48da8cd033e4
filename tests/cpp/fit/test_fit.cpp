// SPDX-License-Identifier: GPL-3.0-or-later
// The FAP Interpolation Table: model, authoring, validation, Tao's interpolation loop, the
// presets and what an encoder may leave out.
#include <gtest/gtest.h>

#include <cmath>

#include "mpeg4face/error.hpp"
#include "mpeg4face/fit/fit.hpp"
#include "mpeg4face/fit/json.hpp"
#include "mpeg4face/fit/node.hpp"
#include "mpeg4face/fit/presets.hpp"
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

namespace {

// The FAPs a preset gives `select` of FAP 1 (viseme) or 2 (expression) shown fully.
FapFrame presetShape(int fap, int select) {
  FapFrame f;
  f.set(fap, 0);
  if (fap == 1) {
    f.viseme = {select, 0, 63};
    interpolateFitFrame(visemeFitTable(), f);
  } else {
    f.expression = {select, 63, 0, 0};
    interpolateFitFrame(expressionFitTable(), f);
  }
  return f;
}

// The inner lips' opening at the middle the lip FAPs give, MNS: FAP 4 lowers the upper lip
// (2.2), FAP 5 raises the lower one (2.3). FAP 3 moves the chin (2.1) only.
int lipOpening(const FapFrame& f) { return -(f.value(4) + f.value(5)); }

// Both sides alike and the outer lip (51..60) where the inner one is (4..13), so the lips
// do not shear.
void expectLipsMoveAsOne(const FapFrame& f, const std::string& what) {
  for (int inner = 4; inner <= 13; ++inner) {
    EXPECT_EQ(f.value(inner + 47), f.value(inner)) << what << " FAP " << inner;
  }
  for (const auto& [left, right] : {std::pair{6, 7}, {8, 9}, {10, 11}, {12, 13}}) {
    EXPECT_EQ(f.value(left), f.value(right)) << what << " FAP " << left;
  }
}

}  // namespace

TEST(Fit, ExpressionPresetUsesTheImpulseOnTheSelect) {
  const FitTable table = expressionFitTable();
  EXPECT_TRUE(fitProblems(table).empty()) << fitProblems(table)[0];
  ASSERT_EQ(table.nodes[1].size(), expressionFitFaps().size());
  const FapFrame joy = presetShape(2, 1), surprise = presetShape(2, 6);
  EXPECT_EQ(surprise.value(3), 400);  // open_jaw at full surprise
  EXPECT_EQ(surprise.value(6), -40);
  FapFrame mixed;
  mixed.set(2, 0);
  mixed.expression = {1, 63, 6, 21};  // full joy, a third of surprise
  EXPECT_EQ(interpolateFitFrame(table, mixed), static_cast<int>(expressionFitFaps().size()));
  EXPECT_EQ(mixed.value(6), std::lround(joy.value(6) + surprise.value(6) / 3.0));
  EXPECT_EQ(mixed.value(3), std::lround(joy.value(3) + surprise.value(3) / 3.0));
}

// Each expression as Tekalp-Ostermann's Table 4 describes it.
TEST(Fit, ExpressionPresetFollowsTheTextualDefinitions) {
  std::vector<FapFrame> e(7);
  for (int select = 1; select <= 6; ++select) {
    e[select] = presetShape(2, select);
    expectLipsMoveAsOne(e[select], "expression " + std::to_string(select));
    for (const auto& [left, right] :
         {std::pair{19, 20}, {21, 22}, {31, 32}, {33, 34}, {35, 36}, {37, 38}}) {
      EXPECT_EQ(e[select].value(left), e[select].value(right)) << select << " FAP " << left;
    }
  }
  const FapFrame &joy = e[1], &sadness = e[2], &anger = e[3], &fear = e[4], &disgust = e[5],
                 &surprise = e[6];
  // Joy: brows relaxed, the mouth open, the corners pulled back (and up).
  for (int brow = 31; brow <= 38; ++brow) EXPECT_EQ(joy.value(brow), 0) << brow;
  EXPECT_GT(lipOpening(joy), 0);
  EXPECT_GT(joy.value(6), 0);
  EXPECT_GT(joy.value(12), 0);
  // Sadness: inner brows bent upward, eyes slightly closed, the mouth relaxed.
  EXPECT_GT(sadness.value(31), sadness.value(35));
  EXPECT_GT(sadness.value(31), 0);
  EXPECT_GT(sadness.value(19), 0);
  EXPECT_LT(sadness.value(19), 512);  // slightly: less than half the iris
  EXPECT_EQ(lipOpening(sadness), 0);
  EXPECT_EQ(sadness.value(3), 0);
  // Anger: inner brows down and together, eyes wide open, lips pressed.
  EXPECT_LT(anger.value(31), 0);
  EXPECT_GT(anger.value(37), 0);
  EXPECT_LT(anger.value(19), 0);
  EXPECT_LT(lipOpening(anger), 0);
  EXPECT_EQ(anger.value(3), 0);
  // Fear: brows raised and together, the inner ones bent upward; eyes alert.
  EXPECT_GT(fear.value(33), 0);
  EXPECT_GT(fear.value(31), fear.value(33));
  EXPECT_GT(fear.value(37), 0);
  EXPECT_LT(fear.value(19), 0);
  // Disgust: brows and eyelids relaxed, the upper lip raised.
  for (int fap : {19, 21, 31, 33, 35, 37}) EXPECT_EQ(disgust.value(fap), 0) << fap;
  EXPECT_LT(disgust.value(4), 0);
  EXPECT_LT(disgust.value(8), 0);
  EXPECT_EQ(disgust.value(5), 0);
  // Surprise: brows raised, upper lids wide open, the lower relaxed, the jaw and lips open.
  for (int brow : {31, 33, 35}) EXPECT_GT(surprise.value(brow), 0) << brow;
  EXPECT_LT(surprise.value(19), 0);
  EXPECT_EQ(surprise.value(21), 0);
  EXPECT_GT(surprise.value(3), 0);
  EXPECT_GE(lipOpening(surprise), 410);  // 0.4 MNS0
}

TEST(Fit, VisemePresetBlendsTheTwoVisemesMouths) {
  const FitTable table = visemeFitTable();
  EXPECT_TRUE(fitProblems(table).empty()) << fitProblems(table)[0];
  ASSERT_EQ(table.nodes[1].size(), visemeFitFaps().size());
  FapFrame a;  // viseme 10 (A:) shown fully, through either select
  a.set(1, 0);
  a.viseme = {10, 0, 63};
  EXPECT_EQ(interpolateFitFrame(table, a), static_cast<int>(visemeFitFaps().size()));
  EXPECT_EQ(a.value(3), 560);  // the jaw wide open
  EXPECT_EQ(a.value(5), -500);
  FapFrame same = a;
  same.viseme = {0, 10, 0};  // select2 at blend 0: all of it
  interpolateFitFrame(table, same);
  for (int fap : visemeFitFaps()) EXPECT_EQ(same.value(fap), a.value(fap)) << fap;
  // A third of the way from U (14) to A: (10): each mouth FAP between the two.
  const FapFrame u = presetShape(1, 14);
  FapFrame blend;
  blend.set(1, 0);
  blend.viseme = {10, 14, 21};
  interpolateFitFrame(table, blend);
  for (int fap : visemeFitFaps()) {
    EXPECT_EQ(blend.value(fap), std::lround(a.value(fap) / 3.0 + u.value(fap) * 2 / 3.0)) << fap;
  }
  FapFrame silence;  // viseme 0: the neutral mouth
  silence.set(1, 0);
  silence.viseme = {0, 0, 63};
  interpolateFitFrame(table, silence);
  EXPECT_EQ(silence.value(3), 0);
  EXPECT_TRUE(silence.has(3));
}

// Each viseme has its phone class's mouth (docs/fit.md): the FAPs' directions as the
// standard defines them (3 open_jaw down, 4 lower_t_midlip down, 5 raise_b_midlip up, 6/7
// stretch outwards, 16/17 push forward).
TEST(Fit, VisemePresetGivesEachPhoneClassItsMouth) {
  std::vector<FapFrame> v(15);
  for (int viseme = 1; viseme <= 14; ++viseme) {
    v[viseme] = presetShape(1, viseme);
    expectLipsMoveAsOne(v[viseme], "viseme " + std::to_string(viseme));
    // The lips never pass through each other by more than a pressed closure.
    EXPECT_GE(lipOpening(v[viseme]), -102) << viseme;
    EXPECT_GE(v[viseme].value(3), 0) << viseme;  // open_jaw is unidirectional
  }
  // Open vowels (A:, e, Q): the jaw open and the lips parted by at least 0.4 MNS0 by the lip
  // FAPs alone, the lower lip going down most.
  for (int open : {10, 11, 13}) {
    EXPECT_GE(lipOpening(v[open]), 410) << open;
    EXPECT_GE(v[open].value(3), 400) << open;
    EXPECT_LT(v[open].value(5), v[open].value(4)) << open;
    EXPECT_LT(v[open].value(10), 0) << open;  // the lower lip's sides follow its middle
  }
  EXPECT_GT(lipOpening(v[10]), lipOpening(v[11]));  // A: the most open
  // The open vowels more open than the close ones (I, U) and the consonants.
  for (int other : {2, 3, 4, 5, 6, 7, 8, 9, 12, 14}) {
    EXPECT_LT(lipOpening(v[other]), 300) << other;
    EXPECT_LT(v[other].value(3), 300) << other;
  }
  // p b m: the jaw at rest, the lips closed: pressed by at most 0.1 MNS0.
  EXPECT_EQ(v[1].value(3), 0);
  EXPECT_LT(lipOpening(v[1]), 0);
  EXPECT_GE(lipOpening(v[1]), -102);
  // f v: the lower lip raised and drawn back to the upper teeth, the upper lip not lowered.
  EXPECT_GT(v[2].value(5), 0);
  EXPECT_LT(v[2].value(16), 0);
  EXPECT_LE(v[2].value(4), 0);
  EXPECT_LT(std::abs(lipOpening(v[2])), 102);
  // Rounded (U, Q, and r, tS dZ S): the corners drawn in and the lips pushed forward, U most.
  for (int rounded : {6, 9, 13, 14}) {
    EXPECT_LT(v[rounded].value(6), 0) << rounded;
    EXPECT_GT(v[rounded].value(16), 0) << rounded;
    EXPECT_GT(v[rounded].value(17), 0) << rounded;
  }
  for (int other = 1; other <= 13; ++other) {
    EXPECT_LT(v[14].value(6), v[other].value(6)) << other;
    EXPECT_GT(v[14].value(17), v[other].value(17)) << other;
  }
  // Spread (I, s z): the corners outwards; unrounded vowels and consonants push nothing.
  EXPECT_GT(v[12].value(6), 0);
  EXPECT_GT(v[7].value(6), 0);
  for (int unrounded : {1, 3, 4, 5, 7, 8, 10, 11, 12}) {
    EXPECT_EQ(v[unrounded].value(17), 0) << unrounded;
  }
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
  e = fieldOf("\"child\": 1", "\"child\": 1,,");  // a syntax error: its line and column
  EXPECT_GT(e.line(), 1) << e.what();
  EXPECT_NE(e.reason().find("column "), std::string::npos) << e.what();
  e = fieldOf("\"nodes\": [", "\"nodes\": 7, \"x\": [");
  EXPECT_EQ(e.field(), "nodes") << e.what();
  EXPECT_EQ(e.reason(), "expected an array") << e.what();
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
