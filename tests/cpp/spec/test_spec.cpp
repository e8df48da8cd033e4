// SPDX-License-Identifier: GPL-3.0-or-later
// Tests of the MPEG-4 tables in spec.hpp against ../shared/reference/mpeg4-face.md and
// Tekalp & Ostermann 2000 (Tables 1-4, 6).
#include <gtest/gtest.h>

#include <cctype>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

// --- A checker for the constraint grammar of FeaturePointInfo ----------------------------------
// Terms separated by one space; a term is OP EXPR, OP one of = < >, EXPR `P.c` or
// `(P.c+Q.c)/2`, P and Q existing feature points, c the axis of the constraint's column.

// Reads "G.I.c" at the start of s; on success stores "G.I" in id and removes the text from s.
bool readRef(std::string_view& s, char axis, std::string& id) {
  std::size_t pos = 0;
  for (int part = 0; part < 2; ++part) {
    const std::size_t start = pos;
    while (pos < s.size() && std::isdigit(static_cast<unsigned char>(s[pos]))) ++pos;
    if (pos == start || pos >= s.size() || s[pos] != '.') return false;
    ++pos;
  }
  if (pos >= s.size() || s[pos] != axis) return false;
  id = std::string(s.substr(0, pos - 1));
  s.remove_prefix(pos + 1);
  return true;
}

// Returns "" when `constraint` is valid, else the reason.
std::string checkConstraint(std::string_view constraint, char axis) {
  if (constraint.empty()) return "";
  bool hasEquals = false;
  int terms = 0;
  while (true) {
    const std::size_t space = constraint.find(' ');
    std::string_view term = constraint.substr(0, space);
    ++terms;
    if (term.size() < 2 || std::string_view("=<>").find(term[0]) == std::string_view::npos) {
      return "bad operator in term '" + std::string(term) + "'";
    }
    hasEquals = hasEquals || term[0] == '=';
    term.remove_prefix(1);
    std::vector<std::string> refs(1);
    if (term[0] == '(') {
      term.remove_prefix(1);
      refs.resize(2);
      if (!readRef(term, axis, refs[0]) || term.empty() || term[0] != '+') {
        return "bad first operand";
      }
      term.remove_prefix(1);
      if (!readRef(term, axis, refs[1]) || term != ")/2") return "bad second operand";
    } else if (!readRef(term, axis, refs[0]) || !term.empty()) {
      return "bad reference";
    }
    for (const std::string& id : refs) {
      if (findFeaturePoint(id) == nullptr) return "unknown feature point " + id;
    }
    if (space == std::string_view::npos) break;
    constraint.remove_prefix(space + 1);
  }
  if (hasEquals && terms > 1) return "'=' combined with other terms";
  return "";
}

TEST(SpecConstraintChecker, RejectsMalformedConstraints) {
  EXPECT_EQ(checkConstraint("=7.1.x", 'x'), "");
  EXPECT_EQ(checkConstraint("=(2.2.x+2.4.x)/2", 'x'), "");
  EXPECT_EQ(checkConstraint(">8.7.x <8.3.x", 'x'), "");
  EXPECT_NE(checkConstraint("7.1.x", 'x'), "");
  EXPECT_NE(checkConstraint("=7.1.y", 'x'), "");
  EXPECT_NE(checkConstraint("=(2.2.x+2.4.x)", 'x'), "");
  EXPECT_NE(checkConstraint("=(2.2.x#2.4.x)/2", 'x'), "");
  EXPECT_NE(checkConstraint("'8.7.x (8.3.x", 'x'), "");
  EXPECT_NE(checkConstraint(">8.7.x  <8.3.x", 'x'), "");
  EXPECT_NE(checkConstraint("=99.1.x", 'x'), "");
  EXPECT_NE(checkConstraint("=7.1.x <8.3.x", 'x'), "");
}

// --- Counts ----------------------------------------------------------------------------------

TEST(SpecCounts, TableSizes) {
  EXPECT_EQ(fapTable().size(), 68u);
  EXPECT_EQ(kFapCount, 68);
  EXPECT_EQ(fapGroupTable().size(), 10u);
  EXPECT_EQ(featurePointTable().size(), 85u);
  EXPECT_EQ(kFeaturePointCount, 84);
  EXPECT_EQ(visemeTable().size(), 15u);
  EXPECT_EQ(expressionTable().size(), 7u);
  EXPECT_EQ(fapuTable().size(), 6u);
}

