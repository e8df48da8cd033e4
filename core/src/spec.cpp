// SPDX-License-Identifier: GPL-3.0-or-later
// The MPEG-4 face animation tables. Sources: ../shared/reference/mpeg4-face.md (from the
// repository root; the FAP table) and Tekalp & Ostermann 2000, Tables 1-4 and 6.
#include "mpeg4face/spec.hpp"

#include <array>
#include <cstddef>
#include <string>
#include <utility>

#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

// ---------------------------------------------------------------------------------------------
// FAPU (Tekalp-Ostermann Table 1)
// ---------------------------------------------------------------------------------------------

// clang-format off
constexpr std::array<FapuInfo, 6> kFapus{{
  {FapuKind::IRISD, "IRISD", "IRISD0", "Iris diameter (by definition equal to the distance between "
                                       "upper and lower eyelid) in neutral face",  "IRISD = IRISD0 / 1024"},
  {FapuKind::ES,    "ES",    "ES0",    "Eye separation",                           "ES = ES0 / 1024"},
  {FapuKind::ENS,   "ENS",   "ENS0",   "Eye-nose separation",                      "ENS = ENS0 / 1024"},
  {FapuKind::MNS,   "MNS",   "MNS0",   "Mouth-nose separation",                    "MNS = MNS0 / 1024"},
  {FapuKind::MW,    "MW",    "MW0",    "Mouth width",                              "MW = MW0 / 1024"},
  {FapuKind::AU,    "AU",    "",       "Angle unit",                               "AU = 1E-5 rad"},
}};
// clang-format on

// ---------------------------------------------------------------------------------------------
// The 68 FAPs (mpeg4-face.md). bifs is "" where the BIFS field name equals the name.
// ---------------------------------------------------------------------------------------------

struct FapRow {
  int number;
  std::string_view name;
  std::string_view bifs;
  FapuKind fapu;
  bool bidirectional;
  std::string_view positiveMotion;
  int group;
  std::string_view featurePoint;
  int quantStep;
  int intraRange;
  int interRange;
};

constexpr bool U = false;  // unidirectional
constexpr bool B = true;   // bidirectional

using enum FapuKind;

