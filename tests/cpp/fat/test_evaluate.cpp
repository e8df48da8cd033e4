// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>

#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "test_support.hpp"

using namespace mpeg4face;
using mpeg4face::test::errorOf;

namespace {

// Displacements are stored as float: results agree with double arithmetic to ~1e-7.
constexpr double kFloat = 1e-6;

bool contains(const Error& e, const std::string& text) {
  return std::string(e.what()).find(text) != std::string::npos;
}

IndexedFaceSet gridMesh(const std::string& name, int vertices) {
  IndexedFaceSet mesh;
  mesh.name = name;
  mesh.coord.resize(vertices, 3);
  for (int v = 0; v < vertices; ++v) mesh.coord.row(v) << v, 2.0 * v, -0.5 * v;
  for (int v = 0; v + 2 < vertices; v += 3)
    mesh.coordIndex.insert(mesh.coordIndex.end(), {v, v + 1, v + 2, -1});
  return mesh;
}

// FAPU with every linear unit = `unit` model units.
FapuMeasurement uniformFapu(double unit = 1.0) {
  FapuMeasurement f;
  for (FapuDistance* d : {&f.ES0, &f.IRISD0, &f.ENS0, &f.MNS0, &f.MW0}) {
    *d = {true, unit * kFapuDivisor, {}, "given"};
  }
  return f;
}

// Tekalp-Ostermann Table 5: FAP 6 on IndexedFaceSet "Face" (vertices 50 and 51) and FAP 23
// on Transform "LeftEyeX".
MpegFace paperFace() {
  MpegFace face;
  face.faceSceneGraph.addMeshWithTransform(gridMesh("Face", 60));
  Transform eye;
  eye.name = "LeftEyeX";
  eye.translation = {3, 4, 5};
  face.faceSceneGraph.roots.push_back(1);
  face.faceSceneGraph.transforms.push_back(eye);
  FaceDefTables fap6;
  fap6.fapID = 6;
  FaceDefMesh m;
  m.mesh = 0;
  m.intervalBorders = {-1000, 0, 500, 1000};
  m.coordIndex = {50, 51};
  m.displacements.resize(6, 3);
  m.displacements << 1, 0, 0, 0.9, 0, 0, 1.5, 0, 4,  //
      0.8, 0, 0, 0.7, 0, 0, 2, 0, 0;
  fap6.faceDefMesh.push_back(m);
  FaceDefTables fap23;
  fap23.fapID = 23;
  FaceDefTransform t;
  t.transform = 1;
  t.rotationDef = {0, -1, 0, 1};
  fap23.faceDefTransform.push_back(t);
  face.faceDefTables = {fap6, fap23};
  return face;
}

FapFrame frameWith(std::initializer_list<std::pair<int, int>> faps) {
  FapFrame f;
  for (auto [fap, value] : faps) f.set(fap, value);
  return f;
}

Eigen::RowVector3d moved(const FatState& s, const MpegFace& face, int mesh, int v) {
  return s.coord[mesh].row(v) - face.faceSceneGraph.meshes[mesh].coord.row(v);
}

void expectNear(const Eigen::RowVector3d& a, const Eigen::RowVector3d& b, double tol) {
  EXPECT_LE((a - b).norm(), tol) << "got " << a << ", expected " << b;
}

}  // namespace

TEST(FatEvaluate, PaperWorkedExample) {
  const MpegFace face = paperFace();
  const FatEvaluator eval(face, uniformFapu());  // FAPU = 1
  FatState s = eval.evaluate(frameWith({{6, 600}}));
  expectNear(moved(s, face, 0, 50), {600, 0, 400}, 600 * kFloat);
  expectNear(moved(s, face, 0, 51), {500 * 0.7 + 100 * 2, 0, 0}, 600 * kFloat);
  EXPECT_EQ(moved(s, face, 0, 49).norm(), 0.0);
  // The negative side multiplies by positive lengths: -500 -> (0 - -500) * (1, 0, 0).
  eval.evaluate(frameWith({{6, -500}}), s);
  expectNear(moved(s, face, 0, 50), {500, 0, 0}, 500 * kFloat);
  expectNear(moved(s, face, 0, 51), {400, 0, 0}, 500 * kFloat);
}

TEST(FatEvaluate, BeyondTheOutermostBordersTheOutermostIntervalContinues) {
  const MpegFace face = paperFace();
  const FatEvaluator eval(face, uniformFapu());
  FatState s = eval.evaluate(frameWith({{6, 1500}}));
  expectNear(moved(s, face, 0, 50), {500 * 0.9 + 1000 * 1.5, 0, 1000 * 4}, 4000 * kFloat);
  eval.evaluate(frameWith({{6, -1300}}), s);
  expectNear(moved(s, face, 0, 50), {1300, 0, 0}, 1300 * kFloat);
  eval.evaluate(frameWith({{6, 1000}}), s);  // exactly on the last border
  expectNear(moved(s, face, 0, 50), {450 + 750, 0, 2000}, 2000 * kFloat);
}