// --- FAPs ------------------------------------------------------------------------------------

TEST(SpecFap, IndexHoldsFapNumberPlusOne) {
  const auto table = fapTable();
  for (std::size_t i = 0; i < table.size(); ++i) {
    EXPECT_EQ(table[i].number, static_cast<int>(i) + 1);
    EXPECT_EQ(&fapInfo(table[i].number), &table[i]);
  }
}

struct ExpectedFap {
  int number;
  std::string_view name;
  std::string_view bifsName;
  FapuKind fapu;
  bool bidirectional;
  std::string_view positiveMotion;
  int group;
  std::string_view featurePoint;
  int quantStep;
  int intraRange;
  int interRange;
};

// Copied by hand from the table in mpeg4-face.md.
const ExpectedFap kSample[] = {
    {1, "viseme", "viseme", FapuKind::None, false, "", 1, "", 1, 0, 0},
    {2, "expression", "expression", FapuKind::None, false, "", 1, "", 1, 0, 0},
    {3, "open_jaw", "open_jaw", FapuKind::MNS, false, "down", 2, "2.1", 4, 1080, 360},
    {5, "raise_b_midlip", "raise_b_midlip", FapuKind::MNS, true, "up", 2, "2.3", 2, 1860, 600},
    {6, "stretch_l_cornerlip", "stretch_l_corner", FapuKind::MW, true, "left", 2, "2.4", 2, 600,
     180},
    {10, "raise_b_lip_lm", "lower_b_lip_lm", FapuKind::MNS, true, "up", 2, "2.8", 2, 1860, 600},
    {15, "shift_jaw", "shift_jaw", FapuKind::MW, true, "right", 2, "2.1", 1, 1080, 360},
    {18, "depress_chin", "depress_chin", FapuKind::MNS, true, "up", 2, "2.10", 1, 420, 180},
    {21, "close_b_l_eyelid", "close_b_l_eyelid", FapuKind::IRISD, true, "up", 3, "3.3", 1, 600,
     240},
    {23, "yaw_l_eyeball", "yaw_l_eyeball", FapuKind::AU, true, "left", 3, "(eye)", 128, 1200, 420},
    {28, "thrust_r_eyeball", "thrust_r_eyeball", FapuKind::ES, true, "forward", 3, "(eye)", 1, 600,
     180},
    {30, "dilate_r_pupil", "dilate_r_pupil", FapuKind::IRISD, true, "growing", 3, "3.6", 1, 420,
     120},
    {38, "squeeze_r_eyebrow", "squeeze_r_eyebrow", FapuKind::ES, true, "left", 4, "4.2", 1, 900,
     300},
    {41, "lift_l_cheek", "lift_l_cheek", FapuKind::ENS, false, "up", 5, "5.3", 2, 600, 180},
    {47, "tongue_roll", "tongue_roll", FapuKind::AU, false, "concave up", 6, "6.3, 6.4", 512, 1080,
     420},
    {48, "head_pitch", "head_pitch", FapuKind::AU, true, "down", 7, "7.1", 170, 1860, 600},
    {53, "stretch_l_cornerlip_o", "stretch_l_cornerlip", FapuKind::MW, true, "left", 8, "8.3", 2,
     600, 180},
    {54, "stretch_r_cornerlip_o", "stretch_r_cornerlip", FapuKind::MW, true, "right", 8, "8.4", 2,
     600, 180},
    {63, "raise_nose", "raise_nose", FapuKind::ENS, true, "up", 9, "9.3", 1, 680, 180},
    {68, "pull_r_ear", "pull_r_ear", FapuKind::ENS, true, "right", 10, "10.4", 1, 900, 300},
};

TEST(SpecFap, SampleRowsMatchReference) {
  for (const ExpectedFap& e : kSample) {
    SCOPED_TRACE("FAP " + std::to_string(e.number));
    const FapInfo& f = fapInfo(e.number);
    EXPECT_EQ(f.number, e.number);
    EXPECT_EQ(f.name, e.name);
    EXPECT_EQ(f.bifsName, e.bifsName);
    EXPECT_EQ(f.fapu, e.fapu);
    EXPECT_EQ(f.bidirectional, e.bidirectional);
    EXPECT_EQ(f.positiveMotion, e.positiveMotion);
    EXPECT_EQ(f.group, e.group);
    EXPECT_EQ(f.featurePoint, e.featurePoint);
    EXPECT_EQ(f.quantStep, e.quantStep);
    EXPECT_EQ(f.intraRange, e.intraRange);
    EXPECT_EQ(f.interRange, e.interRange);
  }
}

