// SPDX-License-Identifier: GPL-3.0-or-later
#include "fat/pose_intersections.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <cmath>
#include <iterator>

namespace mpeg4face::fat {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Segment = Kernel::Segment_3;
using Triangle = Kernel::Triangle_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, int>;
using Faces = std::vector<std::array<int, 3>>;

// CGAL's self_intersections cuts its box recursion off at this many boxes too.
constexpr std::ptrdiff_t kBoxCutoff = 2000;

std::uint64_t pairKey(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
}

void sortUnique(std::vector<std::uint64_t>& keys) {
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

std::vector<Point> surfacePoints(const Points3& coord, const std::vector<int>& source) {
  std::vector<Point> points;
  points.reserve(source.size());
  for (int row : source) points.emplace_back(coord(row, 0), coord(row, 1), coord(row, 2));
  return points;
}

// Triangles joined into a surface: face t is triangle t, over surface vertices; surface
// vertex v sits at row source[v] (vertex i is row i; a triangle CGAL cannot join to its
// neighbours gets three of its own).
struct Joined {
  SurfaceMesh mesh;
  Faces faces;
  std::vector<int> source;
};

Joined joined(Eigen::Index rows, const std::vector<int>& triangles) {
  Joined j;
  for (Eigen::Index v = 0; v < rows; ++v) {
    j.mesh.add_vertex();
    j.source.push_back(static_cast<int>(v));
  }
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
    std::array<SurfaceMesh::Vertex_index, 3> v;
    for (int k = 0; k < 3; ++k) v[k] = SurfaceMesh::Vertex_index(triangles[t + k]);
    if (j.mesh.add_face(v[0], v[1], v[2]) == SurfaceMesh::null_face()) {
      for (int k = 0; k < 3; ++k) {
        v[k] = j.mesh.add_vertex();
        j.source.push_back(triangles[t + k]);
      }
      j.mesh.add_face(v[0], v[1], v[2]);
    }
    j.faces.push_back({static_cast<int>(v[0].idx()), static_cast<int>(v[1].idx()),
                       static_cast<int>(v[2].idx())});
  }
  return j;
}

// CGAL's self_intersections over the whole surface at `points`.
std::vector<std::uint64_t> intersectingPairs(Joined& j, const std::vector<Point>& points) {
  for (SurfaceMesh::Vertex_index v : j.mesh.vertices()) j.mesh.point(v) = points[v.idx()];
  std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(j.mesh, std::back_inserter(pairs));
  std::vector<std::uint64_t> keys;
  for (const auto& [f, g] : pairs) {
    if (f == g) continue;  // a degenerate triangle: the edge ratio judges it
    keys.push_back(pairKey(static_cast<int>(f.idx()), static_cast<int>(g.idx())));
  }
  sortUnique(keys);
  return keys;
}

// The vertex the two faces share when they share exactly one, as (its slot in f, in g);
// {-1, -1} when they share none; {-2, -2} when they share an edge.
std::array<int, 2> sharedVertex(const std::array<int, 3>& f, const std::array<int, 3>& g) {
  std::array<int, 2> found{-1, -1};
  int count = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (f[i] != g[j]) continue;
      if (++count == 1) found = {i, j};
    }
  }
  return count >= 2 ? std::array<int, 2>{-2, -2} : found;
}

Triangle triangleOf(const std::vector<Point>& p, const std::array<int, 3>& f) {
  return {p[f[0]], p[f[1]], p[f[2]]};
}

Segment oppositeSegment(const std::vector<Point>& p, const std::array<int, 3>& f, int slot) {
  return {p[f[(slot + 1) % 3]], p[f[(slot + 2) % 3]]};
}

// CGAL's test for two faces that share no edge (PMP::internal::do_faces_intersect), `shared`
// their sharedVertex.
bool meetApartFromSharedVertex(const std::vector<Point>& p, const std::array<int, 3>& f,
                               const std::array<int, 3>& g, std::array<int, 2> shared) {
  const auto [i, j] = shared;
  const Triangle a = triangleOf(p, f), b = triangleOf(p, g);
  if (i < 0) return CGAL::do_intersect(a, b);
  return CGAL::do_intersect(a, oppositeSegment(p, g, j)) ||
         CGAL::do_intersect(b, oppositeSegment(p, f, i));
}

