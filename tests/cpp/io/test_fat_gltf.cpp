// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "gltf_validator.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/fat_gltf.hpp"
#include "mpeg4face/io/gltf.hpp"
#include "test_support.hpp"

using namespace mpeg4face;
using mpeg4face::test::errorOf;
namespace fs = std::filesystem;

namespace {

// FAPU of the test face, in model units: MW = 0.05, MNS = 0.03, AU = 1e-5 rad.
constexpr double kMW = 0.05;
constexpr double kMNS = 0.03;
constexpr double kAU = 1e-5;

FapuMeasurement testFapu() {
  FapuMeasurement fapu;
  fapu.MW0 = {true, kMW * 1024, {"8.3", "8.4"}, "|8.3 - 8.4|"};
  fapu.MNS0 = {true, kMNS * 1024, {"9.15", "2.2"}, "9.15.y - 2.2.y"};
  return fapu;
}

// Mesh names and transform indices of testFace().
enum { kFace = 0, kLeftEye = 1, kTeeth = 2 };
enum { kHead = 0, kLeftEyeX = 1, kJaw = 2 };

Points3 rows(std::initializer_list<Eigen::RowVector3d> list) {
  Points3 out(static_cast<Eigen::Index>(list.size()), 3);
  Eigen::Index i = 0;
  for (const auto& r : list) out.row(i++) = r;
  return out;
}

// A small face: mesh "Face" of 60 vertices (a 10 x 6 grid) under "Head", which also holds
// "LeftEyeX" (turning about its centre, the eye ball's middle) with mesh "LeftEye", and
// "Jaw" with mesh "Teeth". "Face" has a morph target of its own ("smile", default weight
// 0.25). The tables:
//   0: FAP 6, Tekalp-Ostermann Table 5: borders -1000 0 500 1000 on vertices 50 and 51
//   1: FAP 25: LeftEyeX rotates about (1, 0, 0), angle 1 per AU (before FAP 23, to check
//      that FaceDefTransforms are applied in increasing fapID order, not table order)
//   2: FAP 3 (MNS): one interval [0, 1000] on vertices 10 and 50; Jaw translates (0, -1, 0)
//   3: FAP 1, viseme 3: [0, 63] on vertex 20; Jaw scales by (0, 0.001, 0)
//   4: FAP 23, Table 5: LeftEyeX rotates about (0, -1, 0), angle 1 per AU
//   5: FAP 2, expression 1 (joy): [0, 63] on vertex 30
MpegFace testFace() {
  MpegFace face;
  FaceModel& model = face.faceSceneGraph;
  IndexedFaceSet skin;
  skin.name = "Face";
  skin.coord.resize(60, 3);
  for (int j = 0; j < 6; ++j) {
    for (int i = 0; i < 10; ++i)
      skin.coord.row(10 * j + i) << 0.01 * i - 0.045, 0.01 * j, 0.001 * i;
  }
  for (int j = 0; j + 1 < 6; ++j) {
    for (int i = 0; i + 1 < 10; ++i) {
      const int v = 10 * j + i;
      skin.coordIndex.insert(skin.coordIndex.end(), {v, v + 1, v + 11, v + 10, -1});
    }
  }
  MorphTarget smile{"smile", Points3::Zero(60, 3)};
  smile.displacements(52, 1) = 0.002;
  skin.morphTargets = {smile};
  skin.weights = {0.25};
  IndexedFaceSet eye;
  eye.name = "LeftEye";
  eye.coord =
      rows({{0.03, 0.04, 0.02}, {0.04, 0.04, 0.02}, {0.035, 0.05, 0.02}, {0.035, 0.045, 0.03}});
  eye.coordIndex = {0, 2, 1, -1, 0, 1, 3, -1, 0, 3, 2, -1, 1, 2, 3, -1};
  IndexedFaceSet teeth;
  teeth.name = "Teeth";
  teeth.coord = rows({{-0.02, -0.01, 0.01}, {0.02, -0.01, 0.01}, {0.0, -0.02, 0.01}});
  teeth.coordIndex = {0, 1, 2, -1};
  model.meshes = {skin, eye, teeth};
  Transform head;
  head.name = "Head";
  head.translation = {0, 1.6, 0};
  head.rotation = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX());
  head.meshes = {kFace};
  head.children = {kLeftEyeX, kJaw};
  Transform eyeX;
  eyeX.name = "LeftEyeX";
  eyeX.translation = {0.001, 0, 0};
  eyeX.center = {0.035, 0.045, 0.022};
  eyeX.meshes = {kLeftEye};
  Transform jaw;
  jaw.name = "Jaw";
  jaw.center = {0, 0, -0.05};
  jaw.meshes = {kTeeth};
  model.transforms = {head, eyeX, jaw};
  model.roots = {kHead};

