// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/arkit/capture.hpp"

#include <Eigen/Cholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "arkit/arkit_internal.hpp"
#include "mpeg4face/arkit/shapes.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/model/surface_bump.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// How much the capture's fit weighs the Laplacian of the motion against the motion: a
// vertex's Laplacian is a few percent of a smooth motion, so at 1000 the two terms weigh
// alike on a smooth face and a spike costs a thousand times its error. Chosen by
// measurement on the ICT head and the Live Link capture (docs/arkit.md, "Smooth keys").
constexpr double kSurfaceWeight = 1000;

// The umbrella Laplacian over the face area: each area vertex's motion minus the mean of
// its one-ring's (vertices outside the area do not move). Applied to columns of 3 rows per
// area vertex.
class AreaLaplacian {
 public:
  AreaLaplacian(const FaceModel& head, const std::vector<std::pair<int, int>>& area,
                const std::vector<std::vector<int>>& areaRow) {
    std::vector<Eigen::Triplet<double>> entries;
    std::map<int, WeldedRings> rings;
    std::map<int, std::vector<int>> vertexOf;  // per welded vertex: one of its copies
    for (std::size_t r = 0; r < area.size(); ++r) {
      const auto [mesh, vertex] = area[r];
      auto [it, made] = rings.try_emplace(mesh);
      std::vector<int>& copy = vertexOf[mesh];
      if (made) {
        it->second = weldedRings(head.meshes[static_cast<std::size_t>(mesh)]);
        copy.resize(it->second.copies.size());
        for (std::size_t v = it->second.weld.size(); v-- > 0;)
          copy[static_cast<std::size_t>(it->second.weld[v])] = static_cast<int>(v);
      }
      const WeldedRings& ring = it->second;
      const auto w = static_cast<std::size_t>(ring.weld[static_cast<std::size_t>(vertex)]);
      const int begin = ring.offset[w], end = ring.offset[w + 1];
      if (begin == end) continue;
      const auto row = static_cast<int>(r);
      entries.emplace_back(row, row, 1.0);
      for (int j = begin; j < end; ++j) {
        const auto ringVertex =
            static_cast<std::size_t>(ring.neighbour[static_cast<std::size_t>(j)]);
        const auto neighbour = static_cast<std::size_t>(copy[ringVertex]);
        const int column = areaRow[static_cast<std::size_t>(mesh)][neighbour];
        if (column >= 0) entries.emplace_back(row, column, -1.0 / (end - begin));
      }
    }
    const auto n = static_cast<Eigen::Index>(area.size());
    operator_.resize(n, n);
    operator_.setFromTriplets(entries.begin(), entries.end());
  }
  Eigen::MatrixXd apply(const Eigen::MatrixXd& columns) const {
    Eigen::MatrixXd out(columns.rows(), columns.cols());
    for (Eigen::Index c = 0; c < columns.cols(); ++c) {
      const auto xyz = columns.col(c).reshaped<Eigen::RowMajor>(operator_.rows(), 3);
      out.col(c).reshaped<Eigen::RowMajor>(operator_.rows(), 3) = operator_ * xyz;
    }
    return out;
  }

 private:
  Eigen::SparseMatrix<double, Eigen::RowMajor> operator_;
};

// FAPs a capture's angles give, never fitted to the face area's motion.
bool isAngleFap(int fap) { return (fap >= 23 && fap <= 26) || (fap >= 48 && fap <= 50); }

// The Live Link weight channel (0..51) a morph target shows, or nullopt (ICT's extra shapes
// too); halves of a shape (ICT's browInnerUp_L) add up to it.
std::optional<int> arkitChannel(std::string_view targetName) {
  const std::optional<ArkitShapeRef> ref = arkitShapeIndex(targetName);
  if (!ref || ref->shape >= kArkitShapeCount) return std::nullopt;
  return ref->shape;
}

