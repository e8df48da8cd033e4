// SPDX-License-Identifier: GPL-3.0-or-later
// The motion check on a synthetic head whose keys each break one limit (or touch at the lips
// only), through its shape keys, its tables and a stream played on them; and a spike on
// CANDIDE-3.
#include <gtest/gtest.h>

#include <algorithm>

#include "motion_check_fixture.hpp"
#include "mpeg4face/fat/motion_check.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/wfm.hpp"
#include "test_support.hpp"

namespace {

using namespace mpeg4face;
using mpeg4face::test::MotionHead;
using mpeg4face::test::motionHead;

// A smooth dent of sheet B's (3 x 3) centre by `centre` along z: the whole sheet moves 40% of
// it, so that the centre is no spike (its bump is 60% of its motion, < 0.75).
void dent(MotionHead& h, const std::string& name, int sheet, double centre) {
  for (int v = sheet; v < sheet + 9; ++v) h.key(name, v, {0, 0, 0.4 * centre});
  h.key(name, sheet + 4, {0, 0, 0.6 * centre});
}

MotionHead keyedHead() {
  MotionHead h = motionHead();
  h.key("expression1_stretch", h.stretchSheet, {-2, 0, 0});    // an edge of 1 becomes 3
  h.key("expression2_flip", h.stretchSheet, {1.5, 1.5, 0});    // over its neighbours
  h.key("expression3_pierce", h.crossSheetB + 4, {0, 0, -1});  // B's centre through A
  dent(h, "expression4_lips", h.lipSheetB, -0.1);                // the same at the mouth
  h.key("expression5_corner", h.innerLeft, {0.3, 0, 0});       // 5% of MW0 outside 8.3
  h.key("expression6_corner", h.innerLeft, {0.21, 0, 0});      // 0.5%: within the limit
  h.key("viseme1_lips_fold", h.lipSheetB, {0.15, 0.15, 0});  // as expression2, at the mouth
  h.key("fap3@1024", h.chin, {0, -1, 0});                      // MNS0 = 1: 1024 units
  h.key("fap3@1024", h.lowerLip, {0, -0.3, 0});
  return h;
}

const PoseMotion& pose(const MotionCheck& check, const std::string& name) {
  const auto it = std::find_if(check.keys.begin(), check.keys.end(),
                               [&](const PoseMotion& p) { return p.name == name; });
  EXPECT_NE(it, check.keys.end()) << name;
  return *it;
}

bool fails(const PoseMotion& p, const std::string& what) {
  return std::any_of(p.failures.begin(), p.failures.end(),
                     [&](const std::string& f) { return f.find(what) != std::string::npos; });
}

class MotionCheckTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    head = new MotionHead(keyedHead());
    check = new MotionCheck(checkMotion(head->model, {}));
  }
  static void TearDownTestSuite() {
    delete check;
    delete head;
  }
  static MotionHead* head;
  static MotionCheck* check;
};
MotionHead* MotionCheckTest::head = nullptr;
MotionCheck* MotionCheckTest::check = nullptr;

TEST_F(MotionCheckTest, StretchedEdge) {
  const PoseMotion& p = pose(*check, "expression1_stretch");
  EXPECT_NEAR(p.edgeRatioMax, 3.0, 1e-9);
  EXPECT_GT(p.edgeRatioP99, 2.0);
  EXPECT_TRUE(fails(p, "edge ratio p99")) << ::testing::PrintToString(p.failures);
  ASSERT_EQ(p.meshes.size(), 1u);
  const std::vector<int>& v = p.meshes[0].offendingVertices;
  EXPECT_TRUE(std::binary_search(v.begin(), v.end(), head->stretchSheet));
  EXPECT_EQ(p.normalFlips, 0);
  EXPECT_EQ(p.newIntersections, 0);
  // A corner moved alone is a spike too: its ring (two edges and the diagonal) is still.
  EXPECT_EQ(p.meshes[0].spikeVertices, std::vector<int>{head->stretchSheet});
  EXPECT_EQ(p.spikes, 1);
  EXPECT_NEAR(p.bumpRatioMax, 1.0, 1e-12);
  EXPECT_TRUE(fails(p, "1 spike vertex (bump 1.00 x the local motion > 0.75)"))
      << ::testing::PrintToString(p.failures);
}

