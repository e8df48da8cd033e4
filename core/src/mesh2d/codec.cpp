// SPDX-License-Identifier: GPL-3.0-or-later
// The 2D mesh object's geometry and motion coding; the framing is ours (docs/mesh2d.md).
#include "mpeg4face/mesh2d/codec.hpp"

#include <bit>
#include <cmath>
#include <deque>
#include <unordered_map>

#include "codec/arithmetic_coder.hpp"
#include "codec/bit_io.hpp"
#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

constexpr uint32_t kMagic = 0x4D324401;  // "M2D" and version 1
constexpr double kStepUnit = 1.0 / 256;  // the step is coded in these
constexpr int kMaxClass = 31;            // |value| < 2^31
// Decoding allocates a node per frame: a bound for hostile headers (~256 MB of nodes).
constexpr uint64_t kMaxNodeFrames = uint64_t{1} << 24;

uint64_t edgeKey(int a, int b) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

// A triangle's vertices rotated so that it starts with the directed edge (a, b).
std::array<int, 3> startingWith(const Mesh2dTriangles& triangles, int t, int a) {
  const std::array<int, 3> v{triangles(t, 0), triangles(t, 1), triangles(t, 2)};
  const int k = v[0] == a ? 0 : v[1] == a ? 1 : 2;
  return {v[static_cast<size_t>(k)], v[static_cast<size_t>((k + 1) % 3)],
          v[static_cast<size_t>((k + 2) % 3)]};
}

int floorHalf(int64_t sum) { return static_cast<int>(sum >= 0 ? sum / 2 : -((-sum + 1) / 2)); }

// Integer values as a bit-length class (adaptive) then the sign and the bits below the
// leading 1 (raw): an adaptive Exp-Golomb code.
void encodeValue(ArithmeticEncoder& coder, AdaptiveModel& classes, int64_t value) {
  const uint64_t magnitude = static_cast<uint64_t>(value < 0 ? -value : value);
  const int k = static_cast<int>(std::bit_width(magnitude));
  if (k > kMaxClass) throw Error({}, 0, "value", "too large to code: " + std::to_string(value));
  coder.encode(k, classes);
  if (k == 0) return;
  coder.encodeBits(value < 0 ? 1 : 0, 1);
  for (int left = k - 1; left > 0;) {
    const int n = std::min(left, kMaxRawBits);
    left -= n;
    coder.encodeBits(static_cast<uint32_t>(magnitude >> left) & ((1u << n) - 1), n);
  }
}

int64_t decodeValue(ArithmeticDecoder& coder, AdaptiveModel& classes) {
  const int k = coder.decode(classes);
  if (k == 0) return 0;
  const bool negative = coder.decodeBits(1) != 0;
  uint64_t magnitude = 1;
  for (int left = k - 1; left > 0;) {
    const int n = std::min(left, kMaxRawBits);
    left -= n;
    magnitude = (magnitude << n) | coder.decodeBits(n);
  }
  return negative ? -static_cast<int64_t>(magnitude) : static_cast<int64_t>(magnitude);
}

// The adaptive models, kept from plane to plane.
struct Models {
  AdaptiveModel geometryX{kMaxClass + 1}, geometryY{kMaxClass + 1};
  AdaptiveModel moves{2};
  AdaptiveModel errorX{kMaxClass + 1}, errorY{kMaxClass + 1};
};

// What the encoder and the decoder both know once the intra plane is decoded.
struct IntraPlane {
  Mesh2dSequence sequence;  // frames[0] decoded, triangles derived
  Mesh2dTraversal traversal;
};

void finishIntra(IntraPlane& intra, const std::string& source) {
  intra.sequence.triangles = meshTriangles(intra.sequence, source);
  intra.traversal = mesh2dTraversal(intra.sequence.frames[0], intra.sequence.triangles);
}

