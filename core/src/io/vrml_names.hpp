// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: what the VRML writer and reader agree on beyond VRML97 itself (docs/vrml.md).
#pragma once

#include <string_view>

namespace mpeg4face::vrml_names {

// DEF names: a node's name with every byte outside [A-Za-z0-9_-] (and a leading digit or '-')
// written as kEscape + two hex digits; a name that is empty or already taken gets
// kUniqueSuffix + a number, which the reader drops. The writer never produces kUniqueSuffix
// otherwise ('%' is always escaped), so the two cannot be confused.
inline constexpr char kEscape = '%';
inline constexpr std::string_view kUniqueSuffix = "%_";

// The top-level WorldInfo that says where each feature point is. One info string per point
// that featurePointsCoord cannot express:
//   "<id> mesh <DEF name of an IndexedFaceSet> vertex <n>"
//   "<id> none"                    (unbound; its featurePointsCoord entry is a filler)
//   "<id> position <x> <y> <z>"    (a free point outside the 84 of featurePointsCoord: 7.2)
// A standard point not listed is the free coordinate featurePointsCoord gives.
inline constexpr std::string_view kFeaturePointsTitle = "mpeg4face feature points";
inline constexpr std::string_view kMesh = "mesh";
inline constexpr std::string_view kVertex = "vertex";
inline constexpr std::string_view kNone = "none";
inline constexpr std::string_view kPosition = "position";

}  // namespace mpeg4face::vrml_names