// clang-format off
constexpr std::array<FapRow, kFapCount> kFapRows{{
  // #  name                     BIFS field name         FAPU U/B  positive     grp FP          QP   I+-  P+-
  { 1, "viseme",                 "",                     None,  U, "",            1, "",           1,    0,   0},
  { 2, "expression",             "",                     None,  U, "",            1, "",           1,    0,   0},
  { 3, "open_jaw",               "",                     MNS,   U, "down",        2, "2.1",        4, 1080, 360},
  { 4, "lower_t_midlip",         "",                     MNS,   B, "down",        2, "2.2",        2,  600, 180},
  { 5, "raise_b_midlip",         "",                     MNS,   B, "up",          2, "2.3",        2, 1860, 600},
  { 6, "stretch_l_cornerlip",    "stretch_l_corner",     MW,    B, "left",        2, "2.4",        2,  600, 180},
  { 7, "stretch_r_cornerlip",    "stretch_r_corner",     MW,    B, "right",       2, "2.5",        2,  600, 180},
  { 8, "lower_t_lip_lm",         "",                     MNS,   B, "down",        2, "2.6",        2,  600, 180},
  { 9, "lower_t_lip_rm",         "",                     MNS,   B, "down",        2, "2.7",        2,  600, 180},
  {10, "raise_b_lip_lm",         "lower_b_lip_lm",       MNS,   B, "up",          2, "2.8",        2, 1860, 600},
  {11, "raise_b_lip_rm",         "lower_b_lip_rm",       MNS,   B, "up",          2, "2.9",        2, 1860, 600},
  {12, "raise_l_cornerlip",      "",                     MNS,   B, "up",          2, "2.4",        2,  600, 180},
  {13, "raise_r_cornerlip",      "",                     MNS,   B, "up",          2, "2.5",        2,  600, 180},
  {14, "thrust_jaw",             "",                     MNS,   U, "forward",     2, "2.1",        1,  600, 180},
  {15, "shift_jaw",              "",                     MW,    B, "right",       2, "2.1",        1, 1080, 360},
  {16, "push_b_lip",             "",                     MNS,   B, "forward",     2, "2.3",        1, 1080, 360},
  {17, "push_t_lip",             "",                     MNS,   B, "forward",     2, "2.2",        1, 1080, 360},
  {18, "depress_chin",           "",                     MNS,   B, "up",          2, "2.10",       1,  420, 180},
  {19, "close_t_l_eyelid",       "",                     IRISD, B, "down",        3, "3.1",        1, 1080, 600},
  {20, "close_t_r_eyelid",       "",                     IRISD, B, "down",        3, "3.2",        1, 1080, 600},
  {21, "close_b_l_eyelid",       "",                     IRISD, B, "up",          3, "3.3",        1,  600, 240},
  {22, "close_b_r_eyelid",       "",                     IRISD, B, "up",          3, "3.4",        1,  600, 240},
  {23, "yaw_l_eyeball",          "",                     AU,    B, "left",        3, "(eye)",    128, 1200, 420},
  {24, "yaw_r_eyeball",          "",                     AU,    B, "left",        3, "(eye)",    128, 1200, 420},
  {25, "pitch_l_eyeball",        "",                     AU,    B, "down",        3, "(eye)",    128,  900, 300},
  {26, "pitch_r_eyeball",        "",                     AU,    B, "down",        3, "(eye)",    128,  900, 300},
  {27, "thrust_l_eyeball",       "",                     ES,    B, "forward",     3, "(eye)",      1,  600, 180},
  {28, "thrust_r_eyeball",       "",                     ES,    B, "forward",     3, "(eye)",      1,  600, 180},
  {29, "dilate_l_pupil",         "",                     IRISD, B, "growing",     3, "3.5",        1,  420, 120},
  {30, "dilate_r_pupil",         "",                     IRISD, B, "growing",     3, "3.6",        1,  420, 120},
  {31, "raise_l_i_eyebrow",      "",                     ENS,   B, "up",          4, "4.1",        2,  900, 360},
  {32, "raise_r_i_eyebrow",      "",                     ENS,   B, "up",          4, "4.2",        2,  900, 360},
  {33, "raise_l_m_eyebrow",      "",                     ENS,   B, "up",          4, "4.3",        2,  900, 360},
  {34, "raise_r_m_eyebrow",      "",                     ENS,   B, "up",          4, "4.4",        2,  900, 360},
  {35, "raise_l_o_eyebrow",      "",                     ENS,   B, "up",          4, "4.5",        2,  900, 360},
  {36, "raise_r_o_eyebrow",      "",                     ENS,   B, "up",          4, "4.6",        2,  900, 360},
  {37, "squeeze_l_eyebrow",      "",                     ES,    B, "right",       4, "4.1",        1,  900, 300},
  {38, "squeeze_r_eyebrow",      "",                     ES,    B, "left",        4, "4.2",        1,  900, 300},
  {39, "puff_l_cheek",           "",                     ES,    B, "left",        5, "5.1",        2,  900, 300},
  {40, "puff_r_cheek",           "",                     ES,    B, "right",       5, "5.2",        2,  900, 300},
  {41, "lift_l_cheek",           "",                     ENS,   U, "up",          5, "5.3",        2,  600, 180},
  {42, "lift_r_cheek",           "",                     ENS,   U, "up",          5, "5.4",        2,  600, 180},
  {43, "shift_tongue_tip",       "",                     MW,    B, "right",       6, "6.1",        1, 1080, 420},
  {44, "raise_tongue_tip",       "",                     MNS,   B, "up",          6, "6.1",        1, 1080, 420},
  {45, "thrust_tongue_tip",      "",                     MW,    B, "forward",     6, "6.1",        1, 1080, 420},
  {46, "raise_tongue",           "",                     MNS,   B, "up",          6, "6.2",        1, 1080, 420},
  {47, "tongue_roll",            "",                     AU,    U, "concave up",  6, "6.3, 6.4",  512, 1080, 420},
  {48, "head_pitch",             "",                     AU,    B, "down",        7, "7.1",      170, 1860, 600},
  {49, "head_yaw",               "",                     AU,    B, "left",        7, "7.1",      170, 1860, 600},
  {50, "head_roll",              "",                     AU,    B, "right",       7, "7.1",      170, 1860, 600},
  {51, "lower_t_midlip_o",       "",                     MNS,   B, "down",        8, "8.1",        2,  600, 180},
  {52, "raise_b_midlip_o",       "",                     MNS,   B, "up",          8, "8.2",        2, 1860, 600},
  {53, "stretch_l_cornerlip_o",  "stretch_l_cornerlip",  MW,    B, "left",        8, "8.3",        2,  600, 180},
  {54, "stretch_r_cornerlip_o",  "stretch_r_cornerlip",  MW,    B, "right",       8, "8.4",        2,  600, 180},
  {55, "lower_t_lip_lm_o",       "",                     MNS,   B, "down",        8, "8.5",        2,  600, 180},
  {56, "lower_t_lip_rm_o",       "",                     MNS,   B, "down",        8, "8.6",        2,  600, 180},
  {57, "raise_b_lip_lm_o",       "",                     MNS,   B, "up",          8, "8.7",        2, 1860, 600},
  {58, "raise_b_lip_rm_o",       "",                     MNS,   B, "up",          8, "8.8",        2, 1860, 600},
  {59, "raise_l_cornerlip_o",    "",                     MNS,   B, "up",          8, "8.3",        2,  600, 180},
  {60, "raise_r_cornerlip_o",    "",                     MNS,   B, "up",          8, "8.4",        2,  600, 180},
  {61, "stretch_l_nose",         "",                     ENS,   B, "left",        9, "9.1",        1,  540, 120},
  {62, "stretch_r_nose",         "",                     ENS,   B, "right",       9, "9.2",        1,  540, 120},
  {63, "raise_nose",             "",                     ENS,   B, "up",          9, "9.3",        1,  680, 180},
  {64, "bend_nose",              "",                     ENS,   B, "right",       9, "9.3",        1,  900, 180},
  {65, "raise_l_ear",            "",                     ENS,   B, "up",         10, "10.1",       1,  900, 240},
  {66, "raise_r_ear",            "",                     ENS,   B, "up",         10, "10.2",       1,  900, 240},
  {67, "pull_l_ear",             "",                     ENS,   B, "left",       10, "10.3",       1,  900, 300},
  {68, "pull_r_ear",             "",                     ENS,   B, "right",      10, "10.4",       1,  900, 300},
}};
// clang-format on