// The motion vector predicted for the node at `position` in the coding order (3.3.2.2).
std::array<int, 2> prediction(const Mesh2dTraversal& traversal, size_t position,
                              const std::vector<std::array<int, 2>>& motion) {
  const auto [l, m] = traversal.predictors[position];
  if (l < 0) return {0, 0};
  const auto& vl = motion[static_cast<size_t>(l)];
  if (m < 0) return vl;
  const auto& vm = motion[static_cast<size_t>(m)];
  // Rounded to the nearest step, halves up (eq. 7).
  return {floorHalf(int64_t{vl[0]} + vm[0] + 1), floorHalf(int64_t{vl[1]} + vm[1] + 1)};
}

}  // namespace

Mesh2dTraversal mesh2dTraversal(const Mesh2dNodes& nodes, const Mesh2dTriangles& triangles) {
  Mesh2dTraversal out;
  const auto nodeCount = static_cast<size_t>(nodes.rows());
  const auto triangleCount = static_cast<int>(triangles.rows());
  std::unordered_map<uint64_t, int> edgeTriangle;  // directed edge -> its triangle
  std::vector<bool> used(nodeCount, false);
  for (int t = 0; t < triangleCount; ++t) {
    for (int k = 0; k < 3; ++k) {
      edgeTriangle.emplace(edgeKey(triangles(t, k), triangles(t, (k + 1) % 3)), t);
      used[static_cast<size_t>(triangles(t, k))] = true;
    }
  }
  auto across = [&](int a, int b) {  // the triangle with the directed edge (b, a), or -1
    const auto it = edgeTriangle.find(edgeKey(b, a));
    return it == edgeTriangle.end() ? -1 : it->second;
  };
  // The top-left node: minimum x + y, then minimum y.
  int topLeft = -1;
  for (size_t n = 0; n < nodeCount; ++n) {
    if (!used[n]) continue;
    const double s =
        nodes(static_cast<Eigen::Index>(n), 0) + nodes(static_cast<Eigen::Index>(n), 1);
    if (topLeft < 0) {
      topLeft = static_cast<int>(n);
      continue;
    }
    const double best = nodes(topLeft, 0) + nodes(topLeft, 1);
    if (s < best || (s == best && nodes(static_cast<Eigen::Index>(n), 1) < nodes(topLeft, 1))) {
      topLeft = static_cast<int>(n);
    }
  }
  std::vector<int> label(static_cast<size_t>(triangleCount), -1);
  std::vector<bool> done(nodeCount, false);
  auto addNode = [&](int n, int l, int m) {
    if (done[static_cast<size_t>(n)]) return;
    done[static_cast<size_t>(n)] = true;
    out.nodeOrder.push_back(n);
    out.predictors.push_back({l, m});
  };
  auto labelTriangle = [&](int t, std::array<int, 3> v) {
    label[static_cast<size_t>(t)] = static_cast<int>(out.triangle.size());
    out.triangle.push_back(t);
    out.vertices.push_back(v);
  };
  if (topLeft >= 0) {
    // The initial triangle holds the boundary edge from the top-left node to the next node
    // clockwise: a directed edge (topLeft, next) with no triangle on its other side. With the
    // triangles clockwise on the screen, the mesh lies to the right of it.
    int initial = -1;
    for (int t = 0; t < triangleCount && initial < 0; ++t) {
      for (int k = 0; k < 3; ++k) {
        if (triangles(t, k) == topLeft && across(topLeft, triangles(t, (k + 1) % 3)) < 0) {
          initial = t;
          break;
        }
      }
    }
    if (initial >= 0) {
      const auto v = startingWith(triangles, initial, topLeft);
      labelTriangle(initial, v);
      addNode(v[0], -1, -1);
      addNode(v[1], v[0], -1);
    }
  }
  // Labelled triangles become current in label order; each labels its neighbours across its
  // right edge <l n>, then its left edge <m n>, whose base edge is then the shared edge.
  for (size_t current = 0; current < out.triangle.size(); ++current) {
    const auto [l, m, n] = out.vertices[current];
    addNode(n, l, m);
    const int right = across(n, l);
    if (right >= 0 && label[static_cast<size_t>(right)] < 0) {
      labelTriangle(right, startingWith(triangles, right, l));
    }
    const int left = across(m, n);
    if (left >= 0 && label[static_cast<size_t>(left)] < 0) {
      labelTriangle(left, startingWith(triangles, left, n));
    }
  }
  for (size_t n = 0; n < nodeCount; ++n) addNode(static_cast<int>(n), -1, -1);
  return out;
}