// Meshes some FaceDefTransform moves (held by an animated Transform or one below it).
std::vector<bool> meshesUnderAnimatedTransforms(const MpegFace& face) {
  const FaceModel& model = face.faceSceneGraph;
  std::vector<bool> animated(model.transforms.size(), false), meshes(model.meshes.size(), false);
  std::vector<int> stack;
  for (const FaceDefTables& t : face.faceDefTables) {
    for (const FaceDefTransform& d : t.faceDefTransform) stack.push_back(d.transform);
  }
  while (!stack.empty()) {
    const int t = stack.back();
    stack.pop_back();
    if (t < 0 || static_cast<std::size_t>(t) >= animated.size() ||
        animated[static_cast<std::size_t>(t)])
      continue;
    animated[static_cast<std::size_t>(t)] = true;
    const Transform& node = model.transforms[static_cast<std::size_t>(t)];
    for (int m : node.meshes) meshes[static_cast<std::size_t>(m)] = true;
    for (int c : node.children) stack.push_back(c);
  }
  return meshes;
}

double largestBorder(const FaceDefTables& table) {
  double a = 0;
  for (const FaceDefMesh& m : table.faceDefMesh) {
    for (int b : m.intervalBorders) a = std::max(a, std::abs(static_cast<double>(b)));
  }
  return a;
}

// How far one side of a table (sign +1 / -1) keeps the motion of its first interval there:
// the border where an interval's displacements first differ, +inf when none does (the
// outermost interval continues). A table held past its key (arkit/keys.cpp) reaches no
// further than the copy where it goes flat.
double linearReach(const FaceDefTables& table, int sign) {
  double reach = kInfinity;
  for (const FaceDefMesh& m : table.faceDefMesh) {
    const int n = m.intervalCount();
    std::vector<int> outward;  // this side's intervals, from 0 out
    for (int k = 0; k < n; ++k) {
      const auto s = static_cast<std::size_t>(k);
      if (sign > 0 ? m.intervalBorders[s] >= 0 : m.intervalBorders[s + 1] <= 0) {
        outward.push_back(k);
      }
    }
    if (sign < 0) std::reverse(outward.begin(), outward.end());
    const auto rows = [&](int k) {
      Points3 d(static_cast<Eigen::Index>(m.coordIndex.size()), 3);
      for (Eigen::Index i = 0; i < d.rows(); ++i) d.row(i) = m.displacements.row(i * n + k);
      return d;
    };
    if (outward.size() < 2) continue;
    const Points3 first = rows(outward[0]);
    for (std::size_t j = 1; j < outward.size(); ++j) {
      if ((rows(outward[j]) - first).norm() <= 1e-3 * first.norm()) continue;
      const auto inner = static_cast<std::size_t>(outward[j] + (sign > 0 ? 0 : 1));
      reach = std::min(reach, std::abs(static_cast<double>(m.intervalBorders[inner])));
      break;
    }
  }
  return reach;
}

// The capture's angle channels as FAP values (AU), and back; docs/arkit.md, "Captures".
struct AngleFap {
  int fap;
  int channel;
  double sign;  // FAP = sign * channel / AU
};
constexpr std::array<AngleFap, 7> kAngleFaps{{{23, kLeftEyeYaw, -1},
                                              {24, kRightEyeYaw, -1},
                                              {25, kLeftEyePitch, 1},
                                              {26, kRightEyePitch, 1},
                                              {48, kHeadPitch, 1},
                                              {49, kHeadYaw, -1},
                                              {50, kHeadRoll, 1}}};

// The Live Link weight channel of JawOpen.
int jawOpenChannel() {
  const auto names = liveLinkChannelNames();
  return static_cast<int>(std::find(names.begin(), names.end(), "JawOpen") - names.begin());
}

int roundedFap(double value) {
  return static_cast<int>(std::clamp(std::round(value), -1.0e8, 1.0e8));
}

}  // namespace