TEST(FatEvaluate, OneIntervalIsLinearAndSigned) {
  MpegFace face = paperFace();
  FaceDefMesh& m = face.faceDefTables[0].faceDefMesh[0];
  m.intervalBorders = {0, 1000};
  m.displacements.resize(2, 3);
  m.displacements << 1, 2, 3, -1, 0, 0.5;
  const FatEvaluator eval(face, uniformFapu(0.5));
  FatState s = eval.evaluate(frameWith({{6, -250}}));
  expectNear(moved(s, face, 0, 50), -250 * 0.5 * Eigen::RowVector3d(1, 2, 3), 1e-4);
  expectNear(moved(s, face, 0, 51), -250 * 0.5 * Eigen::RowVector3d(-1, 0, 0.5), 1e-4);
  eval.evaluate(frameWith({{6, 3000}}), s);  // far beyond 1000: still linear
  expectNear(moved(s, face, 0, 50), 3000 * 0.5 * Eigen::RowVector3d(1, 2, 3), 1e-2);
}

TEST(FatEvaluate, DisplacementsScaleByTheFapsFapu) {
  MpegFace face = paperFace();
  face.faceDefTables[0].fapID = 3;  // open_jaw: MNS
  FapuMeasurement fapu = uniformFapu();
  fapu.MNS0.value = 3 * kFapuDivisor;
  const FatEvaluator eval(face, fapu);
  const FatState s = eval.evaluate(frameWith({{3, 600}}));
  expectNear(moved(s, face, 0, 50), {1800, 0, 1200}, 2000 * kFloat);
}

TEST(FatEvaluate, RotationIsInAngleUnits) {
  const MpegFace face = paperFace();
  const FatEvaluator eval(face, uniformFapu());
  const FatState s = eval.evaluate(frameWith({{23, 20000}}));
  const Transform& eye = s.transforms[1];
  const Eigen::AngleAxisd turn(eye.rotation);
  EXPECT_NEAR(turn.angle(), 20000 * 1e-5, 1e-12);
  EXPECT_TRUE(turn.axis().isApprox(Eigen::Vector3d(0, -1, 0)));
  EXPECT_EQ(eye.translation, Eigen::Vector3d(3, 4, 5));
  EXPECT_EQ(moved(s, face, 0, 50).norm(), 0.0);  // FAP 6 not in the frame
}

TEST(FatEvaluate, TransformsFollowIncreasingFapOrderFromTheNeutralState) {
  MpegFace face = paperFace();
  face.faceSceneGraph.transforms[1].rotation = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
  FaceDefTables pitch;  // FAP 48 head_pitch about x, listed before FAP 23
  pitch.fapID = 48;
  FaceDefTransform x;
  x.transform = 1;
  x.rotationDef = {1, 0, 0, 2};
  FaceDefTransform move;
  move.transform = 1;
  move.fieldId = FaceDefTransform::Field::Translation;
  move.translationDef = {0, 0, 1e-4};
  FaceDefTransform grow;
  grow.transform = 1;
  grow.fieldId = FaceDefTransform::Field::Scale;
  grow.scaleDef = {1e-5, 0, 0};
  pitch.faceDefTransform = {x, move, grow};
  face.faceDefTables.insert(face.faceDefTables.begin(), pitch);
  const FatEvaluator eval(face, uniformFapu());
  FatState s = eval.neutralState();
  for (int repeat = 0; repeat < 2; ++repeat) {  // each frame starts from the neutral state
    eval.evaluate(frameWith({{23, 10000}, {48, 5000}}), s);
    const Eigen::Quaterniond expected =
        Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) *
        Eigen::AngleAxisd(0.1, Eigen::Vector3d(0, -1, 0)) *  // FAP 23 first
        Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX());    // then FAP 48
    EXPECT_TRUE(s.transforms[1].rotation.isApprox(expected, 1e-12));
    EXPECT_TRUE(
        s.transforms[1].translation.isApprox(Eigen::Vector3d(3, 4, 5 + 5000 * 1e-5 * 1e-4)));
    EXPECT_TRUE(s.transforms[1].scale.isApprox(Eigen::Vector3d(1 + 5000 * 1e-5 * 1e-5, 1, 1)));
  }
  eval.evaluate(FapFrame(), s);
  EXPECT_TRUE(s.transforms[1].rotation.isApprox(face.faceSceneGraph.transforms[1].rotation));
  EXPECT_EQ(s.transforms[1].translation, Eigen::Vector3d(3, 4, 5));
}

