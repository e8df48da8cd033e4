// SPDX-License-Identifier: GPL-3.0-or-later
// Bumps in a displacement field over a triangle mesh: the umbrella Laplacian of the field,
// bump_i = |d_i - mean of d_j over the one-ring of i|, against the local motion
// m_i = max(|d_i|, max |d_j| over the ring). A vertex that a pose moves alone (or holds still
// while its ring moves) has bump_i close to m_i: a spike; smooth skin motion has bump_i a
// small part of m_i. The motion check (fat/motion_check.hpp) reports spikes per pose; why
// and the calibration of the limits: docs/motion-check.md.
//
// The one-rings are built once per mesh (weldedRings), with the vertices at the same
// position welded into one, so that a seam's split copies (UV seams) share their
// neighbours; each displacement field then costs O(vertices + edges).
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face {

// The one-ring of each vertex of a triangle mesh, the vertices at identical positions (exact
// equality, -0 == 0) welded into one: compressed rows over the welded vertices.
struct WeldedRings {
  std::vector<int> weld;       // per vertex: its welded vertex, 0 .. copies.size() - 1
  std::vector<int> copies;     // per welded vertex: how many vertices it welds
  std::vector<int> offset;     // per welded vertex w and one more: its ring is
  std::vector<int> neighbour;  // neighbour[offset[w] .. offset[w + 1]), welded, ascending
};

// The welded one-rings of `triangles` (three vertex indices each) over `coord`. A vertex on
// no triangle (and not at the position of one that is) has an empty ring. Throws Error
// naming the triangle whose index is out of range.
WeldedRings weldedRings(const Eigen::Ref<const Points3>& coord, std::span<const int> triangles);
// The same for a mesh's fan-triangulated faces (IndexedFaceSet::triangles()).
WeldedRings weldedRings(const IndexedFaceSet& mesh);

// Per vertex of a displacement field d (one row per vertex of the mesh of `rings`).
struct SurfaceBump {
  // |d_i - mean of the ring's d_j| (a welded neighbour's d is the mean of its copies);
  // NaN for a vertex with an empty ring.
  Eigen::VectorXd bump;
  // max(|d_i|, max |d_j| over the ring's vertices and their copies); |d_i| without a ring.
  Eigen::VectorXd localMotion;
  Eigen::VectorXd motion;  // |d_i|
  double peak = 0;         // the largest |d_i| of a vertex with a ring
};

// Throws Error when `displacement` has not one row per vertex of `rings`.
SurfaceBump surfaceBump(const WeldedRings& rings, const Eigen::Ref<const Points3>& displacement);

// Umbrella smoothing: `passes` times, each vertex's displacement moved halfway to the mean of
// its ring's (welded: seam copies move alike); a vertex with an empty ring, or one `where`
// excludes (when given: one entry per vertex), keeps its own. It flattens a field's bumps;
// cloning relaxes what it carries with it (CloneRelaxation). Throws Error when `displacement`
// or `where` does not have one row per vertex of `rings`.
void relaxDisplacement(const WeldedRings& rings, Points3& displacement, int passes,
                       const std::vector<bool>& where = {});

// The spikes of a field, and two figures of how bumpy it is, relative to `peak`: the field's
// own (bump.peak), or the motion of a whole pose the field is part of (a mesh's bumps against
// the face's motion). Vertices with an empty ring are left out; peak 0 finds none.
struct SurfaceSpikes {
  // bump_i > bumpOfPeak * peak and bump_i > bumpOfLocalMotion * m_i, ascending.
  std::vector<int> vertices;
  // The 99th percentile of bump_i / peak over the moving area: the vertices that move at
  // least movingArea * peak. 0 without any.
  double bumpP99 = 0;
  // The largest bump_i / m_i over the vertices with bump_i > bumpOfPeak * peak; 0 without any.
  double localRatioMax = 0;
};

SurfaceSpikes surfaceSpikes(const SurfaceBump& bump, double peak, double bumpOfPeak,
                            double bumpOfLocalMotion, double movingArea = 0.02);
// Relative to the field's own peak.
inline SurfaceSpikes surfaceSpikes(const SurfaceBump& bump, double bumpOfPeak,
                                   double bumpOfLocalMotion) {
  return surfaceSpikes(bump, bump.peak, bumpOfPeak, bumpOfLocalMotion);
}

}  // namespace mpeg4face
