// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/fat/evaluate.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <string>
#include <type_traits>
#include <utility>

#include "fat/add_runs.hpp"
#include "fat/support.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

constexpr int kVisemeCount = 15;     // 0..14, 0 = none
constexpr int kExpressionCount = 7;  // 0..6, 0 = neutral
constexpr int kMaxAmount = 63;       // viseme_blend, expression intensities
// Runs of consecutive vertices replace the per-vertex slot list when they average this long.
constexpr std::size_t kMinRun = 4;

std::string tableField(std::size_t i, const FaceDefTables& t) {
  return "faceDefTables[" + std::to_string(i) + "] (" + fat::fapLabel(t.fapID, t.highLevelSelect) +
         ")";
}

void validateMesh(const FaceModel& graph, const FaceDefMesh& m, const std::string& where) {
  const int meshCount = static_cast<int>(graph.meshes.size());
  if (m.mesh < 0 || m.mesh >= meshCount) {
    throw Error({}, 0, where + ".faceSceneGraphNode",
                "mesh " + std::to_string(m.mesh) + " out of range (the scene graph has " +
                    std::to_string(meshCount) + " meshes)");
  }
  try {
    checkIntervalBorders(m.intervalBorders);
  } catch (const Error& e) {
    throw Error({}, 0, where + ".intervalBorders", e.reason());
  }
  const IndexedFaceSet& mesh = graph.meshes[m.mesh];
  std::vector<bool> seen(static_cast<std::size_t>(mesh.vertexCount()), false);
  for (std::size_t i = 0; i < m.coordIndex.size(); ++i) {
    const int v = m.coordIndex[i];
    // The field's name is made only for an error: a table lists thousands of vertices.
    const auto field = [&] { return where + ".coordIndex[" + std::to_string(i) + "]"; };
    if (v < 0 || v >= mesh.vertexCount()) {
      throw Error({}, 0, field(),
                  "vertex " + std::to_string(v) + " out of range (mesh '" + mesh.name + "' has " +
                      std::to_string(mesh.vertexCount()) + " vertices)");
    }
    if (seen[v]) throw Error({}, 0, field(), "vertex " + std::to_string(v) + " is listed twice");
    seen[v] = true;
  }
  const auto expected = static_cast<Eigen::Index>(m.coordIndex.size()) * m.intervalCount();
  if (m.displacements.rows() != expected) {
    throw Error({}, 0, where + ".displacements",
                std::to_string(m.displacements.rows()) + " displacements, expected " +
                    std::to_string(expected) + " (" + std::to_string(m.coordIndex.size()) +
                    " vertices x " + std::to_string(m.intervalCount()) + " intervals)");
  }
  for (Eigen::Index r = 0; r < m.displacements.rows(); ++r) {
    if (!m.displacements.row(r).allFinite()) {
      throw Error({}, 0, where + ".displacements[" + std::to_string(r) + "]", "not finite");
    }
  }
}

void validateTransform(const FaceModel& graph, const FaceDefTransform& t,
                       const std::string& where) {
  const int count = static_cast<int>(graph.transforms.size());
  if (t.transform < 0 || t.transform >= count) {
    throw Error({}, 0, where + ".faceSceneGraphNode",
                "transform " + std::to_string(t.transform) + " out of range (the scene graph has " +
                    std::to_string(count) + " transforms)");
  }
  const int field = static_cast<int>(t.fieldId);
  if (field < 1 || field > 3) {
    throw Error({}, 0, where + ".fieldId",
                std::to_string(field) + " is not 1 (rotation), 2 (scale) or 3 (translation)");
  }
  if (!t.rotationDef.allFinite()) throw Error({}, 0, where + ".rotationDef", "not finite");
  if (!t.scaleDef.allFinite()) throw Error({}, 0, where + ".scaleDef", "not finite");
  if (!t.translationDef.allFinite()) throw Error({}, 0, where + ".translationDef", "not finite");
  if (t.fieldId == FaceDefTransform::Field::Rotation && t.rotationDef.head<3>().norm() == 0) {
    throw Error({}, 0, where + ".rotationDef", "rotation axis is zero");
  }
}