// A second implementation straight from intervalWeights, in double, for random tables; the
// 16-bit tables within their documented bound (FatStorage::Int16).
TEST(FatEvaluate, AgreesWithTheIntervalWeightsOnRandomTables) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> intervals(1, 5), border(1, 400), valueOf(-3000, 3000);
  std::uniform_real_distribution<double> d(-2, 2);
  for (int round = 0; round < 50; ++round) {
    MpegFace face;
    face.faceSceneGraph.addMeshWithTransform(gridMesh("m", 40));
    face.faceSceneGraph.addMeshWithTransform(gridMesh("n", 10));
    for (int fap : {3, 4, 19, 31}) {
      FaceDefTables t;
      t.fapID = fap;
      for (int mesh = 0; mesh < 2; ++mesh) {
        FaceDefMesh m;
        m.mesh = mesh;
        const int n = intervals(rng);
        const int below = n == 1 ? 0 : std::uniform_int_distribution<int>(0, n)(rng);
        int b = 0;
        for (int k = 0; k < below; ++k)
          m.intervalBorders.insert(m.intervalBorders.begin(), b -= border(rng));
        m.intervalBorders.push_back(0);
        b = 0;
        for (int k = below; k < n; ++k) m.intervalBorders.push_back(b += border(rng));
        for (int v = mesh; v < face.faceSceneGraph.meshes[mesh].vertexCount();
             v += fap == 3 ? 1 : 2) {
          m.coordIndex.push_back(v);
        }
        // Runs of consecutive vertices (FAP 3), every other vertex, and any order (FAP 31).
        if (fap == 31) std::reverse(m.coordIndex.begin(), m.coordIndex.end());
        m.displacements.resize(static_cast<Eigen::Index>(m.coordIndex.size()) * n, 3);
        for (Eigen::Index r = 0; r < m.displacements.rows(); ++r)
          m.displacements.row(r) << d(rng), d(rng), d(rng);
        t.faceDefMesh.push_back(m);
      }
      face.faceDefTables.push_back(t);
    }
    FapuMeasurement fapu = uniformFapu(0.01);
    fapu.IRISD0.value = 0.003 * kFapuDivisor;
    FapFrame frame;
    for (int fap : {3, 4, 19, 31}) {
      if (rng() % 4 != 0) frame.set(fap, valueOf(rng));
    }
    const FatState s = FatEvaluator(face, fapu).evaluate(frame);
    const FatState s16 = FatEvaluator(face, fapu, FatStorage::Int16).evaluate(frame);
    std::vector<Points3> expected;
    for (const auto& mesh : face.faceSceneGraph.meshes) expected.push_back(mesh.coord);
    double largest = 1;
    std::vector<Eigen::RowVector3d> bound16(expected.size(), Eigen::RowVector3d::Zero());
    for (const FaceDefTables& t : face.faceDefTables) {
      if (!frame.has(t.fapID)) continue;
      for (const FaceDefMesh& m : t.faceDefMesh) {
        std::vector<double> w;
        intervalWeights(m.intervalBorders, frame.value(t.fapID), w);
        for (int k = 0; k < m.intervalCount(); ++k) {
          Eigen::RowVector3d top = Eigen::RowVector3d::Zero();
          for (std::size_t i = 0; i < m.coordIndex.size(); ++i) {
            top = top.cwiseMax(
                m.displacements.row(static_cast<Eigen::Index>(i) * m.intervalCount() + k)
                    .cwiseAbs());
          }
          bound16[m.mesh] += std::abs(fapScale(fapu, t.fapID) * w[k]) / 32768 * top;
        }
        for (std::size_t i = 0; i < m.coordIndex.size(); ++i) {
          for (int k = 0; k < m.intervalCount(); ++k) {
            const Eigen::RowVector3d step =
                fapScale(fapu, t.fapID) * w[k] *
                m.displacements.row(static_cast<Eigen::Index>(i) * m.intervalCount() + k);
            expected[m.mesh].row(m.coordIndex[i]) += step;
            largest = std::max(largest, step.norm());
          }
        }
      }
    }
    for (std::size_t mesh = 0; mesh < expected.size(); ++mesh) {
      EXPECT_LE((s.coord[mesh] - expected[mesh]).cwiseAbs().maxCoeff(), largest * kFloat)
          << "round " << round << " mesh " << mesh;
      const Eigen::MatrixXd error16 = (s16.coord[mesh] - expected[mesh]).cwiseAbs();
      for (int axis = 0; axis < 3; ++axis) {
        EXPECT_LE(error16.col(axis).maxCoeff(), bound16[mesh][axis] + largest * kFloat)
            << "16-bit, round " << round << " mesh " << mesh << " axis " << axis;
      }
    }
  }
}

namespace {

// Five vertices: viseme 3 / 5 and expression 1 move 0..3, FAP 3 moves 1, FAP 4 moves 3; the
// viseme translates and FAP 3 rotates Transform "Jaw".
MpegFace highLevelFace() {
  MpegFace face;
  face.faceSceneGraph.addMeshWithTransform(gridMesh("Face", 5));
  const auto table = [](int fap, int select, std::vector<int> vertices, Eigen::RowVector3d d) {
    FaceDefTables t;
    t.fapID = fap;
    t.highLevelSelect = select;
    FaceDefMesh m;
    m.mesh = 0;
    m.intervalBorders = {0, 63};
    m.coordIndex = vertices;
    m.displacements = d.replicate(static_cast<Eigen::Index>(vertices.size()), 1);
    t.faceDefMesh.push_back(m);
    return t;
  };
  face.faceDefTables = {table(1, 3, {0, 1, 2, 3}, {1, 0, 0}), table(1, 5, {0, 1, 2, 3}, {0, 1, 0}),
                        table(2, 1, {0, 1, 2, 3}, {0, 0, 1}), table(3, 1, {1}, {0, -0.001, 0}),
                        table(4, 1, {3}, {0, 0.002, 0})};
  FaceDefTransform shift;
  shift.transform = 0;
  shift.fieldId = FaceDefTransform::Field::Translation;
  shift.translationDef = {0, 0, 0.5};
  face.faceDefTables[0].faceDefTransform.push_back(shift);
  FaceDefTransform turn;
  turn.transform = 0;
  turn.rotationDef = {1, 0, 0, 1e-5};
  face.faceDefTables[3].faceDefTransform.push_back(turn);
  return face;
}

}  // namespace