constexpr std::array<FapInfo, kFapCount> kFaps = [] {
  std::array<FapInfo, kFapCount> out{};
  for (std::size_t i = 0; i < out.size(); ++i) {
    const FapRow& r = kFapRows[i];
    out[i] = {r.number,     r.name,          r.bifs.empty() ? r.name : r.bifs,
              r.fapu,       r.bidirectional, r.positiveMotion,
              r.group,      r.featurePoint,  r.quantStep,
              r.intraRange, r.interRange};
  }
  return out;
}();

// ---------------------------------------------------------------------------------------------
// FAP groups (Tekalp-Ostermann Table 2)
// ---------------------------------------------------------------------------------------------

// clang-format off
constexpr std::array<FapGroupInfo, 10> kGroups{{
  { 1, "Visemes and expressions",                          1,  2},
  { 2, "Jaw, chin, inner lowerlip, cornerlips, midlip",    3, 18},
  { 3, "Eyeballs, pupils, eyelids",                       19, 30},
  { 4, "Eyebrow",                                         31, 38},
  { 5, "Cheeks",                                          39, 42},
  { 6, "Tongue",                                          43, 47},
  { 7, "Head rotation",                                   48, 50},
  { 8, "Outer lip positions",                             51, 60},
  { 9, "Nose",                                            61, 64},
  {10, "Ears",                                            65, 68},
}};
// clang-format on

