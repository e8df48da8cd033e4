// SPDX-License-Identifier: GPL-3.0-or-later
// The 2D mesh object's data model, JSON, geometry (uniform, constrained Delaunay) and coding.
#include <gtest/gtest.h>

#include <cstdio>

#include "mesh2d_fixture.hpp"
#include "mpeg4face/mesh2d/codec.hpp"
#include "mpeg4face/mesh2d/json.hpp"
#include "mpeg4face/mesh2d/mesh2d.hpp"
#include "mpeg4face/mesh2d/portrait.hpp"
#include "test_support.hpp"

namespace mpeg4face {
namespace {

using test::errorOf;

double cross(const Mesh2dNodes& p, int a, int b, int c) {
  const Eigen::Vector2d u = p.row(b) - p.row(a), v = p.row(c) - p.row(a);
  return u.x() * v.y() - u.y() * v.x();
}

Mesh2dSequence roundTrip(const Mesh2dSequence& s, double step, Mesh2dSequence& encoderSide,
                         Mesh2dCodingStats* stats = nullptr) {
  const std::vector<uint8_t> bytes = encodeMesh2d(s, step, &encoderSide, stats);
  return decodeMesh2d(bytes, "test.m2d");
}

void expectWithin(const Mesh2dSequence& source, const Mesh2dSequence& decoded, double tolerance) {
  ASSERT_EQ(source.frames.size(), decoded.frames.size());
  double worst = 0;
  for (size_t f = 0; f < source.frames.size(); ++f) {
    worst = std::max(worst, (source.frames[f] - decoded.frames[f]).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(worst, tolerance);
}

TEST(Mesh2d, UniformTopologyCodesSplitEachCellAsFig20) {
  // The diagonal of the top-left cell and of its right neighbour, per code: true when it runs
  // top-left to bottom-right (the triangles then share nodes a and d).
  const std::array<std::array<bool, 2>, 4> expected{
      {{true, true}, {false, false}, {true, false}, {false, true}}};
  for (int code = 0; code < 4; ++code) {
    SCOPED_TRACE(code);
    Mesh2dSequence s = test::uniformFixture(5, 4, code);  // Fig. 21's 5 x 4 nodes
    const Mesh2dTriangles t = uniformMeshTriangles(s.uniform);
    ASSERT_EQ(t.rows(), 2 * 4 * 3);
    double area = 0;
    for (Eigen::Index i = 0; i < t.rows(); ++i) {
      const double c = cross(s.frames[0], t(i, 0), t(i, 1), t(i, 2));
      EXPECT_GT(c, 0) << "triangle " << i << " is not clockwise on the screen";
      area += c / 2;
    }
    EXPECT_NEAR(area, 4 * 20 * 3 * 17.5, 1e-9);
    for (int cell = 0; cell < 2; ++cell) {
      const int a = cell, d = cell + 6;
      const auto has = [&](Eigen::Index row, int n) { return (t.row(row).array() == n).any(); };
      EXPECT_EQ(
          has(2 * cell, a) && has(2 * cell, d) && has(2 * cell + 1, a) && has(2 * cell + 1, d),
          expected[static_cast<size_t>(code)][static_cast<size_t>(cell)]);
    }
    test::addSmoothFrames(s, 3);
    Mesh2dSequence encoded;
    const Mesh2dSequence decoded = roundTrip(s, 0.5, encoded);
    EXPECT_EQ(decoded.uniform.topology, code);
    EXPECT_EQ(decoded.triangles, t);
    EXPECT_EQ(encoded.triangles, decoded.triangles);
    expectWithin(s, decoded, 0.25);
  }
}

// Is the segment from a to b crossed by a boundary edge (touching at an end does not count)?
bool blocked(const Mesh2dNodes& p, int boundary, int a, int b) {
  for (int i = 0; i < boundary; ++i) {
    const int c = i, d = (i + 1) % boundary;
    if (c == a || c == b || d == a || d == b) continue;
    const double d1 = cross(p, a, b, c), d2 = cross(p, a, b, d);
    const double d3 = cross(p, c, d, a), d4 = cross(p, c, d, b);
    if (((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0))) return true;
  }
  return false;
}

void expectConstrainedDelaunay(const Mesh2dSequence& s, bool convex) {
  const Mesh2dNodes& p = s.frames[0];
  std::vector<Eigen::Vector2d> polygon;
  for (int i = 0; i < s.boundary; ++i) polygon.emplace_back(p.row(i).transpose());
  double polygonArea = 0, meshArea = 0;
  for (int i = 0; i < s.boundary; ++i) {
    polygonArea += cross(p, 0, i, (i + 1) % s.boundary) / 2;
  }
  int violations = 0, outside = 0;
  // The empty-circle test is quadratic: on large meshes every 16th triangle (the suite runs
  // this under ASan in Debug too).
  const Eigen::Index stride = p.rows() > 1000 ? 16 : 1;
  for (Eigen::Index t = 0; t < s.triangles.rows(); ++t) {
    const int a = s.triangles(t, 0), b = s.triangles(t, 1), c = s.triangles(t, 2);
    meshArea += cross(p, a, b, c) / 2;
    const Eigen::Vector2d centroid = (p.row(a) + p.row(b) + p.row(c)).transpose() / 3;
    if (!test::insidePolygon(polygon, centroid)) ++outside;
    // Circumcircle.
    const Eigen::Vector2d A = p.row(a), B = p.row(b), C = p.row(c);
    const double d =
        2 * (A.x() * (B.y() - C.y()) + B.x() * (C.y() - A.y()) + C.x() * (A.y() - B.y()));
    const Eigen::Vector2d centre(
        (A.squaredNorm() * (B.y() - C.y()) + B.squaredNorm() * (C.y() - A.y()) +
         C.squaredNorm() * (A.y() - B.y())) /
            d,
        (A.squaredNorm() * (C.x() - B.x()) + B.squaredNorm() * (A.x() - C.x()) +
         C.squaredNorm() * (B.x() - A.x())) /
            d);
    const double r2 = (A - centre).squaredNorm() * (1 - 1e-9);
    for (int n = 0; n < p.rows() && t % stride == 0; ++n) {
      if (n == a || n == b || n == c) continue;
      const Eigen::Vector2d q = p.row(n);
      if (std::abs(q.x() - centre.x()) > std::sqrt(r2) || (q - centre).squaredNorm() >= r2) {
        continue;
      }
      // Inside: allowed only for a node hidden by the boundary from one of the vertices.
      const bool visible = !blocked(p, s.boundary, n, a) && !blocked(p, s.boundary, n, b) &&
                           !blocked(p, s.boundary, n, c);
      if (convex || visible) ++violations;
    }
  }
  EXPECT_EQ(violations, 0);
  EXPECT_EQ(outside, 0);
  EXPECT_NEAR(std::abs(meshArea), std::abs(polygonArea), 1e-6 * std::abs(polygonArea));
}

// CGAL without optimisation (the sanitizer build is Debug) takes minutes over 5,000 nodes;
// the release run of the suite covers them.
#if defined(__SANITIZE_ADDRESS__)
constexpr int kLargeMesh = 1000;
#else
constexpr int kLargeMesh = 5000;
#endif

TEST(Mesh2d, DelaunayMeshesDecodeToTheEncodersNodesAndTriangles) {
  struct Case {
    int count, boundary;
    bool concave;
    double radius;
  };
  for (const Case c : {Case{10, 6, false, 60}, Case{10, 8, true, 60}, Case{300, 40, false, 150},
                       Case{300, 40, true, 150}, Case{kLargeMesh, 200, false, 400},
                       Case{kLargeMesh, 240, true, 400}}) {
    SCOPED_TRACE(std::to_string(c.count) + (c.concave ? " concave" : " convex"));
    Mesh2dSequence s = test::delaunayFixture(c.count, c.boundary, c.concave, c.radius);
    test::addSmoothFrames(s, 2);
    Mesh2dSequence encoded;
    Mesh2dCodingStats stats;
    const Mesh2dSequence decoded = roundTrip(s, 0.5, encoded, &stats);
    EXPECT_EQ(decoded.boundary, c.boundary);
    expectWithin(s, decoded, 0.25);
    EXPECT_EQ(decoded.frames[0], encoded.frames[0]);
    EXPECT_EQ(decoded.triangles, encoded.triangles);
    // Euler: a triangulated polygon with N_i interior nodes has N_b - 2 + 2 N_i triangles.
    EXPECT_EQ(decoded.triangles.rows(), c.boundary - 2 + 2 * (c.count - c.boundary));
    expectConstrainedDelaunay(decoded, !c.concave);
    std::printf("[ delaunay ] %d nodes%s: intra %.2f bits/node\n", c.count,
                c.concave ? " concave" : " convex", static_cast<double>(stats.intraBits) / c.count);
  }
}

TEST(Mesh2d, BadGeometryIsNamed) {
  Mesh2dSequence s = test::delaunayFixture(10, 6, false, 60);
  std::swap(s.frames[0](1, 0), s.frames[0](2, 0));  // edges 0-1 and 2-3 now cross
  std::swap(s.frames[0](1, 1), s.frames[0](2, 1));
  Error e = errorOf([&] { meshTriangles(s, "mesh.json"); });
  EXPECT_NE(std::string(e.what()).find("intersects itself"), std::string::npos) << e.what();
  EXPECT_EQ(e.file(), "mesh.json");
  s = test::delaunayFixture(10, 6, false, 60);
  s.frames[0].row(8) << 0, 0;  // outside the circle
  e = errorOf([&] { meshTriangles(s); });
  EXPECT_EQ(e.field(), "nodes[8]");
  s.frames[0].row(8) = s.frames[0].row(7);
  e = errorOf([&] { meshTriangles(s); });
  EXPECT_EQ(e.field(), "nodes[8]");
  EXPECT_NE(e.reason().find("coincides with node 7"), std::string::npos) << e.what();
}

TEST(Mesh2d, TraversalIsBreadthFirstFromTheTopLeftNode) {
  // A 3 x 3 node uniform mesh, code 00; worked by hand from section 3.3.2.1: triangle 0 is
  // (0, 1, 4) with base edge 0-1 (top-left node, next clockwise on the boundary); each current
  // triangle labels its right-edge neighbour, then its left-edge one.
  const UniformMesh2d u{3, 3, 0, 0, 1, 1, 0};
  const Mesh2dTraversal t = mesh2dTraversal(uniformMeshNodes(u), uniformMeshTriangles(u));
  EXPECT_EQ(t.triangle, (std::vector<int>{0, 1, 3, 4, 6, 2, 5, 7}));
  EXPECT_EQ(t.vertices[2], (std::array<int, 3>{4, 1, 5}));
  EXPECT_EQ(t.nodeOrder, (std::vector<int>{0, 1, 4, 3, 5, 7, 8, 2, 6}));
  EXPECT_EQ(t.predictors[1], (std::array<int, 2>{0, -1}));
  EXPECT_EQ(t.predictors[2], (std::array<int, 2>{0, 1}));
  EXPECT_EQ(t.predictors[7], (std::array<int, 2>{5, 1}));
  // The top-left node is the minimum of x + y, then of y: move node 2 up to tie with 0.
  Mesh2dNodes nodes = uniformMeshNodes(u);
  nodes.row(2) << 1, -1;
  EXPECT_EQ(mesh2dTraversal(nodes, uniformMeshTriangles(u)).nodeOrder[0], 2);
}

TEST(Mesh2d, TraversalMatchesTheTextOfFig24) {
  // Section 3.3.2.3 describes Fig. 24 (the drawing is not in our copy of the paper): after five
  // triangles are labelled, six nodes are ordered; triangle 3 is current, with base edge b,
  // right edge r and left edge l; the next two labelled triangles share r and l with it; then
  // triangle 4 is current. A Delaunay mesh built to match that text (node names A..J, not the
  // drawing's): A top-left, A B E J H I G the boundary clockwise, C D F inside.
  enum { A, B, E, J, H, I, G, C, D, F };
  Mesh2dSequence s;
  s.type = Mesh2dType::Delaunay;
  s.width = s.height = 10;
  s.boundary = 7;
  Mesh2dNodes nodes(10, 2);
  nodes << 0, 0, 4, 0, 6, 3, 7, 6, 4, 7, 1.5, 7.5, 0, 7, 3, 2, 2, 4, 0.5, 5;
  s.frames = {nodes};
  const Mesh2dTraversal t = mesh2dTraversal(nodes, meshTriangles(s));
  ASSERT_GE(t.vertices.size(), 8u);
  using V = std::array<int, 3>;
  EXPECT_EQ(t.vertices[0], (V{A, B, C}));  // base edge: the top-left node, the next clockwise
  EXPECT_EQ(t.vertices[1], (V{A, C, D}));  // triangle 0's right neighbour, then its left one
  EXPECT_EQ(t.vertices[2], (V{C, B, E}));
  EXPECT_EQ(t.vertices[3], (V{A, D, F}));  // triangle 1's: b = AD, r = AF, l = DF
  EXPECT_EQ(t.vertices[4], (V{D, C, E}));
  // Five triangles labelled: six nodes ordered (triangle 4's third node E was triangle 2's).
  EXPECT_EQ(std::vector<int>(t.nodeOrder.begin(), t.nodeOrder.begin() + 6),
            (std::vector<int>{A, B, C, D, E, F}));
  // Triangle 2 labels nothing (its other edges are the boundary and triangle 4's), so
  // triangle 3 is current: labels 5 and 6 go across r = <l n> = AF and l = <m n> = DF, each
  // with the shared edge as its base.
  const V current = t.vertices[3];
  EXPECT_EQ(t.vertices[5][0], current[0]);
  EXPECT_EQ(t.vertices[5][1], current[2]);
  EXPECT_EQ(t.vertices[6][0], current[2]);
  EXPECT_EQ(t.vertices[6][1], current[1]);
  // Then triangle 4 is current: label 7 lies across its right edge DE.
  EXPECT_EQ(t.vertices[7][0], D);
  EXPECT_EQ(t.vertices[7][1], E);
  EXPECT_EQ(t.vertices.size(), 11u);  // and so on until every triangle is labelled
}

TEST(Mesh2d, PortraitFollowsTracks) {
  // ES0 = 40 px: 2.3 lies within ES0 / 12 of 2.2 (a closed mouth) and is no node of its own.
  const PortraitFeaturePoints points = parsePortraitFeaturePoints(
      "fp,x,y\n3.5,100,80\n3.6,60,80\n9.15,80,115\n2.2,80,140\n2.3,80,141\n2.4,98,144\n"
      "2.5,62,144\n2.1,80,175\n");
  std::string text = "frame,fp,x,y\n";
  for (int f = 0; f < 3; ++f) {
    for (size_t i = 0; i < points.ids.size(); ++i) {
      const double down = points.ids[i] == "2.1" ? 6.0 * f : points.ids[i] == "2.3" ? 5.0 * f : 0;
      text += std::to_string(f) + "," + points.ids[i] + "," +
              std::to_string(points.positions(static_cast<Eigen::Index>(i), 0)) + "," +
              std::to_string(points.positions(static_cast<Eigen::Index>(i), 1) + down) + "\n";
    }
  }
  const Mesh2dSequence s = portraitMesh2d(160, 200, points, parsePortraitTracks(text, points));
  ASSERT_EQ(s.frames.size(), 3u);
  auto nodeAt = [&](double x, double y) {
    for (Eigen::Index n = 0; n < s.frames[0].rows(); ++n) {
      if ((s.frames[0].row(n) - Eigen::RowVector2d(x, y)).norm() < 1e-9) return n;
    }
    return Eigen::Index{-1};
  };
  const Eigen::Index chin = nodeAt(80, 175);
  ASSERT_GE(chin, 0);
  EXPECT_EQ(nodeAt(80, 141), -1);
  EXPECT_NEAR(s.frames[2](chin, 1) - s.frames[0](chin, 1), 12, 1e-9);
  EXPECT_EQ(s.frames[2].row(nodeAt(80, 140)), s.frames[0].row(nodeAt(80, 140)));
  for (const Mesh2dNodes& plane : s.frames) {
    for (Eigen::Index t = 0; t < s.triangles.rows(); ++t) {
      EXPECT_GT(cross(plane, s.triangles(t, 0), s.triangles(t, 1), s.triangles(t, 2)), 0);
    }
  }
  // Bad tracks are named by line and field.
  const auto bad = [&](const std::string& tracks, int line, const std::string& field,
                       const std::string& reason) {
    const Error e = errorOf([&] { parsePortraitTracks(tracks, points, "t.csv"); });
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_EQ(e.field(), field) << e.what();
    EXPECT_NE(e.reason().find(reason), std::string::npos) << e.what();
  };
  const size_t firstFrame = text.find("\n1,");
  bad(text.substr(0, firstFrame + 1) + "2,2.1,80,175\n", 10, "frame", "expected 1, not 2");
  bad("frame,fp,x,y\n0,3.5,100,80\n1,3.5,100,80\n", 3, "fp", "frame 0 lacks 3.6");
  bad("0,9.1,1,1\n", 1, "fp", "'9.1' is not one of the portrait's feature points");
  bad("0,3.5,1,1\n0,3.5,1,1\n", 2, "fp", "3.5 is given twice in a frame");
  bad("0,3.5,1,y\n", 1, "y", "'y' is not a number");
  bad("0,3.5,1\n", 1, "row", "expected frame,fp,x,y");
  bad("", 0, "frame", "no frames");
}

TEST(Mesh2d, SmoothMotionDecodesWithinHalfTheStep) {
  for (const double step : {0.5, 0.25, 1.0}) {
    for (const bool uniform : {true, false}) {
      Mesh2dSequence s =
          uniform ? test::uniformFixture(25, 20, 2) : test::delaunayFixture(500, 60, true, 200);
      test::addSmoothFrames(s, 25);
      Mesh2dSequence encoded;
      Mesh2dCodingStats stats;
      const Mesh2dSequence decoded = roundTrip(s, step, encoded, &stats);
      EXPECT_EQ(decoded.frames.back(), encoded.frames.back());
      // Intra nodes of a uniform mesh are exact (the fixture is on half pixels).
      expectWithin(s, decoded, step / 2 + 1e-9);
      uint64_t inter = 0;
      for (uint64_t b : stats.interBits) inter += b;
      const double perNode =
          static_cast<double>(inter) / static_cast<double>(s.frames[0].rows() * 24);
      std::printf("[ motion ] %s, step %.2f: %.2f bits/node/frame (raw 2 x float32: 64)\n",
                  uniform ? "uniform 25x20" : "delaunay 500", step, perNode);
      EXPECT_LT(perNode, 16);
    }
  }
}

TEST(Mesh2d, NodesThatDoNotMoveCostAlmostNothing) {
  Mesh2dSequence s = test::uniformFixture(10, 10, 0);
  for (int f = 1; f < 10; ++f) s.frames.push_back(s.frames[0]);
  s.frames.back()(5, 0) += 3;  // one node moves in the last frame
  Mesh2dSequence encoded;
  Mesh2dCodingStats stats;
  const Mesh2dSequence decoded = roundTrip(s, 0.5, encoded, &stats);
  EXPECT_DOUBLE_EQ(decoded.frames.back()(5, 0), s.frames.back()(5, 0));
  EXPECT_LT(stats.interBits[3], 40u);  // a flag per node, adapted to "still"
}

TEST(Mesh2d, JsonRoundTripsAndNamesBadFields) {
  Mesh2dSequence s = test::delaunayFixture(30, 8, true, 60);
  test::addSmoothFrames(s, 3);
  s.triangles = meshTriangles(s);
  const Mesh2dSequence back = parseMesh2dJson(mesh2dJson(s), "seq.json");
  EXPECT_EQ(back.boundary, s.boundary);
  EXPECT_EQ(back.triangles, s.triangles);
  ASSERT_EQ(back.frames.size(), 3u);
  EXPECT_LT((back.frames[2] - s.frames[2]).cwiseAbs().maxCoeff(), 1e-6);
  Mesh2dSequence u = test::uniformFixture(4, 3, 3);
  const Mesh2dSequence uBack = parseMesh2dJson(mesh2dJson(u));
  EXPECT_EQ(uBack.uniform.topology, 3);
  EXPECT_EQ(uBack.frames[0], u.frames[0]);

  Error e = errorOf([] { parseMesh2dJson("{\"width\": 4,\n \"height\": }", "b.json"); });
  EXPECT_EQ(e.line(), 2);
  EXPECT_NE(std::string(e.what()).find("column 12"), std::string::npos) << e.what();
  std::string text = mesh2dJson(s);
  const size_t first = text.find("\"triangles\": [[") + 15;
  text.replace(first, text.find(',', first) - first, "99");
  e = errorOf([&] { parseMesh2dJson(text, "t.json"); });
  EXPECT_EQ(e.field(), "triangles[0][0]");
  EXPECT_NE(e.reason().find("out of range"), std::string::npos);
  e = errorOf([] {
    parseMesh2dJson(R"({"width": 4, "height": 4, "mesh": "delaunay", "boundary": 3,
                        "frames": [[[0, 0], [1, 0], [0, 1]], [[0, 0], [1, "x"], [0, 1]]]})");
  });
  EXPECT_EQ(e.field(), "frames[1][1][1]");
  e = errorOf([] {
    parseMesh2dJson(R"({"width": 4, "height": 4, "mesh": "delaunay", "boundary": 3,
                        "frames": [[[0, 0], [1, 0], [0, 1]], [[0, 0], [1, 1]]]})");
  });
  EXPECT_EQ(e.field(), "frames[1]");
  e = errorOf([] { parseMesh2dJson(R"({"width": 4, "height": 4, "mesh": "hex", "frames": []})"); });
  EXPECT_EQ(e.field(), "mesh");
  e = errorOf([] { parseMesh2dJson(R"({"width": 4})"); });  // a missing member, at its object
  EXPECT_EQ(e.field(), "(top)");
  EXPECT_EQ(e.reason(), "has no \"height\"");
  e = errorOf([] {
    parseMesh2dJson(R"({"width": 4, "height": 4, "mesh": "uniform", "uniform": {"nodes_x": 2}})");
  });
  EXPECT_EQ(e.field(), "uniform");
  EXPECT_EQ(e.reason(), "has no \"nodes_y\"");
}

TEST(Mesh2d, TruncatedOrForeignStreamsAreNamed) {
  Mesh2dSequence s = test::delaunayFixture(40, 10, false, 60);
  test::addSmoothFrames(s, 4);
  std::vector<uint8_t> bytes = encodeMesh2d(s, 0.5);
  for (const size_t keep : {size_t{3}, size_t{12}, bytes.size() / 2, bytes.size() - 2}) {
    const std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<long>(keep));
    const Error e = errorOf([&] { decodeMesh2d(cut, "cut.m2d"); });
    EXPECT_EQ(e.file(), "cut.m2d");
    EXPECT_FALSE(e.field().empty()) << e.what();
  }
  bytes[0] = 'X';
  EXPECT_EQ(errorOf([&] { decodeMesh2d(bytes, "x.m2d"); }).field(), "magic");
}

}  // namespace
}  // namespace mpeg4face