TEST_F(MotionCheckTest, FlippedTriangle) {
  const PoseMotion& p = pose(*check, "expression2_flip");
  EXPECT_GE(p.normalFlips, 1);
  EXPECT_TRUE(fails(p, "flipped"));
  // The first triangle of the sheet, (0 1 4), turned over.
  const std::vector<int>& t = p.meshes.at(0).flippedTriangles;
  EXPECT_NE(std::find(t.begin(), t.end(), 0), t.end());
}

TEST_F(MotionCheckTest, SheetPushedThroughAnotherIsANewSelfIntersection) {
  const PoseMotion& p = pose(*check, "expression3_pierce");
  EXPECT_GT(p.newIntersections, 0);
  EXPECT_TRUE(fails(p, "new self-intersections"));
  EXPECT_LT(p.edgeRatioP99, 2.0);
  EXPECT_EQ(p.normalFlips, 0);
  EXPECT_EQ(check->neutralIntersections, 0);
}

TEST_F(MotionCheckTest, LipsTouchingIsNotAFailure) {
  const PoseMotion& p = pose(*check, "expression4_lips");
  EXPECT_GT(p.touchingIntersections, 0);
  EXPECT_EQ(p.newIntersections, 0);
  EXPECT_TRUE(p.failures.empty()) << ::testing::PrintToString(p.failures);
  // The dent: the centre's bump 0.06 is 60% of its motion 0.1.
  EXPECT_EQ(p.spikes, 0);
  EXPECT_NEAR(p.bumpRatioMax, 0.6, 1e-9);
}

TEST_F(MotionCheckTest, LipsFoldingWhereTheyMeetIsNotAFlip) {
  const PoseMotion& p = pose(*check, "viseme1_lips_fold");
  EXPECT_GE(p.contactFolds, 1);
  EXPECT_EQ(p.normalFlips, 0);
  EXPECT_FALSE(fails(p, "flipped")) << ::testing::PrintToString(p.failures);
  ASSERT_EQ(p.meshes.size(), 1u);
  EXPECT_TRUE(p.meshes[0].flippedTriangles.empty());
  // The same fold away from the lips and lids is a flip (FlippedTriangle).
  EXPECT_EQ(pose(*check, "expression2_flip").contactFolds, 0);
}

TEST_F(MotionCheckTest, InnerLipCornerOutsideTheOuterOne) {
  const PoseMotion& out = pose(*check, "expression5_corner");
  ASSERT_TRUE(out.lipCornerOutside);
  EXPECT_NEAR(*out.lipCornerOutside, 0.05, 1e-9);  // 0.1 past 8.3, MW0 = 2
  EXPECT_TRUE(fails(out, "inner lip corner"));
  const PoseMotion& in = pose(*check, "expression6_corner");
  EXPECT_NEAR(*in.lipCornerOutside, 0.005, 1e-9);
  EXPECT_TRUE(in.failures.empty());
  // The neutral corners are 0.2 inside: 10% of MW0.
  EXPECT_NEAR(*pose(*check, "expression1_stretch").lipCornerOutside, -0.1, 1e-9);
}

TEST_F(MotionCheckTest, LowerLipShareAndGap) {
  ASSERT_TRUE(check->lowerLipShare);
  EXPECT_NEAR(*check->lowerLipShare, 0.3, 1e-6);
  ASSERT_EQ(check->failures.size(), 1u);
  EXPECT_NE(check->failures[0].find("lower lip"), std::string::npos);
  EXPECT_NEAR(*check->neutralLipGap, 0.05, 1e-9);
  EXPECT_FALSE(check->passed());
}