// Writes one axis of `count` interleaved x, y, z floats as 16-bit integers and returns their
// step: the power of two that brings the largest magnitude into 16384..32767 (1 if all are 0).
// A power of two keeps values such as 0.5 or 600 exact and step * integer exact in float;
// each value is off by at most half a step, 1/32768 of the largest.
float quantise(const float* in, std::size_t count, std::int16_t* out) {
  float largest = 0;
  for (std::size_t i = 0; i < count; ++i) largest = std::max(largest, std::abs(in[3 * i]));
  int exponent = 0;
  std::frexp(largest, &exponent);  // largest = f * 2^exponent, f in [0.5, 1)
  const float step = largest > 0 ? std::ldexp(1.0f, exponent - 15) : 1.0f;
  for (std::size_t i = 0; i < count; ++i) {
    out[3 * i] =
        static_cast<std::int16_t>(std::clamp(std::lround(in[3 * i] / step), -32767L, 32767L));
  }
  return step;
}

// The interval a value falls in or continues, as FatEvaluator::Interval describes, chosen
// exactly as intervalWeights chooses its non-zero weights.
template <typename Interval>
std::size_t intervalOf(const std::vector<Interval>& iv, std::size_t zero, double value) {
  const std::size_t n = iv.size();
  if (n == 1) return 0;
  if (value > 0) {
    if (zero == n) return n - 1;  // no positive interval: the last continues through 0
    std::size_t j = zero;
    while (j + 1 < n && value > iv[j].upper) ++j;
    return j;
  }
  if (zero == 0) return 0;  // no negative interval: the first continues through 0
  std::size_t j = zero - 1;
  while (j > 0 && value < iv[j].lower) --j;
  return j;
}

}  // namespace

void validateMpegFace(const MpegFace& face) {
  const FaceModel& graph = face.faceSceneGraph;
  graph.validate();
  std::map<std::pair<int, int>, std::size_t> tableOf;  // (fapID, select) -> first table
  for (std::size_t i = 0; i < face.faceDefTables.size(); ++i) {
    const FaceDefTables& t = face.faceDefTables[i];
    const std::string where = tableField(i, t);
    if (t.fapID < 1 || t.fapID > kFapCount) {
      throw Error({}, 0, where + ".fapID", std::to_string(t.fapID) + " is not a FAP (1..68)");
    }
    if (t.fapID == 1 && (t.highLevelSelect < 1 || t.highLevelSelect >= kVisemeCount)) {
      throw Error({}, 0, where + ".highLevelSelect",
                  "viseme " + std::to_string(t.highLevelSelect) + " is not 1..14");
    }
    if (t.fapID == 2 && (t.highLevelSelect < 1 || t.highLevelSelect >= kExpressionCount)) {
      throw Error({}, 0, where + ".highLevelSelect",
                  "expression " + std::to_string(t.highLevelSelect) + " is not 1..6");
    }
    const int select = t.fapID <= 2 ? t.highLevelSelect : 0;
    const auto [first, added] = tableOf.try_emplace({t.fapID, select}, i);
    if (!added) {
      throw Error({}, 0, where,
                  "a second table for " + fat::fapLabel(t.fapID, t.highLevelSelect) +
                      " (the first is faceDefTables[" + std::to_string(first->second) + "])");
    }
    std::map<int, std::size_t> meshSeen;
    for (std::size_t m = 0; m < t.faceDefMesh.size(); ++m) {
      const std::string field = where + ".faceDefMesh[" + std::to_string(m) + "]";
      validateMesh(graph, t.faceDefMesh[m], field);
      const auto [other, fresh] = meshSeen.try_emplace(t.faceDefMesh[m].mesh, m);
      if (!fresh) {
        throw Error({}, 0, field,
                    "deforms mesh '" + graph.meshes[t.faceDefMesh[m].mesh].name +
                        "' again (faceDefMesh[" + std::to_string(other->second) + "])");
      }
    }
    std::map<std::pair<int, int>, std::size_t> fieldSeen;
    for (std::size_t k = 0; k < t.faceDefTransform.size(); ++k) {
      const FaceDefTransform& def = t.faceDefTransform[k];
      const std::string field = where + ".faceDefTransform[" + std::to_string(k) + "]";
      validateTransform(graph, def, field);
      const auto [other, fresh] =
          fieldSeen.try_emplace({def.transform, static_cast<int>(def.fieldId)}, k);
      if (!fresh) {
        throw Error({}, 0, field,
                    "animates the same field of transform '" +
                        graph.transforms[def.transform].name + "' again (faceDefTransform[" +
                        std::to_string(other->second) + "])");
      }
    }
  }
}