TEST(FatEvaluate, VisemesBlendAndExpressionsAddByIntensity) {
  const MpegFace face = highLevelFace();
  const FatEvaluator eval(face, uniformFapu());
  FapFrame frame;
  frame.viseme = {3, 5, 20, false};
  frame.expression = {1, 10, 1, 30, false, false};
  FatState s = eval.evaluate(frame);
  EXPECT_EQ(moved(s, face, 0, 0).norm(), 0.0);  // neither bit 1 nor bit 2 set
  frame.mask.set(0);
  frame.mask.set(1);
  eval.evaluate(frame, s);
  expectNear(moved(s, face, 0, 0), {20, 43, 40}, 1e-4);
  expectNear(moved(s, face, 0, 4), {0, 0, 0}, 0);
  EXPECT_TRUE(s.transforms[0].translation.isApprox(Eigen::Vector3d(0, 0, 10)));
  frame.viseme = {3, 3, 20, false};  // the same viseme twice: fully shown
  eval.evaluate(frame, s);
  expectNear(moved(s, face, 0, 2), {63, 0, 40}, 1e-4);
}

TEST(FatEvaluate, LowLevelFapsPresentInTheFrameOverrideVisemesAndExpressions) {
  const MpegFace face = highLevelFace();
  const FatEvaluator eval(face, uniformFapu());
  FapFrame frame;
  frame.mask.set(0);
  frame.mask.set(1);
  frame.viseme = {3, 0, 63, false};
  frame.expression = {1, 63, 0, 0, false, false};
  frame.set(3, 100);
  FatState s = eval.evaluate(frame);
  expectNear(moved(s, face, 0, 0), {63, 0, 63}, 1e-4);
  expectNear(moved(s, face, 0, 1), {0, -0.1, 0}, 1e-6);  // FAP 3 only
  expectNear(moved(s, face, 0, 3), {63, 0, 63}, 1e-4);   // FAP 4 absent
  // FAP 3 rotates the jaw, the viseme translates it: different fields, both apply.
  EXPECT_TRUE(s.transforms[0].translation.isApprox(Eigen::Vector3d(0, 0, 31.5)));
  EXPECT_NEAR(Eigen::AngleAxisd(s.transforms[0].rotation).angle(), 100 * 1e-5, 1e-12);
  // A low-level FAP present with value 0 still holds its vertices (the sender set them).
  frame.set(3, 0);
  frame.set(4, 0);
  eval.evaluate(frame, s);
  expectNear(moved(s, face, 0, 1), {0, 0, 0}, 0);
  expectNear(moved(s, face, 0, 3), {0, 0, 0}, 0);
  expectNear(moved(s, face, 0, 2), {63, 0, 63}, 1e-4);
}

TEST(FatEvaluate, PriorityFadesWithTheLowLevelFapsMotion) {
  // FAP 5 moves vertex 1 fully and vertices 2 and 3 by a half and a hundredth of that (a
  // key that fades out): the viseme keeps 0, a half and 99% of its motion there.
  MpegFace face = highLevelFace();
  FaceDefTables lip;
  lip.fapID = 5;
  FaceDefMesh m;
  m.mesh = 0;
  m.intervalBorders = {-100, 0, 100};
  m.coordIndex = {1, 2, 3};
  // Per vertex, its two intervals; the negative side reaches further at vertex 1.
  m.displacements.resize(6, 3);
  m.displacements << 0, 2e-3, 0, 0, 1e-3, 0,  // vertex 1: 0.2 below, 0.1 above
      0, 0.5e-3, 0, 0, 0.5e-3, 0,             // vertex 2: 0.05 each side
      0, 0, 0, 0, 2e-5, 0;                    // vertex 3: 0.002 above
  lip.faceDefMesh.push_back(m);
  face.faceDefTables.push_back(lip);
  const FatEvaluator eval(face, uniformFapu());
  FapFrame frame;
  frame.mask.set(0);
  frame.viseme = {3, 0, 63, false};
  frame.set(5, 0);  // present at 0: it holds what it moves, by its share
  const FatState s = eval.evaluate(frame);
  expectNear(moved(s, face, 0, 0), {63, 0, 0}, 1e-4);         // not FAP 5's
  expectNear(moved(s, face, 0, 1), {0, 0, 0}, 1e-4);          // its largest motion
  expectNear(moved(s, face, 0, 2), {63 * 0.75, 0, 0}, 1e-4);  // 0.05 of 0.2
  expectNear(moved(s, face, 0, 3), {63 * 0.99, 0, 0}, 1e-4);  // 0.002 of 0.2
}

