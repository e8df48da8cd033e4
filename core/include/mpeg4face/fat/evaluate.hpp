// SPDX-License-Identifier: GPL-3.0-or-later
// Checking an MpegFace's tables and animating it with them: a FAP frame -> the deformed
// meshes and the changed Transforms (Tekalp-Ostermann 2.1.3.4). Rules in docs/fat.md.
#pragma once

#include <array>
#include <bitset>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "mpeg4face/fat/tables.hpp"
#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face {

// Throws mpeg4face::Error naming the first broken part, e.g. field
// "faceDefTables[3] (FAP 6).faceDefMesh[0].coordIndex[17]": the scene graph (FaceModel::
// validate), fapID outside 1..68, highLevelSelect outside 1..14 (FAP 1) or 1..6 (FAP 2), two
// tables for the same FAP (or viseme / expression), a mesh or transform reference out of
// range, one table deforming a mesh or a Transform field twice, invalid interval borders,
// coordIndex outside the mesh or repeated, a displacement count other than
// coordIndex.size() * intervalCount, a value that is not finite, a fieldId other than 1..3,
// a zero rotation axis.
void validateMpegFace(const MpegFace& face);

// The animated state of an MpegFace: what a renderer draws for one frame.
struct FatState {
  std::vector<Points3> coord;         // vertex positions, one array per faceSceneGraph mesh
  std::vector<Transform> transforms;  // faceSceneGraph.transforms with the animated fields set
  std::vector<float> work;            // evaluate()'s working memory: no allocation per frame
};

// How FatEvaluator stores the tables' displacements, already multiplied by the FAP's unit.
enum class FatStorage {
  // float, about 7 significant digits: the default, for everything that measures or fits.
  Float,
  // 16-bit integers in steps of a power of two per table, interval and axis, chosen for the
  // largest value: half the bytes a frame reads, for playback. A table's motion of a vertex
  // along an axis is off by at most sum_k |w_k| * max_e |d_ek| / 32768 (w: intervalWeights,
  // d: the interval's displacements in model units; docs/fat.md), about 3e-5 of its largest.
  Int16,
};

// The tables of one MpegFace compiled for one FAPU measurement: built once, then evaluate()
// turns any number of frames into states without allocating. Motions are summed per frame
// in float before they are added to the double positions.
class FatEvaluator {
 public:
  // Validates `face` (validateMpegFace) and throws mpeg4face::Error if a table's FAP needs a
  // FAPU that `fapu` lacks, naming the table and the feature points that FAPU needs.
  FatEvaluator(const MpegFace& face, const FapuMeasurement& fapu,
               FatStorage storage = FatStorage::Float);

  // The neutral state, shaped for evaluate().
  FatState neutralState() const;

  // Sets `state` (made by neutralState(), possibly used before) to the face animated by
  // `frame`, a resolved frame: a low-level FAP (3..68) acts when its mask bit is set, the
  // viseme when bit 1 is set, the expression when bit 2 is set. Rules (docs/fat.md):
  // - each table moves its vertices by fapScale * the paper's piecewise-linear function of
  //   its value (intervalWeights); several FAPs on one vertex add;
  // - a viseme table is driven by viseme_blend (select1) and 63 - viseme_blend (select2), an
  //   expression table by the intensity of the select that names it (both if both do);
  // - low-level FAPs have priority: a vertex in the coordIndex of a table (same mesh) of a
  //   low-level FAP present in the frame gives up the share of its viseme and expression
  //   motion that the FAP moves it by, relative to the vertex that FAP moves most (all of
  //   it there, a little where the FAP's motion fades out; the largest share over the
  //   present FAPs), and a Transform field that such a FAP animates ignores them;
  // - FaceDefTransforms are applied in increasing fapID order (then highLevelSelect), from
  //   the neutral Transform (applyFaceDefTransform).
  // Throws mpeg4face::Error for a state of another shape and for viseme / expression fields
  // out of range (select 0..14 / 0..6, blend and intensities 0..63).
  void evaluate(const FapFrame& frame, FatState& state) const;
  FatState evaluate(const FapFrame& frame) const;

  // Whether the low-level FAPs' priority changes `frame`'s result: a viseme or expression
  // with a non-zero input moves a vertex or Transform field that a low-level FAP present in
  // the frame also moves. Where it does not, the result is the plain sum of every table's
  // motion, which shape keys weighted by borderWeights show exactly (the bake).
  bool priorityApplies(const FapFrame& frame) const;

 private:
  using FapBits = std::bitset<kFapCount>;  // bit i: FAP i + 1