  FaceDefTables fap6{.fapID = 6, .highLevelSelect = 1, .faceDefMesh = {}, .faceDefTransform = {}};
  fap6.faceDefMesh.push_back(
      {.mesh = kFace,
       .intervalBorders = {-1000, 0, 500, 1000},
       .coordIndex = {50, 51},
       .displacements =
           rows({{1, 0, 0}, {0.9, 0, 0}, {1.5, 0, 4}, {0.8, 0, 0}, {0.7, 0, 0}, {2, 0, 0}})});
  FaceDefTables fap23{.fapID = 23, .highLevelSelect = 1, .faceDefMesh = {}, .faceDefTransform = {}};
  fap23.faceDefTransform.push_back({.transform = kLeftEyeX, .rotationDef = {0, -1, 0, 1}});
  FaceDefTables fap3{.fapID = 3, .highLevelSelect = 1, .faceDefMesh = {}, .faceDefTransform = {}};
  fap3.faceDefMesh.push_back({.mesh = kFace,
                              .intervalBorders = {0, 1000},
                              .coordIndex = {10, 50},
                              .displacements = rows({{0, -1, 0}, {0, -0.5, 0.1}})});
  fap3.faceDefTransform.push_back({.transform = kJaw,
                                   .fieldId = FaceDefTransform::Field::Translation,
                                   .translationDef = {0, -1, 0}});
  FaceDefTables viseme3{
      .fapID = 1, .highLevelSelect = 3, .faceDefMesh = {}, .faceDefTransform = {}};
  viseme3.faceDefMesh.push_back({.mesh = kFace,
                                 .intervalBorders = {0, 63},
                                 .coordIndex = {20},
                                 .displacements = rows({{0.0001, -0.0002, 0}})});
  viseme3.faceDefTransform.push_back(
      {.transform = kJaw, .fieldId = FaceDefTransform::Field::Scale, .scaleDef = {0, 0.001, 0}});
  FaceDefTables fap25{.fapID = 25, .highLevelSelect = 1, .faceDefMesh = {}, .faceDefTransform = {}};
  fap25.faceDefTransform.push_back({.transform = kLeftEyeX, .rotationDef = {1, 0, 0, 1}});
  FaceDefTables joy{.fapID = 2, .highLevelSelect = 1, .faceDefMesh = {}, .faceDefTransform = {}};
  joy.faceDefMesh.push_back({.mesh = kFace,
                             .intervalBorders = {0, 63},
                             .coordIndex = {30},
                             .displacements = rows({{0, 0.0003, 0}})});
  face.faceDefTables = {fap6, fap25, fap3, viseme3, fap23, joy};
  return face;
}

// Tekalp-Ostermann's rules 1-6 written out as the overlap of each interval with [0, FAP]
// (the outermost intervals reaching to infinity): the motion of one vertex, in FAPU.
Eigen::Vector3d paperMotion(const std::vector<int>& I, const std::vector<Eigen::Vector3d>& D,
                            double fap) {
  const size_t n = I.size() - 1;
  if (n == 1) return fap * D[0];  // rule 6
  const double inf = std::numeric_limits<double>::infinity();
  Eigen::Vector3d motion = Eigen::Vector3d::Zero();
  for (size_t j = 0; j < n; ++j) {
    const double lo = j == 0 ? -inf : I[j];
    const double hi = j + 1 == n ? inf : I[j + 1];
    if (fap >= 0 && I[j] >= 0) motion += std::max(0.0, std::min(fap, hi) - I[j]) * D[j];
    if (fap < 0 && I[j + 1] <= 0) motion += std::max(0.0, I[j + 1] - std::max(fap, lo)) * D[j];
  }
  return motion;
}

// The FAP state after each frame by the hold rule, written out for the test stream.
struct Held {
  double fap3 = 0, fap6 = 0, fap23 = 0, fap25 = 0, viseme3 = 0, joy = 0;
};