TEST(FatEvaluate, PriorityIsPerMesh) {
  MpegFace face = highLevelFace();
  face.faceSceneGraph.addMeshWithTransform(gridMesh("Teeth", 3));
  FaceDefTables teeth;  // FAP 5 moves vertex 0 of Teeth, not vertex 0 of Face
  teeth.fapID = 5;
  FaceDefMesh m;
  m.mesh = 1;
  m.intervalBorders = {0, 100};
  m.coordIndex = {0};
  m.displacements = Points3::Constant(1, 3, 0.01);
  teeth.faceDefMesh.push_back(m);
  face.faceDefTables.push_back(teeth);
  const FatEvaluator eval(face, uniformFapu());
  FapFrame frame;
  frame.mask.set(0);
  frame.viseme = {3, 0, 63, false};
  frame.set(5, 100);
  const FatState s = eval.evaluate(frame);
  expectNear(moved(s, face, 0, 0), {63, 0, 0}, 1e-4);
  expectNear(moved(s, face, 1, 0), {1, 1, 1}, 1e-6);
}

// The 16-bit tables follow the same rules as float ones (priority shares, several meshes,
// Transforms, one state frame after frame), within their bound: here at most 4 tables of
// motions up to 63 model units (FatStorage::Int16).
TEST(FatEvaluate, SixteenBitTablesFollowTheSameRules) {
  MpegFace face = highLevelFace();
  face.faceSceneGraph.addMeshWithTransform(gridMesh("Teeth", 3));
  FaceDefTables lip;  // FAP 5: a fading key on Face, and Teeth
  lip.fapID = 5;
  FaceDefMesh m;
  m.mesh = 0;
  m.intervalBorders = {-100, 0, 40, 100};
  m.coordIndex = {1, 2, 3};
  m.displacements.resize(9, 3);
  m.displacements << 0, 2e-3, 1e-4, 0, 1e-3, 0, 3e-4, 1e-3, 0,  //
      0, 0.5e-3, 0, 0, 0.3e-3, 0, 1e-4, 0, 0,                   //
      0, 0, 0, 0, 2e-5, 0, 0, 1e-5, 7e-6;
  lip.faceDefMesh.push_back(m);
  m.mesh = 1;
  m.intervalBorders = {0, 100};
  m.coordIndex = {0, 1, 2};
  m.displacements = Points3::Constant(3, 3, 1.0 / 3);
  lip.faceDefMesh.push_back(m);
  face.faceDefTables.push_back(lip);
  face.faceDefTables[1].faceDefMesh[0].displacements.col(1).setConstant(0.7);
  const FatEvaluator exact(face, uniformFapu()), fast(face, uniformFapu(), FatStorage::Int16);
  FatState a = exact.neutralState(), b = fast.neutralState();
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> select(0, 14), amount(0, 63), value(-150, 150);
  double largestError = 0;
  for (int k = 0; k < 200; ++k) {
    FapFrame frame;
    if (rng() % 3) frame.mask.set(0), frame.viseme = {select(rng), select(rng), amount(rng), false};
    if (rng() % 3) {
      frame.mask.set(1);
      frame.expression = {int(rng() % 7), amount(rng), int(rng() % 7), amount(rng), false, false};
    }
    for (int fap : {3, 4, 5}) {
      if (rng() % 2) frame.set(fap, value(rng));
    }
    exact.evaluate(frame, a);
    fast.evaluate(frame, b);
    for (std::size_t mesh = 0; mesh < a.coord.size(); ++mesh) {
      largestError = std::max(largestError, (a.coord[mesh] - b.coord[mesh]).cwiseAbs().maxCoeff());
    }
    EXPECT_TRUE(a.transforms[0].translation.isApprox(b.transforms[0].translation)) << k;
    EXPECT_TRUE(a.transforms[0].rotation.isApprox(b.transforms[0].rotation)) << k;
  }
  EXPECT_LE(largestError, 4 * 63.0 / 32768);
}

// Where priorityApplies says no, the result is the plain sum of the tables' motions (what
// shape keys add up to); where it says yes, it is not.
// A FaceDefMesh that lists no vertex moves nothing in either storage (found by fuzz_fat: the
// 16-bit tables were made from an empty array).
TEST(FatEvaluate, AnEmptyFaceDefMeshMovesNothing) {
  MpegFace face = highLevelFace();
  FaceDefTables empty;
  empty.fapID = 6;
  FaceDefMesh m;
  m.mesh = 0;
  m.intervalBorders = {-100, 0, 50, 100};
  m.displacements.resize(0, 3);
  empty.faceDefMesh.push_back(m);
  face.faceDefTables.push_back(empty);
  for (FatStorage storage : {FatStorage::Float, FatStorage::Int16}) {
    const FatEvaluator eval(face, uniformFapu(), storage);
    const FatState s = eval.evaluate(frameWith({{6, 80}}));
    EXPECT_EQ(s.coord[0], face.faceSceneGraph.meshes[0].coord);
  }
}