TEST(SpecFap, OnlySixBifsNamesDiffer) {
  std::map<int, std::string_view> differing;
  for (const FapInfo& f : fapTable()) {
    if (f.bifsName != f.name) differing[f.number] = f.bifsName;
  }
  const std::map<int, std::string_view> expected = {
      {6, "stretch_l_corner"}, {7, "stretch_r_corner"},     {10, "lower_b_lip_lm"},
      {11, "lower_b_lip_rm"},  {53, "stretch_l_cornerlip"}, {54, "stretch_r_cornerlip"}};
  EXPECT_EQ(differing, expected);
}

TEST(SpecFap, NamesAndBifsNamesAreUniqueAndNonEmpty) {
  std::set<std::string_view> names;
  std::set<std::string_view> bifsNames;
  for (const FapInfo& f : fapTable()) {
    EXPECT_FALSE(f.name.empty()) << f.number;
    EXPECT_FALSE(f.bifsName.empty()) << f.number;
    EXPECT_TRUE(names.insert(f.name).second) << f.name;
    EXPECT_TRUE(bifsNames.insert(f.bifsName).second) << f.bifsName;
  }
}

TEST(SpecFap, LowLevelFapsHaveUnitMotionAndRanges) {
  for (const FapInfo& f : fapTable()) {
    SCOPED_TRACE("FAP " + std::to_string(f.number));
    if (f.number <= 2) {
      EXPECT_EQ(f.fapu, FapuKind::None);
      EXPECT_TRUE(f.positiveMotion.empty());
      EXPECT_TRUE(f.featurePoint.empty());
      EXPECT_EQ(f.intraRange, 0);
      EXPECT_EQ(f.interRange, 0);
    } else {
      EXPECT_NE(f.fapu, FapuKind::None);
      EXPECT_FALSE(f.positiveMotion.empty());
      EXPECT_FALSE(f.featurePoint.empty());
      EXPECT_GT(f.quantStep, 0);
      EXPECT_GT(f.intraRange, 0);
      EXPECT_GT(f.interRange, 0);
      EXPECT_LE(f.interRange, f.intraRange);
    }
  }
}

TEST(SpecFap, FeaturePointsExist) {
  for (const FapInfo& f : fapTable()) {
    if (f.featurePoint.empty() || f.featurePoint == "(eye)") continue;
    std::string_view list = f.featurePoint;
    while (true) {
      const std::size_t comma = list.find(", ");
      const std::string_view id = list.substr(0, comma);
      const FeaturePointInfo* fp = findFeaturePoint(id);
      ASSERT_NE(fp, nullptr) << "FAP " << f.number << " names unknown feature point " << id;
      EXPECT_TRUE(fp->inStandard) << id;
      if (comma == std::string_view::npos) break;
      list.remove_prefix(comma + 2);
    }
  }
  EXPECT_EQ(fapInfo(47).featurePoint, "6.3, 6.4");
}

TEST(SpecFap, OutOfRangeNumbersThrow) {
  EXPECT_THROW(fapInfo(0), Error);
  EXPECT_THROW(fapInfo(69), Error);
  EXPECT_THROW(fapInfo(-1), Error);
  EXPECT_NO_THROW(fapInfo(1));
  EXPECT_NO_THROW(fapInfo(68));
  try {
    fapInfo(69);
    FAIL() << "no exception";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("69"), std::string::npos) << what;
    EXPECT_NE(what.find("1..68"), std::string::npos) << what;
  }
}

TEST(SpecFapNumber, ResolvesNamesAndBifsNames) {
  EXPECT_EQ(fapNumber("viseme"), 1);
  EXPECT_EQ(fapNumber("open_jaw"), 3);
  EXPECT_EQ(fapNumber("stretch_l_corner"), 6);  // BIFS name of FAP 6
  EXPECT_EQ(fapNumber("stretch_r_corner"), 7);
  EXPECT_EQ(fapNumber("lower_b_lip_lm"), 10);  // BIFS name of FAP 10
  EXPECT_EQ(fapNumber("raise_b_lip_lm"), 10);
  EXPECT_EQ(fapNumber("stretch_l_cornerlip_o"), 53);
  EXPECT_EQ(fapNumber("pull_r_ear"), 68);
  EXPECT_EQ(fapNumber("no_such_fap"), std::nullopt);
  EXPECT_EQ(fapNumber(""), std::nullopt);
  EXPECT_EQ(fapNumber("OPEN_JAW"), std::nullopt);  // case-sensitive
  for (const FapInfo& f : fapTable()) {
    EXPECT_EQ(fapNumber(f.name), f.number) << f.name;
  }
}