FatEvaluator::FatEvaluator(const MpegFace& face, const FapuMeasurement& fapu, FatStorage storage)
    : storage_(storage) {
  validateMpegFace(face);
  const FaceModel& graph = face.faceSceneGraph;
  neutralTransforms_ = graph.transforms;
  neutralCoord_.reserve(graph.meshes.size());
  for (const IndexedFaceSet& mesh : graph.meshes) neutralCoord_.push_back(mesh.coord);

  // The vertices of the meshes some table deforms get consecutive slots in FatState::work.
  std::vector<std::int64_t> firstSlot(graph.meshes.size(), -1);
  std::vector<bool> transformAnimated(graph.transforms.size(), false);
  for (const FaceDefTables& t : face.faceDefTables) {
    for (const FaceDefMesh& m : t.faceDefMesh) firstSlot[m.mesh] = 0;
    for (const FaceDefTransform& d : t.faceDefTransform) transformAnimated[d.transform] = true;
  }
  for (std::size_t m = 0; m < graph.meshes.size(); ++m) {
    if (firstSlot[m] < 0) continue;
    if (slotCount_ + graph.meshes[m].coord.rows() > std::size_t{UINT32_MAX}) {
      throw Error({}, 0, "faceSceneGraph", "too many animated vertices");
    }
    firstSlot[m] = static_cast<std::int64_t>(slotCount_);
    animatedMeshes_.push_back(static_cast<int>(m));
    firstSlot_.push_back(static_cast<std::uint32_t>(slotCount_));
    slotCount_ += static_cast<std::size_t>(graph.meshes[m].coord.rows());
  }
  for (std::size_t t = 0; t < transformAnimated.size(); ++t) {
    if (transformAnimated[t]) animatedTransforms_.push_back(static_cast<int>(t));
  }

  for (std::size_t i = 0; i < face.faceDefTables.size(); ++i) {
    const FaceDefTables& in = face.faceDefTables[i];
    const std::string where = tableField(i, in);
    Table& table = tables_.emplace_back();
    table.fapID = in.fapID;
    table.highLevelSelect = in.fapID <= 2 ? in.highLevelSelect : 0;
    table.scale = fat::requireFapScale(fapu, in.fapID, where);
    if (in.fapID >= 3) lowLevelWithTables_.set(static_cast<std::size_t>(in.fapID - 1));
    for (std::size_t k = 0; k < in.faceDefMesh.size(); ++k) {
      const FaceDefMesh& src = in.faceDefMesh[k];
      const auto toFloat = [&](double value) {
        const auto f = static_cast<float>(value);
        if (!std::isfinite(f)) {
          throw Error({}, 0, where + ".faceDefMesh[" + std::to_string(k) + "].displacements",
                      "a motion of " + std::to_string(value) + " model units is out of range");
        }
        return f;
      };
      Mesh& m = table.meshes.emplace_back();
      m.mesh = src.mesh;
      const auto n = static_cast<std::size_t>(src.intervalCount());
      const std::size_t count = src.coordIndex.size();
      m.zeroIndex =
          static_cast<int>(std::ranges::find(src.intervalBorders, 0) - src.intervalBorders.begin());
      for (int v : src.coordIndex) {
        m.slot.push_back(static_cast<std::uint32_t>(firstSlot[src.mesh] + v));
      }
      for (std::size_t e = 0; e < count; ++e) {
        if (e > 0 && m.slot[e] == m.slot[e - 1] + 1) {
          ++m.runs.back().second;
        } else {
          m.runs.emplace_back(m.slot[e], 1);
        }
      }
      if (m.runs.size() * kMinRun > count) m.runs.clear();
      m.slope.resize(3 * count * n);
      for (std::size_t j = 0; j < n; ++j) {
        Interval iv;
        iv.lower = src.intervalBorders[j];
        iv.upper = src.intervalBorders[j + 1];
        const bool negativeSide = n > 1 && j < static_cast<std::size_t>(m.zeroIndex);
        iv.sign = negativeSide ? -1.0f : 1.0f;
        iv.inner = static_cast<float>(n == 1 ? 0 : negativeSide ? iv.upper : iv.lower);
        m.intervals.push_back(iv);
        for (std::size_t v = 0; v < count; ++v) {
          for (std::size_t c = 0; c < 3; ++c) {
            m.slope[3 * (j * count + v) + c] =
                toFloat(table.scale *
                        src.displacements(static_cast<Eigen::Index>(v * n + j), Eigen::Index(c)));
          }
        }
      }
      // base_j: the motion at interval j's inner border, i.e. the full intervals between it
      // and 0 (the paper's sums), for the intervals not touching 0.
      const auto zero = static_cast<std::size_t>(m.zeroIndex);
      for (std::size_t j = 0; n > 1 && j < n; ++j) {
        std::size_t from = j + 1, to = zero;  // negative side: intervals j+1 .. zero-1
        if (j >= zero) from = zero, to = j;   // positive side: intervals zero .. j-1
        if (from >= to) continue;
        const std::size_t offset = m.base.size();
        m.intervals[j].baseOffset = static_cast<std::int64_t>(offset);
        m.base.resize(offset + 3 * count);
        for (std::size_t v = 0; v < count; ++v) {
          Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
          for (std::size_t b = from; b < to; ++b) {
            sum += (double(src.intervalBorders[b + 1]) - src.intervalBorders[b]) *
                   src.displacements.row(static_cast<Eigen::Index>(v * n + b));
          }
          for (std::size_t c = 0; c < 3; ++c) {
            m.base[offset + 3 * v + c] = toFloat(table.scale * sum[Eigen::Index(c)]);
          }
        }
      }
      if (storage == FatStorage::Int16 && count > 0) {  // an empty table stores nothing
        m.slope16.resize(m.slope.size());
        m.base16.resize(m.base.size());
        for (std::size_t j = 0; j < n; ++j) {
          Interval& iv = m.intervals[j];
          for (std::size_t c = 0; c < 3; ++c) {
            const std::size_t at = 3 * j * count + c;
            iv.slopeStep[c] = quantise(m.slope.data() + at, count, m.slope16.data() + at);
            if (iv.baseOffset < 0) continue;
            const std::size_t baseAt = static_cast<std::size_t>(iv.baseOffset) + c;
            iv.baseStep[c] = quantise(m.base.data() + baseAt, count, m.base16.data() + baseAt);
          }
        }
        m.slope = {};
        m.base = {};
      }
    }
    for (const FaceDefTransform& def : in.faceDefTransform) table.transforms.push_back({def, {}});
    if (in.fapID <= 2) continue;
    // Each entry's motion at the outermost border on either side: the priority's share.
    for (std::size_t k = 0; k < in.faceDefMesh.size(); ++k) {
      const FaceDefMesh& src = in.faceDefMesh[k];
      const auto n = static_cast<std::size_t>(src.intervalCount());
      const auto zero = static_cast<std::size_t>(table.meshes[k].zeroIndex);
      std::vector<float>& reach = table.meshes[k].reach;
      for (std::size_t v = 0; v < src.coordIndex.size(); ++v) {
        Eigen::RowVector3d below = Eigen::RowVector3d::Zero(), above = below;
        for (std::size_t j = 0; j < n; ++j) {
          const double width = double(src.intervalBorders[j + 1]) - src.intervalBorders[j];
          (n > 1 && j < zero ? below : above) +=
              width * src.displacements.row(static_cast<Eigen::Index>(v * n + j));
        }
        reach.push_back(static_cast<float>(std::max(below.norm(), above.norm())));
      }
    }
  }
  std::ranges::sort(tables_, [](const Table& a, const Table& b) {
    return std::pair(a.fapID, a.highLevelSelect) < std::pair(b.fapID, b.highLevelSelect);
  });

  // Priority of low-level FAPs: which of them cover each vertex slot / Transform field that a
  // viseme or expression table moves, and by what share (the entry's reach over the table's
  // largest, so that a FAP whose motion fades out does not cut the viseme off at its edge).
  // The shares are compressed rows made in two passes (count, then fill in table order, so
  // by FAP): a slot has at most one entry per FAP (validated: one table per FAP, one
  // FaceDefMesh per mesh, no vertex listed twice).
  std::vector<FapBits> slotCover(slotCount_);
  std::map<std::pair<int, int>, FapBits> fieldCover;
  coverStart_.assign(slotCount_ + 1, 0);
  for (const Table& t : tables_) {
    if (t.fapID <= 2) continue;
    for (const Mesh& m : t.meshes) {
      for (std::uint32_t s : m.slot) ++coverStart_[s + 1];
    }
  }
  std::partial_sum(coverStart_.begin(), coverStart_.end(), coverStart_.begin());
  cover_.resize(coverStart_.back());
  std::vector<std::uint32_t> next(coverStart_.begin(), coverStart_.end() - 1);
  for (const Table& t : tables_) {
    if (t.fapID <= 2) continue;
    const auto bit = static_cast<std::size_t>(t.fapID - 1);
    float largest = 0;
    for (const Mesh& m : t.meshes) {
      for (float r : m.reach) largest = std::max(largest, r);
    }
    for (const Mesh& m : t.meshes) {
      for (std::size_t e = 0; e < m.slot.size(); ++e) {
        const std::uint32_t s = m.slot[e];
        slotCover[s].set(bit);
        cover_[next[s]++] = {static_cast<std::uint8_t>(bit),
                             largest > 0 ? m.reach[e] / largest : 1.0f};
      }
    }
    for (const TransformDef& d : t.transforms) {
      fieldCover[{d.def.transform, static_cast<int>(d.def.fieldId)}].set(bit);
    }
  }
  for (Table& t : tables_) {
    if (t.fapID > 2) continue;
    for (Mesh& m : t.meshes) {
      m.coveredBy.resize(m.slot.size());
      for (std::size_t i = 0; i < m.slot.size(); ++i) m.coveredBy[i] = slotCover[m.slot[i]];
    }
    for (TransformDef& d : t.transforms) {
      const auto it = fieldCover.find({d.def.transform, static_cast<int>(d.def.fieldId)});
      if (it != fieldCover.end()) d.coveredBy = it->second;
    }
  }
}