// A stream exercising the hold rule, both sides of 0, values beyond the outermost borders,
// visemes (blends of viseme 3 as select1 and as select2) and an expression.
FapStream testStream(std::vector<Held>& held) {
  FapStream stream;
  stream.name = "talk";
  stream.frameRate = 25;
  FapFrame f;
  f.set(6, 600);
  f.set(23, 20000);
  f.set(3, 200);
  stream.frames.push_back(f);
  held.push_back({.fap3 = 200, .fap6 = 600, .fap23 = 20000});
  f = {};
  f.set(6, -500);
  f.set(25, -10000);
  f.mask.set(0);  // FAP 1: viseme 3 blended 40 / 63 with viseme 0
  f.viseme = {.select1 = 3, .select2 = 0, .blend = 40};
  stream.frames.push_back(f);
  held.push_back({.fap3 = 200, .fap6 = -500, .fap23 = 20000, .fap25 = -10000, .viseme3 = 40});
  f = {};
  f.set(3, 0);
  stream.frames.push_back(f);
  held.push_back({.fap3 = 0, .fap6 = -500, .fap23 = 20000, .fap25 = -10000, .viseme3 = 40});
  f = {};
  f.set(6, 1500);
  f.mask.set(0);  // viseme 3 as select2: 63 - 10
  f.viseme = {.select1 = 5, .select2 = 3, .blend = 10};
  f.mask.set(1);  // FAP 2: joy at 40
  f.expression = {.select1 = 1, .intensity1 = 40, .select2 = 4, .intensity2 = 20};
  stream.frames.push_back(f);
  held.push_back(
      {.fap3 = 0, .fap6 = 1500, .fap23 = 20000, .fap25 = -10000, .viseme3 = 53, .joy = 40});
  f = {};
  f.set(6, -1300);
  f.set(23, -30000);
  f.set(3, 700);
  stream.frames.push_back(f);
  held.push_back(
      {.fap3 = 700, .fap6 = -1300, .fap23 = -30000, .fap25 = -10000, .viseme3 = 53, .joy = 40});
  f = {};
  f.set(6, 250);
  f.set(25, 5000);
  f.mask.set(0);  // another viseme: 3 no longer shows
  f.viseme = {.select1 = 7, .select2 = 8, .blend = 30};
  stream.frames.push_back(f);
  held.push_back(
      {.fap3 = 700, .fap6 = 250, .fap23 = -30000, .fap25 = 5000, .viseme3 = 0, .joy = 40});
  // Frame numbers as sent: 0, 1, 2, then 5, 6, 7 (frames 3 and 4 skipped: values hold).
  for (size_t i = 0; i < stream.frames.size(); ++i) {
    stream.frames[i].number = static_cast<int>(i < 3 ? i : i + 2);
  }
  return stream;
}

// The model-space displacement of every Face vertex for one frame, straight from the
// tables (in the paper's terms, not through intervalWeights).
Points3 expectedFaceMotion(const MpegFace& face, const Held& h) {
  const FaceModel& model = face.faceSceneGraph;
  Points3 motion = Points3::Zero(model.meshes[kFace].vertexCount(), 3);
  const std::vector<int> borders6 = {-1000, 0, 500, 1000};
  motion.row(50) += kMW * paperMotion(borders6, {{1, 0, 0}, {0.9, 0, 0}, {1.5, 0, 4}}, h.fap6);
  motion.row(51) += kMW * paperMotion(borders6, {{0.8, 0, 0}, {0.7, 0, 0}, {2, 0, 0}}, h.fap6);
  motion.row(10) += kMNS * h.fap3 * Eigen::RowVector3d(0, -1, 0);
  motion.row(50) += kMNS * h.fap3 * Eigen::RowVector3d(0, -0.5, 0.1);
  motion.row(20) += h.viseme3 * Eigen::RowVector3d(0.0001, -0.0002, 0);
  motion.row(30) += h.joy * Eigen::RowVector3d(0, 0.0003, 0);
  motion.row(52) += 0.25 * Eigen::RowVector3d(0, 0.002, 0);  // "smile" at its default weight
  return motion;
}

// LeftEyeX's rotation for a frame: FAP 23 then FAP 25 (increasing fapID), about its centre.
Eigen::Quaterniond expectedEyeRotation(const Held& h) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(h.fap23 * kAU, -Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(h.fap25 * kAU, Eigen::Vector3d::UnitX()));
}