void boundedLeastSquares(const Eigen::MatrixXd& G, const Eigen::VectorXd& b,
                         const Eigen::VectorXd& lower, const Eigen::VectorXd& upper,
                         Eigen::VectorXd& x, const std::vector<bool>& locked) {
  const Eigen::Index n = b.size();
  enum class State { Free, AtLower, AtUpper, Locked };
  thread_local std::vector<State> state;
  state.assign(static_cast<std::size_t>(n), State::Free);
  if (x.size() != n) x = lower;
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto s = static_cast<std::size_t>(i);
    x[i] = std::clamp(x[i], lower[i], upper[i]);
    if (!locked.empty() && locked[s]) {
      x[i] = lower[i];
      state[s] = State::Locked;
    } else if (x[i] <= lower[i]) {
      state[s] = State::AtLower;
    } else if (x[i] >= upper[i]) {
      state[s] = State::AtUpper;
    } else {
      state[s] = State::Free;
    }
  }
  const double tolerance = 1e-10 * std::max(1.0, b.cwiseAbs().maxCoeff());
  // Working memory kept between calls: a solve per captured frame allocates nothing.
  thread_local std::vector<Eigen::Index> free;
  thread_local Eigen::MatrixXd subGram;
  thread_local Eigen::VectorXd rhs, z;
  thread_local Eigen::LLT<Eigen::MatrixXd> cholesky;
  for (Eigen::Index iteration = 0; iteration < 4 * n + 20; ++iteration) {
    free.clear();
    for (Eigen::Index i = 0; i < n; ++i) {
      if (state[static_cast<std::size_t>(i)] == State::Free) free.push_back(i);
    }
    if (!free.empty()) {
      const auto f = static_cast<Eigen::Index>(free.size());
      subGram.resize(f, f);
      rhs.resize(f);
      for (Eigen::Index r = 0; r < f; ++r) {
        const Eigen::Index i = free[static_cast<std::size_t>(r)];
        // b_F - G_FB x_B: the bound variables' pull on the free ones.
        rhs[r] = b[i];
        for (Eigen::Index j = 0; j < n; ++j) {
          if (state[static_cast<std::size_t>(j)] != State::Free && x[j] != 0)
            rhs[r] -= G(i, j) * x[j];
        }
        for (Eigen::Index c = 0; c < f; ++c)
          subGram(r, c) = G(i, free[static_cast<std::size_t>(c)]);
      }
      cholesky.compute(subGram);
      z = cholesky.solve(rhs);
      double alpha = 1;
      for (Eigen::Index r = 0; r < f; ++r) {
        const Eigen::Index i = free[static_cast<std::size_t>(r)];
        if (z[r] < lower[i]) alpha = std::min(alpha, (x[i] - lower[i]) / (x[i] - z[r]));
        if (z[r] > upper[i]) alpha = std::min(alpha, (upper[i] - x[i]) / (z[r] - x[i]));
      }
      if (alpha < 1) {
        // Step towards the free optimum until a variable reaches its bound; it leaves the set.
        for (Eigen::Index r = 0; r < f; ++r) {
          const Eigen::Index i = free[static_cast<std::size_t>(r)];
          const auto s = static_cast<std::size_t>(i);
          x[i] += alpha * (z[r] - x[i]);
          const double span = 1e-12 * std::max(1.0, std::abs(x[i]));
          if (x[i] <= lower[i] + span) {
            x[i] = lower[i];
            state[s] = State::AtLower;
          } else if (x[i] >= upper[i] - span) {
            x[i] = upper[i];
            state[s] = State::AtUpper;
          }
        }
        continue;
      }
      for (Eigen::Index r = 0; r < f; ++r) x[free[static_cast<std::size_t>(r)]] = z[r];
    }
    // Kuhn-Tucker: a bound variable whose gradient points into the box is freed.
    Eigen::Index best = -1;
    double bestPull = tolerance;
    for (Eigen::Index i = 0; i < n; ++i) {
      const State s = state[static_cast<std::size_t>(i)];
      if (s != State::AtLower && s != State::AtUpper) continue;
      const double pull = (b[i] - G.row(i).dot(x)) * (s == State::AtLower ? 1 : -1);
      if (pull > bestPull) {
        bestPull = pull;
        best = i;
      }
    }
    if (best < 0) return;
    state[static_cast<std::size_t>(best)] = State::Free;
  }
}