FatState FatEvaluator::neutralState() const {
  return {neutralCoord_, neutralTransforms_, std::vector<float>(3 * slotCount_, 0.0f)};
}

FatState FatEvaluator::evaluate(const FapFrame& frame) const {
  FatState state = neutralState();
  evaluate(frame, state);
  return state;
}

namespace {

// On x86-64 the final pass is also compiled for AVX2 (8 floats a step instead of SSE2's 4) and
// the CPU picks the version when the program loads.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define MPEG4FACE_AVX2_CLONE __attribute__((target_clones("avx2", "default")))
#else
#define MPEG4FACE_AVX2_CLONE
#endif

// p = p0 + the summed motion (both x, y, z interleaved: one flat loop), and the sums reset.
MPEG4FACE_AVX2_CLONE
void addToNeutral(const double* __restrict p0, float* __restrict w, std::size_t count,
                  double* __restrict p) {
  for (std::size_t i = 0; i < 3 * count; ++i) {
    p[i] = p0[i] + w[i];
    w[i] = 0.0f;
  }
}

// The stored tables of a Mesh, as FatStorage chose them.
template <typename Stored, typename Mesh>
std::pair<const Stored*, const Stored*> slopesAndBases(const Mesh& m) {
  if constexpr (std::is_same_v<Stored, float>) {
    return {m.slope.data(), m.base.data()};
  } else {
    return {m.slope16.data(), m.base16.data()};
  }
}

// What one table contributes at one value: its interval's slope and base (null: zero) and
// the factors per axis that turn stored units into the motion.
template <typename Stored>
struct IntervalMotion {
  const Stored* slope;
  const Stored* base;
  std::array<float, 3> B, C;
};

template <typename Stored, typename Mesh>
IntervalMotion<Stored> intervalMotion(const Mesh& m, int value) {
  const std::size_t j = intervalOf(m.intervals, static_cast<std::size_t>(m.zeroIndex), value);
  const auto& iv = m.intervals[j];
  const float c = iv.sign * (static_cast<float>(value) - iv.inner);
  const auto [slopes, bases] = slopesAndBases<Stored>(m);
  return {slopes + 3 * m.slot.size() * j,
          iv.baseOffset >= 0 ? bases + iv.baseOffset : nullptr,
          iv.baseStep,
          {c * iv.slopeStep[0], c * iv.slopeStep[1], c * iv.slopeStep[2]}};
}

}  // namespace

