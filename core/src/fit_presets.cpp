// SPDX-License-Identifier: GPL-3.0-or-later
// Ready-made FAP Interpolation Tables. docs/fit.md.
#include "mpeg4face/fit_presets.hpp"

#include <array>
#include <span>
#include <string>
#include <vector>

#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

// A link from node `parent` = {from} to node `child` = {to}, f = F.
void addDuplication(FitTable& table, int parent, int child) {
  const int from = table.nodes[static_cast<std::size_t>(parent)][0];
  const int to = table.nodes[static_cast<std::size_t>(child)][0];
  setFitFunction(table, addFitLink(table, parent, child), to, linearFitFunction({from}, from));
}

constexpr std::array<int, 27> kExpressionFaps{3,  4,  5,  6,  7,  8,  9,  10, 11,
                                              12, 13, 19, 20, 21, 22, 23, 24, 25,
                                              26, 31, 32, 33, 34, 35, 36, 37, 38};

// Each expression's low-level FAPs at full intensity (63), FAPU; the rest 0. Our own
// estimates from the expressions' descriptions (ISO/IEC 14496-2 Table C-3): a starting point
// for `mpeg4face fit learn`, which fits them to a real face's data.
// A viseme's or an expression's low-level FAPs at its full amount (63), FAPU.
template <std::size_t N>
struct SelectShape {
  int select;
  std::array<std::pair<int, int>, N> faps;
};

constexpr std::array<SelectShape<12>, 6> kExpressionShapes{{
    {1, {{{6, 250}, {7, 250}, {12, 200}, {13, 200}, {4, -50}, {21, 150}, {22, 150}}}},  // joy
    {2,
     {{{12, -150},
       {13, -150},
       {31, 150},
       {32, 150},
       {37, 50},
       {38, 50},
       {19, 200},
       {20, 200}}}},  // sadness
    {3,
     {{{31, -200},
       {32, -200},
       {33, -200},
       {34, -200},
       {37, 150},
       {38, 150},
       {19, -100},
       {20, -100},
       {5, 100}}}},  // anger
    {4,
     {{{31, 250},
       {32, 250},
       {33, 150},
       {34, 150},
       {37, 100},
       {38, 100},
       {19, -200},
       {20, -200},
       {3, 150},
       {6, 150},
       {7, 150}}}},  // fear
    {5,
     {{{4, -250},
       {8, -200},
       {9, -200},
       {12, -100},
       {13, -100},
       {37, 100},
       {38, 100},
       {21, 100},
       {22, 100}}}},  // disgust
    {6,
     {{{3, 400},
       {31, 300},
       {32, 300},
       {33, 300},
       {34, 300},
       {35, 300},
       {36, 300},
       {19, -250},
       {20, -250}}}},  // surprise
}};

constexpr std::array<int, 7> kVisemeFaps{3, 4, 5, 6, 7, 16, 17};

// Each viseme's mouth FAPs when it is shown fully (amount 63), FAPU; the rest 0. Our own
// estimates from the visemes' phonemes (Tekalp-Ostermann Table 3; docs/fit.md): open vowels
// open the jaw, rounded ones narrow and push the lips, /p b m/ presses them, /f v/ lifts the
// lower lip to the teeth.
constexpr std::array<SelectShape<5>, 14> kVisemeShapes{{
    {1, {{{4, 40}, {5, 40}}}},                                       // p, b, m
    {2, {{{3, 60}, {5, 150}, {16, -80}}}},                           // f, v
    {3, {{{3, 120}, {5, 40}}}},                                      // T, D
    {4, {{{3, 100}}}},                                               // t, d
    {5, {{{3, 160}}}},                                               // k, g
    {6, {{{3, 90}, {6, -80}, {7, -80}, {16, 120}, {17, 120}}}},      // tS, dZ, S
    {7, {{{3, 50}, {6, 60}, {7, 60}}}},                              // s, z
    {8, {{{3, 120}}}},                                               // n, l
    {9, {{{3, 100}, {6, -60}, {7, -60}, {16, 60}, {17, 60}}}},       // r
    {10, {{{3, 380}, {6, 40}, {7, 40}}}},                            // A:
    {11, {{{3, 240}, {6, 100}, {7, 100}}}},                          // e
    {12, {{{3, 140}, {6, 160}, {7, 160}}}},                          // I
    {13, {{{3, 300}, {6, -140}, {7, -140}, {16, 80}, {17, 80}}}},    // Q
    {14, {{{3, 140}, {6, -200}, {7, -200}, {16, 140}, {17, 140}}}},  // U
}};