const MorphTarget* findTarget(const IndexedFaceSet& mesh, const std::string& name) {
  for (const MorphTarget& t : mesh.morphTargets) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

// The floats of accessor `index` (tightly packed FLOAT, as writeGltf writes them).
std::vector<double> floatsOf(const tinygltf::Model& gltf, int index) {
  const tinygltf::Accessor& a = gltf.accessors[index];
  const tinygltf::BufferView& view = gltf.bufferViews[a.bufferView];
  const size_t n = a.count * static_cast<size_t>(tinygltf::GetNumComponentsInType(a.type));
  std::vector<float> values(n);
  std::memcpy(values.data(), gltf.buffers[view.buffer].data.data() + view.byteOffset + a.byteOffset,
              n * sizeof(float));
  return {values.begin(), values.end()};
}

class FatGltfTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = mpeg4face::test::scratchDir(); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

}  // namespace

TEST(FatTargetName, Grammar) {
  EXPECT_EQ(fatTargetName(6, 1, 0, 500), "fap6_stretch_l_cornerlip[0,500]");
  EXPECT_EQ(fatTargetName(6, 1, -1000, 0), "fap6_stretch_l_cornerlip[-1000,0]");
  EXPECT_EQ(fatTargetName(1, 3, 0, 63), "viseme3[0,63]");
  EXPECT_EQ(fatTargetName(2, 1, 0, 63), "expression1_joy[0,63]");
}

// (a) Tekalp-Ostermann Table 5, through a .glb and back: FAP 6 = 600 moves vertex 50 by
// 500 * (0.9, 0, 0) + 100 * (1.5, 0, 4) = (600, 0, 400) FAPU and vertex 51 by
// 500 * (0.7, 0, 0) + 100 * (2, 0, 0) = (550, 0, 0); FAP 6 = -500 moves vertex 50 by
// 500 * (1, 0, 0) = (500, 0, 0). The weights are the paper's interval lengths, by hand.
TEST_F(FatGltfTest, PaperTable5ThroughGlb) {
  const MpegFace face = testFace();
  writeFatGltf(face, testFapu(), {}, dir_ / "face.glb");
  const FaceModel back = readGltf(dir_ / "face.glb");
  const IndexedFaceSet& skin = back.meshes[kFace];
  std::vector<std::string> names;
  for (const MorphTarget& t : skin.morphTargets) names.push_back(t.name);
  EXPECT_EQ(names, (std::vector<std::string>{
                       "smile", "fap6_stretch_l_cornerlip[-1000,0]",
                       "fap6_stretch_l_cornerlip[0,500]", "fap6_stretch_l_cornerlip[500,1000]",
                       "fap3_open_jaw[0,1000]", "viseme3[0,63]", "expression1_joy[0,63]"}));
  EXPECT_EQ(skin.weights, (std::vector<double>{0.25, 0, 0, 0, 0, 0, 0}));
  const MorphTarget* below = findTarget(skin, "fap6_stretch_l_cornerlip[-1000,0]");
  const MorphTarget* low = findTarget(skin, "fap6_stretch_l_cornerlip[0,500]");
  const MorphTarget* high = findTarget(skin, "fap6_stretch_l_cornerlip[500,1000]");
  ASSERT_TRUE(below && low && high);
  auto moved = [&](int v, double w0, double w1, double w2) -> Eigen::Vector3d {
    return (skin.coord.row(v) + w0 * below->displacements.row(v) + w1 * low->displacements.row(v) +
            w2 * high->displacements.row(v))
        .transpose();
  };
  const Eigen::Vector3d p50 = face.faceSceneGraph.meshes[kFace].coord.row(50);
  const Eigen::Vector3d p51 = face.faceSceneGraph.meshes[kFace].coord.row(51);
  EXPECT_TRUE(moved(50, 0, 500, 100).isApprox(p50 + Eigen::Vector3d(600, 0, 400) * kMW, 1e-6));
  EXPECT_TRUE(moved(51, 0, 500, 100).isApprox(p51 + Eigen::Vector3d(550, 0, 0) * kMW, 1e-6));
  EXPECT_TRUE(moved(50, 500, 0, 0).isApprox(p50 + Eigen::Vector3d(500, 0, 0) * kMW, 1e-6));
  // Vertices outside coordIndex do not move.
  EXPECT_TRUE(low->displacements.row(49).isZero(0));
  // No streams, no animations.
  EXPECT_TRUE(back.animations.empty());
}