template <typename Stored>
void FatEvaluator::addMeshByVertex(const Mesh& m, int value, float* work,
                                   const FapBits* active) const {
  const IntervalMotion<Stored> at = intervalMotion<Stored>(m, value);
  for (std::size_t i = 0; i < m.slot.size(); ++i) {
    const std::uint32_t slot = m.slot[i];
    float keep = 1;
    if (active && (m.coveredBy[i] & *active).any()) {
      // a viseme or expression: less where a present low-level FAP moves
      for (std::uint32_t e = coverStart_[slot]; e < coverStart_[slot + 1]; ++e) {
        if (active->test(cover_[e].first)) keep = std::min(keep, 1 - cover_[e].second);
      }
    }
    for (std::size_t axis = 0; axis < 3; ++axis) {
      const float motion =
          (at.base ? at.B[axis] * static_cast<float>(at.base[3 * i + axis]) : 0.0f) +
          at.C[axis] * static_cast<float>(at.slope[3 * i + axis]);
      work[3 * slot + axis] += keep * motion;
    }
  }
}

template <typename Stored>
void FatEvaluator::addMotion(const FapFrame& frame, FatState& state) const {
  float* work = state.work.data();
  const FapBits active = frame.mask & lowLevelWithTables_;
  const fat::RunsKernel kernel = fat::bestRunsKernel();
  for (const Table& t : tables_) {
    if (!frame.has(t.fapID)) continue;
    const int value = tableInput(t.fapID, t.highLevelSelect, frame);
    if (value == 0) continue;
    // Visemes and expressions give way to present low-level FAPs, vertex by vertex.
    const FapBits* priority = t.fapID <= 2 && active.any() ? &active : nullptr;
    for (const Mesh& m : t.meshes) {
      if (priority || m.runs.empty()) {
        addMeshByVertex<Stored>(m, value, work, priority);
      } else {
        const IntervalMotion<Stored> at = intervalMotion<Stored>(m, value);
        fat::addRuns(m.runs.data(), m.runs.size(), work, at.base, at.slope, at.B.data(),
                     at.C.data(), kernel);
      }
    }
    for (const TransformDef& d : t.transforms) {
      if (priority && (d.coveredBy & active).any()) continue;
      applyFaceDefTransform(d.def, value * t.scale, state.transforms[d.def.transform]);
    }
  }
  for (std::size_t k = 0; k < animatedMeshes_.size(); ++k) {
    const Points3& neutral = neutralCoord_[animatedMeshes_[k]];
    addToNeutral(neutral.data(), work + 3 * std::size_t(firstSlot_[k]),
                 static_cast<std::size_t>(neutral.rows()), state.coord[animatedMeshes_[k]].data());
  }
}