// ---------------------------------------------------------------------------------------------
// Feature points (Tekalp-Ostermann Table 6, plus 7.2). Constraint grammar: see spec.hpp.
// Coordinates: +X is the face's left, +Y up, +Z the gaze direction.
// ---------------------------------------------------------------------------------------------

struct FpRow {
  std::string_view id;
  std::string_view x;
  std::string_view y;
  std::string_view z;
  std::string_view description;
  std::string_view note = "";
};

// clang-format off
constexpr std::array<FpRow, kFeaturePointCount + 1> kFpRows{{
  // id     x                     y                     z                   description
  {"2.1",  "=7.1.x",             "",                   "",                 "Bottom of the chin"},
  {"2.2",  "=7.1.x",             "",                   "",                 "Middle point of inner upper lip contour"},
  {"2.3",  "=7.1.x",             "",                   "",                 "Middle point of inner lower lip contour"},
  {"2.4",  "",                   "",                   "",                 "Left corner of inner lip contour"},
  {"2.5",  "",                   "",                   "",                 "Right corner of inner lip contour"},
  {"2.6",  "=(2.2.x+2.4.x)/2",   "",                   "",                 "Midpoint between f.p. 2.2 and 2.4 in the inner upper lip contour"},
  {"2.7",  "=(2.2.x+2.5.x)/2",   "",                   "",                 "Midpoint between f.p. 2.2 and 2.5 in the inner upper lip contour"},
  {"2.8",  "=(2.3.x+2.4.x)/2",   "",                   "",                 "Midpoint between f.p. 2.3 and 2.4 in the inner lower lip contour"},
  {"2.9",  "=(2.3.x+2.5.x)/2",   "",                   "",                 "Midpoint between f.p. 2.3 and 2.5 in the inner lower lip contour"},
  {"2.10", "=7.1.x",             "",                   "",                 "Chin boss"},
  {"2.11", ">8.7.x <8.3.x",      "",                   "",                 "Chin left corner"},
  {"2.12", ">8.4.x <8.8.x",      "",                   "",                 "Chin right corner"},
  {"2.13", "",                   "",                   "",                 "Left corner of jaw bone"},
  {"2.14", "",                   "",                   "",                 "Right corner of jaw bone"},
  {"3.1",  "=(3.7.x+3.11.x)/2",  "",                   "",                 "Center of upper inner left eyelid"},
  {"3.2",  "=(3.8.x+3.12.x)/2",  "",                   "",                 "Center of upper inner right eyelid"},
  {"3.3",  "=(3.7.x+3.11.x)/2",  "",                   "",                 "Center of lower inner left eyelid"},
  {"3.4",  "=(3.8.x+3.12.x)/2",  "",                   "",                 "Center of lower inner right eyelid"},
  {"3.5",  "",                   "",                   "",                 "Center of the pupil of left eye"},
  {"3.6",  "",                   "",                   "",                 "Center of the pupil of right eye"},
  {"3.7",  "",                   "",                   "",                 "Left corner of left eye"},
  {"3.8",  "",                   "",                   "",                 "Left corner of right eye"},
  {"3.9",  "=(3.7.x+3.11.x)/2",  "",                   "",                 "Center of lower outer left eyelid"},
  // 3.10, 3.13: the paper swaps the eyes (3.7/3.11 for 3.10, 3.8/3.12 for 3.13); corrected.
  {"3.10", "=(3.8.x+3.12.x)/2",  "",                   "",                 "Center of lower outer right eyelid"},
  {"3.11", "",                   "",                   "",                 "Right corner of left eye"},
  {"3.12", "",                   "",                   "",                 "Right corner of right eye"},
  {"3.13", "=(3.7.x+3.11.x)/2",  "",                   "",                 "Center of upper outer left eyelid"},
  {"3.14", "=(3.8.x+3.12.x)/2",  "",                   "",                 "Center of upper outer right eyelid"},
  {"4.1",  "",                   "",                   "",                 "Right corner of left eyebrow"},
  {"4.2",  "",                   "",                   "",                 "Left corner of right eyebrow"},
  {"4.3",  "=(4.1.x+4.5.x)/2",   "",                   "",                 "Uppermost point of the left eyebrow",
           "x may instead be that of the uppermost point of the contour"},
  {"4.4",  "=(4.2.x+4.6.x)/2",   "",                   "",                 "Uppermost point of the right eyebrow",
           "x may instead be that of the uppermost point of the contour"},
  {"4.5",  "",                   "",                   "",                 "Left corner of left eyebrow"},
  {"4.6",  "",                   "",                   "",                 "Right corner of right eyebrow"},
  {"5.1",  "",                   "=8.3.y",             "",                 "Center of the left cheek"},
  {"5.2",  "",                   "=8.4.y",             "",                 "Center of the right cheek"},
  {"5.3",  ">3.5.x <3.7.x",      ">9.15.y <9.12.y",    "",                 "Left cheek bone"},
  // 5.4: the paper has x >3.6.x and <3.12.x, which no face satisfies (3.12.x < 3.6.x); mirrored.
  {"5.4",  ">3.12.x <3.6.x",     ">9.15.y <9.12.y",    "",                 "Right cheek bone"},
  {"6.1",  "=7.1.x",             "",                   "",                 "Tip of the tongue"},
  {"6.2",  "=7.1.x",             "",                   "",                 "Center of the tongue body"},
  {"6.3",  "",                   "",                   "=6.2.z",           "Left border of the tongue"},
  {"6.4",  "",                   "",                   "=6.2.z",           "Right border of the tongue"},
  {"7.1",  "",                   "",                   "",                 "Top of spine (center of head rotation)"},
  // 7.2 is not in the standard; Pandzic's facial motion cloning needs it ("neck base").
  {"7.2",  "",                   "",                   "",                 "Bottom of the neck / base of the head rotation"},
  {"8.1",  "=7.1.x",             "",                   "",                 "Middle point of outer upper lip contour"},
  {"8.2",  "=7.1.x",             "",                   "",                 "Middle point of outer lower lip contour"},
  {"8.3",  "",                   "",                   "",                 "Left corner of outer lip contour"},
  {"8.4",  "",                   "",                   "",                 "Right corner of outer lip contour"},
  {"8.5",  "=(8.3.x+8.1.x)/2",   "",                   "",                 "Midpoint between f.p. 8.3 and 8.1 in outer upper lip contour"},
  {"8.6",  "=(8.4.x+8.1.x)/2",   "",                   "",                 "Midpoint between f.p. 8.4 and 8.1 in outer upper lip contour"},
  {"8.7",  "=(8.3.x+8.2.x)/2",   "",                   "",                 "Midpoint between f.p. 8.3 and 8.2 in outer lower lip contour"},
  {"8.8",  "=(8.4.x+8.2.x)/2",   "",                   "",                 "Midpoint between f.p. 8.4 and 8.2 in outer lower lip contour"},
  // 8.9, 8.10: "hiph" in the paper.
  {"8.9",  "",                   "",                   "",                 "Right high point of Cupid's bow"},
  {"8.10", "",                   "",                   "",                 "Left high point of Cupid's bow"},
  {"9.1",  "",                   "",                   "",                 "Left nostril border"},
  {"9.2",  "",                   "",                   "",                 "Right nostril border"},
  {"9.3",  "=7.1.x",             "",                   "",                 "Nose tip"},
  {"9.4",  "",                   "",                   "",                 "Bottom right edge of nose"},
  {"9.5",  "",                   "",                   "",                 "Bottom left edge of nose"},
  {"9.6",  "",                   "",                   "",                 "Right upper edge of nose bone"},
  {"9.7",  "",                   "",                   "",                 "Left upper edge of nose bone"},
  {"9.8",  "=7.1.x",             "",                   "",                 "Top of the upper teeth"},
  {"9.9",  "=7.1.x",             "",                   "",                 "Bottom of the lower teeth"},
  {"9.10", "=7.1.x",             "",                   "",                 "Bottom of the upper teeth"},
  {"9.11", "=7.1.x",             "",                   "",                 "Top of the lower teeth"},
  {"9.12", "=7.1.x",             "=(9.6.y+9.3.y)/2",   "",                 "Middle lower edge of nose bone (or nose bump)",
           "y may instead be that of the nose bump"},
  {"9.13", "",                   "=(9.6.y+9.3.y)/2",   "",                 "Left lower edge of nose bone"},
  {"9.14", "",                   "=(9.6.y+9.3.y)/2",   "",                 "Right lower edge of nose bone"},
  {"9.15", "=7.1.x",             "",                   "",                 "Bottom middle edge of nose"},
  {"10.1", "",                   "",                   "",                 "Top of left ear"},
  {"10.2", "",                   "",                   "",                 "Top of right ear"},
  {"10.3", "",                   "=(10.1.y+10.5.y)/2", "",                 "Back of left ear"},
  {"10.4", "",                   "=(10.2.y+10.6.y)/2", "",                 "Back of right ear"},
  {"10.5", "",                   "",                   "",                 "Bottom of left ear lobe"},
  {"10.6", "",                   "",                   "",                 "Bottom of right ear lobe"},
  {"10.7", "",                   "",                   "",                 "Lower contact point between left lobe and face"},
  {"10.8", "",                   "",                   "",                 "Lower contact point between right lobe and face"},
  {"10.9", "",                   "",                   "",                 "Upper contact point between left ear and face"},
  {"10.10", "",                  "",                   "",                 "Upper contact point between right ear and face"},
  {"11.1", "=7.1.x",             "",                   "",                 "Middle border between hair and forehead"},
  {"11.2", "<4.4.x",             "",                   "",                 "Right border between hair and forehead"},
  {"11.3", ">4.3.x",             "",                   "",                 "Left border between hair and forehead"},
  {"11.4", "=7.1.x",             "",                   ">10.4.z <10.2.z",  "Top of skull"},
  {"11.5", "=11.4.x",            "",                   "=11.4.z",          "Hair thickness over f.p. 11.4"},
  {"11.6", "=7.1.x",             "=3.5.y",             "",                 "Back of skull"},
}};
// clang-format on