std::vector<uint8_t> encodeMesh2d(const Mesh2dSequence& sequence, double step,
                                  Mesh2dSequence* decoded, Mesh2dCodingStats* stats) {
  validateMesh2d(sequence);
  const long stepCode = std::lround(step / kStepUnit);
  if (!std::isfinite(step) || stepCode < 1 || stepCode > 65535) {
    throw Error({}, 0, "step", "must be 1/256 .. 255 pixels");
  }
  if (sequence.width > 65535 || sequence.height > 65535) {
    throw Error({}, 0, "width", "the image must be at most 65535 pixels a side");
  }
  const double q = static_cast<double>(stepCode) * kStepUnit;
  const auto nodeCount = static_cast<size_t>(sequence.frames[0].rows());
  if (sequence.frames.size() * nodeCount > kMaxNodeFrames) {
    throw Error({}, 0, "frames", "more than 2^24 nodes in all frames");
  }
  auto quantise = [&](double value, const char* what) {
    const double v = std::round(value / q);
    if (std::abs(v) >= std::ldexp(1.0, kMaxClass)) {
      throw Error({}, 0, what, "out of the coding range at step " + std::to_string(q));
    }
    return static_cast<int64_t>(v);
  };
  BitWriter out;
  Models models;
  out.writeBits(kMagic, 32);
  out.writeBits(static_cast<uint32_t>(sequence.width), 16);
  out.writeBits(static_cast<uint32_t>(sequence.height), 16);
  out.writeBits(static_cast<uint32_t>(stepCode), 16);
  out.writeBits(static_cast<uint32_t>(sequence.frames.size()), 32);
  out.writeBit(sequence.type == Mesh2dType::Delaunay);
  IntraPlane intra;
  intra.sequence.width = sequence.width;
  intra.sequence.height = sequence.height;
  intra.sequence.type = sequence.type;
  uint64_t intraStart = 0;
  if (sequence.type == Mesh2dType::Uniform) {
    const UniformMesh2d& u = sequence.uniform;
    UniformMesh2d& coded = intra.sequence.uniform;
    auto halfPixels = [](double v, const char* field, long min, long max) {
      const long h = std::lround(2 * v);
      if (h < min || h > max) throw Error({}, 0, field, "out of the coding range");
      return h;
    };
    const long x0 = halfPixels(u.x0, "uniform.x0", -(1L << 30), 1L << 30);
    const long y0 = halfPixels(u.y0, "uniform.y0", -(1L << 30), 1L << 30);
    const long dx = halfPixels(u.dx, "uniform.dx", 1, 65535);
    const long dy = halfPixels(u.dy, "uniform.dy", 1, 65535);
    if (u.nodesX > 65535 || u.nodesY > 65535) {
      throw Error({}, 0, "uniform.nodes_x", "at most 65535 nodes a side");
    }
    coded = {u.nodesX,
             u.nodesY,
             static_cast<double>(x0) / 2,
             static_cast<double>(y0) / 2,
             static_cast<double>(dx) / 2,
             static_cast<double>(dy) / 2,
             u.topology};
    out.writeBits(static_cast<uint32_t>(u.nodesX), 16);
    out.writeBits(static_cast<uint32_t>(u.nodesY), 16);
    out.writeBits(static_cast<uint32_t>(x0), 32);
    out.writeBits(static_cast<uint32_t>(y0), 32);
    out.writeBits(static_cast<uint32_t>(dx), 16);
    out.writeBits(static_cast<uint32_t>(dy), 16);
    out.writeBits(static_cast<uint32_t>(u.topology), 2);
    intra.sequence.frames.push_back(uniformMeshNodes(coded));
    intraStart = out.bitCount();
  } else {
    if (nodeCount > 65535) throw Error({}, 0, "frames[0]", "at most 65535 Delaunay nodes");
    out.writeBits(static_cast<uint32_t>(nodeCount), 16);
    out.writeBits(static_cast<uint32_t>(sequence.boundary), 16);
    intra.sequence.boundary = sequence.boundary;
    intraStart = out.bitCount();
    // The first point, then differences to the previous one (eq. 4).
    Mesh2dNodes& nodes = intra.sequence.frames.emplace_back(nodeCount, 2);
    ArithmeticEncoder coder(out);
    int64_t previousX = 0, previousY = 0;
    for (size_t n = 0; n < nodeCount; ++n) {
      const auto i = static_cast<Eigen::Index>(n);
      const int64_t x = quantise(sequence.frames[0](i, 0), "frames[0]");
      const int64_t y = quantise(sequence.frames[0](i, 1), "frames[0]");
      encodeValue(coder, models.geometryX, x - previousX);
      encodeValue(coder, models.geometryY, y - previousY);
      nodes.row(i) << static_cast<double>(x) * q, static_cast<double>(y) * q;
      previousX = x;
      previousY = y;
    }
    coder.flush();
  }
  const uint64_t interStart = out.bitCount();
  finishIntra(intra, "the quantised intra plane");
  Mesh2dSequence& result = intra.sequence;
  // Closed loop: each plane's motion is measured from the previous decoded plane.
  std::vector<std::array<int, 2>> motion(nodeCount);
  std::vector<uint64_t> interBits;
  for (size_t f = 1; f < sequence.frames.size(); ++f) {
    const uint64_t start = out.bitCount();
    Mesh2dNodes next = result.frames.back();
    ArithmeticEncoder coder(out);
    const std::string field = "frames[" + std::to_string(f) + "]";
    for (size_t k = 0; k < intra.traversal.nodeOrder.size(); ++k) {
      const int n = intra.traversal.nodeOrder[k];
      const auto i = static_cast<Eigen::Index>(n);
      const int64_t vx = quantise(sequence.frames[f](i, 0) - next(i, 0), field.c_str());
      const int64_t vy = quantise(sequence.frames[f](i, 1) - next(i, 1), field.c_str());
      auto& v = motion[static_cast<size_t>(n)];
      v = {static_cast<int>(vx), static_cast<int>(vy)};
      const bool moves = vx != 0 || vy != 0;
      coder.encode(moves ? 1 : 0, models.moves);
      if (moves) {
        const auto w = prediction(intra.traversal, k, motion);
        encodeValue(coder, models.errorX, vx - w[0]);
        encodeValue(coder, models.errorY, vy - w[1]);
      }
      next(i, 0) += static_cast<double>(vx) * q;
      next(i, 1) += static_cast<double>(vy) * q;
    }
    coder.flush();
    result.frames.push_back(std::move(next));
    interBits.push_back(out.bitCount() - start);
  }
  if (stats) {
    stats->headerBits = intraStart;
    stats->intraBits = interStart - intraStart;
    stats->interBits = std::move(interBits);
    stats->totalBits = out.bitCount();
  }
  if (decoded) *decoded = std::move(result);
  return out.take();
}