ArkitCaptureFace prepareArkitCaptureFace(const FaceModel& head) {
  head.validate();
  ArkitCaptureFace out;
  const ShapeKeyFace keyed = faceFromShapeKeys(head);
  out.face = keyed.face;
  out.fapu = measureFapu(out.face.faceSceneGraph);
  const std::vector<bool> moving = meshesUnderAnimatedTransforms(out.face);
  const std::vector<Eigen::Affine3d> world = head.meshWorldMatrices();

  // Which vertices are in the face area: those the ARKit shapes or the tables move.
  out.hasShape.assign(kLiveLinkWeightCount, false);
  std::vector<std::vector<int>> areaRow(head.meshes.size());  // per vertex, -1 or its row
  for (std::size_t m = 0; m < head.meshes.size(); ++m) {
    areaRow[m].assign(static_cast<std::size_t>(head.meshes[m].vertexCount()), -1);
  }
  const auto addVertex = [&](int mesh, int vertex) {
    int& row = areaRow[static_cast<std::size_t>(mesh)][static_cast<std::size_t>(vertex)];
    if (row < 0) {
      row = static_cast<int>(out.area.size());
      out.area.emplace_back(mesh, vertex);
    }
  };
  for (std::size_t m = 0; m < head.meshes.size(); ++m) {
    if (moving[m]) continue;
    for (const MorphTarget& t : head.meshes[m].morphTargets) {
      const std::optional<int> k = arkitChannel(t.name);
      if (!k) continue;
      out.hasShape[static_cast<std::size_t>(*k)] = true;
      for (Eigen::Index v = 0; v < t.displacements.rows(); ++v) {
        if (t.displacements.row(v).squaredNorm() > 0)
          addVertex(static_cast<int>(m), static_cast<int>(v));
      }
    }
  }
  std::string missing, looked;
  int found = 0;
  for (int k = 0; k < kLiveLinkWeightCount; ++k) {
    const std::string_view name = liveLinkChannelNames()[static_cast<std::size_t>(k)];
    looked += (looked.empty() ? "" : ", ") + std::string(name);
    if (out.hasShape[static_cast<std::size_t>(k)]) {
      ++found;
    } else {
      missing += (missing.empty() ? "" : ", ") + std::string(name);
    }
  }
  if (found == 0) {
    throw Error({}, 0, "morph targets",
                "the face has no ARKit blendshape (on a mesh no Transform animates); looked for "
                "morph targets named as ARKit's (eyeBlinkLeft, EyeBlinkLeft, eyeBlink_L, "
                "blendShape1.eyeBlinkLeft, eye_blink_left): " +
                    looked);
  }
  if (!missing.empty()) {
    out.warnings.push_back("the face lacks " + std::to_string(kLiveLinkWeightCount - found) +
                           " of the 52 ARKit shapes; their weights are skipped: " + missing);
  }

  // The FAP tables that fit: low-level, not the angle FAPs, moving some area mesh.
  std::vector<const FaceDefTables*> tables, angleTables;
  for (const FaceDefTables& t : out.face.faceDefTables) {
    if (t.fapID < 3 || largestBorder(t) <= 0) continue;
    bool movesArea = false;
    for (const FaceDefMesh& d : t.faceDefMesh) {
      if (moving[static_cast<std::size_t>(d.mesh)]) continue;
      movesArea = true;
      for (int v : d.coordIndex) addVertex(d.mesh, v);
    }
    if (movesArea) (isAngleFap(t.fapID) ? angleTables : tables).push_back(&t);
  }
  out.fromTables = !tables.empty();
  // Without tables each FAP moves its own feature point (a vertex of the area meshes).
  struct DefinitionColumn {
    int fap, row;
    Eigen::Vector3d motion;
  };
  std::vector<DefinitionColumn> definition;
  if (!out.fromTables) {
    for (const FapInfo& info : fapTable()) {
      if (info.number < 3 || isAngleFap(info.number)) continue;
      const Eigen::Vector3d direction =
          arkit::fapDirection(info.positiveMotion).value_or(Eigen::Vector3d::Zero());
      const double unit = out.fapu.unit(info.fapu);
      const auto binding = head.featurePoints.find(std::string(info.featurePoint));
      if (direction.isZero() || unit <= 0 || binding == head.featurePoints.end() ||
          binding->second.mesh < 0 || moving[static_cast<std::size_t>(binding->second.mesh)]) {
        continue;
      }
      addVertex(binding->second.mesh, binding->second.vertex);
      definition.push_back({info.number,
                            areaRow[static_cast<std::size_t>(binding->second.mesh)]
                                   [static_cast<std::size_t>(binding->second.vertex)],
                            direction * unit});
    }
    if (definition.empty()) {
      throw Error({}, 0, "feature points",
                  "the face has neither FAP keys (fap<N>@<value> morph targets) nor feature "
                  "points on its meshes with their FAPU measured, so no FAP can be fitted");
    }
  }

  const auto rows = static_cast<Eigen::Index>(3 * out.area.size());
  Eigen::MatrixXd angleMotion(rows, 0);  // the angle FAPs' mesh motion (eyelids riding along)
  out.shapeMotion = Eigen::MatrixXd::Zero(rows, kLiveLinkWeightCount);
  for (std::size_t m = 0; m < head.meshes.size(); ++m) {
    if (moving[m]) continue;
    const Eigen::Matrix3d linear = world[m].linear();
    for (const MorphTarget& t : head.meshes[m].morphTargets) {
      const std::optional<int> k = arkitChannel(t.name);
      if (!k) continue;
      for (Eigen::Index v = 0; v < t.displacements.rows(); ++v) {
        const int row = areaRow[m][static_cast<std::size_t>(v)];
        if (row >= 0) {
          out.shapeMotion.block<3, 1>(3 * row, *k) += linear * t.displacements.row(v).transpose();
        }
      }
    }
  }

  if (out.fromTables) {
    const FatEvaluator evaluator(out.face, out.fapu);
    const FatState neutralState = evaluator.neutralState();
    FatState state = evaluator.neutralState();
    const auto areaMotion = [&](int fap, int value) {
      FapFrame frame;
      frame.set(fap, value);
      evaluator.evaluate(frame, state);
      Eigen::VectorXd column = Eigen::VectorXd::Zero(rows);
      for (std::size_t r = 0; r < out.area.size(); ++r) {
        const auto [mesh, vertex] = out.area[r];
        const auto ms = static_cast<std::size_t>(mesh);
        column.segment<3>(3 * static_cast<Eigen::Index>(r)) =
            world[ms].linear() *
            (state.coord[ms].row(vertex) - neutralState.coord[ms].row(vertex)).transpose();
      }
      return column;
    };
    // Each table's motion of the area per unit on each side, at its innermost border there
    // (a key), and how far that motion stays linear: a table held flat past its key
    // (arkit/keys.cpp, kKeyReach) reaches no further, one whose outermost interval continues
    // is linear without end. A side without borders of its own is the one interval's
    // signed continuation (rule 6).
    const auto columnsOf = [&](const std::vector<const FaceDefTables*>& list,
                               std::vector<int>& faps, std::vector<int>& signs,
                               std::vector<double>& reach) {
      std::vector<Eigen::VectorXd> columns;
      for (const FaceDefTables* t : list) {
        for (int sign : {1, -1}) {
          if (sign < 0 && !fapInfo(t->fapID).bidirectional) continue;
          std::set<int> side;  // |border| on this side
          for (const FaceDefMesh& m : t->faceDefMesh) {
            for (int b : m.intervalBorders) {
              if (b * sign > 0) side.insert(std::abs(b));
            }
          }
          const int amplitude = side.empty() ? static_cast<int>(largestBorder(*t)) : *side.begin();
          Eigen::VectorXd column = areaMotion(t->fapID, sign * amplitude) / amplitude;
          if (column.cwiseAbs().maxCoeff() <= 0) continue;
          const double linear = linearReach(*t, sign);
          columns.push_back(std::move(column));
          faps.push_back(t->fapID);
          signs.push_back(sign);
          reach.push_back(linear);
        }
      }
      Eigen::MatrixXd motion(rows, static_cast<Eigen::Index>(columns.size()));
      for (std::size_t c = 0; c < columns.size(); ++c) {
        motion.col(static_cast<Eigen::Index>(c)) = columns[c];
      }
      return motion;
    };
    out.fapMotion = columnsOf(tables, out.columnFap, out.columnSign, out.columnReach);
    std::vector<double> angleReach;  // the angle FAPs are not solved for
    angleMotion = columnsOf(angleTables, out.angleColumnFap, out.angleColumnSign, angleReach);
  } else {
    std::size_t count = 0;
    for (const DefinitionColumn& d : definition) count += fapInfo(d.fap).bidirectional ? 2 : 1;
    out.fapMotion = Eigen::MatrixXd::Zero(rows, static_cast<Eigen::Index>(count));
    Eigen::Index c = 0;
    for (const DefinitionColumn& d : definition) {
      for (int sign : {1, -1}) {
        if (sign < 0 && !fapInfo(d.fap).bidirectional) continue;
        out.fapMotion.block<3, 1>(3 * d.row, c++) = sign * d.motion;
        out.columnFap.push_back(d.fap);
        out.columnSign.push_back(sign);
        out.columnReach.push_back(kInfinity);
      }
    }
  }
  if (out.fapMotion.cols() == 0) {
    throw Error({}, 0, "FAP keys", "none of the face's FAP tables moves its face area");
  }

  const int jaw = jawOpenChannel();
  for (std::size_t c = 0; c < out.columnFap.size(); ++c) {
    const auto col = static_cast<Eigen::Index>(c);
    if (out.columnFap[c] != 3 || out.columnSign[c] < 0 ||
        !out.hasShape[static_cast<std::size_t>(jaw)])
      continue;
    out.jawColumn = static_cast<int>(c);
    out.jawPerWeight = std::max(0.0, out.fapMotion.col(col).dot(out.shapeMotion.col(jaw)) /
                                         out.fapMotion.col(col).squaredNorm());
  }
  // The fit weighs the motion and, kSurfaceWeight times, its umbrella Laplacian (each
  // vertex against its one-ring): a combination of keys that matches the motion on the
  // whole but leaves single vertices out of the surface (a feature point's vertex pushed
  // where its neighbours are not) costs what it looks like. A small ridge keeps the normal
  // equations definite and, where a FAP's two sides mirror each other, prefers one side to
  // both.
  // Without tables each FAP moves its feature point alone: there is no surface to keep.
  out.fapGram = out.fapMotion.transpose() * out.fapMotion;
  out.fapRhs = out.fapMotion.transpose() * out.shapeMotion;
  out.angleRhs = out.fapMotion.transpose() * angleMotion;
  if (out.fromTables) {
    const AreaLaplacian laplacian(head, out.area, areaRow);
    const Eigen::MatrixXd fapBend = kSurfaceWeight * laplacian.apply(out.fapMotion);
    out.fapGram += fapBend.transpose() * laplacian.apply(out.fapMotion);
    out.fapRhs += fapBend.transpose() * laplacian.apply(out.shapeMotion);
    out.angleRhs += fapBend.transpose() * laplacian.apply(angleMotion);
  }
  out.fapGram.diagonal().array() += 1e-6 * out.fapGram.diagonal().mean();
  // FAP -> ARKit compares motion where the FAPs have any: everywhere with tables, at the
  // feature points without.
  Eigen::MatrixXd compared = out.shapeMotion;
  if (!out.fromTables) {
    for (Eigen::Index r = 0; r < rows; ++r) {
      if (out.fapMotion.row(r).isZero()) compared.row(r).setZero();
    }
  }
  out.shapeGram = compared.transpose() * compared;
  out.shapeGram.diagonal().array() += 1e-6 * out.shapeGram.diagonal().mean();
  return out;
}