// "10.3" -> {10, 3}. Only used on the table above, whose ids are well formed.
constexpr std::pair<int, int> splitId(std::string_view id) {
  int parts[2] = {0, 0};
  int k = 0;
  for (char c : id) {
    if (c == '.') {
      ++k;
    } else {
      parts[k] = parts[k] * 10 + (c - '0');
    }
  }
  return {parts[0], parts[1]};
}

constexpr std::array<FeaturePointInfo, kFeaturePointCount + 1> kFeaturePoints = [] {
  std::array<FeaturePointInfo, kFeaturePointCount + 1> out{};
  for (std::size_t i = 0; i < out.size(); ++i) {
    const FpRow& r = kFpRows[i];
    const auto [group, index] = splitId(r.id);
    out[i] = {r.id, group, index, r.description, r.x, r.y, r.z, r.note, r.id != "7.2"};
  }
  return out;
}();

// ---------------------------------------------------------------------------------------------
// Visemes (Table 3) and expressions (Table 4)
// ---------------------------------------------------------------------------------------------

// clang-format off
constexpr std::array<VisemeInfo, 15> kVisemes{{
  { 0, "none",      ""},  // "na" in the paper
  { 1, "p, b, m",   "put, bed, mill"},
  { 2, "f, v",      "far, voice"},
  { 3, "T, D",      "think, that"},
  { 4, "t, d",      "tip, doll"},
  { 5, "k, g",      "call, gas"},
  { 6, "tS, dZ, S", "chair, join, she"},
  { 7, "s, z",      "sir, zeal"},
  { 8, "n, l",      "lot, not"},
  { 9, "r",         "red"},
  {10, "A:",        "car"},
  {11, "e",         "bed"},
  {12, "I",         "tip"},
  {13, "Q",         "top"},
  {14, "U",         "book"},
}};