// Decision documented in spec.hpp: standard names win over BIFS field names.
TEST(SpecFapNumber, StandardNameWinsOverBifsName) {
  EXPECT_EQ(fapNumber("stretch_l_cornerlip"), 6);  // name of 6, BIFS name of 53
  EXPECT_EQ(fapNumber("stretch_r_cornerlip"), 7);  // name of 7, BIFS name of 54
  // A BIFS reader matches bifsName over the table, which is unambiguous.
  auto byBifs = [](std::string_view field) {
    for (const FapInfo& f : fapTable()) {
      if (f.bifsName == field) return f.number;
    }
    return 0;
  };
  EXPECT_EQ(byBifs("stretch_l_cornerlip"), 53);
  EXPECT_EQ(byBifs("stretch_r_cornerlip"), 54);
  EXPECT_EQ(byBifs("stretch_l_corner"), 6);
}

// --- Groups ----------------------------------------------------------------------------------

TEST(SpecGroups, CoverAllFapsWithoutGaps) {
  int next = 1;
  int number = 1;
  for (const FapGroupInfo& g : fapGroupTable()) {
    EXPECT_EQ(g.number, number++);
    EXPECT_EQ(g.firstFap, next);
    EXPECT_LE(g.firstFap, g.lastFap);
    EXPECT_FALSE(g.name.empty());
    for (int n = g.firstFap; n <= g.lastFap; ++n) {
      EXPECT_EQ(fapInfo(n).group, g.number) << n;
    }
    next = g.lastFap + 1;
  }
  EXPECT_EQ(next, 69);
}

TEST(SpecGroups, MatchTable2) {
  const auto groups = fapGroupTable();
  const int sizes[10] = {2, 16, 12, 8, 4, 5, 3, 10, 4, 4};  // "Number of FAPs" column
  for (std::size_t i = 0; i < 10; ++i) {
    EXPECT_EQ(groups[i].lastFap - groups[i].firstFap + 1, sizes[i]) << i + 1;
  }
  EXPECT_EQ(groups[0].name, "Visemes and expressions");
  EXPECT_EQ(groups[1].name, "Jaw, chin, inner lowerlip, cornerlips, midlip");
  EXPECT_EQ(groups[2].name, "Eyeballs, pupils, eyelids");
  EXPECT_EQ(groups[6].name, "Head rotation");
  EXPECT_EQ(groups[7].name, "Outer lip positions");
  EXPECT_EQ(groups[9].name, "Ears");
}

// --- Feature points --------------------------------------------------------------------------

TEST(SpecFeaturePoints, CountsPerGroup) {
  std::map<int, int> standard;
  int nonStandard = 0;
  for (const FeaturePointInfo& fp : featurePointTable()) {
    if (fp.inStandard) {
      ++standard[fp.group];
    } else {
      ++nonStandard;
      EXPECT_EQ(fp.id, "7.2");
    }
  }
  const std::map<int, int> expected = {{2, 14}, {3, 14}, {4, 6},  {5, 4},   {6, 4},
                                       {7, 1},  {8, 10}, {9, 15}, {10, 10}, {11, 6}};
  EXPECT_EQ(standard, expected);
  EXPECT_EQ(nonStandard, 1);
  int total = 0;
  for (const auto& [group, count] : standard) total += count;
  EXPECT_EQ(total, kFeaturePointCount);
}

TEST(SpecFeaturePoints, IdsMatchGroupAndIndexInOrder) {
  std::set<std::string_view> ids;
  int previousGroup = 0;
  int previousIndex = 0;
  for (const FeaturePointInfo& fp : featurePointTable()) {
    EXPECT_EQ(fp.id, std::to_string(fp.group) + "." + std::to_string(fp.index));
    EXPECT_TRUE(ids.insert(fp.id).second) << fp.id;
    EXPECT_TRUE(fp.group > previousGroup ||
                (fp.group == previousGroup && fp.index == previousIndex + 1))
        << fp.id;
    if (fp.group != previousGroup) {
      EXPECT_EQ(fp.index, 1) << fp.id;
    }
    previousGroup = fp.group;
    previousIndex = fp.index;
    EXPECT_FALSE(fp.description.empty()) << fp.id;
    EXPECT_EQ(findFeaturePoint(fp.id), &fp);
  }
}