Eigen::VectorXd captureWeightsAt(const LiveLinkCapture& capture, double time) {
  const auto after = std::upper_bound(capture.times.begin(), capture.times.end(), time);
  const int next = std::min(static_cast<int>(after - capture.times.begin()), capture.frameCount() - 1);
  const int source = std::max(next - 1, 0);
  const double t0 = capture.times[static_cast<std::size_t>(source)];
  const double t1 = capture.times[static_cast<std::size_t>(next)];
  const double blend = t1 > t0 ? std::clamp((time - t0) / (t1 - t0), 0.0, 1.0) : 0.0;
  return (1 - blend) * capture.values.row(source).transpose() +
         blend * capture.values.row(next).transpose();
}

FapStream arkitCaptureToFaps(const LiveLinkCapture& capture, const ArkitCaptureFace& face,
                             const CaptureOptions& options) {
  if (capture.frameCount() == 0) throw Error({}, 0, "capture", "the capture has no frames");
  if (!(options.fps > 0) || !std::isfinite(options.fps)) {
    throw Error({}, 0, "fps", "the frame rate must be a positive number");
  }
  if (capture.values.cols() != kLiveLinkChannelCount ||
      capture.values.rows() != capture.frameCount()) {
    throw Error({}, 0, "capture", "values must be frames x 61, one row per time");
  }
  FapStream stream;
  stream.frameRate = options.fps;
  const double start = capture.times.front();
  const double span = capture.times.back() - start;
  const int frames = static_cast<int>(std::floor(span * options.fps + 1e-6)) + 1;
  stream.frames.resize(static_cast<std::size_t>(frames));

  const auto columns = face.fapMotion.cols();
  const Eigen::VectorXd lower = Eigen::VectorXd::Zero(columns);
  const Eigen::VectorXd upper = Eigen::Map<const Eigen::VectorXd>(face.columnReach.data(), columns);
  Eigen::VectorXd x = lower, b;
  Eigen::VectorXd weights;
  std::vector<bool> locked(static_cast<std::size_t>(columns));
  const int jawChannel = jawOpenChannel();
  for (int f = 0; f < frames; ++f) {
    weights = captureWeightsAt(capture, start + f / options.fps);

    // The angle FAPs first: what their tables move on the face area (lids following the
    // eyes) is not asked of the others.
    std::array<int, kFapCount> angleValue{};
    for (const AngleFap& a : kAngleFaps) {
      angleValue[static_cast<std::size_t>(a.fap - 1)] =
          roundedFap(a.sign * weights[a.channel] / kAngleUnitRadians);
    }
    b = face.fapRhs * weights.head(kLiveLinkWeightCount);
    for (std::size_t c = 0; c < face.angleColumnFap.size(); ++c) {
      const double v = face.angleColumnSign[c] *
                       angleValue[static_cast<std::size_t>(face.angleColumnFap[c] - 1)];
      if (v > 0) b -= v * face.angleRhs.col(static_cast<Eigen::Index>(c));
    }
    std::fill(locked.begin(), locked.end(), false);
    const double jaw = face.jawPerWeight * weights[jawChannel];
    if (face.jawColumn >= 0) {
      b -= jaw * face.fapGram.col(face.jawColumn);
      locked[static_cast<std::size_t>(face.jawColumn)] = true;
    }
    boundedLeastSquares(face.fapGram, b, lower, upper, x, locked);
    // One side per FAP: where both sides came out positive the weaker is held at 0 (all
    // such FAPs at once), and the rest solved again.
    for (bool again = true; again;) {
      again = false;
      for (Eigen::Index c = 0; c + 1 < columns; ++c) {
        const auto cs = static_cast<std::size_t>(c);
        if (face.columnFap[cs] != face.columnFap[cs + 1] || x[c] <= 0 || x[c + 1] <= 0) continue;
        locked[x[c] < x[c + 1] ? cs : cs + 1] = true;
        again = true;
      }
      if (again) boundedLeastSquares(face.fapGram, b, lower, upper, x, locked);
    }

    if (face.jawColumn >= 0) x[face.jawColumn] = jaw;

    FapFrame& frame = stream.frames[static_cast<std::size_t>(f)];
    frame.number = f;
    std::array<double, kFapCount> value{};
    for (Eigen::Index c = 0; c < columns; ++c) {
      const auto cs = static_cast<std::size_t>(c);
      value[static_cast<std::size_t>(face.columnFap[cs] - 1)] += face.columnSign[cs] * x[c];
    }
    for (Eigen::Index c = 0; c < columns; ++c) {
      const int fap = face.columnFap[static_cast<std::size_t>(c)];
      frame.set(fap, roundedFap(value[static_cast<std::size_t>(fap - 1)]));
    }
    for (const AngleFap& a : kAngleFaps)
      frame.set(a.fap, angleValue[static_cast<std::size_t>(a.fap - 1)]);
    if (options.progress && (f % 256 == 255 || f + 1 == frames)) options.progress(f + 1, frames);
  }
  return stream;
}

