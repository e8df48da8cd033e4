// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: the motion check's self-intersection test, for many poses of one mesh. Not
// installed.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face::fat {

// Two triangles intersect as CGAL's Polygon_mesh_processing::self_intersections says: the
// triangles meet other than in the vertex or edge they share. Keys: (smaller triangle << 32)
// | larger triangle, triangles counted in the order given.
//
// A pose can only make a new pair where two triangles moved, relative to one another, as far
// as they were apart. Each triangle's clearance is just under its distance in the neutral to
// the nearest triangle that shares no edge with it (kept apart for those sharing a vertex:
// there the distance of each one's opposite edge to the other); a pair whose vertices moved
// relative to one another less than the larger of their clearances has not met. A
// bounding-volume tree, its shape fixed by the neutral and its boxes and motions refit to each
// pose, skips whole groups of triangles by that rule; the pairs left are tested with CGAL's
// exact predicates, and every pair sharing an edge with one orientation test (such a pair
// meets only when flat and folded over).
class PoseIntersections {
 public:
  // `triangles`: three rows of `neutral` each. They are joined as a CGAL Surface_mesh joins
  // them; a triangle that cannot be (a non-manifold edge or vertex, or one facing the other
  // way) is kept apart, touching its neighbours in the neutral as in every pose.
  PoseIntersections(const Points3& neutral, const std::vector<int>& triangles);
  ~PoseIntersections();
  PoseIntersections(PoseIntersections&&) noexcept;
  PoseIntersections& operator=(PoseIntersections&&) noexcept;

  // The neutral's intersecting pairs, sorted.
  const std::vector<std::uint64_t>& neutralPairs() const;

  // The pose's intersecting pairs that are not the neutral's, sorted. Not const: it keeps
  // its buffers from one pose to the next.
  std::vector<std::uint64_t> newPairs(const Points3& pose);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// `mesh`'s triangles (three rows each) without those that name a corner twice: the
// triangles the motion check measures.
std::vector<int> checkedTriangles(const IndexedFaceSet& mesh);

// Every intersecting pair of `triangles` at `coord`, sorted: CGAL's self_intersections on the
// whole mesh (joined as above), the reference the fast test is measured against.
std::vector<std::uint64_t> allIntersectingPairs(const Points3& coord,
                                                const std::vector<int>& triangles);

}  // namespace mpeg4face::fat
