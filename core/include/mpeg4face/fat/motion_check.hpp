// SPDX-License-Identifier: GPL-3.0-or-later
// The motion check: does a face look right in motion? Every shape key of a head, and every
// frame of FAP streams evaluated through the face's tables, measured against the neutral
// face, per mesh: edge stretch, flipped triangles, new self-intersections (CGAL's Polygon
// Mesh Processing), spikes (model/surface_bump.hpp), and at the mouth the inner lip corners
// against the outer ones, the inner-lip gap and the lower lip's share of the jaw. What each
// measure means, the limits and why: docs/motion-check.md.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mpeg4face/fat/tables.hpp"
#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face {

struct MotionLimits {
  // Edge-length ratio max(l/l0, l0/l), 99th percentile over the edges a pose moves.
  double edgeRatioP99 = 2.0;
  // A triangle is flipped when its normal turned by more than this.
  double flipDegrees = 120.0;
  // Flipped triangles allowed per pose, beyond folds where lips or lids meet: triangles whose
  // three vertices all lie in the lip region or all in the lid region (below).
  int normalFlips = 0;
  // New self-intersections allowed per pose, beyond touching: pairs whose six vertices all
  // lie in the lip region (within lipRegion * MW0 of a bound point 2.x or 8.x) or all in
  // the lid region (within lidRegion * ES0 of a bound point 3.x), in the neutral face.
  int newIntersections = 0;
  double lipRegion = 0.25;
  double lidRegion = 0.2;
  // How far an inner lip corner (2.4, 2.5) may be outside its outer one (8.3, 8.4), in MW0.
  double lipCornerOutside = 0.02;
  // The lower lip's (8.2) share of the chin's (2.1) motion under FAP 3, at least.
  double lowerLipShare = 0.5;
  // A spike: a vertex whose bump (|d_i - the mean d of its one-ring|, d the displacement from
  // the neutral) is more than bumpOfPeak of the pose's largest |d| (all meshes) and more than
  // bumpOfLocalMotion of its local motion m_i = max(|d_i|, |d_j| over the ring). Calibrated
  // on the ICT scanned head (issue 41): its 51 ARKit expression shapes and the 137 frames of
  // a Live Link capture played through them reach bump / m at most 0.47 and 0.58 over the
  // vertices with bump > 5% of the peak; a FAP playback with spikes has p99 1.49, max 1.86.
  double bumpOfPeak = 0.05;
  double bumpOfLocalMotion = 0.75;
  int spikeVertices = 0;  // spike vertices allowed per pose
  // A head's own shapes (its shape keys outside the grammar: a scan's ARKit shapes, an
  // artist's sculpts), each alone at 1, measured first: a flip of a triangle they turn over
  // or make intersect, a new pair with such a triangle, and a spike at one of their spike
  // vertices are the head's, not its tables', and are not counted in the keys and frames.
  // false: everything counts.
  bool ownShapes = true;
  // Spikes are looked for in the meshes a pose moves by at least this share of the pose's
  // largest motion (any mesh, model space): a FAP's rounding on other meshes (an eyelid FAP
  // moving the ICT head's lower teeth by a micrometre) is not skin motion.
  double bumpMeshShare = 0.01;
};

// One mesh in one pose against the neutral.
struct MeshMotion {
  int mesh = 0;
  int movedEdges = 0;  // edges with an end that moved
  double edgeRatioMax = 1, edgeRatioP99 = 1;
  std::vector<int> stretchedVertices;  // ends of edges past the edge-ratio limit
  // Triangles as indices into IndexedFaceSet::triangles() / 3.
  std::vector<int> flippedTriangles;  // not folds at contact
  int contactFolds = 0;               // flipped triangles within the lips or the lids
  std::vector<std::array<int, 2>> newIntersections;  // not in the neutral, not touching
  int touchingIntersections = 0;                     // new pairs within the lips or the lids
  // Flipped triangles, new pairs and spikes that the head's own shapes make too.
  int ownShapeFaults = 0;
  // The bump (model/surface_bump.hpp): p99 of bump / peak over the vertices that move at
  // least 2% of the peak, the largest bump / local motion over those with bump > bumpOfPeak *
  // peak, and the spikes (ascending). 0 and none for a mesh whose peak is within the
  // tolerance of a still vertex or less than bumpMeshShare of the pose's.
  double bumpP99 = 0, bumpRatioMax = 0;
  std::vector<int> spikeVertices;
  // Sorted vertices of the stretched edges, flipped and newly intersecting triangles, and
  // the spikes.
  std::vector<int> offendingVertices;
};

// One shape key or one stream frame.
struct PoseMotion {
  std::string name;                           // the shape key, or "<stream name> frame <n>"
  int stream = -1;                            // index into the streams checked; -1 for a shape key
  int frame = -1;                             // frame number in the stream
  std::vector<MeshMotion> meshes;             // the meshes the pose moves
  double edgeRatioMax = 1, edgeRatioP99 = 1;  // worst mesh
  int normalFlips = 0, contactFolds = 0, newIntersections = 0, touchingIntersections = 0;
  int spikes = 0;                        // spike vertices, all meshes
  int ownShapeFaults = 0;                // all meshes, not counted (MotionLimits::ownShapes)
  double bumpP99 = 0, bumpRatioMax = 0;  // worst mesh
  // max over both sides of (inner corner - outer corner) along the mouth, outwards, in MW0:
  // > 0 when an inner corner is outside its outer one. nullopt without 2.4/2.5/8.3/8.4.
  std::optional<double> lipCornerOutside;
  std::optional<double> innerLipGap;  // (2.2.y - 2.3.y) / MNS0; nullopt without them
  std::vector<std::string> failures;  // the limits passed, e.g. "edge ratio p99 3.1 > 2"
};

struct StreamMotion {
  std::string name;
  int frames = 0;
  double innerLipGapMin = 0, innerLipGapMax = 0;  // over its frames (MNS0), if measured
};

struct MotionCheck {
  MotionLimits limits;
  std::vector<PoseMotion> keys;    // one per shape key (or, for a face, table extreme)
  std::vector<PoseMotion> frames;  // every frame of every stream, in order
  std::vector<StreamMotion> streams;
  std::optional<double> neutralLipGap;  // MNS0
  // 8.2's displacement along 2.1's over 2.1's squared, at FAP 3 = 1024 through the tables.
  std::optional<double> lowerLipShare;
  std::vector<std::string> failures;  // face-level: the lower-lip share
  std::vector<std::string> notes;     // what could not be measured, and why
  int neutralIntersections = 0;       // self-intersecting pairs of the neutral (all meshes)
  std::vector<std::string> ownShapes;  // the head's own shapes measured first, by name

  bool passed() const;
};

// Called after each pose with (poses done, poses in all).
using MotionProgress = std::function<void(std::size_t, std::size_t)>;

// A head with shape keys (.glb): its keys in the grammar of fat/names.hpp
// (shapesFromShapeKeys), and the streams through the tables made from them
// (faceFromShapeKeys).
MotionCheck checkMotion(const FaceModel& head, std::span<const FapStream> streams,
                        const MotionLimits& limits = {}, const MotionProgress& progress = {});
// A face with tables (.wrl): as keys each table at its outermost interval borders (a
// viseme or expression fully on), and the streams through the tables (the face's FIT
// deriving the FAPs a stream does not send).
MotionCheck checkMotion(const MpegFace& face, std::span<const FapStream> streams,
                        const MotionLimits& limits = {}, const MotionProgress& progress = {});

}  // namespace mpeg4face