TEST(FatEvaluate, PriorityAppliesWhereALowLevelFapSharesAVisemesVertex) {
  const MpegFace face = highLevelFace();  // FAP 3 moves vertex 1, FAP 4 vertex 3: both visemes'
  const FatEvaluator eval(face, uniformFapu());
  const auto sumOfTables = [&](const FapFrame& frame) {
    Points3 p = face.faceSceneGraph.meshes[0].coord;
    for (const FaceDefTables& t : face.faceDefTables) {
      if (!frame.has(t.fapID)) continue;
      const int value = tableInput(t.fapID, t.highLevelSelect, frame);
      for (const FaceDefMesh& m : t.faceDefMesh) {
        std::vector<double> w;
        intervalWeights(m.intervalBorders, value, w);
        for (std::size_t i = 0; i < m.coordIndex.size(); ++i) {
          p.row(m.coordIndex[i]) +=
              fapScale(uniformFapu(), t.fapID) * w[0] * m.displacements.row(i);
        }
      }
    }
    return p;
  };
  FapFrame frame;
  frame.mask.set(0);
  frame.viseme = {3, 0, 63, false};
  EXPECT_FALSE(eval.priorityApplies(frame));  // a viseme alone
  EXPECT_LE((eval.evaluate(frame).coord[0] - sumOfTables(frame)).cwiseAbs().maxCoeff(), 1e-4);
  frame.set(3, 100);  // FAP 3 moves vertex 1, which the viseme moves too
  EXPECT_TRUE(eval.priorityApplies(frame));
  EXPECT_GT((eval.evaluate(frame).coord[0] - sumOfTables(frame)).cwiseAbs().maxCoeff(), 1);
  frame.viseme = {0, 0, 63, false};  // viseme 0 (none): nothing to override
  EXPECT_FALSE(eval.priorityApplies(frame));
  frame.mask.reset(0);
  frame.mask.set(1);                              // expression 1 moves vertex 1 too
  frame.expression = {1, 0, 0, 0, false, false};  // ... at intensity 0
  EXPECT_FALSE(eval.priorityApplies(frame));
  frame.expression = {1, 20, 0, 0, false, false};
  EXPECT_TRUE(eval.priorityApplies(frame));
}

TEST(FatEvaluate, LowLevelTranslationOverridesTheVisemesTranslation) {
  MpegFace face = highLevelFace();
  FaceDefTransform move;
  move.transform = 0;
  move.fieldId = FaceDefTransform::Field::Translation;
  move.translationDef = {1e-3, 0, 0};
  face.faceDefTables[4].faceDefTransform.push_back(move);  // FAP 4 (MNS)
  const FatEvaluator eval(face, uniformFapu());
  FapFrame frame;
  frame.mask.set(0);
  frame.viseme = {3, 0, 63, false};
  frame.set(4, 0);
  const FatState s = eval.evaluate(frame);
  EXPECT_EQ(s.transforms[0].translation, Eigen::Vector3d::Zero());
}

// A head (mesh 0) and an eye (mesh 1) under the head's Transform, both posed off their
// rest, the head nodded by FAP 3 (on its Transform: a jaw-like turn) and the eye turned by
// FAP 23: each object's coordinates are its mesh where the evaluated Transforms put it,
// seen from the neutral Transforms' frame, in Z-up axes.
TEST(FatEvaluate, ObjectCoordinatesUndoTheNeutralChain) {
  MpegFace face;
  FaceModel& graph = face.faceSceneGraph;
  graph.addMeshWithTransform(gridMesh("Head", 9));
  graph.addMeshWithTransform(gridMesh("Eye", 6));
  graph.roots = {0};
  graph.transforms[0].children = {1};
  graph.transforms[0].translation = {0.5, -1, 2};
  graph.transforms[0].center = {0, 1, 0};
  graph.transforms[1].translation = {3, 4, 5};
  graph.transforms[1].center = {0.2, 0.1, 0.3};
  graph.transforms[1].rotation = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
  graph.transforms[1].scale = {1, 2, 1};
  const auto turn = [](int fap, int transform, Eigen::Vector3d axis) {
    FaceDefTables t;
    t.fapID = fap;
    FaceDefTransform def;
    def.transform = transform;
    def.rotationDef = {axis.x(), axis.y(), axis.z(), 1};
    t.faceDefTransform.push_back(def);
    return t;
  };
  face.faceDefTables = {turn(3, 0, {1, 0, 0}), turn(23, 1, {0, 1, 0})};
  const FatEvaluator eval(face, uniformFapu());
  const FatState neutral = eval.neutralState();
  const FatState s = eval.evaluate(frameWith({{3, 20000}, {23, -30000}}));
  Eigen::Matrix3d zUp;
  zUp << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  std::vector<Points3f> coords;
  std::vector<Eigen::Affine3d> placements;
  const std::vector<std::vector<int>> chains{{0}, {0, 1}};
  objectCoordinates(s, neutral.transforms, chains, zUp, coords, placements);
  ASSERT_EQ(coords.size(), 2u);
  // The same by hand, as 4x4 matrices and point by point.
  const auto local = [](const Transform& t) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    Eigen::Matrix4d c = Eigen::Matrix4d::Identity(), back = Eigen::Matrix4d::Identity();
    c.block<3, 1>(0, 3) = t.center;
    back.block<3, 1>(0, 3) = -t.center;
    m.block<3, 1>(0, 3) = t.translation;
    Eigen::Matrix4d r = Eigen::Matrix4d::Identity(), sc = Eigen::Matrix4d::Identity();
    r.block<3, 3>(0, 0) = t.rotation.toRotationMatrix();
    sc.block<3, 3>(0, 0) = t.scale.asDiagonal();
    return Eigen::Matrix4d(m * c * r * sc * back);
  };
  Eigen::Matrix4d axes = Eigen::Matrix4d::Identity();
  axes.block<3, 3>(0, 0) = zUp;
  for (std::size_t i = 0; i < chains.size(); ++i) {
    Eigen::Matrix4d posed = Eigen::Matrix4d::Identity(), rest = Eigen::Matrix4d::Identity();
    for (int t : chains[i]) {
      posed *= local(s.transforms[static_cast<std::size_t>(t)]);
      rest *= local(neutral.transforms[static_cast<std::size_t>(t)]);
    }
    const Eigen::Matrix4d expected = axes * rest.inverse() * posed;
    EXPECT_TRUE(placements[i].matrix().isApprox(expected, 1e-12)) << placements[i].matrix();
    ASSERT_EQ(coords[i].rows(), s.coord[i].rows());
    for (Eigen::Index v = 0; v < coords[i].rows(); ++v) {
      const Eigen::Vector4d p = expected * s.coord[i].row(v).transpose().homogeneous();
      EXPECT_LE((coords[i].row(v).cast<double>() - p.head<3>().transpose()).norm(), 1e-5)
          << "mesh " << i << " vertex " << v;
    }
  }
  // The motion is there: the eye moved against its neutral place, and at rest nothing does.
  EXPECT_GT((placements[1].matrix() - axes).norm(), 0.1);
  objectCoordinates(neutral, neutral.transforms, chains, zUp, coords, placements);
  for (std::size_t i = 0; i < chains.size(); ++i) {
    EXPECT_TRUE(placements[i].matrix().isApprox(axes, 1e-12));
  }
  EXPECT_THROW(
      objectCoordinates(s, neutral.transforms, {{0}, {0, 1}, {0}}, zUp, coords, placements), Error);
  EXPECT_THROW(objectPlacement(s.transforms, neutral.transforms, std::vector<int>{2}, zUp), Error);
}