constexpr std::array<ExpressionInfo, 7> kExpressions{{
  {0, "neutral",  "All face muscles are relaxed (the neutral face, section 2.1.1)."},
  {1, "joy",      "The eyebrows are relaxed. The mouth is open and the mouth corners pulled back "
                  "toward the ears."},
  {2, "sadness",  "The inner eyebrows are bent upward. The eyes are slightly closed. The mouth is "
                  "relaxed."},
  {3, "anger",    "The inner eyebrows are pulled downward and together. The eyes are wide open. "
                  "The lips are pressed against each other or opened to expose the teeth."},
  {4, "fear",     "The eyebrows are raised and pulled together. The inner eyebrows are bent "
                  "upward. The eyes are tense and alert."},
  {5, "disgust",  "The eyebrows and eyelids are relaxed. The upper lip is raised and curled, "
                  "often asymmetrically."},
  {6, "surprise", "The eyebrows are raised. The upper eyelids are wide open, the lower relaxed. "
                  "The jaw is opened."},
}};
// clang-format on

// ---------------------------------------------------------------------------------------------
// Compile-time consistency checks
// ---------------------------------------------------------------------------------------------

constexpr bool fapsNumberedInOrder() {
  for (std::size_t i = 0; i < kFaps.size(); ++i) {
    if (kFaps[i].number != static_cast<int>(i) + 1) return false;
  }
  return true;
}
static_assert(fapsNumberedInOrder(), "kFapRows must list FAP 1..68 in order");

