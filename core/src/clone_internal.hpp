// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: the steps of Facial Motion Cloning (docs/clone.md). Not installed.
#pragma once

#include <Eigen/Core>
#include <array>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mpeg4face/clone.hpp"
#include "mpeg4face/face_model.hpp"
#include "mpeg4face/fapu.hpp"

namespace mpeg4face::clone {

enum class LipRegion : unsigned char { Outside = 0, Upper = 1, Lower = 2 };

// --- clone_feature_points.cpp: the fixed feature-point triangulation and lip polygons.
std::span<const std::array<std::string_view, 3>> alignmentTriangles();
// Triangles that fill the eye and mouth slits (the normalisation factors only).
std::span<const std::array<std::string_view, 3>> slitTriangles();
// The lip feature points and the lip each belongs to; the corners (2.4, 2.5, 8.3, 8.4)
// belong to both lips and so are Outside.
std::span<const std::pair<std::string_view, LipRegion>> lipFeaturePoints();
// Inner upper / lower lip contour (sorted along the mouth when used), then the nose / chin
// sides that close the polygon.
std::span<const std::string_view> upperLipContour();
std::span<const std::string_view> lowerLipContour();
std::span<const std::string_view> noseSides();
std::span<const std::string_view> chinSides();

// --- clone_normalisation.cpp: normalised facial space and the cylindrical projection.
// The normalisation factors (FAPU distances along x, y, z) of motion near feature point `id`.
Eigen::Vector3d motionFactors(std::string_view id, const FapuMeasurement& fapu);
struct FaceFrame {
  Eigen::Vector3d centre;         // C: feature point 9.15
  Eigen::Vector3d positionScale;  // (ES0, ENS0, ES0)
  double axisX = 0, axisZ = 0;    // the projection's vertical axis, normalised space
  double radius = 1;              // axis to mouth corner: u = radius * angle
  double angle0 = 0;              // the nose tip's angle
};
// Needs every point of cloneFeaturePoints() and the measured FAPU.
FaceFrame faceFrame(const FaceModel& model, const FapuMeasurement& fapu);
// Alignment-space point (u, v) of a model-space point; `depth` = -(distance from the axis).
Eigen::Vector2d project(const FaceFrame& frame, const Eigen::Vector3d& p, double* depth = nullptr);
// The normalised-space point of an alignment-space point (u, v) at `depth`, about the
// projection's axis and turned so that the nose tip is at angle 0: project() undone up to
// that rigid motion, so that distances are those of normalised space.
Eigen::Vector3d unproject(const FaceFrame& frame, const Eigen::Vector2d& uv, double depth);

// --- clone_mapping.cpp: the surface that takes part and the per-vertex sparse weights.
// Every mesh not excluded (the rigid parts), in model space, as one point set.
struct Surface {
  Points3 positions;                       // model space
  std::vector<std::pair<int, int>> owner;  // (mesh, vertex) of each row
  std::vector<int> triangles;              // rows of positions, three per triangle
  std::vector<int> firstRow;               // per mesh: its first row, -1 when excluded
};
Surface gatherSurface(const FaceModel& model, std::span<const int> excludedMeshes);

// Target motion (normalised) = sum over row's entries of weight * source motion (normalised).
struct Mapping {
  std::vector<int> rowStart;  // target vertex count + 1
  std::vector<int> source;    // source rows
  std::vector<double> weight;
  Points3 sourceFactors;  // N(FP) of each source row (motion / N = normalised motion)
  Points3 targetFactors;  // N(FP) of each target row
  std::vector<LipRegion> sourceLips, targetLips;
};
Mapping buildMapping(const FaceModel& source, const Surface& sourceSurface, const FaceModel& target,
                     const Surface& targetSurface, const CloneOptions& options);

}  // namespace mpeg4face::clone