// One link from FAP 1 or 2 to `faps`: each FAP's function sums, over the shapes that move
// it, terms(p, select) with p its value in the shape / 63 (the selects' impulse terms).
template <std::size_t N, std::size_t M, class Terms>
FitTable selectFitTable(int fap, std::span<const int> faps,
                        const std::array<SelectShape<N>, M>& shapes, Terms terms) {
  FitTable table;
  const int parent = addFitNode(table, {fap});
  const int child = addFitNode(table, {faps.begin(), faps.end()});
  const int link = addFitLink(table, parent, child);
  const std::size_t variables = fitVariables({fap}).size();
  for (int derived : faps) {
    FitFunction f;
    f.denominator.push_back({1.0, std::vector<int>(variables, 0)});
    for (const SelectShape<N>& shape : shapes) {
      for (const auto& [id, value] : shape.faps) {
        if (id != derived || value == 0) continue;
        for (FitTerm& term : terms(value / 63.0, shape.select)) {
          f.numerator.push_back(std::move(term));
        }
      }
    }
    setFitFunction(table, link, derived, f);
  }
  return table;
}

}  // namespace

FitTable leftRightFitTable() {
  FitTable table;
  for (int fap = 3; fap <= kFapCount; ++fap) {
    const int mirror = fapMirror(fap);
    if (mirror > fap) {
      const int a = addFitNode(table, {fap});
      const int b = addFitNode(table, {mirror});
      addDuplication(table, a, b);
      addDuplication(table, b, a);
    }
  }
  return table;
}

FitTable innerOuterLipFitTable(double fmax) {
  if (!(fmax > 0)) throw Error({}, 0, "fmax", "the upper lip's Fmax must be > 0");
  FitTable table;
  for (int inner = 4; inner <= 13; ++inner) {
    const int parent = addFitNode(table, {inner});
    addDuplication(table, parent, addFitNode(table, {inner + 47}));
  }
  // Tao's lower_t_midlip -> lower_t_midlip_o: F - F^3 / fmax^2.
  FitFunction thinning = linearFitFunction({4}, 4);
  thinning.numerator.push_back({-1 / (fmax * fmax), {3}});
  setFitFunction(table, 0, 51, thinning);
  return table;
}

FitTable eyebrowFitTable() {
  FitTable table;
  for (const auto& [middle, inner, outer] : {std::array{33, 31, 35}, std::array{34, 32, 36}}) {
    const int parent = addFitNode(table, {middle});
    const int child = addFitNode(table, {inner, outer});
    const int link = addFitLink(table, parent, child);
    setFitFunction(table, link, inner, linearFitFunction({middle}, middle));
    setFitFunction(table, link, outer, linearFitFunction({middle}, middle));
  }
  return table;
}

std::span<const int> expressionFitFaps() { return kExpressionFaps; }

FitTable expressionFitTable() {
  // Variables of {2}: select1, select2, intensity1, intensity2.
  return selectFitTable(2, kExpressionFaps, kExpressionShapes, [](double p, int expression) {
    return std::vector<FitTerm>{{p, {0, 0, 1, 0}, kExpressionSelect1, expression},
                                {p, {0, 0, 0, 1}, kExpressionSelect2, expression}};
  });
}

std::span<const int> visemeFitFaps() { return kVisemeFaps; }

FitTable visemeFitTable() {
  // Variables of {1}: select1, select2, blend. Viseme select1 is shown by blend / 63, select2
  // by (63 - blend) / 63, as a FaceDefTables for FAP 1 shows them.
  return selectFitTable(1, kVisemeFaps, kVisemeShapes, [](double p, int viseme) {
    return std::vector<FitTerm>{{p, {0, 0, 1}, kVisemeSelect1, viseme},
                                {63 * p, {0, 0, 0}, kVisemeSelect2, viseme},
                                {-p, {0, 0, 1}, kVisemeSelect2, viseme}};
  });
}

std::span<const std::string_view> fitPresetNames() {
  static constexpr std::array<std::string_view, 5> kNames{"left-right", "inner-outer-lip",
                                                          "eyebrow", "expression", "viseme"};
  return kNames;
}

FitTable fitPreset(std::string_view name) {
  if (name == "left-right") return leftRightFitTable();
  if (name == "inner-outer-lip") return innerOuterLipFitTable();
  if (name == "eyebrow") return eyebrowFitTable();
  if (name == "expression") return expressionFitTable();
  if (name == "viseme") return visemeFitTable();
  std::string known;
  for (std::string_view n : fitPresetNames()) known += (known.empty() ? "" : ", ") + std::string(n);
  throw Error({}, 0, "preset",
              "unknown FIT preset '" + std::string(name) + "' (known: " + known + ")");
}

FitTable mergedFitTables(const FitTable& first, const FitTable& second) {
  FitTable out = first;
  const int offset = static_cast<int>(first.nodes.size());
  out.nodes.insert(out.nodes.end(), second.nodes.begin(), second.nodes.end());
  for (FitLink link : second.links) {
    link.parent += offset;
    link.child += offset;
    out.links.push_back(std::move(link));
  }
  return out;
}

}  // namespace mpeg4face
