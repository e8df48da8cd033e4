// SPDX-License-Identifier: GPL-3.0-or-later
// The MPEG-4 face animation tables (ISO/IEC 14496-2 FBA): FAPs, feature points, FAPU,
// FAP groups, visemes and expressions. This is the single source of truth for every other
// module, the Python bindings and the Blender add-on.
#pragma once

#include <optional>
#include <span>
#include <string_view>

namespace mpeg4face {

// Face Animation Parameter Units. None is used by FAP 1 and 2 (high-level FAPs).
enum class FapuKind { None, IRISD, ES, ENS, MNS, MW, AU };
std::string_view fapuName(FapuKind kind);  // "IRISD", "ES", ..., "AU", "-" for None

// The FAPU definitions (Tekalp-Ostermann Table 1).
struct FapuInfo {
  FapuKind kind;
  std::string_view name;         // "ES"
  std::string_view neutralName;  // "ES0" ("" for AU)
  std::string_view description;  // "Eye separation"
  std::string_view definition;   // "ES = ES0 / 1024"
};
std::span<const FapuInfo> fapuTable();  // 6 entries: IRISD, ES, ENS, MNS, MW, AU
inline constexpr double kAngleUnitRadians = 1e-5;
inline constexpr double kFapuDivisor = 1024.0;

// One row of the 68-FAP table (../shared/reference/mpeg4-face.md).
struct FapInfo {
  int number;                       // 1..68
  std::string_view name;            // "stretch_l_cornerlip"
  std::string_view bifsName;        // BIFS FAP node field name ("stretch_l_corner"); = name if same
  FapuKind fapu;                    // None for FAP 1, 2
  bool bidirectional;               // U/B column: false = unidirectional; FAP 1, 2: false
  std::string_view positiveMotion;  // "down", "left", "concave up", ... ("" for FAP 1, 2)
  int group;                        // 1..10
  std::string_view featurePoint;    // "2.1", "6.3, 6.4", "(eye)" or "" for FAP 1, 2
  int quantStep;                    // QP; effective step = QP * fap_quant
  int intraRange;                   // default I+- (0 for FAP 1, 2)
  int interRange;                   // default P+- (0 for FAP 1, 2)
};
inline constexpr int kFapCount = 68;
std::span<const FapInfo> fapTable();  // index i holds FAP i + 1
// Throws mpeg4face::Error for a number outside 1..68.
const FapInfo& fapInfo(int number);
// By name or BIFS field name; nullopt if unknown. Standard names are tried first, then BIFS
// field names. Two strings are both: "stretch_l_cornerlip" / "stretch_r_cornerlip" are the
// names of FAP 6 / 7 and the BIFS field names of FAP 53 / 54; fapNumber returns 6 / 7 for them.
// A reader of BIFS FAP node fields must match FapInfo::bifsName over fapTable() instead.
std::optional<int> fapNumber(std::string_view name);

// The ten FAP groups (Tekalp-Ostermann Table 2).
struct FapGroupInfo {
  int number;  // 1..10
  std::string_view name;
  int firstFap;
  int lastFap;
};
std::span<const FapGroupInfo> fapGroupTable();  // 10 entries

// One feature point (Tekalp-Ostermann Fig. 2 / Table 6), plus 7.2 which Pandzic's FMC needs.
// Table 6's slips are corrected in spec.cpp (3.10 / 3.13 eyes swapped, 5.4 x bounds not
// mirrored, "hiph" for "high" in 8.9 / 8.10).
struct FeaturePointInfo {
  std::string_view id;           // "2.1"
  int group;                     // 2..11
  int index;                     // 1..15
  std::string_view description;  // "Bottom of the chin"
  // Recommended location constraints per coordinate, as space-separated terms
  // `OP EXPR` with OP one of = < > and EXPR `P.c` or `(P.c+Q.c)/2` (P, Q feature points,
  // c the same axis): "" none, "=7.1.x", "=(2.2.x+2.4.x)/2", ">8.7.x <8.3.x".
  // Where the paper offers an alternative ("... or nose bump") it is in constraintNote and
  // a violated constraint is reported as advice, not as a warning.
  std::string_view constraintX;
  std::string_view constraintY;
  std::string_view constraintZ;
  std::string_view constraintNote;
  bool inStandard;  // false only for 7.2
};
inline constexpr int kFeaturePointCount = 84;           // in the standard; the table also has 7.2
std::span<const FeaturePointInfo> featurePointTable();  // 85 entries, in group/index order
const FeaturePointInfo* findFeaturePoint(std::string_view id);

// FAP 1 values (Tekalp-Ostermann Table 3).
struct VisemeInfo {
  int number;                 // 0..14
  std::string_view phonemes;  // "p, b, m"
  std::string_view example;   // "put, bed, mill"
};
std::span<const VisemeInfo> visemeTable();  // 15 entries

// FAP 2 values (Tekalp-Ostermann Table 4).
struct ExpressionInfo {
  int number;             // 0..6
  std::string_view name;  // "joy"
  std::string_view description;
};
std::span<const ExpressionInfo> expressionTable();  // 7 entries

}  // namespace mpeg4face