// (b) A baked stream: every frame of the .glb's weights reproduces the tables' rule at every
// vertex, and the Transform channels hold the FaceDefTransform results.
TEST_F(FatGltfTest, BakedStreamMatchesTheTables) {
  const MpegFace face = testFace();
  std::vector<Held> held;
  const FapStream stream = testStream(held);
  writeFatGltf(face, testFapu(), std::span(&stream, 1), dir_ / "talk.glb");
  const FaceModel back = readGltf(dir_ / "talk.glb");
  ASSERT_EQ(back.animations.size(), 1u);
  const MorphWeightAnimation& animation = back.animations[0];
  EXPECT_EQ(animation.name, "talk");
  ASSERT_EQ(animation.channels.size(), 1u) << "one mesh has FAT targets";
  const MorphWeightChannel& channel = animation.channels[0];
  EXPECT_EQ(channel.mesh, kFace);
  EXPECT_EQ(channel.interpolation, MorphWeightChannel::Interpolation::Linear);
  const IndexedFaceSet& skin = back.meshes[kFace];
  const size_t targets = skin.morphTargets.size();
  ASSERT_EQ(channel.times.size(), held.size());
  ASSERT_EQ(channel.weights.size(), held.size() * targets);
  for (size_t f = 0; f < held.size(); ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    EXPECT_NEAR(channel.times[f], static_cast<double>(f < 3 ? f : f + 2) / 25.0, 1e-6);
    Points3 posed = skin.coord;
    for (size_t k = 0; k < targets; ++k) {
      posed += channel.weights[f * targets + k] * skin.morphTargets[k].displacements;
    }
    const Points3 expected =
        face.faceSceneGraph.meshes[kFace].coord + expectedFaceMotion(face, held[f]);
    // 32-bit floats: the error grows with the motion (the paper's example moves far).
    const double scale = std::max(1.0, expectedFaceMotion(face, held[f]).cwiseAbs().maxCoeff());
    EXPECT_LT((posed - expected).cwiseAbs().maxCoeff(), 1e-7 * scale)
        << "frame " << f << "\n"
        << (posed - expected).cwiseAbs().rowwise().maxCoeff().transpose();
  }

  // Transform channels: LeftEyeX rotation, Jaw translation (FAP 3), Jaw scale (viseme 3).
  ASSERT_EQ(animation.transformChannels.size(), 3u);
  for (const TransformChannel& c : animation.transformChannels) {
    SCOPED_TRACE("transform " + std::to_string(c.transform));
    EXPECT_EQ(c.interpolation, MorphWeightChannel::Interpolation::Linear);
    ASSERT_EQ(c.times.size(), held.size());
    for (size_t f = 0; f < held.size(); ++f) {
      const Held& h = held[f];
      if (c.path == TransformChannel::Path::Rotation) {
        EXPECT_EQ(c.transform, kLeftEyeX);
        const Eigen::Quaterniond q(c.values[4 * f + 3], c.values[4 * f], c.values[4 * f + 1],
                                   c.values[4 * f + 2]);
        EXPECT_NEAR(std::abs(q.dot(expectedEyeRotation(h))), 1.0, 1e-6) << "frame " << f;
        if (f > 0) {  // consecutive keys in one hemisphere
          const Eigen::Map<const Eigen::Vector4d> previous(&c.values[4 * (f - 1)]);
          EXPECT_GE(q.coeffs().dot(previous), 0);
        }
      } else if (c.path == TransformChannel::Path::Translation) {
        EXPECT_EQ(c.transform, kJaw);
        const Eigen::Vector3d t(c.values[3 * f], c.values[3 * f + 1], c.values[3 * f + 2]);
        EXPECT_TRUE(t.isApprox(Eigen::Vector3d(0, -kMNS * h.fap3, 0), 1e-6) ||
                    (h.fap3 == 0 && t.norm() < 1e-9))
            << t.transpose();
      } else {
        EXPECT_EQ(c.transform, kJaw);
        const Eigen::Vector3d s(c.values[3 * f], c.values[3 * f + 1], c.values[3 * f + 2]);
        EXPECT_TRUE(s.isApprox(Eigen::Vector3d(1, 1 + 0.001 * h.viseme3, 1), 1e-6))
            << s.transpose();
      }
    }
  }
}