TEST(FatEvaluate, StateBuffersAreReused) {
  const MpegFace face = paperFace();
  const FatEvaluator eval(face, uniformFapu());
  FatState s = eval.neutralState();
  const double* before = s.coord[0].data();
  eval.evaluate(frameWith({{6, 600}}), s);
  eval.evaluate(frameWith({{6, -20}}), s);
  EXPECT_EQ(s.coord[0].data(), before);
  eval.evaluate(FapFrame(), s);
  EXPECT_EQ(s.coord[0], face.faceSceneGraph.meshes[0].coord);
}

TEST(FatEvaluate, BadStatesAndFrameFieldsAreErrors) {
  const MpegFace face = highLevelFace();
  const FatEvaluator eval(face, uniformFapu());
  FatState s = eval.neutralState();
  s.coord[0].resize(2, 3);
  EXPECT_EQ(errorOf([&] { eval.evaluate(FapFrame(), s); }).field(), "state.coord[0]");
  s.coord.clear();
  EXPECT_EQ(errorOf([&] { eval.evaluate(FapFrame(), s); }).field(), "state");
  FapFrame frame;
  frame.mask.set(0);
  frame.viseme.blend = 64;
  EXPECT_EQ(errorOf([&] { eval.evaluate(frame); }).field(), "viseme_blend");
  frame.viseme = {15, 0, 0, false};
  EXPECT_EQ(errorOf([&] { eval.evaluate(frame); }).field(), "viseme_select1");
  frame = FapFrame();
  frame.mask.set(1);
  frame.expression.select2 = 7;
  EXPECT_EQ(errorOf([&] { eval.evaluate(frame); }).field(), "expression_select2");
  frame.expression = {1, -1, 0, 0, false, false};
  EXPECT_EQ(errorOf([&] { eval.evaluate(frame); }).field(), "expression_intensity1");
}

TEST(FatEvaluate, AnUnmeasuredFapuNamesTheFeaturePointsItNeeds) {
  MpegFace face = paperFace();
  face.faceDefTables[0].fapID = 19;  // close_t_l_eyelid: IRISD
  FapuMeasurement fapu = uniformFapu();
  fapu.IRISD0 = {};
  fapu.IRISD0.method = "needs 3.1 and 3.3, or 3.2 and 3.4";
  const Error e = errorOf([&] { FatEvaluator(face, fapu); });
  EXPECT_EQ(e.field(), "faceDefTables[0] (FAP 19)");
  EXPECT_TRUE(contains(e, "IRISD0 is not measured: needs 3.1 and 3.3")) << e.what();
}

namespace {

std::string validationField(const std::function<void(MpegFace&)>& breakIt) {
  MpegFace face = paperFace();
  breakIt(face);
  return errorOf([&] { validateMpegFace(face); }).field();
}

}  // namespace