TEST(SpecFeaturePoints, FindUnknown) {
  EXPECT_EQ(findFeaturePoint("1.1"), nullptr);
  EXPECT_EQ(findFeaturePoint("2.15"), nullptr);
  EXPECT_EQ(findFeaturePoint("7.3"), nullptr);
  EXPECT_EQ(findFeaturePoint(""), nullptr);
  EXPECT_EQ(findFeaturePoint("2.1 "), nullptr);
  ASSERT_NE(findFeaturePoint("10.10"), nullptr);
  ASSERT_NE(findFeaturePoint("7.2"), nullptr);
  EXPECT_FALSE(findFeaturePoint("7.2")->inStandard);
  EXPECT_TRUE(findFeaturePoint("7.1")->inStandard);
}

TEST(SpecFeaturePoints, EveryConstraintParsesAndNamesExistingPoints) {
  for (const FeaturePointInfo& fp : featurePointTable()) {
    EXPECT_EQ(checkConstraint(fp.constraintX, 'x'), "") << fp.id << " x: " << fp.constraintX;
    EXPECT_EQ(checkConstraint(fp.constraintY, 'y'), "") << fp.id << " y: " << fp.constraintY;
    EXPECT_EQ(checkConstraint(fp.constraintZ, 'z'), "") << fp.id << " z: " << fp.constraintZ;
    const std::string self = std::string(fp.id) + ".";
    for (std::string_view c : {fp.constraintX, fp.constraintY, fp.constraintZ}) {
      EXPECT_EQ(c.find(self), std::string_view::npos) << fp.id << " refers to itself";
    }
  }
}

TEST(SpecFeaturePoints, SampleMatchesTable6) {
  struct Expected {
    std::string_view id, description, x, y, z;
    bool hasNote;
  };
  const Expected sample[] = {
      {"2.1", "Bottom of the chin", "=7.1.x", "", "", false},
      {"2.6", "Midpoint between f.p. 2.2 and 2.4 in the inner upper lip contour",
       "=(2.2.x+2.4.x)/2", "", "", false},
      {"2.11", "Chin left corner", ">8.7.x <8.3.x", "", "", false},
      {"2.12", "Chin right corner", ">8.4.x <8.8.x", "", "", false},
      // The paper gives 3.10 the left eye's corners and 3.13 the right eye's; corrected.
      {"3.10", "Center of lower outer right eyelid", "=(3.8.x+3.12.x)/2", "", "", false},
      {"3.13", "Center of upper outer left eyelid", "=(3.7.x+3.11.x)/2", "", "", false},
      {"4.3", "Uppermost point of the left eyebrow", "=(4.1.x+4.5.x)/2", "", "", true},
      {"5.3", "Left cheek bone", ">3.5.x <3.7.x", ">9.15.y <9.12.y", "", false},
      {"6.3", "Left border of the tongue", "", "", "=6.2.z", false},
      {"9.12", "Middle lower edge of nose bone (or nose bump)", "=7.1.x", "=(9.6.y+9.3.y)/2", "",
       true},
      {"10.4", "Back of right ear", "", "=(10.2.y+10.6.y)/2", "", false},
      {"11.4", "Top of skull", "=7.1.x", "", ">10.4.z <10.2.z", false},
      {"11.5", "Hair thickness over f.p. 11.4", "=11.4.x", "", "=11.4.z", false},
      {"11.6", "Back of skull", "=7.1.x", "=3.5.y", "", false},
  };
  for (const Expected& e : sample) {
    SCOPED_TRACE(std::string(e.id));
    const FeaturePointInfo* fp = findFeaturePoint(e.id);
    ASSERT_NE(fp, nullptr);
    EXPECT_EQ(fp->description, e.description);
    EXPECT_EQ(fp->constraintX, e.x);
    EXPECT_EQ(fp->constraintY, e.y);
    EXPECT_EQ(fp->constraintZ, e.z);
    EXPECT_EQ(!fp->constraintNote.empty(), e.hasNote);
    EXPECT_TRUE(fp->inStandard);
  }
  EXPECT_NE(findFeaturePoint("4.3")->constraintNote.find("uppermost point of the contour"),
            std::string_view::npos);
  EXPECT_NE(findFeaturePoint("9.12")->constraintNote.find("nose bump"), std::string_view::npos);
}

