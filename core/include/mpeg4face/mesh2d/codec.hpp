// SPDX-License-Identifier: GPL-3.0-or-later
// Coding of the 2D mesh object (Tekalp & Ostermann 2000, section 3.3): the intra plane's
// geometry (uniform parameters, or Delaunay nodes as first point and differences) and each
// inter plane's node motion, predicted along the breadth-first traversal of the triangles
// (3.3.2.1-2) and arithmetic coded. The framing, code tables and precision are ours
// (docs/mesh2d.md, "Bitstream").
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "mpeg4face/mesh2d/mesh2d.hpp"

namespace mpeg4face {

// The breadth-first traversal of section 3.3.2.1 and the node order of 3.3.2.2.
struct Mesh2dTraversal {
  // Per label 0..M-1: the triangle's index and its vertices (l, m, n), clockwise, <l m> the
  // base edge (then <l n> is the right edge, <m n> the left one).
  std::vector<int> triangle;
  std::vector<std::array<int, 3>> vertices;
  // The nodes in the order their motion is coded, and for each the two nodes whose motion
  // predicts it: {-1, -1} for the top-left node, {n0, -1} for the next clockwise boundary node,
  // the base edge's {l, m} for the others (nodes in no triangle come last, unpredicted).
  std::vector<int> nodeOrder;
  std::vector<std::array<int, 2>> predictors;
};

// The traversal from the top-left node (minimum x + y, then minimum y) of `nodes`.
Mesh2dTraversal mesh2dTraversal(const Mesh2dNodes& nodes, const Mesh2dTriangles& triangles);

struct Mesh2dCodingStats {
  uint64_t headerBits = 0;          // framing and the intra plane's parameters
  uint64_t intraBits = 0;           // the intra plane's node geometry (Delaunay)
  std::vector<uint64_t> interBits;  // per inter plane, frames 1..
  uint64_t totalBits = 0;
};

// Codes `sequence` (validated first) with motion vectors and Delaunay coordinates in units of
// `step` pixels (1/256 .. 255, rounded to 1/256). Uniform parameters are coded in half pixels.
// The coding is closed-loop: every decoded node lies within step / 2 of its source position
// (uniform intra nodes: within 1/4 pixel of the parameters'). Fills `decoded` (what
// decodeMesh2d will return) and `stats` when given.
std::vector<uint8_t> encodeMesh2d(const Mesh2dSequence& sequence, double step,
                                  Mesh2dSequence* decoded = nullptr,
                                  Mesh2dCodingStats* stats = nullptr);

// Decodes a .m2d stream, the triangles included. Throws mpeg4face::Error naming `source` and
// the syntax element (with the frame) if the data is truncated, broken or out of range, or if
// its header declares more than `maxNodeFrames` nodes over all frames (a bound on memory and
// time for streams from elsewhere).
Mesh2dSequence decodeMesh2d(std::span<const uint8_t> data, const std::string& source = {},
                            uint64_t maxNodeFrames = uint64_t{1} << 24);

}  // namespace mpeg4face