double segmentTriangleDistance(const Segment& s, const Triangle& t) {
  double d = std::min(CGAL::squared_distance(s.source(), t), CGAL::squared_distance(s.target(), t));
  for (int k = 0; k < 3; ++k) {
    d = std::min(d, CGAL::squared_distance(s, Segment(t.vertex(k), t.vertex(k + 1))));
  }
  return std::sqrt(d);
}

// How far apart two faces that share no edge and do not intersect are, as far as the test
// above goes: the triangles' distance, or with a shared vertex the nearer opposite edge's.
double gap(const std::vector<Point>& p, const std::array<int, 3>& f, const std::array<int, 3>& g) {
  const auto [i, j] = sharedVertex(f, g);
  const Triangle a = triangleOf(p, f), b = triangleOf(p, g);
  if (i < 0) return std::sqrt(CGAL::squared_distance(a, b));
  return std::min(segmentTriangleDistance(oppositeSegment(p, g, j), a),
                  segmentTriangleDistance(oppositeSegment(p, f, i), b));
}

Box boxOf(const std::vector<Point>& p, const std::array<int, 3>& f, int id, double grow = 0) {
  CGAL::Bbox_3 box = p[f[0]].bbox() + p[f[1]].bbox() + p[f[2]].bbox();
  if (grow > 0) {
    box = CGAL::Bbox_3(box.xmin() - grow, box.ymin() - grow, box.zmin() - grow,
                       box.xmax() + grow, box.ymax() + grow, box.zmax() + grow);
  }
  return Box(box, id);
}

std::vector<const Box*> pointers(const std::vector<Box>& boxes) {
  std::vector<const Box*> out;
  out.reserve(boxes.size());
  for (const Box& b : boxes) out.push_back(&b);
  return out;
}

}  // namespace

struct PoseIntersections::Impl {
  // Two faces sharing the edge (u, v), and each one's third vertex (surface vertices).
  struct EdgePair {
    int f, g, u, v, apexF, apexG;
  };

  Faces faces;
  std::vector<int> source;
  std::vector<Point> neutral;
  std::vector<EdgePair> edgePairs;
  std::vector<double> clearance;  // per face; < 0: always tested
  std::vector<std::uint64_t> neutralPairs;

  // The pairs sharing an edge that meet at `p`: flat and folded over.
  void foldedEdges(const std::vector<Point>& p, const std::vector<bool>& degenerate,
                   std::vector<std::uint64_t>& keys) const {
    for (const EdgePair& e : edgePairs) {
      if (degenerate[e.f] || degenerate[e.g]) continue;
      const Point &u = p[e.u], &v = p[e.v], &r = p[e.apexF], &s = p[e.apexG];
      if (CGAL::coplanar(u, v, r, s) && CGAL::coplanar_orientation(u, v, r, s) == CGAL::POSITIVE)
        keys.push_back(pairKey(e.f, e.g));
    }
  }
};

PoseIntersections::PoseIntersections(const Points3& neutral, const std::vector<int>& triangles)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  Joined surface = joined(neutral.rows(), triangles);
  s.source = surface.source;
  s.neutral = surfacePoints(neutral, s.source);
  s.neutralPairs = intersectingPairs(surface, s.neutral);
  s.faces = std::move(surface.faces);
  const int faceCount = static_cast<int>(s.faces.size());

  std::vector<std::array<int, 3>> edges;  // (u, v, face), u < v
  for (int f = 0; f < faceCount; ++f) {
    for (int k = 0; k < 3; ++k) {
      int u = s.faces[f][k], v = s.faces[f][(k + 1) % 3];
      if (u > v) std::swap(u, v);
      edges.push_back({u, v, f});
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<double> lengths;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    lengths.push_back(std::sqrt(CGAL::squared_distance(s.neutral[edges[e][0]],
                                                       s.neutral[edges[e][1]])));
    if (e + 1 < edges.size() && edges[e][0] == edges[e + 1][0] &&
        edges[e][1] == edges[e + 1][1]) {
      const int f = edges[e][2], g = edges[e + 1][2], u = edges[e][0], v = edges[e][1];
      const auto apex = [&](int face) {
        for (int w : s.faces[face]) {
          if (w != u && w != v) return w;
        }
        return u;  // not reached: a face has three distinct vertices
      };
      s.edgePairs.push_back({f, g, u, v, apex(f), apex(g)});
    }
  }

  // The clearances: every pair whose boxes, grown by half the reach, overlap is measured;
  // farther ones are more than the reach apart. The reach is twice the median edge: past the
  // faces around a face, the nearest one sharing no vertex with it is about an edge away.
  double reach = 0;
  if (!lengths.empty()) {
    std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
    reach = 2 * lengths[lengths.size() / 2];
  }
  // A tolerance on the rounding of the distances, in the mesh's size.
  double size = 0;
  for (const Point& q : s.neutral) size = std::max({size, std::abs(q.x()), std::abs(q.y()),
                                                    std::abs(q.z())});
  const double rounding = 1e-12 * size;
  const auto share = [&](double distance) { return 0.45 * distance - rounding; };
  s.clearance.assign(faceCount, share(reach));
  std::vector<Box> boxes;
  for (int f = 0; f < faceCount; ++f) {
    const std::array<int, 3>& t = s.faces[f];
    if (CGAL::collinear(s.neutral[t[0]], s.neutral[t[1]], s.neutral[t[2]])) {
      s.clearance[f] = -1;
    } else {
      boxes.push_back(boxOf(s.neutral, t, f, reach / 2));
    }
  }
  std::vector<const Box*> grown = pointers(boxes);
  CGAL::box_self_intersection_d(
      grown.begin(), grown.end(),
      [&](const Box* a, const Box* b) {
        const int f = a->info(), g = b->info();
        const std::array<int, 2> shared = sharedVertex(s.faces[f], s.faces[g]);
        if (shared[0] == -2) return;
        if (std::binary_search(s.neutralPairs.begin(), s.neutralPairs.end(), pairKey(f, g)))
          return;
        const double c = share(gap(s.neutral, s.faces[f], s.faces[g]));
        s.clearance[f] = std::min(s.clearance[f], c);
        s.clearance[g] = std::min(s.clearance[g], c);
      },
      CGAL::Box_intersection_d::Box_traits_d<const Box*>(), kBoxCutoff);
}