FapStream arkitCaptureToFaps(const LiveLinkCapture& capture, const FaceModel& arkitHead,
                             const CaptureOptions& options) {
  return arkitCaptureToFaps(capture, prepareArkitCaptureFace(arkitHead), options);
}

LiveLinkCapture fapsToArkit(const FapStream& stream, const ArkitCaptureFace& face,
                            const std::function<void(int, int)>& progress) {
  LiveLinkCapture capture;
  capture.channels.assign(liveLinkChannelNames().begin(), liveLinkChannelNames().end());
  capture.frameRate = stream.frameRate;
  const auto frames = static_cast<Eigen::Index>(stream.frames.size());
  capture.values = Eigen::MatrixXd::Zero(frames, kLiveLinkChannelCount);
  capture.times.reserve(stream.frames.size());

  std::optional<FatEvaluator> evaluator;
  FatState neutral, state;
  std::vector<Eigen::Matrix3d> linear;
  if (face.fromTables) {
    evaluator.emplace(face.face, face.fapu);
    neutral = evaluator->neutralState();
    state = evaluator->neutralState();
    for (const Eigen::Affine3d& w : face.face.faceSceneGraph.meshWorldMatrices()) {
      linear.push_back(w.linear());
    }
  }
  std::vector<bool> locked(kLiveLinkWeightCount);
  for (int k = 0; k < kLiveLinkWeightCount; ++k) {
    locked[static_cast<std::size_t>(k)] = !face.hasShape[static_cast<std::size_t>(k)];
  }
  const Eigen::VectorXd lower = Eigen::VectorXd::Zero(kLiveLinkWeightCount);
  const Eigen::VectorXd upper = Eigen::VectorXd::Ones(kLiveLinkWeightCount);
  Eigen::VectorXd weights = lower;
  Eigen::VectorXd motion(face.shapeMotion.rows());
  FapState resolved;
  for (Eigen::Index f = 0; f < frames; ++f) {
    const FapFrame& sent = stream.frames[static_cast<std::size_t>(f)];
    applyFrame(resolved, sent);
    const FapFrame& frame = resolved;
    capture.times.push_back(std::max(0.0, frameTime(stream, sent)));
    if (evaluator) {
      evaluator->evaluate(frame, state);
      for (std::size_t r = 0; r < face.area.size(); ++r) {
        const auto [mesh, vertex] = face.area[r];
        const auto ms = static_cast<std::size_t>(mesh);
        motion.segment<3>(3 * static_cast<Eigen::Index>(r)) =
            linear[ms] * (state.coord[ms].row(vertex) - neutral.coord[ms].row(vertex)).transpose();
      }
    } else {
      motion.setZero();
      for (Eigen::Index c = 0; c < face.fapMotion.cols(); ++c) {
        const auto cs = static_cast<std::size_t>(c);
        const int fap = face.columnFap[cs];
        const double v = frame.has(fap) ? frame.value(fap) : 0;
        if (v * face.columnSign[cs] > 0) motion += std::abs(v) * face.fapMotion.col(c);
      }
    }
    boundedLeastSquares(face.shapeGram, face.shapeMotion.transpose() * motion, lower, upper,
                        weights, locked);
    capture.values.row(f).head(kLiveLinkWeightCount) = weights.transpose();
    for (const AngleFap& a : kAngleFaps) {
      const double v = frame.has(a.fap) ? frame.value(a.fap) : 0;
      capture.values(f, a.channel) = a.sign * v * kAngleUnitRadians;
    }
    if (progress && (f % 64 == 63 || f + 1 == frames)) {
      progress(static_cast<int>(f + 1), static_cast<int>(frames));
    }
  }
  return capture;
}

LiveLinkCapture fapsToArkit(const FapStream& stream, const FaceModel& arkitHead,
                            const std::function<void(int, int)>& progress) {
  return fapsToArkit(stream, prepareArkitCaptureFace(arkitHead), progress);
}

}  // namespace mpeg4face
