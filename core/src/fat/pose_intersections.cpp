// SPDX-License-Identifier: GPL-3.0-or-later
#include "fat/pose_intersections.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <type_traits>

namespace mpeg4face::fat {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Segment = Kernel::Segment_3;
using Triangle = Kernel::Triangle_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, int>;
using Faces = std::vector<std::array<int, 3>>;

// CGAL's self_intersections cuts its box recursion off at this many boxes too (the
// clearances are found with it, once).
constexpr std::ptrdiff_t kBoxCutoff = 2000;

std::uint64_t pairKey(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
}

void sortUnique(std::vector<std::uint64_t>& keys) {
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

// The surface's points: surface vertex v at row source[v] of `coord`.
void surfacePoints(const Points3& coord, const std::vector<int>& source,
                   std::vector<Point>& points) {
  points.resize(source.size());
  for (std::size_t v = 0; v < source.size(); ++v) {
    const auto row = coord.row(source[v]);
    points[v] = Point(row[0], row[1], row[2]);
  }
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

// Face f's box grown by `grow` on every side.
Box grownBox(const std::vector<Point>& p, const std::array<int, 3>& f, int id, double grow) {
  const CGAL::Bbox_3 box = p[f[0]].bbox() + p[f[1]].bbox() + p[f[2]].bbox();
  return Box(CGAL::Bbox_3(box.xmin() - grow, box.ymin() - grow, box.zmin() - grow,
                          box.xmax() + grow, box.ymax() + grow, box.zmax() + grow),
             id);
}

std::vector<const Box*> pointers(const std::vector<Box>& boxes) {
  std::vector<const Box*> out;
  out.reserve(boxes.size());
  for (const Box& b : boxes) out.push_back(&b);
  return out;
}

// How far two groups' vertices moved relative to one another at most, squared, from the boxes
// their displacements span.
double squaredRelativeMotion(const CGAL::Bbox_3& a, const CGAL::Bbox_3& b) {
  double sum = 0;
  for (int k = 0; k < 3; ++k) {
    const double m = std::max(a.max(k) - b.min(k), b.max(k) - a.min(k));
    sum += m * m;
  }
  return sum;
}

// A bounding-volume hierarchy over the faces: its shape fixed once from the neutral (each
// node split at the median of its longest side), its boxes refit to each pose. A pose moves
// the faces, not their neighbourhoods, so the shape stays good and a refit costs one pass.
// The faces are numbered in the tree's order (`order()`), so a node's faces are a range.
// Each node keeps the box of its faces, the box their vertices' displacements span, and the
// smallest clearance of its faces.
class FaceTree {
 public:
  FaceTree() = default;
  explicit FaceTree(const std::vector<Eigen::Vector3d>& centre) {
    for (std::size_t f = 0; f < centre.size(); ++f) order_.push_back(static_cast<int>(f));
    if (!order_.empty()) split(centre, static_cast<int>(order_.size()));
  }

  // Face i in the tree's order is face order()[i] of those given.
  const std::vector<int>& order() const { return order_; }

  // Each face's clearance, in the tree's order (< 0: always tested).
  void setClearances(const std::vector<double>& clearance) {
    clearance_.assign(nodes_.size(), std::numeric_limits<double>::infinity());
    for (std::size_t n = nodes_.size(); n-- > 0;) {
      const Node& node = nodes_[n];
      if (node.left >= 0) {
        clearance_[n] = std::min(clearance_[node.left], clearance_[node.left + 1]);
        continue;
      }
      for (int i = node.first; i < node.first + node.count; ++i)
        clearance_[n] = std::min(clearance_[n], clearance[i]);
    }
  }

  // The nodes' boxes and displacement boxes from the faces' (an empty box for a face left
  // out), faces in the tree's order.
  void refit(const std::vector<CGAL::Bbox_3>& faceBox, const std::vector<CGAL::Bbox_3>& faceMotion,
             std::vector<CGAL::Bbox_3>& nodeBox, std::vector<CGAL::Bbox_3>& nodeMotion) const {
    nodeBox.resize(nodes_.size());
    nodeMotion.resize(nodes_.size());
    for (std::size_t n = nodes_.size(); n-- > 0;) {
      const Node& node = nodes_[n];
      if (node.left < 0) {
        nodeBox[n] = CGAL::Bbox_3();
        nodeMotion[n] = CGAL::Bbox_3();
        for (int i = node.first; i < node.first + node.count; ++i) {
          nodeBox[n] += faceBox[i];
          nodeMotion[n] += faceMotion[i];
        }
      } else {
        nodeBox[n] = nodeBox[node.left] + nodeBox[node.left + 1];
        nodeMotion[n] = nodeMotion[node.left] + nodeMotion[node.left + 1];
      }
    }
  }

  // Calls `visit(f, g)` once for each pair of faces in leaves whose boxes meet, except where
  // no vertex of two nodes moved relative to one of the other as far as the larger of their
  // clearances (a face without one, < 0, was not measured against the others).
  template <typename Visit>
  void pairs(const std::vector<CGAL::Bbox_3>& nodeBox, const std::vector<CGAL::Bbox_3>& nodeMotion,
             Visit&& visit) const {
    if (nodes_.empty()) return;
    std::vector<std::array<int, 2>> todo{{0, 0}};
    while (!todo.empty()) {
      const auto [a, b] = todo.back();
      todo.pop_back();
      const double larger = std::max(clearance_[a], clearance_[b]);
      if (std::min(clearance_[a], clearance_[b]) >= 0 &&
          squaredRelativeMotion(nodeMotion[a], nodeMotion[b]) < larger * larger)
        continue;
      const Node &na = nodes_[a], &nb = nodes_[b];
      if (a == b) {
        if (na.left >= 0) {
          todo.push_back({na.left, na.left});
          todo.push_back({na.left + 1, na.left + 1});
          todo.push_back({na.left, na.left + 1});
          continue;
        }
        for (int i = na.first; i < na.first + na.count; ++i) {
          for (int j = i + 1; j < na.first + na.count; ++j) visit(i, j);
        }
        continue;
      }
      if (!CGAL::do_overlap(nodeBox[a], nodeBox[b])) continue;
      if (na.left < 0 && nb.left < 0) {
        for (int i = na.first; i < na.first + na.count; ++i) {
          for (int j = nb.first; j < nb.first + nb.count; ++j) visit(i, j);
        }
      } else if (nb.left < 0 || (na.left >= 0 && na.count >= nb.count)) {
        todo.push_back({na.left, b});
        todo.push_back({na.left + 1, b});
      } else {
        todo.push_back({a, nb.left});
        todo.push_back({a, nb.left + 1});
      }
    }
  }

 private:
  struct Node {
    int first = 0, count = 0;  // a leaf's faces: [first, first + count) in the tree's order
    int left = -1;             // an inner node's children: left, left + 1
  };
  static constexpr int kLeafFaces = 4;

  // Children are stored in pairs after their parent, so a reverse pass meets them first.
  void split(const std::vector<Eigen::Vector3d>& centre, int count) {
    struct Range {
      int node, first, count;
    };
    nodes_.push_back({0, count, -1});
    std::vector<Range> todo{{0, 0, count}};
    while (!todo.empty()) {
      const Range r = todo.back();
      todo.pop_back();
      if (r.count <= kLeafFaces) continue;
      Eigen::Vector3d lo = centre[order_[r.first]], hi = lo;
      for (int i = r.first; i < r.first + r.count; ++i) {
        lo = lo.cwiseMin(centre[order_[i]]);
        hi = hi.cwiseMax(centre[order_[i]]);
      }
      int axis = 0;
      (hi - lo).maxCoeff(&axis);
      const int half = r.count / 2;
      std::nth_element(order_.begin() + r.first, order_.begin() + r.first + half,
                       order_.begin() + r.first + r.count,
                       [&](int a, int b) { return centre[a][axis] < centre[b][axis]; });
      const int left = static_cast<int>(nodes_.size());
      nodes_[r.node].left = left;
      nodes_.push_back({r.first, half, -1});
      nodes_.push_back({r.first + half, r.count - half, -1});
      todo.push_back({left, r.first, half});
      todo.push_back({left + 1, r.first + half, r.count - half});
    }
  }

  std::vector<int> order_;
  std::vector<Node> nodes_;
  std::vector<double> clearance_;  // per node
};

}  // namespace

struct PoseIntersections::Impl {
  // Two faces sharing the edge (u, v), and each one's third vertex (surface vertices).
  struct EdgePair {
    int f, g, u, v, apexF, apexG;
  };

  Faces faces;            // in the tree's order
  std::vector<int> given;  // each face's index among the triangles given
  std::vector<int> source;
  std::vector<Point> neutral;
  std::vector<EdgePair> edgePairs;
  // Per face (< 0: always tested), against the faces sharing no vertex with it and against
  // those sharing one.
  std::vector<double> clearance, fanClearance;
  std::vector<std::uint64_t> neutralPairs;
  FaceTree tree;

  // Each pose's, kept from one to the next: a dense head's would be fresh pages every time.
  std::vector<Point> p;
  std::vector<Eigen::Vector3d> d;  // each surface vertex's motion
  std::vector<bool> degenerate;
  std::vector<CGAL::Bbox_3> box, nodeBox;
  std::vector<CGAL::Bbox_3> motion, nodeMotion;  // the box a face's vertices' motions span
  std::vector<std::uint64_t> keys;

  void addPair(int f, int g) { keys.push_back(pairKey(given[f], given[g])); }

  // The pairs sharing an edge that meet in the pose `p` holds: flat and folded over.
  void foldedEdges() {
    for (const EdgePair& e : edgePairs) {
      if (degenerate[e.f] || degenerate[e.g]) continue;
      const Point &u = p[e.u], &v = p[e.v], &r = p[e.apexF], &s = p[e.apexG];
      if (CGAL::coplanar(u, v, r, s) && CGAL::coplanar_orientation(u, v, r, s) == CGAL::POSITIVE)
        addPair(e.f, e.g);
    }
  }
};

PoseIntersections::PoseIntersections(const Points3& neutral, const std::vector<int>& triangles)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  Joined surface = joined(neutral.rows(), triangles);
  s.source = surface.source;
  surfacePoints(neutral, s.source, s.neutral);
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
  const auto share = [&](double distance) { return 0.9 * distance - rounding; };
  s.clearance.assign(faceCount, share(reach));
  s.fanClearance.assign(faceCount, share(reach));
  std::vector<Box> boxes;
  for (int f = 0; f < faceCount; ++f) {
    const std::array<int, 3>& t = s.faces[f];
    if (CGAL::collinear(s.neutral[t[0]], s.neutral[t[1]], s.neutral[t[2]])) {
      s.clearance[f] = s.fanClearance[f] = -1;
    } else {
      boxes.push_back(grownBox(s.neutral, t, f, reach / 2));
    }
  }
  std::vector<const Box*> grown = pointers(boxes);
  CGAL::box_self_intersection_d(
      grown.begin(), grown.end(),
      [&](const Box* a, const Box* b) {
        const int f = a->info(), g = b->info();
        const std::array<int, 2> shared = sharedVertex(s.faces[f], s.faces[g]);
        if (shared[0] == -2) return;
        // The faces are at least as far apart as their boxes: a pair that could lower
        // neither clearance is not measured.
        std::vector<double>& of = shared[0] < 0 ? s.clearance : s.fanClearance;
        double boxGap = 0;
        for (int k = 0; k < 3; ++k) {
          const double apart = std::max(a->min_coord(k) - b->max_coord(k),
                                        b->min_coord(k) - a->max_coord(k)) + reach;
          if (apart > 0) boxGap += apart * apart;
        }
        if (share(std::sqrt(boxGap)) >= std::max(of[f], of[g])) return;
        if (std::binary_search(s.neutralPairs.begin(), s.neutralPairs.end(), pairKey(f, g)))
          return;
        const double c = share(gap(s.neutral, s.faces[f], s.faces[g]));
        of[f] = std::min(of[f], c);
        of[g] = std::min(of[g], c);
      },
      CGAL::Box_intersection_d::Box_traits_d<const Box*>(), kBoxCutoff);

  // The faces renumbered in the tree's order: a node's faces and their data are then ranges.
  std::vector<Eigen::Vector3d> centre;
  for (const std::array<int, 3>& t : s.faces) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int v : t) c += Eigen::Vector3d(s.neutral[v].x(), s.neutral[v].y(), s.neutral[v].z());
    centre.push_back(c / 3);
  }
  s.tree = FaceTree(centre);
  s.given = s.tree.order();
  const auto reordered = [&](const auto& values) {
    std::remove_cvref_t<decltype(values)> out;
    for (int f : s.given) out.push_back(values[f]);
    return out;
  };
  s.faces = reordered(s.faces);
  s.clearance = reordered(s.clearance);
  s.fanClearance = reordered(s.fanClearance);
  std::vector<int> slot(faceCount);
  for (int i = 0; i < faceCount; ++i) slot[s.given[i]] = i;
  for (Impl::EdgePair& e : s.edgePairs) {
    e.f = slot[e.f];
    e.g = slot[e.g];
  }
  std::vector<double> least(faceCount);
  for (int f = 0; f < faceCount; ++f) least[f] = std::min(s.clearance[f], s.fanClearance[f]);
  s.tree.setClearances(least);
}