void FatEvaluator::evaluate(const FapFrame& frame, FatState& state) const {
  if (state.coord.size() != neutralCoord_.size() ||
      state.transforms.size() != neutralTransforms_.size() || state.work.size() != 3 * slotCount_) {
    throw Error({}, 0, "state", "not shaped for this face (make it with neutralState())");
  }
  for (int m : animatedMeshes_) {
    if (state.coord[m].rows() != neutralCoord_[m].rows()) {
      throw Error({}, 0, "state.coord[" + std::to_string(m) + "]",
                  std::to_string(state.coord[m].rows()) + " vertices, the mesh has " +
                      std::to_string(neutralCoord_[m].rows()));
    }
  }
  const auto check = [](int value, int limit, const char* field) {
    if (value < 0 || value > limit) {
      throw Error({}, 0, field, std::to_string(value) + " is not 0.." + std::to_string(limit));
    }
  };
  const Viseme& vis = frame.viseme;
  const Expression& ex = frame.expression;
  if (frame.has(1)) {
    check(vis.select1, kVisemeCount - 1, "viseme_select1");
    check(vis.select2, kVisemeCount - 1, "viseme_select2");
    check(vis.blend, kMaxAmount, "viseme_blend");
  }
  if (frame.has(2)) {
    check(ex.select1, kExpressionCount - 1, "expression_select1");
    check(ex.select2, kExpressionCount - 1, "expression_select2");
    check(ex.intensity1, kMaxAmount, "expression_intensity1");
    check(ex.intensity2, kMaxAmount, "expression_intensity2");
  }
  for (int t : animatedTransforms_) {
    state.transforms[t].translation = neutralTransforms_[t].translation;
    state.transforms[t].rotation = neutralTransforms_[t].rotation;
    state.transforms[t].scale = neutralTransforms_[t].scale;
  }

  // Sum every table's motion per vertex slot, then add the sums to the neutral positions.
  if (storage_ == FatStorage::Int16) {
    addMotion<std::int16_t>(frame, state);
  } else {
    addMotion<float>(frame, state);
  }
}