PoseIntersections::~PoseIntersections() = default;
PoseIntersections::PoseIntersections(PoseIntersections&&) noexcept = default;
PoseIntersections& PoseIntersections::operator=(PoseIntersections&&) noexcept = default;

const std::vector<std::uint64_t>& PoseIntersections::neutralPairs() const {
  return impl_->neutralPairs;
}

std::vector<std::uint64_t> PoseIntersections::newPairs(const Points3& pose) const {
  const Impl& s = *impl_;
  const std::vector<Point> p = surfacePoints(pose, s.source);
  const std::size_t faceCount = s.faces.size();
  std::vector<double> moved(p.size());
  for (std::size_t v = 0; v < p.size(); ++v) {
    moved[v] = std::sqrt(CGAL::squared_distance(p[v], s.neutral[v]));
  }
  std::vector<bool> degenerate(faceCount);
  std::vector<Box> active, quiet;
  for (std::size_t f = 0; f < faceCount; ++f) {
    const std::array<int, 3>& t = s.faces[f];
    degenerate[f] = CGAL::collinear(p[t[0]], p[t[1]], p[t[2]]);
    if (degenerate[f]) continue;
    const double m = std::max({moved[t[0]], moved[t[1]], moved[t[2]]});
    (m >= s.clearance[f] ? active : quiet).push_back(boxOf(p, t, static_cast<int>(f)));
  }

  std::vector<std::uint64_t> keys;
  s.foldedEdges(p, degenerate, keys);
  const auto test = [&](const Box* a, const Box* b) {
    const int f = a->info(), g = b->info();
    const std::array<int, 2> shared = sharedVertex(s.faces[f], s.faces[g]);
    if (shared[0] == -2) return;
    if (meetApartFromSharedVertex(p, s.faces[f], s.faces[g], shared))
      keys.push_back(pairKey(f, g));
  };
  const CGAL::Box_intersection_d::Box_traits_d<const Box*> traits;
  std::vector<const Box*> a = pointers(active), q = pointers(quiet);
  CGAL::box_self_intersection_d(a.begin(), a.end(), test, traits, kBoxCutoff);
  CGAL::box_intersection_d(a.begin(), a.end(), q.begin(), q.end(), test, traits,
                           kBoxCutoff);
  sortUnique(keys);
  std::vector<std::uint64_t> fresh;
  std::set_difference(keys.begin(), keys.end(), s.neutralPairs.begin(), s.neutralPairs.end(),
                      std::back_inserter(fresh));
  return fresh;
}

std::vector<std::uint64_t> allIntersectingPairs(const Points3& coord,
                                                const std::vector<int>& triangles) {
  Joined surface = joined(coord.rows(), triangles);
  return intersectingPairs(surface, surfacePoints(coord, surface.source));
}

}  // namespace mpeg4face::fat