PoseIntersections::~PoseIntersections() = default;
PoseIntersections::PoseIntersections(PoseIntersections&&) noexcept = default;
PoseIntersections& PoseIntersections::operator=(PoseIntersections&&) noexcept = default;

const std::vector<std::uint64_t>& PoseIntersections::neutralPairs() const {
  return impl_->neutralPairs;
}

std::vector<std::uint64_t> PoseIntersections::newPairs(const Points3& pose) {
  Impl& s = *impl_;
  const std::size_t faceCount = s.faces.size();
  std::vector<Point>& p = s.p;
  std::vector<Eigen::Vector3d>& d = s.d;
  surfacePoints(pose, s.source, p);
  d.resize(p.size());
  for (std::size_t v = 0; v < p.size(); ++v) {
    d[v] = Eigen::Vector3d(p[v].x() - s.neutral[v].x(), p[v].y() - s.neutral[v].y(),
                           p[v].z() - s.neutral[v].z());
  }
  std::vector<bool>& degenerate = s.degenerate;
  std::vector<CGAL::Bbox_3>& box = s.box;
  degenerate.resize(faceCount);
  box.resize(faceCount);
  s.motion.resize(faceCount);
  for (std::size_t f = 0; f < faceCount; ++f) {
    const std::array<int, 3>& t = s.faces[f];
    const Eigen::Vector3d lo = d[t[0]].cwiseMin(d[t[1]]).cwiseMin(d[t[2]]);
    const Eigen::Vector3d hi = d[t[0]].cwiseMax(d[t[1]]).cwiseMax(d[t[2]]);
    s.motion[f] = CGAL::Bbox_3(lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z());
    degenerate[f] = CGAL::collinear(p[t[0]], p[t[1]], p[t[2]]);
    box[f] = degenerate[f] ? CGAL::Bbox_3() : p[t[0]].bbox() + p[t[1]].bbox() + p[t[2]].bbox();
  }
  s.tree.refit(box, s.motion, s.nodeBox, s.nodeMotion);

  std::vector<std::uint64_t>& keys = s.keys;
  keys.clear();
  s.foldedEdges();
  s.tree.pairs(s.nodeBox, s.nodeMotion, [&](int f, int g) {
    if (degenerate[f] || degenerate[g]) return;  // CGAL leaves them out too
    if (!CGAL::do_overlap(box[f], box[g])) return;
    const std::array<int, 2> shared = sharedVertex(s.faces[f], s.faces[g]);
    if (shared[0] == -2) return;
    // The pair's distance is more than either's clearance; the motion of every point of f
    // relative to every point of g is at most the largest of their vertices' (bounded first
    // by their boxes).
    const std::vector<double>& clearance = shared[0] == -1 ? s.clearance : s.fanClearance;
    const double larger = std::max(clearance[f], clearance[g]);
    if (std::min(clearance[f], clearance[g]) >= 0) {
      if (squaredRelativeMotion(s.motion[f], s.motion[g]) < larger * larger) return;
      double relative = 0;
      for (int i : s.faces[f]) {
        for (int j : s.faces[g]) relative = std::max(relative, (d[i] - d[j]).squaredNorm());
      }
      if (relative < larger * larger) return;
    }
    if (meetApartFromSharedVertex(p, s.faces[f], s.faces[g], shared)) s.addPair(f, g);
  });
  sortUnique(keys);
  std::vector<std::uint64_t> fresh;
  std::set_difference(keys.begin(), keys.end(), s.neutralPairs.begin(), s.neutralPairs.end(),
                      std::back_inserter(fresh));
  return fresh;
}

std::vector<std::uint64_t> allIntersectingPairs(const Points3& coord,
                                                const std::vector<int>& triangles) {
  Joined surface = joined(coord.rows(), triangles);
  std::vector<Point> points;
  surfacePoints(coord, surface.source, points);
  return intersectingPairs(surface, points);
}

std::vector<int> checkedTriangles(const IndexedFaceSet& mesh) {
  std::vector<int> checked;
  const std::vector<int> all = mesh.triangles();
  for (std::size_t i = 0; i + 2 < all.size(); i += 3) {
    const int a = all[i], b = all[i + 1], c = all[i + 2];
    if (a == b || b == c || a == c) continue;
    checked.insert(checked.end(), {a, b, c});
  }
  return checked;
}

}  // namespace mpeg4face::fat
