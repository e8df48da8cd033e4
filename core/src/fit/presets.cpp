// SPDX-License-Identifier: GPL-3.0-or-later
// Ready-made FAP Interpolation Tables. docs/fit.md.
#include "mpeg4face/fit/presets.hpp"

#include <array>
#include <cmath>
#include <span>
#include <string>
#include <utility>
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

// A mouth posture by its articulatory parts, FAPU: the jaw (open_jaw, 3), the middle of the
// upper lip (lower_t_midlip, 4: + down) and of the lower lip (raise_b_midlip, 5: + up), the
// corners' width (stretch_l/r_cornerlip, 6/7: + outwards) and height (raise_l/r_cornerlip,
// 12/13: + up), the lips pushed forward (push_b_lip 16, push_t_lip 17). docs/fit.md says
// where the values come from.
struct Mouth {
  int jaw = 0, upper = 0, lower = 0, width = 0, corners = 0;
  int pushB = 0, pushT = 0;
};
// The brows (raise_l/r_i/m/o_eyebrow 31..36: + up; squeeze 37/38: + together) and the
// eyelids (close_t 19/20: + down; close_b 21/22: + up), both sides alike.
struct Eyes {
  int innerBrow = 0, middleBrow = 0, outerBrow = 0, squeeze = 0, upperLid = 0, lowerLid = 0;
};
// A viseme's or an expression's face at its full amount (63), FAPU; the rest 0.
struct SelectShape {
  int select;
  Mouth mouth;
  Eyes eyes = {};
};

// The shape as FAPs, both sides alike. The outer lip (51..60) moves with the inner one
// (4..13) so that the lips move as one and do not shear; the points between the middle and
// the corners (8..11) go where a parabolic lip contour through the two puts them: 3/4 of the
// middle's motion and 1/4 of the corner's.
std::vector<std::pair<int, int>> shapeFaps(const SelectShape& shape) {
  const Mouth& m = shape.mouth;
  const Eyes& e = shape.eyes;
  const int upperSide = static_cast<int>(std::lround(0.75 * m.upper - 0.25 * m.corners));
  const int lowerSide = static_cast<int>(std::lround(0.75 * m.lower + 0.25 * m.corners));
  std::vector<std::pair<int, int>> out{{3, m.jaw}, {16, m.pushB}, {17, m.pushT}};
  for (const int outer : {0, 47}) {  // inner lip FAP n, outer lip FAP n + 47
    for (const auto& [fap, value] : {std::pair{4, m.upper},
                                     {5, m.lower},
                                     {6, m.width},
                                     {8, upperSide},
                                     {10, lowerSide},
                                     {12, m.corners}}) {
      out.emplace_back(fap + outer, value);
      if (fap != 4 && fap != 5) out.emplace_back(fap + 1 + outer, value);  // the right side
    }
  }
  for (const auto& [left, value] : {std::pair{19, e.upperLid},
                                    {21, e.lowerLid},
                                    {31, e.innerBrow},
                                    {33, e.middleBrow},
                                    {35, e.outerBrow},
                                    {37, e.squeeze}}) {
    out.emplace_back(left, value);
    out.emplace_back(left + 1, value);
  }
  return out;
}

// Tao's Fig. 7 FAPs (3..13, 19..26, 31..38) and the outer lip (51..60), which follows the
// inner one.
constexpr std::array<int, 37> kExpressionFaps{3,  4,  5,  6,  7,  8,  9,  10, 11, 12, 13, 19, 20,
                                              21, 22, 23, 24, 25, 26, 31, 32, 33, 34, 35, 36, 37,
                                              38, 51, 52, 53, 54, 55, 56, 57, 58, 59, 60};