bool FatEvaluator::priorityApplies(const FapFrame& frame) const {
  const FapBits active = frame.mask & lowLevelWithTables_;
  if (active.none()) return false;
  for (const Table& t : tables_) {
    if (t.fapID > 2) break;  // sorted by fapID: the visemes and expressions come first
    if (!frame.has(t.fapID) || tableInput(t.fapID, t.highLevelSelect, frame) == 0) continue;
    for (const Mesh& m : t.meshes) {
      for (const FapBits& covered : m.coveredBy) {
        if ((covered & active).any()) return true;
      }
    }
    for (const TransformDef& d : t.transforms) {
      if ((d.coveredBy & active).any()) return true;
    }
  }
  return false;
}

Eigen::Affine3d objectPlacement(const std::vector<Transform>& transforms,
                                const std::vector<Transform>& neutral, std::span<const int> chain,
                                const Eigen::Matrix3d& axes) {
  Eigen::Affine3d posed = Eigen::Affine3d::Identity(), rest = Eigen::Affine3d::Identity();
  for (int t : chain) {
    if (t < 0 || static_cast<std::size_t>(t) >= std::min(transforms.size(), neutral.size())) {
      throw Error({}, 0, "chain",
                  "Transform " + std::to_string(t) + " outside the " +
                      std::to_string(transforms.size()) + " Transforms");
    }
    posed = posed * transforms[static_cast<std::size_t>(t)].localMatrix();
    rest = rest * neutral[static_cast<std::size_t>(t)].localMatrix();
  }
  Eigen::Affine3d placement = Eigen::Affine3d::Identity();
  placement.linear() = axes;
  return placement * rest.inverse() * posed;
}

void objectCoordinates(const FatState& state, const std::vector<Transform>& neutral,
                       const std::vector<std::vector<int>>& chains, const Eigen::Matrix3d& axes,
                       std::vector<Points3f>& coords, std::vector<Eigen::Affine3d>& placements) {
  if (chains.size() > state.coord.size()) {
    throw Error({}, 0, "chains",
                std::to_string(chains.size()) + " chains for " +
                    std::to_string(state.coord.size()) + " meshes");
  }
  coords.resize(chains.size());
  placements.resize(chains.size());
  for (std::size_t i = 0; i < chains.size(); ++i) {
    const Eigen::Affine3d& p = placements[i] =
        objectPlacement(state.transforms, neutral, chains[i], axes);
    const Points3& from = state.coord[i];
    coords[i].resize(from.rows(), 3);
    // Row by row, in double and rounded once: no temporary, the closest floats.
    for (Eigen::Index r = 0; r < from.rows(); ++r) {
      coords[i].row(r) = (p * from.row(r).transpose()).transpose().cast<float>();
    }
  }
}

}  // namespace mpeg4face