// The eye turns about its centre in glTF's own terms: node matrices T R S from the file
// (read with tinygltf, not with readGltf), the rotation taken from the animation's key, must
// put an eye vertex where the VRML Transform (T C R -C) puts it.
TEST_F(FatGltfTest, AnimatedRotationStaysAboutTheCentre) {
  const MpegFace face = testFace();
  std::vector<Held> held;
  const FapStream stream = testStream(held);
  writeFatGltf(face, testFapu(), std::span(&stream, 1), dir_ / "talk.gltf");
  tinygltf::TinyGLTF loader;
  tinygltf::Model gltf;
  std::string err;
  std::string warn;
  ASSERT_TRUE(loader.LoadASCIIFromFile(&gltf, &err, &warn, (dir_ / "talk.gltf").string())) << err;

  // The rotation sampler of node "LeftEyeX".
  int eyeNode = -1;
  for (size_t n = 0; n < gltf.nodes.size(); ++n) {
    if (gltf.nodes[n].name == "LeftEyeX") eyeNode = static_cast<int>(n);
  }
  ASSERT_GE(eyeNode, 0);
  std::vector<double> rotations;
  ASSERT_EQ(gltf.animations.size(), 1u);
  for (const tinygltf::AnimationChannel& c : gltf.animations[0].channels) {
    if (c.target_node == eyeNode && c.target_path == "rotation") {
      rotations = floatsOf(gltf, gltf.animations[0].samplers[c.sampler].output);
    }
  }
  ASSERT_EQ(rotations.size(), 4 * held.size());

  std::vector<int> parent(gltf.nodes.size(), -1);
  for (size_t n = 0; n < gltf.nodes.size(); ++n) {
    for (int child : gltf.nodes[n].children) parent[child] = static_cast<int>(n);
  }
  auto local = [&](int n, size_t frame) {
    const tinygltf::Node& node = gltf.nodes[n];
    Eigen::Affine3d m = Eigen::Affine3d::Identity();
    if (!node.translation.empty()) {
      m.translate(Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]));
    }
    if (n == eyeNode) {
      const double* q = &rotations[4 * frame];
      m.rotate(Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized());
    } else if (!node.rotation.empty()) {
      m.rotate(Eigen::Quaterniond(node.rotation[3], node.rotation[0], node.rotation[1],
                                  node.rotation[2]));
    }
    if (!node.scale.empty()) m.scale(Eigen::Vector3d(node.scale[0], node.scale[1], node.scale[2]));
    return m;
  };
  int eyeMeshNode = -1;
  for (size_t n = 0; n < gltf.nodes.size(); ++n) {
    if (gltf.nodes[n].mesh >= 0 && gltf.meshes[gltf.nodes[n].mesh].name == "LeftEye") {
      eyeMeshNode = static_cast<int>(n);
    }
  }
  ASSERT_GE(eyeMeshNode, 0);

  const FaceModel& model = face.faceSceneGraph;
  const Transform& head = model.transforms[kHead];
  const Transform& eye = model.transforms[kLeftEyeX];
  const Eigen::Vector3d p = model.meshes[kLeftEye].coord.row(1);
  for (size_t f = 0; f < held.size(); ++f) {
    Eigen::Affine3d world = Eigen::Affine3d::Identity();
    for (int n = eyeMeshNode; n >= 0; n = parent[n]) world = local(n, f) * world;
    // By hand: Head (no centre) * (T + C + R (p - C)).
    const Eigen::Vector3d expected =
        head.translation + head.rotation * (eye.translation + eye.center +
                                            expectedEyeRotation(held[f]) * (p - eye.center));
    EXPECT_TRUE((world * p).isApprox(expected, 1e-6))
        << "frame " << f << ": " << (world * p).transpose() << " vs " << expected.transpose();
  }
}