  // One FaceDefMesh, ready to evaluate. Per interval j, a vertex's displacement for a value
  // in (or continuing) interval j is base_j + c * slope_j with c = sign_j * (value -
  // inner_j), inner_j the border of the interval nearer to 0 (the paper's sums, folded).
  struct Interval {
    int lower = 0, upper = 0;  // borders
    float inner = 0, sign = 1;
    std::int64_t baseOffset = -1;  // into Mesh::base, -1: base is zero
    // Model units per stored unit of slope and base, per axis (1 for float storage).
    std::array<float, 3> slopeStep{1, 1, 1}, baseStep{1, 1, 1};
  };
  struct Mesh {
    int mesh = -1;
    int zeroIndex = 0;  // index of the 0 border (multi-interval)
    std::vector<Interval> intervals;
    std::vector<std::uint32_t> slot;  // each entry's vertex slot in FatState::work
    // Entries whose slots follow one another (coordIndex runs like 17 18 19), as (first
    // slot, length) in entry order, when they are long enough to pay: empty otherwise.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> runs;
    // Interval j's x, y, z of entry e at 3 * (j * slot.size() + e) + 0, 1, 2; base likewise
    // from Interval::baseOffset; interleaved like FatState::work, so that runs are flat
    // loops. Either the float or the 16-bit pair is filled, as FatStorage says.
    std::vector<float> slope, base;
    std::vector<std::int16_t> slope16, base16;
    std::vector<FapBits> coveredBy;  // viseme / expression tables: low-level FAPs per vertex
    // The largest motion of each entry at the table's outermost borders (low-level tables).
    std::vector<float> reach;
  };
  struct TransformDef {
    FaceDefTransform def;
    FapBits coveredBy;  // viseme / expression tables: low-level FAPs on the same field
  };
  struct Table {
    int fapID = 0;
    int highLevelSelect = 0;
    double scale = 1;  // for transforms; mesh displacements are stored pre-multiplied
    std::vector<Mesh> meshes;
    std::vector<TransformDef> transforms;
  };

  template <typename Stored>
  void addMotion(const FapFrame& frame, FatState& state) const;
  template <typename Stored>
  void addMeshByVertex(const Mesh& m, int value, float* work, const FapBits* active) const;

  FatStorage storage_;
  std::vector<Table> tables_;          // sorted by fapID, highLevelSelect
  std::vector<Points3> neutralCoord_;  // per mesh
  std::vector<Transform> neutralTransforms_;
  std::vector<int> animatedMeshes_;
  std::vector<std::uint32_t> firstSlot_;  // per animated mesh: its vertex 0 in FatState::work
  std::size_t slotCount_ = 0;
  std::vector<int> animatedTransforms_;
  FapBits lowLevelWithTables_;
  // Per vertex slot, the share of its viseme / expression motion each low-level FAP takes
  // when present (coverStart_[s] .. coverStart_[s + 1] in cover_): compressed rows.
  std::vector<std::uint32_t> coverStart_;
  std::vector<std::pair<std::uint8_t, float>> cover_;  // (FAP - 1, share)
};

// Float vertex positions, as a vertex buffer holds them.
using Points3f = Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>;

// The placement that shows a mesh in the frame of the object holding it, for a view that
// leaves its objects where they are (the Blender add-on's live preview) and moves the
// vertices instead: where the `transforms` along `chain` (indices, outermost first) put
// the mesh (the product of their local matrices), taken back through the inverse of the
// same product of the `neutral` Transforms, then turned by `axes` (say Y-up to Z-up). A
// turn of an eye or a nod of the head thus moves the vertices, not the object. Throws
// mpeg4face::Error for an index outside `transforms` or `neutral`.
Eigen::Affine3d objectPlacement(const std::vector<Transform>& transforms,
                                const std::vector<Transform>& neutral, std::span<const int> chain,
                                const Eigen::Matrix3d& axes);

// Mesh i of `state` placed by objectPlacement(state.transforms, neutral, chains[i], axes),
// for i < chains.size(), into coords[i] (float, ready for a vertex buffer) and the
// placement into placements[i] (its linear part turns the mesh's normals). The outputs are
// resized; their buffers are reused from frame to frame. Throws mpeg4face::Error for more
// chains than meshes and as objectPlacement does.
void objectCoordinates(const FatState& state, const std::vector<Transform>& neutral,
                       const std::vector<std::vector<int>>& chains, const Eigen::Matrix3d& axes,
                       std::vector<Points3f>& coords, std::vector<Eigen::Affine3d>& placements);

}  // namespace mpeg4face