TEST_F(MotionCheckTest, StreamFramesThroughTheTables) {
  FapStream stream;
  stream.name = "s";
  for (int n = 0; n < 3; ++n) {
    FapFrame f;
    f.number = n;
    if (n > 0) {  // the stretch fully on, then held
      f.mask.set(1);
      f.expression = {1, 63, 0, 0, false, false};
    }
    stream.frames.push_back(f);
  }
  std::size_t calls = 0;
  const MotionCheck c =
      checkMotion(head->model, {&stream, 1}, {}, [&](std::size_t, std::size_t total) {
        ++calls;
        EXPECT_EQ(total, check->keys.size() + 3);
      });
  EXPECT_EQ(calls, c.keys.size() + 3);
  ASSERT_EQ(c.frames.size(), 3u);
  EXPECT_TRUE(c.frames[0].failures.empty());
  EXPECT_EQ(c.frames[0].meshes.size(), 0u);  // the neutral
  for (int n : {1, 2}) {
    EXPECT_EQ(c.frames[n].name, "s frame " + std::to_string(n));
    EXPECT_EQ(c.frames[n].frame, n);
    EXPECT_NEAR(c.frames[n].edgeRatioMax, 3.0, 1e-5);
    EXPECT_TRUE(fails(c.frames[n], "edge ratio"));
  }
  ASSERT_EQ(c.streams.size(), 1u);
  EXPECT_EQ(c.streams[0].frames, 3);
}

TEST_F(MotionCheckTest, FaceKeysAreTheTablesAtTheirBorders) {
  const MotionCheck c = checkMotion(faceFromShapeKeys(head->model).face, {});
  const PoseMotion& p = pose(c, "expression1");
  EXPECT_NEAR(p.edgeRatioMax, 3.0, 1e-5);
  EXPECT_GT(pose(c, "fap3_open_jaw@1024").edgeRatioMax, 0.0);
  EXPECT_NEAR(*c.lowerLipShare, 0.3, 1e-5);
}

// A flip and a spike that the head's own shape (a key outside the grammar, as a scan's ARKit
// shape) makes too are the head's: not counted, unless asked.
TEST(MotionCheck, WhatTheHeadsOwnShapesDoIsNotCounted) {
  MotionHead h = motionHead();
  h.key("expression1_flip", h.stretchSheet, {1.5, 1.5, 0});
  h.key("scanned_shape", h.stretchSheet, {1.4, 1.6, 0});
  const MotionCheck own = checkMotion(h.model, {});
  EXPECT_EQ(own.ownShapes, std::vector<std::string>{"scanned_shape"});
  ASSERT_EQ(own.keys.size(), 1u);
  const PoseMotion& p = own.keys[0];
  EXPECT_EQ(p.normalFlips, 0);
  EXPECT_EQ(p.spikes, 0);
  EXPECT_GE(p.ownShapeFaults, 2);  // the flipped triangle and the corner's spike
  EXPECT_FALSE(fails(p, "flipped")) << ::testing::PrintToString(p.failures);
  EXPECT_FALSE(fails(p, "spike")) << ::testing::PrintToString(p.failures);

  MotionLimits all;
  all.ownShapes = false;
  const MotionCheck strict = checkMotion(h.model, {}, all);
  EXPECT_TRUE(strict.ownShapes.empty());
  EXPECT_TRUE(fails(strict.keys.at(0), "flipped"));
  EXPECT_TRUE(fails(strict.keys.at(0), "spike"));
  EXPECT_EQ(strict.keys[0].ownShapeFaults, 0);
}

TEST(MotionCheck, ANeutralThatAlreadySelfIntersectsIsNotNew) {
  MotionHead h = motionHead();
  h.model.meshes[0].coord(h.crossSheetB + 4, 2) = -0.5;  // B's centre already through A
  dent(h, "expression1", h.crossSheetB, -0.05);
  const MotionCheck c = checkMotion(h.model, {});
  EXPECT_GT(c.neutralIntersections, 0);
  ASSERT_EQ(c.keys.size(), 1u);
  EXPECT_EQ(c.keys[0].newIntersections, 0);
  EXPECT_TRUE(c.keys[0].failures.empty()) << ::testing::PrintToString(c.keys[0].failures);
}

}  // namespace