// The extras give the tables back: readFatGltf returns the face (without the FAT targets
// and baked animations) and the FAPU.
TEST_F(FatGltfTest, TablesRoundTrip) {
  const MpegFace face = testFace();
  std::vector<Held> held;
  const FapStream stream = testStream(held);
  for (const char* name : {"face.gltf", "face.glb"}) {
    SCOPED_TRACE(name);
    writeFatGltf(face, testFapu(), std::span(&stream, 1), dir_ / name);
    const FatGltf back = readFatGltf(dir_ / name);
    EXPECT_TRUE(back.fapu.MW0.measured);
    EXPECT_DOUBLE_EQ(back.fapu.MW0.value, kMW * 1024);
    EXPECT_DOUBLE_EQ(back.fapu.MNS0.value, kMNS * 1024);
    EXPECT_FALSE(back.fapu.ES0.measured);
    const FaceModel& model = back.face.faceSceneGraph;
    ASSERT_EQ(model.meshes.size(), 3u);
    ASSERT_EQ(model.meshes[kFace].morphTargets.size(), 1u);
    EXPECT_EQ(model.meshes[kFace].morphTargets[0].name, "smile");
    EXPECT_EQ(model.meshes[kFace].weights, std::vector<double>{0.25});
    EXPECT_TRUE(model.animations.empty());
    EXPECT_TRUE(model.transforms[kLeftEyeX].center.isApprox(Eigen::Vector3d(0.035, 0.045, 0.022)));
    ASSERT_EQ(back.face.faceDefTables.size(), face.faceDefTables.size());
    for (size_t t = 0; t < face.faceDefTables.size(); ++t) {
      const FaceDefTables& a = face.faceDefTables[t];
      const FaceDefTables& b = back.face.faceDefTables[t];
      EXPECT_EQ(a.fapID, b.fapID);
      EXPECT_EQ(a.highLevelSelect, b.highLevelSelect);
      ASSERT_EQ(a.faceDefMesh.size(), b.faceDefMesh.size());
      for (size_t m = 0; m < a.faceDefMesh.size(); ++m) {
        EXPECT_EQ(a.faceDefMesh[m].mesh, b.faceDefMesh[m].mesh);
        EXPECT_EQ(a.faceDefMesh[m].intervalBorders, b.faceDefMesh[m].intervalBorders);
        EXPECT_EQ(a.faceDefMesh[m].coordIndex, b.faceDefMesh[m].coordIndex);
        ASSERT_EQ(a.faceDefMesh[m].displacements.rows(), b.faceDefMesh[m].displacements.rows());
        EXPECT_LT(
            (a.faceDefMesh[m].displacements - b.faceDefMesh[m].displacements).cwiseAbs().maxCoeff(),
            1e-6);
      }
      ASSERT_EQ(a.faceDefTransform.size(), b.faceDefTransform.size());
      for (size_t d = 0; d < a.faceDefTransform.size(); ++d) {
        EXPECT_EQ(a.faceDefTransform[d].transform, b.faceDefTransform[d].transform);
        EXPECT_EQ(a.faceDefTransform[d].fieldId, b.faceDefTransform[d].fieldId);
        EXPECT_EQ(a.faceDefTransform[d].rotationDef, b.faceDefTransform[d].rotationDef);
        EXPECT_EQ(a.faceDefTransform[d].scaleDef, b.faceDefTransform[d].scaleDef);
        EXPECT_EQ(a.faceDefTransform[d].translationDef, b.faceDefTransform[d].translationDef);
      }
    }
  }
}

// Several FaceDefMesh giving a mesh the same name get "#2", "#3".
TEST_F(FatGltfTest, RepeatedNamesAreNumbered) {
  MpegFace face = testFace();
  // The mesh's own target already has the name of FAP 6's first interval.
  IndexedFaceSet& mesh = face.faceSceneGraph.meshes[kFace];
  mesh.morphTargets.push_back(
      {"fap6_stretch_l_cornerlip[0,500]", Points3::Zero(mesh.vertexCount(), 3)});
  if (!mesh.weights.empty()) mesh.weights.push_back(0);
  const FaceModel model = fatMorphModel(face, testFapu());
  EXPECT_TRUE(findTarget(model.meshes[kFace], "fap6_stretch_l_cornerlip[0,500]#2"));
}

// (c) The Khronos validator: 0 errors, 0 warnings on the export with a baked stream.
TEST_F(FatGltfTest, KhronosValidatorAcceptsTheExport) {
  MPEG4FACE_SKIP_WITHOUT_GLTF_VALIDATOR();
  const MpegFace face = testFace();
  std::vector<Held> held;
  const FapStream stream = testStream(held);
  writeFatGltf(face, testFapu(), std::span(&stream, 1), dir_ / "fat.gltf");
  writeFatGltf(face, testFapu(), std::span(&stream, 1), dir_ / "fat.glb");
  mpeg4face::test::expectValidGltf({dir_ / "fat.gltf", dir_ / "fat.glb"});
}

