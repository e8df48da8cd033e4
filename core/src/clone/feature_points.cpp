// SPDX-License-Identifier: GPL-3.0-or-later
// The feature points Facial Motion Cloning needs and the fixed triangulation over them
// (Pandzic 2003, Figure 7, redesigned for this project: docs/clone.md and
// docs/images/clone_triangulation.png, drawn from this table by
// scripts/clone_triangulation_plot.py).
#include <algorithm>

#include "clone/clone_internal.hpp"

namespace mpeg4face {
namespace clone {
namespace {

// Left half (+x) and its mirror image, plus three across the middle. The eye slits (3.1 /
// 3.3) and the mouth slit (inside the inner lip contour 2.4 - 2.6 - 2.2 - 2.7 - 2.5 and
// 2.4 - 2.8 - 2.3 - 2.9 - 2.5) are holes: no triangle holds both points of a lid or lip
// pair, which coincide on a face modelled with closed eyes or mouth. The inner lip points
// are aligned too, so that each lip's inner edge lands on the source's.
// clang-format off
constexpr std::array<std::string_view, 3> kTriangles[] = {
    {"11.3", "4.1", "11.2"}, {"11.2", "4.1", "4.2"}, {"4.1", "4.2", "9.12"},
    {"11.3", "4.3", "4.1"}, {"4.2", "4.4", "11.2"}, {"11.3", "4.5", "4.3"},
    {"4.4", "4.6", "11.2"}, {"11.3", "10.9", "4.5"}, {"4.6", "10.10", "11.2"},
    {"4.5", "3.7", "10.9"}, {"10.10", "3.12", "4.6"}, {"4.5", "4.3", "3.7"},
    {"3.12", "4.4", "4.6"}, {"4.3", "3.1", "3.7"}, {"3.12", "3.2", "4.4"},
    {"4.3", "4.1", "3.1"}, {"3.2", "4.2", "4.4"}, {"4.1", "3.11", "3.1"},
    {"3.2", "3.8", "4.2"}, {"4.1", "9.12", "3.11"}, {"3.8", "9.12", "4.2"},
    {"10.9", "3.7", "5.3"}, {"5.4", "3.12", "10.10"}, {"3.7", "3.3", "5.3"},
    {"5.4", "3.4", "3.12"}, {"3.3", "3.11", "5.3"}, {"5.4", "3.8", "3.4"},
    {"3.11", "9.12", "5.3"}, {"5.4", "9.12", "3.8"}, {"9.12", "9.3", "5.3"},
    {"5.4", "9.3", "9.12"}, {"9.3", "9.1", "5.3"}, {"5.4", "9.2", "9.3"},
    {"9.3", "9.15", "9.1"}, {"9.2", "9.15", "9.3"}, {"10.9", "5.3", "2.13"},
    {"2.14", "5.4", "10.10"}, {"5.3", "9.1", "8.3"}, {"8.4", "9.2", "5.4"},
    {"5.3", "8.3", "2.13"}, {"2.14", "8.4", "5.4"}, {"9.1", "9.15", "8.1"},
    {"8.1", "9.15", "9.2"}, {"9.1", "8.1", "8.3"}, {"8.4", "8.1", "9.2"},
    {"8.1", "2.6", "8.3"}, {"8.4", "2.7", "8.1"}, {"8.1", "2.2", "2.6"},
    {"2.7", "2.2", "8.1"}, {"8.3", "2.6", "2.4"}, {"2.5", "2.7", "8.4"},
    {"8.3", "2.4", "2.8"}, {"2.9", "2.5", "8.4"}, {"8.3", "2.8", "8.2"},
    {"8.2", "2.9", "8.4"}, {"8.2", "2.8", "2.3"}, {"2.3", "2.9", "8.2"},
    {"8.3", "8.2", "2.10"}, {"2.10", "8.2", "8.4"},
    {"8.3", "2.10", "2.11"}, {"2.12", "2.10", "8.4"}, {"8.3", "2.11", "2.13"},
    {"2.14", "2.12", "8.4"}, {"2.11", "2.10", "2.1"}, {"2.1", "2.10", "2.12"},
    {"2.13", "2.11", "2.1"}, {"2.1", "2.12", "2.14"},
};
// The eye and mouth slits filled: for the normalisation factors, which are the same all
// round each slit (one region), so a point inside a slit takes them and not those of a far
// corner of the closest triangle by the paper's measure.
constexpr std::array<std::string_view, 3> kSlitTriangles[] = {
    {"3.7", "3.1", "3.11"}, {"3.7", "3.11", "3.3"}, {"3.12", "3.8", "3.2"},
    {"3.12", "3.4", "3.8"}, {"2.4", "2.6", "2.2"},  {"2.2", "2.7", "2.5"},
    {"2.4", "2.2", "2.5"},  {"2.4", "2.3", "2.8"},  {"2.3", "2.5", "2.9"},
    {"2.4", "2.5", "2.3"},
};
// The triangulation's points, and so every FAPU's.
constexpr std::string_view kRequired[] = {
    "2.1", "2.2", "2.3", "2.4", "2.5", "2.6", "2.7", "2.8", "2.9", "2.10", "2.11", "2.12",
    "2.13", "2.14", "3.1", "3.2", "3.3", "3.4", "3.7", "3.8", "3.11", "3.12", "4.1", "4.2",
    "4.3", "4.4", "4.5", "4.6", "5.3", "5.4", "8.1", "8.2", "8.3", "8.4", "9.1", "9.2", "9.3",
    "9.12", "9.15", "10.9", "10.10", "11.2", "11.3"};
// clang-format on
constexpr std::string_view kUpperLip[] = {"2.4", "2.6", "2.2", "2.7", "2.5"};
constexpr std::string_view kLowerLip[] = {"2.4", "2.8", "2.3", "2.9", "2.5"};
constexpr std::pair<std::string_view, LipRegion> kLipPoints[] = {
    {"2.2", LipRegion::Upper},   {"2.6", LipRegion::Upper},   {"2.7", LipRegion::Upper},
    {"8.1", LipRegion::Upper},   {"8.5", LipRegion::Upper},   {"8.6", LipRegion::Upper},
    {"8.9", LipRegion::Upper},   {"8.10", LipRegion::Upper},  {"2.3", LipRegion::Lower},
    {"2.8", LipRegion::Lower},   {"2.9", LipRegion::Lower},   {"8.2", LipRegion::Lower},
    {"8.7", LipRegion::Lower},   {"8.8", LipRegion::Lower},   {"2.4", LipRegion::Outside},
    {"2.5", LipRegion::Outside}, {"8.3", LipRegion::Outside}, {"8.4", LipRegion::Outside},
};
constexpr std::string_view kNoseSides[] = {"9.1", "9.2"};
constexpr std::string_view kChinSides[] = {"2.11", "2.12"};

}  // namespace

std::span<const std::array<std::string_view, 3>> alignmentTriangles() { return kTriangles; }
std::span<const std::array<std::string_view, 3>> slitTriangles() { return kSlitTriangles; }
std::span<const std::pair<std::string_view, LipRegion>> lipFeaturePoints() { return kLipPoints; }
std::span<const std::string_view> upperLipContour() { return kUpperLip; }
std::span<const std::string_view> lowerLipContour() { return kLowerLip; }
std::span<const std::string_view> noseSides() { return kNoseSides; }
std::span<const std::string_view> chinSides() { return kChinSides; }

}  // namespace clone

std::span<const std::string_view> cloneFeaturePoints() { return clone::kRequired; }

std::vector<std::string> missingCloneFeaturePoints(const FaceModel& model) {
  std::vector<std::string> missing;
  for (std::string_view id : clone::kRequired) {
    if (!model.featurePointPosition(std::string(id))) missing.emplace_back(id);
  }
  return missing;
}

}  // namespace mpeg4face