// Left/right mirror pairs must have mirrored x constraints; this is what caught the paper's
// slips for 3.10/3.13 and 5.4.
TEST(SpecFeaturePoints, EyeAndCheekConstraintsUseTheirOwnSide) {
  for (std::string_view id : {"3.1", "3.3", "3.9", "3.13"}) {
    EXPECT_EQ(findFeaturePoint(id)->constraintX, "=(3.7.x+3.11.x)/2") << id;
  }
  for (std::string_view id : {"3.2", "3.4", "3.10", "3.14"}) {
    EXPECT_EQ(findFeaturePoint(id)->constraintX, "=(3.8.x+3.12.x)/2") << id;
  }
  EXPECT_EQ(findFeaturePoint("5.4")->constraintX, ">3.12.x <3.6.x");
  EXPECT_EQ(findFeaturePoint("5.4")->constraintY, ">9.15.y <9.12.y");
}

// --- FAPU, visemes, expressions -------------------------------------------------------------

TEST(SpecFapu, Table1) {
  const auto table = fapuTable();
  const FapuKind kinds[6] = {FapuKind::IRISD, FapuKind::ES, FapuKind::ENS,
                             FapuKind::MNS,   FapuKind::MW, FapuKind::AU};
  const std::string_view names[6] = {"IRISD", "ES", "ENS", "MNS", "MW", "AU"};
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(table[i].kind, kinds[i]);
    EXPECT_EQ(table[i].name, names[i]);
    EXPECT_EQ(fapuName(kinds[i]), names[i]);
    if (kinds[i] == FapuKind::AU) {
      EXPECT_EQ(table[i].neutralName, "");
    } else {
      EXPECT_EQ(table[i].neutralName, std::string(names[i]) + "0");
      EXPECT_EQ(table[i].definition,
                std::string(names[i]) + " = " + std::string(names[i]) + "0 / 1024");
    }
  }
  EXPECT_EQ(fapuName(FapuKind::None), "-");
  EXPECT_EQ(table[1].description, "Eye separation");
  EXPECT_EQ(table[2].description, "Eye-nose separation");
  EXPECT_EQ(table[3].description, "Mouth-nose separation");
  EXPECT_EQ(table[4].description, "Mouth width");
  EXPECT_EQ(table[5].description, "Angle unit");
  EXPECT_DOUBLE_EQ(kAngleUnitRadians, 1e-5);
  EXPECT_DOUBLE_EQ(kFapuDivisor, 1024.0);
}

TEST(SpecVisemes, Table3) {
  const auto table = visemeTable();
  for (std::size_t i = 0; i < table.size(); ++i) EXPECT_EQ(table[i].number, static_cast<int>(i));
  EXPECT_EQ(table[0].phonemes, "none");
  EXPECT_EQ(table[1].phonemes, "p, b, m");
  EXPECT_EQ(table[1].example, "put, bed, mill");
  EXPECT_EQ(table[6].phonemes, "tS, dZ, S");
  EXPECT_EQ(table[6].example, "chair, join, she");
  EXPECT_EQ(table[9].phonemes, "r");
  EXPECT_EQ(table[9].example, "red");
  EXPECT_EQ(table[10].phonemes, "A:");
  EXPECT_EQ(table[10].example, "car");
  EXPECT_EQ(table[14].phonemes, "U");
  EXPECT_EQ(table[14].example, "book");
}

TEST(SpecExpressions, Table4) {
  const auto table = expressionTable();
  const std::string_view names[7] = {"neutral", "joy",     "sadness", "anger",
                                     "fear",    "disgust", "surprise"};
  for (std::size_t i = 0; i < 7; ++i) {
    EXPECT_EQ(table[i].number, static_cast<int>(i));
    EXPECT_EQ(table[i].name, names[i]);
    if (i > 0) {
      EXPECT_FALSE(table[i].description.empty()) << names[i];
    }
  }
  EXPECT_EQ(table[1].description,
            "The eyebrows are relaxed. The mouth is open and the mouth corners pulled back toward "
            "the ears.");
  EXPECT_EQ(table[6].description,
            "The eyebrows are raised. The upper eyelids are wide open, the lower relaxed. The jaw "
            "is opened.");
}

}  // namespace
}  // namespace mpeg4face