TEST(FatValidate, NamesTheBrokenTable) {
  EXPECT_NO_THROW(validateMpegFace(paperFace()));
  EXPECT_NO_THROW(validateMpegFace(highLevelFace()));
  const auto mesh = [](MpegFace& f) -> FaceDefMesh& { return f.faceDefTables[0].faceDefMesh[0]; };
  const auto transform = [](MpegFace& f) -> FaceDefTransform& {
    return f.faceDefTables[1].faceDefTransform[0];
  };
  EXPECT_EQ(validationField([&](MpegFace& f) { mesh(f).coordIndex[1] = 60; }),
            "faceDefTables[0] (FAP 6).faceDefMesh[0].coordIndex[1]");
  EXPECT_EQ(validationField([&](MpegFace& f) { mesh(f).coordIndex[1] = -1; }),
            "faceDefTables[0] (FAP 6).faceDefMesh[0].coordIndex[1]");
  EXPECT_EQ(validationField([&](MpegFace& f) { mesh(f).coordIndex[1] = 50; }),
            "faceDefTables[0] (FAP 6).faceDefMesh[0].coordIndex[1]");
  EXPECT_EQ(validationField([&](MpegFace& f) { mesh(f).displacements.conservativeResize(5, 3); }),
            "faceDefTables[0] (FAP 6).faceDefMesh[0].displacements");
  EXPECT_EQ(validationField([&](MpegFace& f) { mesh(f).displacements(3, 1) = NAN; }),
            "faceDefTables[0] (FAP 6).faceDefMesh[0].displacements[3]");
  EXPECT_EQ(validationField([&](MpegFace& f) {
              mesh(f).intervalBorders = {-5, 5, 10, 20};
            }),
            "faceDefTables[0] (FAP 6).faceDefMesh[0].intervalBorders");
  EXPECT_EQ(validationField([&](MpegFace& f) { mesh(f).mesh = 1; }),
            "faceDefTables[0] (FAP 6).faceDefMesh[0].faceSceneGraphNode");
  EXPECT_EQ(
      validationField([&](MpegFace& f) { f.faceDefTables[0].faceDefMesh.push_back(mesh(f)); }),
      "faceDefTables[0] (FAP 6).faceDefMesh[1]");
  EXPECT_EQ(validationField([&](MpegFace& f) { f.faceDefTables[1].fapID = 69; }),
            "faceDefTables[1] (FAP 69).fapID");
  EXPECT_EQ(validationField([&](MpegFace& f) { f.faceDefTables[1].fapID = 0; }),
            "faceDefTables[1] (FAP 0).fapID");
  EXPECT_EQ(validationField([&](MpegFace& f) { f.faceDefTables[1].fapID = 6; }),
            "faceDefTables[1] (FAP 6)");
  EXPECT_EQ(validationField([&](MpegFace& f) {
              f.faceDefTables[1].fapID = 1;
              f.faceDefTables[1].highLevelSelect = 15;
            }),
            "faceDefTables[1] (FAP 1 viseme 15).highLevelSelect");
  EXPECT_EQ(validationField([&](MpegFace& f) {
              f.faceDefTables[1].fapID = 2;
              f.faceDefTables[1].highLevelSelect = 0;
            }),
            "faceDefTables[1] (FAP 2 expression 0).highLevelSelect");
  EXPECT_EQ(validationField([&](MpegFace& f) { transform(f).transform = 2; }),
            "faceDefTables[1] (FAP 23).faceDefTransform[0].faceSceneGraphNode");
  EXPECT_EQ(validationField([&](MpegFace& f) {
              transform(f).fieldId = static_cast<FaceDefTransform::Field>(4);
            }),
            "faceDefTables[1] (FAP 23).faceDefTransform[0].fieldId");
  EXPECT_EQ(validationField([&](MpegFace& f) {
              transform(f).rotationDef = {0, 0, 0, 1};
            }),
            "faceDefTables[1] (FAP 23).faceDefTransform[0].rotationDef");
  EXPECT_EQ(validationField([&](MpegFace& f) { transform(f).translationDef[0] = INFINITY; }),
            "faceDefTables[1] (FAP 23).faceDefTransform[0].translationDef");
  EXPECT_EQ(validationField(
                [&](MpegFace& f) { f.faceDefTables[1].faceDefTransform.push_back(transform(f)); }),
            "faceDefTables[1] (FAP 23).faceDefTransform[1]");
  EXPECT_EQ(validationField([&](MpegFace& f) { f.faceSceneGraph.roots = {5}; }), "roots");
  // Two tables for one viseme are an error; for two visemes they are not.
  MpegFace face = highLevelFace();
  face.faceDefTables[1].highLevelSelect = 3;
  const Error e = errorOf([&] { validateMpegFace(face); });
  EXPECT_EQ(e.field(), "faceDefTables[1] (FAP 1 viseme 3)");
  EXPECT_TRUE(contains(e, "faceDefTables[0]")) << e.what();
}

TEST(FatValidate, MessagesSayWhatIsWrong) {
  MpegFace face = paperFace();
  face.faceDefTables[0].faceDefMesh[0].coordIndex[1] = 60;
  EXPECT_EQ(errorOf([&] { validateMpegFace(face); }).reason(),
            "vertex 60 out of range (mesh 'Face' has 60 vertices)");
  face = paperFace();
  face.faceDefTables[0].faceDefMesh[0].displacements.conservativeResize(5, 3);
  EXPECT_EQ(errorOf([&] { validateMpegFace(face); }).reason(),
            "5 displacements, expected 6 (2 vertices x 3 intervals)");
  face = paperFace();
  face.faceDefTables[0].faceDefMesh[0].intervalBorders = {-5, 5, 10, 20};
  EXPECT_EQ(errorOf([&] { validateMpegFace(face); }).reason(),
            "with several intervals exactly one border must be 0");
}