constexpr bool groupsConsistent() {
  int next = 1;
  for (std::size_t g = 0; g < kGroups.size(); ++g) {
    const FapGroupInfo& info = kGroups[g];
    if (info.number != static_cast<int>(g) + 1 || info.firstFap != next) return false;
    for (int n = info.firstFap; n <= info.lastFap; ++n) {
      if (kFaps[static_cast<std::size_t>(n - 1)].group != info.number) return false;
    }
    next = info.lastFap + 1;
  }
  return next == kFapCount + 1;
}
static_assert(groupsConsistent(), "FAP groups must cover 1..68 and agree with the FAP rows");

constexpr bool featurePointsSorted() {
  for (std::size_t i = 1; i < kFeaturePoints.size(); ++i) {
    const FeaturePointInfo& a = kFeaturePoints[i - 1];
    const FeaturePointInfo& b = kFeaturePoints[i];
    if (a.group > b.group || (a.group == b.group && a.index >= b.index)) return false;
  }
  return true;
}
static_assert(featurePointsSorted(), "kFpRows must be in group/index order without duplicates");

}  // namespace

std::string_view fapuName(FapuKind kind) {
  for (const FapuInfo& info : kFapus) {
    if (info.kind == kind) return info.name;
  }
  return "-";
}

std::span<const FapuInfo> fapuTable() { return kFapus; }

std::span<const FapInfo> fapTable() { return kFaps; }

const FapInfo& fapInfo(int number) {
  if (number < 1 || number > kFapCount) {
    throw Error("FAP number " + std::to_string(number) + " is out of range (valid: 1.." +
                std::to_string(kFapCount) + ")");
  }
  return kFaps[static_cast<std::size_t>(number - 1)];
}

std::optional<int> fapNumber(std::string_view name) {
  for (const FapInfo& info : kFaps) {
    if (info.name == name) return info.number;
  }
  for (const FapInfo& info : kFaps) {
    if (info.bifsName == name) return info.number;
  }
  return std::nullopt;
}

std::span<const FapGroupInfo> fapGroupTable() { return kGroups; }

std::span<const FeaturePointInfo> featurePointTable() { return kFeaturePoints; }

const FeaturePointInfo* findFeaturePoint(std::string_view id) {
  for (const FeaturePointInfo& info : kFeaturePoints) {
    if (info.id == id) return &info;
  }
  return nullptr;
}

std::span<const VisemeInfo> visemeTable() { return kVisemes; }

std::span<const ExpressionInfo> expressionTable() { return kExpressions; }

}  // namespace mpeg4face
