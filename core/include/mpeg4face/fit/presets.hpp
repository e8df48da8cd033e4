// SPDX-License-Identifier: GPL-3.0-or-later
// Ready-made FAP Interpolation Tables: the cases of Tao et al. III-C and Tekalp-Ostermann
// 2.2.3. Their coefficients are starting points to edit or to learn (fit/learn.hpp);
// docs/fit.md says where each comes from.
#pragma once

#include <span>
#include <string_view>

#include "mpeg4face/fit/fit.hpp"

namespace mpeg4face {

// Every left/right pair (fapMirror) both ways, f = F: one node per FAP, so that a stream
// that animates only some pairs still uses the links it can (Tao's Fig. 5 puts each side's
// 23 FAPs in one node, which fires only when all 23 are sent).
FitTable leftRightFitTable();
// Inner lip (FAP 4..13) -> outer lip (51..60), f = F, except lower_t_midlip ->
// lower_t_midlip_o, Tao's upper-lip thinning f = F (1 - (F / fmax)^2).
inline constexpr double kDefaultLipFmax =
    1024;  // one MNS: the upper lip raised by the whole mouth-nose separation
FitTable innerOuterLipFitTable(double fmax = kDefaultLipFmax);
// raise_l/r_m_eyebrow (33, 34) -> raise_l/r_i_eyebrow and raise_l/r_o_eyebrow, f = F.
FitTable eyebrowFitTable();
// Expression (FAP 2) -> the 27 low-level FAPs of Tao's Fig. 7 experiment (3..13, 19..26,
// 31..38) and the outer lip (51..60), which moves with the inner one: f_i = sum_j
// delta(select1 - j) p_ij intensity1 + delta(select2 - j) p_ij intensity2, j = 1..6 (joy,
// sadness, anger, fear, disgust, surprise), p_ij our own estimates of each expression's FAP i
// at full intensity (after Tekalp-Ostermann Table 4) / 63.
FitTable expressionFitTable();
// The 37 FAPs of expressionFitTable, in its child node's order.
std::span<const int> expressionFitFaps();

// Viseme (FAP 1) -> the mouth's low-level FAPs (jaw 3, inner lip 4..13, lips pushed 16/17,
// outer lip 51..60), so that a face with tables for those FAPs only (CANDIDE-3's units) speaks
// a viseme stream: f_i = sum_v delta(select1 - v) p_iv blend + delta(select2 - v) p_iv
// (63 - blend), v = 1..14, p_iv viseme v's FAP i when shown fully / 63: each phone class's
// jaw, lip opening, rounding and protrusion from articulatory phonetics (docs/fit.md).
FitTable visemeFitTable();
// The FAPs of visemeFitTable, in its child node's order.
std::span<const int> visemeFitFaps();

// The presets by their CLI names: "left-right", "inner-outer-lip", "eyebrow", "expression",
// "viseme".
std::span<const std::string_view> fitPresetNames();
// Throws mpeg4face::Error naming the known presets for an unknown name.
FitTable fitPreset(std::string_view name);

// The tables one after the other (nodes renumbered): one table with every link of both.
FitTable mergedFitTables(const FitTable& first, const FitTable& second);

}  // namespace mpeg4face