namespace {

// A second mesh (lower teeth, say) that a pose moves by rounding, 0.5% of the skin's motion,
// is not measured for spikes; its vertex poked alone by 3% of it is no spike either (bumps
// count against the pose's motion, not the mesh's own); poked by 10% of it, it is one.
TEST(MotionCheck, AMeshThePoseBarelyMovesIsNotMeasuredForSpikes) {
  MotionHead h = motionHead();
  IndexedFaceSet teeth;
  teeth.name = "teeth";
  mpeg4face::test::addSheet(teeth, {0, 5, 0}, 3, 1);
  h.model.addMeshWithTransform(std::move(teeth));
  for (const char* name : {"expression1_rounding", "expression2_poke", "expression3_nudge"}) {
    for (int v = h.stretchSheet; v < h.stretchSheet + 9; ++v) h.key(name, v, {1, 0, 0});
  }
  IndexedFaceSet& mesh = h.model.meshes[1];
  MorphTarget rounding{"expression1_rounding", Points3::Zero(9, 3)};
  rounding.displacements(4, 2) = 0.005;
  MorphTarget poke{"expression2_poke", Points3::Zero(9, 3)};
  poke.displacements(4, 2) = 0.1;
  MorphTarget nudge{"expression3_nudge", Points3::Zero(9, 3)};
  nudge.displacements(4, 2) = 0.03;
  mesh.morphTargets = {rounding, poke, nudge};

  const MotionCheck c = checkMotion(h.model, {});
  const PoseMotion& still = pose(c, "expression1_rounding");
  EXPECT_EQ(still.spikes, 0);
  EXPECT_TRUE(still.failures.empty()) << ::testing::PrintToString(still.failures);
  const PoseMotion& poked = pose(c, "expression2_poke");
  EXPECT_EQ(poked.spikes, 1);
  const auto teethMotion = std::find_if(poked.meshes.begin(), poked.meshes.end(),
                                        [](const MeshMotion& m) { return m.mesh == 1; });
  ASSERT_NE(teethMotion, poked.meshes.end());
  EXPECT_EQ(teethMotion->spikeVertices, std::vector<int>{4});
  const PoseMotion& nudged = pose(c, "expression3_nudge");
  EXPECT_EQ(nudged.spikes, 0);
  EXPECT_TRUE(nudged.failures.empty()) << ::testing::PrintToString(nudged.failures);
}

// CANDIDE-3 with its feature points and a key that pushes the nose tip 9.3 alone, by 0.01
// (a fifth of its shortest edge) along +z, out of the face: no edge ratio, flip or
// intersection sees it; the spike measure does. And a key that moves the whole face, which
// has no bump at all.
TEST(MotionCheck, OneVertexPushedOnAHeadIsASpike) {
  FaceModel head = readWfm(mpeg4face::test::kData / "candide3" / "candide3.wfm").model;
  head.featurePoints =
      readFeaturePointCsv(mpeg4face::test::kData / "candide3" / "feature_points.csv", head)
          .featurePoints;
  const FeaturePointBinding nose = head.featurePoints.at("9.3");
  ASSERT_GE(nose.mesh, 0);
  IndexedFaceSet& mesh = head.meshes[static_cast<std::size_t>(nose.mesh)];
  MorphTarget spike{"expression1_spike", Points3::Zero(mesh.vertexCount(), 3)};
  spike.displacements(nose.vertex, 2) = 0.01;
  MorphTarget shift{"expression2_shift", Points3::Zero(mesh.vertexCount(), 3)};
  shift.displacements.col(1).setConstant(0.05);
  mesh.morphTargets = {spike, shift};

  const MotionCheck c = checkMotion(head, {});
  const PoseMotion& p = pose(c, "expression1_spike");
  ASSERT_EQ(p.failures.size(), 1u) << ::testing::PrintToString(p.failures);
  EXPECT_EQ(p.failures[0].rfind("1 spike vertex (bump 1.00 x the local motion > 0.75)", 0), 0u)
      << p.failures[0];
  EXPECT_LT(p.edgeRatioP99, 2.0);
  ASSERT_EQ(p.meshes.size(), 1u);
  EXPECT_EQ(p.meshes[0].spikeVertices, std::vector<int>{nose.vertex});
  const std::vector<int>& offending = p.meshes[0].offendingVertices;
  EXPECT_TRUE(std::binary_search(offending.begin(), offending.end(), nose.vertex));
  EXPECT_NEAR(p.bumpRatioMax, 1.0, 1e-9);

  const PoseMotion& still = pose(c, "expression2_shift");
  EXPECT_TRUE(still.failures.empty()) << ::testing::PrintToString(still.failures);
  EXPECT_EQ(still.spikes, 0);
  EXPECT_LT(still.bumpP99, 1e-9);

  // Allowed, the spike passes.
  MotionLimits limits;
  limits.spikeVertices = 1;
  EXPECT_TRUE(pose(checkMotion(head, {}, limits), "expression1_spike").failures.empty());
}

}  // namespace
