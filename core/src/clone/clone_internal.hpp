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

#include "mpeg4face/clone/clone.hpp"
#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/model/fapu.hpp"

namespace mpeg4face::clone {

enum class LipRegion : unsigned char { Outside = 0, Upper = 1, Lower = 2 };

// --- clone/feature_points.cpp: the fixed feature-point triangulation and lip polygons.
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

// --- clone/normalisation.cpp: normalised facial space and the cylindrical projection.
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

// --- clone/mapping.cpp: the surface that takes part and the per-vertex sparse weights.
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

// The surface projected (project()): each row's point in alignment space and its depth.
struct Projected {
  Points2 uv;
  std::vector<double> depth;
  std::vector<int> triangles;  // without those that cross the seam behind the head
};
// The projected point of feature point `id`, which `model` must have.
Eigen::Vector2d projectedPoint(const FaceModel& model, const FaceFrame& frame, std::string_view id);

// --- clone/lips.cpp: the lip of each surface point (docs/clone.md, the lip rule).
std::vector<LipRegion> classifyLips(const FaceModel& model, const FaceFrame& frame,
                                    const Projected& p, const Points2& centroid,
                                    const Surface& surface);

// --- clone/same_place.cpp
// How near two points of a projected surface are to be at one place: a fraction (kSame) of
// the mean length of the edges at each row, measured in (u, v, depth) as SamePlace measures
// (0 for a row on no triangle). Relative to the mesh, not a fixed distance: a head stored in
// single precision (a glTF file, Blender) away from the origin has coordinates rounded by
// about 1e-7 of their distance from it, which no fixed tolerance small enough for a fine
// mesh absorbs.
std::vector<double> samePlaceTolerance(const Projected& p);
// Finds the source vertex at a target point's place (alignment space and depth), for the
// exact motion of coincident vertices.
class SamePlace {
 public:
  SamePlace(const Projected& source, const Points2& centroid);
  int find(const Eigen::Vector2d& p, double depth, const Eigen::Vector2d& centroid,
           LipRegion excluded, const std::vector<LipRegion>& lips) const;
  static constexpr double kSame = 1e-3;  // of the mean edge length at a point

 private:
  const Projected& source_;
  const Points2& centroid_;
  std::vector<int> byU_;
  std::vector<double> tolerance_;  // per source row (samePlaceTolerance)
  double widest_ = 0;              // the largest of them
};

// --- clone/butterfly.cpp
// The modified butterfly rule's value at the midpoint of a mesh edge (Zorin et al. 1996, regular
// case: 1/2 at its ends, 1/8 at the two opposite corners, -1/16 at the four wing corners), as
// weights over the mesh's points: with the corners', it makes a quadratic interpolation in a
// triangle that keeps a peak round where linear interpolation flattens it (ours).
class ButterflyMidpoints {
 public:
  ButterflyMidpoints(std::span<const int> triangles, Eigen::Index pointCount);
  // Appends the stencil of edge (a, b) times `weight` to `out`; the plain midpoint where the
  // edge's neighbourhood is not two regular triangles on each side, or where it reaches a
  // point `excluded` says no to.
  template <class Excluded>
  void add(int a, int b, double weight, const Excluded& excluded,
           std::vector<std::pair<int, double>>& out) const {
    std::array<int, 8> v{a, b, -1, -1, -1, -1, -1, -1};
    // The corner of the two triangles on edge (x, y) other than `not_` (-1: not two).
    const auto other = [&](int x, int y, int not_) {
      const auto [first, second] = opposite(x, y);
      return second < 0 ? -1 : first == not_ ? second : first;
    };
    const auto [o0, o1] = opposite(a, b);
    bool regular = o1 >= 0;
    if (regular) {
      v[2] = o0;
      v[3] = o1;
      v[4] = other(a, v[2], b);
      v[5] = other(b, v[2], a);
      v[6] = other(a, v[3], b);
      v[7] = other(b, v[3], a);
      for (int x : v) regular = regular && x >= 0 && !excluded(x);
    }
    static constexpr std::array<double, 8> kButterfly{0.5,     0.5,     0.125,   0.125,
                                                      -0.0625, -0.0625, -0.0625, -0.0625};
    for (std::size_t i = 0; i < (regular ? 8u : 2u); ++i) {
      out.emplace_back(v[i], weight * (regular ? kButterfly[i] : 0.5));
    }
  }

 private:
  std::pair<int, int> opposite(int x, int y) const;
  std::vector<int> start_;
  std::vector<std::pair<int, int>> edges_;  // (higher point, opposite corner)
};

// --- clone/relax.cpp: CloneRelaxation applied to the cloned shapes of `target`, whose
// meshes `surfaceMeshes` carry vertex motion (the rigid parts' do not).
void relaxClonedShapes(const FaceModel& target, const std::vector<int>& surfaceMeshes,
                       const CloneRelaxation& relaxation, std::vector<FaceShape>& shapes);

}  // namespace mpeg4face::clone