// Each expression at full intensity after its textual definition (Tekalp-Ostermann Table 4).
// Our own estimates (docs/fit.md): a starting point for `mpeg4face fit learn`, which fits them
// to a real face's data.
constexpr std::array<SelectShape, 6> kExpressionShapes{{
    // Joy: brows relaxed; the mouth open, its corners pulled back and up; the cheeks lift the
    // lower eyelids.
    {1, {.jaw = 100, .upper = -60, .lower = -120, .width = 150, .corners = 200}, {.lowerLid = 150}},
    // Sadness: inner brows bent upward (and a little together), eyes slightly closed, the
    // mouth relaxed, its corners a little down.
    {2, {.corners = -100}, {.innerBrow = 150, .squeeze = 50, .upperLid = 200}},
    // Anger: inner brows pulled down and together, eyes wide open, lips pressed together.
    {3,
     {.upper = 40, .lower = 60, .width = -60},
     {.innerBrow = -200, .middleBrow = -120, .squeeze = 150, .upperLid = -100}},
    // Fear: brows raised and pulled together, the inner ones higher; eyes wide open; the lips
    // stretched and parted.
    {4,
     {.jaw = 150, .upper = -40, .lower = -150, .width = 150},
     {.innerBrow = 250, .middleBrow = 150, .squeeze = 100, .upperLid = -200}},
    // Disgust: brows and eyelids relaxed, the upper lip raised, the corners down.
    {5, {.upper = -250, .corners = -100}},
    // Surprise: brows raised, upper eyelids wide open, the lower relaxed, the jaw and the lips
    // open.
    {6,
     {.jaw = 400, .upper = -60, .lower = -350, .width = -40, .corners = -60},
     {.innerBrow = 300, .middleBrow = 300, .outerBrow = 300, .upperLid = -250}},
}};

// The mouth's FAPs (shapeFaps without the eyes).
constexpr std::array<int, 23> kVisemeFaps{3,  4,  5,  6,  7,  8,  9,  10, 11, 12, 13, 16,
                                          17, 51, 52, 53, 54, 55, 56, 57, 58, 59, 60};

// Each viseme's mouth shown fully, per phone class (Tekalp-Ostermann Table 3 gives the
// phonemes; docs/fit.md the articulatory sources). The lips open by their own FAPs: FAP 3
// moves the chin (2.1), and how far the lips follow it depends on the face's tables. 6 is
// tS dZ S, 9 r, 14 U.
constexpr std::array<SelectShape, 14> kVisemeShapes{{
    {1, {.upper = 40, .lower = 40}},                             // p b m: the lips closed, pressed
    {2, {.jaw = 40, .upper = -80, .lower = 60, .pushB = -200}},  // f v: to the upper teeth
    {3, {.jaw = 150, .upper = -40, .lower = -120}},              // T D
    {4, {.jaw = 100, .upper = -30, .lower = -90, .width = 20}},  // t d
    {5, {.jaw = 180, .upper = -40, .lower = -140}},              // k g
    {6, {.jaw = 80, .upper = -100, .lower = -120, .width = -100, .pushB = 200, .pushT = 200}},
    {7, {.jaw = 40, .upper = -50, .lower = -80, .width = 60}},  // s z
    {8, {.jaw = 130, .upper = -30, .lower = -110}},             // n l
    {9, {.jaw = 100, .upper = -40, .lower = -90, .width = -120, .pushB = 150, .pushT = 150}},
    {10, {.jaw = 560, .upper = -100, .lower = -500, .corners = -120}},             // A:
    {11, {.jaw = 400, .upper = -80, .lower = -380, .width = 60, .corners = -80}},  // e
    {12, {.jaw = 200, .upper = -50, .lower = -180, .width = 120}},                 // I
    {13,
     {.jaw = 480,
      .upper = -100,
      .lower = -420,
      .width = -100,
      .corners = -100,
      .pushB = 120,
      .pushT = 120}},  // Q
    {14, {.jaw = 180, .upper = -40, .lower = -160, .width = -160, .pushB = 250, .pushT = 250}},
}};

// One link from FAP 1 or 2 to `faps`: each FAP's function sums, over the shapes that move
// it, terms(p, select) with p its value in the shape / 63 (the selects' impulse terms).
template <std::size_t M, class Terms>
FitTable selectFitTable(int fap, std::span<const int> faps,
                        const std::array<SelectShape, M>& shapes, Terms terms) {
  FitTable table;
  const int parent = addFitNode(table, {fap});
  const int child = addFitNode(table, {faps.begin(), faps.end()});
  const int link = addFitLink(table, parent, child);
  const std::size_t variables = fitVariables({fap}).size();
  for (int derived : faps) {
    FitFunction f;
    f.denominator.push_back({1.0, std::vector<int>(variables, 0)});
    for (const SelectShape& shape : shapes) {
      for (const auto& [id, value] : shapeFaps(shape)) {
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