Mesh2dSequence decodeMesh2d(std::span<const uint8_t> data, const std::string& source,
                            uint64_t maxNodeFrames) {
  BitReader in(data, source);
  if (in.readBits(32, "magic") != kMagic) in.fail("magic", "not a version 1 .m2d stream");
  IntraPlane intra;
  Mesh2dSequence& s = intra.sequence;
  s.width = static_cast<int>(in.readBits(16, "width"));
  s.height = static_cast<int>(in.readBits(16, "height"));
  if (s.width == 0 || s.height == 0) in.fail("width", "the image size is 0");
  const uint32_t stepCode = in.readBits(16, "step");
  if (stepCode == 0) in.fail("step", "is 0");
  const double q = stepCode * kStepUnit;
  const uint32_t frameCount = in.readBits(32, "frames");
  if (frameCount == 0) in.fail("frames", "is 0: no intra plane");
  Models models;
  uint64_t nodeCount = 0;
  if (!in.readBit("mesh_type")) {
    s.type = Mesh2dType::Uniform;
    UniformMesh2d& u = s.uniform;
    u.nodesX = static_cast<int>(in.readBits(16, "nodes_x"));
    u.nodesY = static_cast<int>(in.readBits(16, "nodes_y"));
    u.x0 = static_cast<int32_t>(in.readBits(32, "x0")) / 2.0;
    u.y0 = static_cast<int32_t>(in.readBits(32, "y0")) / 2.0;
    u.dx = in.readBits(16, "dx") / 2.0;
    u.dy = in.readBits(16, "dy") / 2.0;
    u.topology = static_cast<int>(in.readBits(2, "topology"));
    try {
      uniformMeshTriangles({u.nodesX, u.nodesY, 0, 0, 1, 1, 0});  // the node counts' range
    } catch (const Error& e) {
      in.fail(e.field(), e.reason());
    }
    if (u.dx == 0 || u.dy == 0) in.fail("dx", "a cell size is 0");
    nodeCount = static_cast<uint64_t>(u.nodesX) * static_cast<uint64_t>(u.nodesY);
    if (nodeCount * frameCount > maxNodeFrames) {
      in.fail("frames", "more than " + std::to_string(maxNodeFrames) + " nodes in all frames");
    }
    s.frames.push_back(uniformMeshNodes(u));
  } else {
    s.type = Mesh2dType::Delaunay;
    nodeCount = in.readBits(16, "nodes");
    s.boundary = static_cast<int>(in.readBits(16, "boundary"));
    if (s.boundary < 3 || s.boundary > static_cast<int>(nodeCount)) {
      in.fail("boundary", "needs 3.." + std::to_string(nodeCount) + " boundary nodes");
    }
    if (nodeCount * frameCount > maxNodeFrames) {
      in.fail("frames", "more than " + std::to_string(maxNodeFrames) + " nodes in all frames");
    }
    Mesh2dNodes& nodes = s.frames.emplace_back(nodeCount, 2);
    ArithmeticDecoder coder(in);
    int64_t x = 0, y = 0;
    for (Eigen::Index i = 0; i < nodes.rows(); ++i) {
      x += decodeValue(coder, models.geometryX);
      y += decodeValue(coder, models.geometryY);
      nodes.row(i) << static_cast<double>(x) * q, static_cast<double>(y) * q;
    }
    coder.finish("intra geometry");
  }
  finishIntra(intra, source);
  std::vector<std::array<int, 2>> motion(nodeCount);
  for (uint32_t f = 1; f < frameCount; ++f) {
    Mesh2dNodes next = s.frames.back();
    ArithmeticDecoder coder(in);
    for (size_t k = 0; k < intra.traversal.nodeOrder.size(); ++k) {
      const int n = intra.traversal.nodeOrder[k];
      auto& v = motion[static_cast<size_t>(n)];
      v = {0, 0};
      if (coder.decode(models.moves) == 1) {
        const auto w = prediction(intra.traversal, k, motion);
        const int64_t vx = w[0] + decodeValue(coder, models.errorX);
        const int64_t vy = w[1] + decodeValue(coder, models.errorY);
        if (std::abs(vx) >= (int64_t{1} << kMaxClass) ||
            std::abs(vy) >= (int64_t{1} << kMaxClass)) {
          in.fail("motion of frame " + std::to_string(f), "a motion vector is out of range");
        }
        v = {static_cast<int>(vx), static_cast<int>(vy)};
      }
      next(n, 0) += v[0] * q;
      next(n, 1) += v[1] * q;
    }
    coder.finish("motion of frame " + std::to_string(f));
    s.frames.push_back(std::move(next));
  }
  return s;
}

}  // namespace mpeg4face