TEST(FatGltfErrors, BadTablesNameTheField) {
  const FapuMeasurement fapu = testFapu();
  auto fieldOf = [&](const MpegFace& face) {
    return errorOf([&] { (void)fatMorphModel(face, fapu); }).field();
  };
  MpegFace face = testFace();
  face.faceDefTables[0].faceDefMesh[0].coordIndex[1] = 60;
  EXPECT_EQ(fieldOf(face), "faceDefTables[0] (FAP 6).faceDefMesh[0].coordIndex[1]");
  face = testFace();
  face.faceDefTables[0].faceDefMesh[0].coordIndex[1] = 50;
  EXPECT_EQ(fieldOf(face), "faceDefTables[0] (FAP 6).faceDefMesh[0].coordIndex[1]");
  face = testFace();
  face.faceDefTables[2].faceDefMesh[0].displacements.conservativeResize(1, 3);
  EXPECT_EQ(fieldOf(face), "faceDefTables[2] (FAP 3).faceDefMesh[0].displacements");
  face = testFace();
  face.faceDefTables[0].faceDefMesh[0].intervalBorders = {-1000, 10, 500, 1000};
  EXPECT_EQ(fieldOf(face), "faceDefTables[0] (FAP 6).faceDefMesh[0].intervalBorders");
  face = testFace();
  face.faceDefTables[1].faceDefTransform[0].rotationDef = {0, 0, 0, 1};
  EXPECT_EQ(fieldOf(face), "faceDefTables[1] (FAP 25).faceDefTransform[0].rotationDef");
  face = testFace();
  face.faceDefTables[1].faceDefTransform[0].transform = 7;
  EXPECT_EQ(fieldOf(face), "faceDefTables[1] (FAP 25).faceDefTransform[0].faceSceneGraphNode");
  face = testFace();
  face.faceDefTables[3].highLevelSelect = 15;
  EXPECT_EQ(fieldOf(face), "faceDefTables[3] (FAP 1 viseme 15).highLevelSelect");
  face = testFace();
  face.faceDefTables[0].fapID = 69;
  EXPECT_EQ(fieldOf(face), "faceDefTables[0] (FAP 69).fapID");

  // A FAP whose FAPU the face does not measure.
  FapuMeasurement noMouth = fapu;
  noMouth.MW0 = {false, 0, {}, "needs feature points 8.3 and 8.4 (or 2.4 and 2.5)"};
  const Error e = errorOf([&] { (void)fatMorphModel(testFace(), noMouth); });
  EXPECT_EQ(e.field(), "faceDefTables[0].fapID");
  EXPECT_NE(e.reason().find("MW0 is not measured: needs feature points 8.3"), std::string::npos)
      << e.reason();

  FapStream stream;
  stream.frameRate = 0;
  stream.frames.resize(1);
  EXPECT_EQ(errorOf([&] { (void)bakeFapStream(testFace(), fapu, stream); }).field(), "frameRate");
  stream.frameRate = 25;
  stream.frames.clear();
  EXPECT_EQ(errorOf([&] { (void)bakeFapStream(testFace(), fapu, stream); }).field(), "frames");
}

TEST_F(FatGltfTest, ReadingChecksTheExtras) {
  // A plain glTF has no tables.
  writeGltf(testFace().faceSceneGraph, dir_ / "plain.glb");
  EXPECT_EQ(errorOf([&] { (void)readFatGltf(dir_ / "plain.glb"); }).field(),
            "scenes[0].extras.mpeg4face.faceDefTables");

  writeFatGltf(testFace(), testFapu(), {}, dir_ / "face.gltf");
  std::ifstream in(dir_ / "face.gltf");
  const std::string json{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  auto expectField = [&](const std::string& from, const std::string& to, const std::string& field) {
    SCOPED_TRACE(to);
    std::string edited = json;
    const size_t at = edited.find(from, edited.find("\"faceDefTables\""));
    ASSERT_NE(at, std::string::npos) << from;
    edited.replace(at, from.size(), to);
    const Error e = errorOf([&] { (void)parseFatGltf(edited, "face.gltf"); });
    EXPECT_EQ(e.file(), "face.gltf");
    EXPECT_EQ(e.field(), field) << e.what();
  };
  const std::string base = "scenes[0].extras.mpeg4face.";
  expectField("\"targets\": [\n", "\"targets\": [\n 99,",
              base + "faceDefTables[0].faceDefMesh[0].targets");
  expectField("\"fapID\": 6", "\"fapID\": 0", base + "faceDefTables[0].fapID");
  expectField("\"MW0\":", "\"MW0\": -1, \"x\":", base + "fapu.MW0");
  expectField("\"node\": 1", "\"node\": 5", base + "faceDefTables[1].faceDefTransform[0].node");
  expectField("\"coordIndex\": [\n", "\"coordIndex\": [\n 77,",
              base + "faceDefTables[0].faceDefMesh[0].coordIndex[0]");
}
