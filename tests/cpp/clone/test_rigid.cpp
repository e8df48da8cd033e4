// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "mpeg4face/clone/rigid.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "test_support.hpp"

using namespace mpeg4face;
using Kind = RigidPart::Kind;

namespace {

// A box with centre c and half sizes h (8 corners, 6 quads); corner i has x sign bit 0,
// y bit 1, z bit 2.
IndexedFaceSet box(const std::string& name, const Eigen::Vector3d& c, const Eigen::Vector3d& h) {
  IndexedFaceSet mesh;
  mesh.name = name;
  mesh.coord.resize(8, 3);
  for (int i = 0; i < 8; ++i) {
    mesh.coord.row(i) << c.x() + ((i & 1) ? h.x() : -h.x()), c.y() + ((i & 2) ? h.y() : -h.y()),
        c.z() + ((i & 4) ? h.z() : -h.z());
  }
  mesh.coordIndex = {0, 2, 3, 1, -1, 4, 5, 7, 6, -1, 0, 1, 5, 4, -1,
                     2, 6, 7, 3, -1, 0, 4, 6, 2, -1, 1, 3, 7, 5, -1};
  return mesh;
}

// A UV sphere of radius r about c; vertex 0 is the front pole (+z).
IndexedFaceSet sphere(const std::string& name, const Eigen::Vector3d& c, double r) {
  constexpr int kRings = 8, kSegments = 12;
  IndexedFaceSet mesh;
  mesh.name = name;
  mesh.coord.resize(2 + (kRings - 1) * kSegments, 3);
  mesh.coord.row(0) = (c + Eigen::Vector3d(0, 0, r)).transpose();
  mesh.coord.row(1) = (c - Eigen::Vector3d(0, 0, r)).transpose();
  for (int i = 1; i < kRings; ++i) {
    const double polar = std::numbers::pi * i / kRings;
    for (int j = 0; j < kSegments; ++j) {
      const double a = 2 * std::numbers::pi * j / kSegments;
      mesh.coord.row(2 + (i - 1) * kSegments + j) =
          (c + r * Eigen::Vector3d(std::sin(polar) * std::cos(a), std::sin(polar) * std::sin(a),
                                   std::cos(polar)))
              .transpose();
    }
  }
  const auto ring = [](int i, int j) { return 2 + (i - 1) * kSegments + (j % kSegments); };
  for (int j = 0; j < kSegments; ++j) {
    mesh.coordIndex.insert(mesh.coordIndex.end(), {0, ring(1, j), ring(1, j + 1), -1});
    mesh.coordIndex.insert(mesh.coordIndex.end(),
                           {1, ring(kRings - 1, j + 1), ring(kRings - 1, j), -1});
    for (int i = 1; i + 1 < kRings; ++i) {
      mesh.coordIndex.insert(mesh.coordIndex.end(),
                             {ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1), -1});
    }
  }
  return mesh;
}

struct FaceSpec {
  double scale = 1.0;         // of all geometry
  double mns0 = 0.03;         // 9.15.y - 2.2.y before scaling
  bool eyesAtOrigin = false;  // eye meshes in model coordinates, Transforms at identity
  double eyeTilt = 0.0;       // neutral rotation of the left eye Transform about z
  bool tonguePoints = true;   // binds 6.1, 6.2
  bool eyePoints = true;      // binds 3.5, 3.6
  bool eyesInHead = false;    // eye meshes held by Head itself, beside the skin
};

// Eye centres (before scaling).
const Eigen::Vector3d kLeftEye(0.03, 0.03, 0.0), kRightEye(-0.03, 0.03, 0.0);
const Eigen::Vector3d kNeck(0.0, -0.15, -0.05);
constexpr double kEyeRadius = 0.012;

// Transforms: Head (root, skin) with children EyeL, EyeR, UpperTeethX (upper teeth + gum),
// JawX (lower teeth + gum), TongueX. Upper and lower teeth touch (clenched).
FaceModel syntheticFace(const FaceSpec& spec = {}) {
  FaceModel m;
  const double s = spec.scale;
  const auto addMesh = [&](IndexedFaceSet mesh, int transform) {
    mesh.coord *= s;
    m.meshes.push_back(std::move(mesh));
    m.transforms[transform].meshes.push_back(static_cast<int>(m.meshes.size()) - 1);
    return static_cast<int>(m.meshes.size()) - 1;
  };
  const auto addTransform = [&](const std::string& name, int parent) {
    Transform t;
    t.name = name;
    m.transforms.push_back(t);
    const int index = static_cast<int>(m.transforms.size()) - 1;
    if (parent >= 0) m.transforms[parent].children.push_back(index);
    return index;
  };
  const int head = addTransform("Head", -1);
  m.roots = {head};
  // Skin: an 11 x 13 grid in front of everything, 9.15 and 2.2 on two of its vertices.
  IndexedFaceSet skin;
  skin.name = "Skin";
  constexpr int kCols = 11, kRows = 13;
  skin.coord.resize(kCols * kRows, 3);
  for (int i = 0; i < kRows; ++i) {
    for (int j = 0; j < kCols; ++j) {
      skin.coord.row(i * kCols + j) << -0.1 + 0.02 * j, -0.12 + 0.02 * i, 0.05;
      if (i + 1 < kRows && j + 1 < kCols) {
        const int v = i * kCols + j;
        skin.coordIndex.insert(skin.coordIndex.end(), {v, v + 1, v + kCols + 1, v + kCols, -1});
      }
    }
  }
  const int nose = 6 * kCols + 5, lip = 3 * kCols + 5;
  skin.coord.row(nose) << 0, 0, 0.05;
  skin.coord.row(lip) << 0, -spec.mns0, 0.05;
  const int skinMesh = addMesh(skin, head);
  m.featurePoints["9.15"] = {skinMesh, nose, Eigen::Vector3d::Zero()};
  m.featurePoints["2.2"] = {skinMesh, lip, Eigen::Vector3d::Zero()};
  // Eyes: spheres; 3.5 / 3.6 on the front pole (the pupil centre).
  for (int side = 0; side < 2; ++side) {
    const Eigen::Vector3d centre = side == 0 ? kLeftEye : kRightEye;
    const int t = spec.eyesInHead ? head : addTransform(side == 0 ? "EyeL" : "EyeR", head);
    int mesh;
    if (spec.eyesAtOrigin || spec.eyesInHead) {
      mesh = addMesh(sphere(side == 0 ? "EyeballL" : "EyeballR", centre, kEyeRadius), t);
    } else {
      m.transforms[t].translation = s * centre;
      IndexedFaceSet ball = sphere(side == 0 ? "EyeballL" : "EyeballR", {0, 0, 0}, kEyeRadius);
      if (side == 0) {
        // Tilted Transform, mesh counter-rotated: the same eye in model space.
        const Eigen::Quaterniond tilt(Eigen::AngleAxisd(spec.eyeTilt, Eigen::Vector3d::UnitZ()));
        m.transforms[t].rotation = tilt;
        for (int v = 0; v < ball.vertexCount(); ++v) {
          ball.coord.row(v) = (tilt.inverse() * ball.coord.row(v).transpose()).transpose();
        }
      }
      mesh = addMesh(ball, t);
    }
    if (spec.eyePoints)
      m.featurePoints[side == 0 ? "3.5" : "3.6"] = {mesh, 0, Eigen::Vector3d::Zero()};
  }
  // Teeth: upper y in [-0.045, -0.035], lower [-0.055, -0.045]; gums above / below.
  const int upper = addTransform("UpperTeethX", head);
  const int upperTeeth = addMesh(box("UpperTeeth", {0, -0.04, 0.02}, {0.015, 0.005, 0.005}), upper);
  addMesh(box("UpperGum", {0, -0.0325, 0.02}, {0.015, 0.0025, 0.005}), upper);
  const int jaw = addTransform("JawX", head);
  const int lowerTeeth = addMesh(box("LowerTeeth", {0, -0.05, 0.02}, {0.015, 0.005, 0.005}), jaw);
  addMesh(box("LowerGum", {0, -0.0575, 0.02}, {0.015, 0.0025, 0.005}), jaw);
  m.featurePoints["9.10"] = {upperTeeth, 4, Eigen::Vector3d::Zero()};  // bottom front corner
  m.featurePoints["9.11"] = {lowerTeeth, 6, Eigen::Vector3d::Zero()};  // top front corner
  const int tongueX = addTransform("TongueX", head);
  const int tongue = addMesh(box("Tongue", {0, -0.05, 0.0}, {0.01, 0.003, 0.012}), tongueX);
  if (spec.tonguePoints) {
    m.featurePoints["6.1"] = {tongue, 4, Eigen::Vector3d::Zero()};
    m.featurePoints["6.2"] = {tongue, 0, Eigen::Vector3d::Zero()};
  }
  m.featurePoints["7.2"] = {-1, -1, s * kNeck};
  m.validate();
  return m;
}

// A copy that moves nothing yet: the neutral's Transforms, for the test to change.
FaceShape copyOf(const FaceModel& neutral, const std::string& name) {
  FaceShape c;
  c.name = name;
  c.amplitude = 100;
  c.transforms = neutral.transforms;
  return c;
}

int transformIndex(const FaceModel& m, const std::string& name) {
  const auto t = m.findTransform(name);
  EXPECT_TRUE(t) << name;
  return t.value_or(0);
}

std::vector<std::string> meshNames(const FaceModel& m, const std::vector<int>& meshes) {
  std::vector<std::string> names;
  for (int mesh : meshes) names.push_back(m.meshes[mesh].name);
  std::sort(names.begin(), names.end());
  return names;
}

const RigidPart* findPart(const RigidPartMap& map, Kind kind) {
  for (const RigidPart& p : map.parts) {
    if (p.kind == kind) return &p;
  }
  return nullptr;
}

// Model-space vertex positions of one mesh.
Points3 worldPoints(const FaceModel& m, int mesh) {
  const Eigen::Affine3d w = m.meshWorldMatrices()[mesh];
  Points3 out(m.meshes[mesh].vertexCount(), 3);
  for (int v = 0; v < out.rows(); ++v) {
    out.row(v) = (w * m.meshes[mesh].coord.row(v).transpose()).transpose();
  }
  return out;
}

bool mentions(const std::vector<std::string>& warnings, const std::string& text) {
  return std::any_of(warnings.begin(), warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

// A source whose copies move every part: each eye turns, the head turns, the upper teeth,
// the jaw and the tongue translate.
std::vector<FaceShape> movingCopies(const FaceModel& source) {
  std::vector<FaceShape> copies;
  for (const char* eye : {"EyeL", "EyeR"}) {
    FaceShape c = copyOf(source, std::string("turn ") + eye);
    Transform& t = c.transforms[transformIndex(source, eye)];
    t.rotation = t.rotation * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY());
    copies.push_back(std::move(c));
  }
  for (const char* part : {"UpperTeethX", "JawX", "TongueX"}) {
    FaceShape c = copyOf(source, std::string("move ") + part);
    c.transforms[transformIndex(source, part)].translation += Eigen::Vector3d(0, -0.006, 0);
    copies.push_back(std::move(c));
  }
  FaceShape c = copyOf(source, "head yaw");
  c.transforms[transformIndex(source, "Head")].rotation =
      Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY());
  copies.push_back(std::move(c));
  return copies;
}

TEST(CloneRigid, FindsEveryPartsMeshesAndTransforms) {
  const FaceModel source = syntheticFace();
  FaceModel target = syntheticFace({.scale = 1.5, .mns0 = 0.04});
  const RigidPartMap map = matchRigidParts(source, movingCopies(source), target);
  EXPECT_TRUE(map.warnings.empty()) << map.warnings.front();
  struct Expected {
    Kind kind;
    std::string transform;
    std::vector<std::string> meshes;
  };
  const std::vector<Expected> expected = {
      {Kind::LeftEye, "EyeL", {"EyeballL"}},
      {Kind::RightEye, "EyeR", {"EyeballR"}},
      {Kind::UpperTeeth, "UpperTeethX", {"UpperGum", "UpperTeeth"}},
      {Kind::LowerTeeth, "JawX", {"LowerGum", "LowerTeeth"}},
      {Kind::Tongue, "TongueX", {"Tongue"}},
      {Kind::Head, "Head", {"EyeballL", "EyeballR", "LowerTeeth", "Skin", "Tongue", "UpperTeeth"}},
  };
  ASSERT_EQ(map.parts.size(), expected.size());
  for (const Expected& e : expected) {
    SCOPED_TRACE(std::string(rigidPartName(e.kind)));
    const RigidPart* part = findPart(map, e.kind);
    ASSERT_NE(part, nullptr);
    EXPECT_EQ(source.transforms[part->sourceTransform].name, e.transform);
    EXPECT_EQ(target.transforms[part->targetTransform].name, e.transform);
    EXPECT_EQ(meshNames(source, part->sourceMeshes), e.meshes);
    EXPECT_EQ(meshNames(target, part->targetMeshes), e.meshes);
  }
  const std::vector<std::string> rigid = {"EyeballL", "EyeballR", "LowerGum",  "LowerTeeth",
                                          "Tongue",   "UpperGum", "UpperTeeth"};
  EXPECT_EQ(meshNames(source, map.sourceRigidMeshes), rigid);
  EXPECT_EQ(meshNames(target, map.targetRigidMeshes), rigid);
}

TEST(CloneRigid, ClenchedTeethAreSeparatedByTheirFeaturePoints) {
  // Upper and lower teeth touch; each grows only over its own gum.
  const FaceModel source = syntheticFace();
  FaceModel target = source;
  const RigidPartMap map = matchRigidParts(source, movingCopies(source), target);
  const RigidPart* upper = findPart(map, Kind::UpperTeeth);
  const RigidPart* lower = findPart(map, Kind::LowerTeeth);
  ASSERT_TRUE(upper && lower);
  EXPECT_EQ(meshNames(source, upper->sourceMeshes),
            (std::vector<std::string>{"UpperGum", "UpperTeeth"}));
  EXPECT_EQ(meshNames(source, lower->sourceMeshes),
            (std::vector<std::string>{"LowerGum", "LowerTeeth"}));
  // The skin sharing a vertex with the upper gum is not taken either (it holds 2.2, 9.15).
  FaceModel touching = source;
  touching.meshes[0].coord.row(0) = touching.meshes[*touching.findMesh("UpperGum")].coord.row(7);
  FaceModel touchingTarget = touching;
  const RigidPartMap t = matchRigidParts(touching, movingCopies(touching), touchingTarget);
  ASSERT_NE(findPart(t, Kind::UpperTeeth), nullptr);
  EXPECT_EQ(meshNames(touching, findPart(t, Kind::UpperTeeth)->sourceMeshes),
            (std::vector<std::string>{"UpperGum", "UpperTeeth"}));
  // A bridge sharing corners with both teeth, holding no feature point, belongs to neither.
  FaceModel bridged = source;
  bridged.meshes.push_back(box("Bridge", {0.02, -0.045, 0.02}, {0.005, 0.01, 0.005}));
  bridged.transforms[0].meshes.push_back(static_cast<int>(bridged.meshes.size()) - 1);
  FaceModel bridgedTarget = bridged;
  const RigidPartMap b = matchRigidParts(bridged, movingCopies(bridged), bridgedTarget);
  EXPECT_EQ(meshNames(bridged, b.sourceRigidMeshes),
            (std::vector<std::string>{"EyeballL", "EyeballR", "LowerGum", "LowerTeeth", "Tongue",
                                      "UpperGum", "UpperTeeth"}));
}

TEST(CloneRigid, InstallsEyeAndNeckCentresWithoutMovingTheNeutral) {
  const FaceModel source = syntheticFace();
  const double s = 1.5;
  FaceModel target = syntheticFace({.scale = s, .eyesAtOrigin = true});
  const FaceModel before = target;
  const RigidPartMap map = matchRigidParts(source, movingCopies(source), target);
  ASSERT_EQ(map.parts.size(), 6u);
  for (int mesh = 0; mesh < static_cast<int>(target.meshes.size()); ++mesh) {
    EXPECT_TRUE(worldPoints(target, mesh).isApprox(worldPoints(before, mesh), 1e-12))
        << target.meshes[mesh].name;
  }
  // The pivot (parent world * (T + C)) is the eyeball centre and the neck base.
  const auto pivot = [&](const std::string& name) {
    const Transform& t = target.transforms[transformIndex(target, name)];
    const Eigen::Affine3d up =
        name == "Head" ? Eigen::Affine3d::Identity() : target.transforms[0].localMatrix();
    return Eigen::Vector3d(up * (t.translation + t.center));
  };
  EXPECT_LT((pivot("EyeL") - s * kLeftEye).norm(), 1e-9);
  EXPECT_LT((pivot("EyeR") - s * kRightEye).norm(), 1e-9);
  EXPECT_LT((pivot("Head") - s * kNeck).norm(), 1e-12);
  EXPECT_LT((findPart(map, Kind::LeftEye)->targetCentre - s * kLeftEye).norm(), 1e-9);
  // Before, the eye Transforms turned about the origin.
  EXPECT_EQ(before.transforms[transformIndex(before, "EyeL")].center, Eigen::Vector3d::Zero());
}

TEST(CloneRigid, EyeRotationIsClonedAsItIsAboutTheTargetEyeCentre) {
  // The source eye Transform is tilted in the neutral: its local y axis is not the model's.
  const double tilt = 0.5, angle = 0.3, s = 1.5;
  const FaceModel source = syntheticFace({.eyeTilt = tilt});
  FaceShape turn = copyOf(source, "turn");
  Transform& eye = turn.transforms[transformIndex(source, "EyeL")];
  eye.rotation = eye.rotation * Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY());
  FaceModel target = syntheticFace({.scale = s, .eyesAtOrigin = true});
  const std::vector<FaceShape> copies = {turn};
  const RigidPartMap map = matchRigidParts(source, copies, target);
  ASSERT_EQ(map.parts.size(), 1u);
  EXPECT_TRUE(map.warnings.empty());
  FaceModel moved = target;
  cloneRigidMotion(map, source, measureFapu(source), turn, target, measureFapu(target),
                   moved.transforms);
  // By hand: the model-space turn is Rz(tilt) Ry(angle) Rz(tilt)^-1 about the eye centre.
  const Eigen::Matrix3d rz = Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d expectedTurn =
      rz * Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix() * rz.transpose();
  const Eigen::Vector3d c = s * kLeftEye;
  const int ball = *target.findMesh("EyeballL");
  const Points3 p0 = worldPoints(target, ball), p1 = worldPoints(moved, ball);
  for (int v = 0; v < p0.rows(); ++v) {
    const Eigen::Vector3d want = c + expectedTurn * (p0.row(v).transpose() - c);
    EXPECT_LT((p1.row(v).transpose() - want).norm(), 1e-12) << v;
  }
  for (const char* other : {"EyeballR", "Skin", "LowerTeeth"}) {
    const int mesh = *target.findMesh(other);
    EXPECT_TRUE(worldPoints(moved, mesh).isApprox(worldPoints(target, mesh), 1e-12)) << other;
  }
}

TEST(CloneRigid, HeadTurnIsTheHeadsNotTheEyes) {
  // Only the head turns, about the origin; the eyes' own Transforms stay still.
  const FaceModel source = syntheticFace();
  FaceShape yaw = copyOf(source, "yaw");
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  yaw.transforms[0].rotation = Eigen::Quaterniond(r);
  const std::vector<FaceShape> copies = {yaw};
  const double s = 1.5;  // ES0 ratio too
  FaceModel target = syntheticFace({.scale = s});
  const FaceModel before = target;
  const RigidPartMap map = matchRigidParts(source, copies, target);
  ASSERT_EQ(map.parts.size(), 1u);
  EXPECT_EQ(map.parts[0].kind, Kind::Head);
  EXPECT_TRUE(map.warnings.empty());
  FaceModel moved = target;
  cloneRigidMotion(map, source, measureFapu(source), yaw, target, measureFapu(target),
                   moved.transforms);
  // By hand: turned about the neck 1.5 * n, the neck displaced by 1.5 (R n - n): for the
  // scaled face that is R p, a turn about the origin like the source's.
  for (int mesh = 0; mesh < static_cast<int>(moved.meshes.size()); ++mesh) {
    const Points3 p0 = worldPoints(before, mesh), p1 = worldPoints(moved, mesh);
    for (int v = 0; v < p0.rows(); ++v) {
      EXPECT_LT((p1.row(v).transpose() - r * p0.row(v).transpose()).norm(), 1e-12);
    }
  }
}

TEST(CloneRigid, InsertsATransformForEyesHeldWithTheSkin) {
  const FaceModel source = syntheticFace();
  FaceShape turn = copyOf(source, "turn");
  Transform& eye = turn.transforms[transformIndex(source, "EyeL")];
  eye.rotation = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX());
  const std::vector<FaceShape> copies = {turn};
  FaceModel target = syntheticFace({.eyesInHead = true});
  const FaceModel before = target;
  const RigidPartMap map = matchRigidParts(source, copies, target);
  ASSERT_EQ(map.parts.size(), 1u);
  const int inserted = map.parts[0].targetTransform;
  EXPECT_EQ(inserted, static_cast<int>(before.transforms.size()));
  EXPECT_EQ(target.transforms[inserted].name, "fmc_left_eye");
  const int ball = *target.findMesh("EyeballL");
  EXPECT_EQ(target.transforms[inserted].meshes, std::vector<int>{ball});
  const auto& headMeshes = target.transforms[0].meshes;
  EXPECT_EQ(std::count(headMeshes.begin(), headMeshes.end(), ball), 0);
  EXPECT_EQ(std::count(target.transforms[0].children.begin(), target.transforms[0].children.end(),
                       inserted),
            1);
  for (int mesh = 0; mesh < static_cast<int>(target.meshes.size()); ++mesh) {
    EXPECT_TRUE(worldPoints(target, mesh).isApprox(worldPoints(before, mesh), 1e-12));
  }
  FaceModel moved = target;
  cloneRigidMotion(map, source, measureFapu(source), turn, target, measureFapu(target),
                   moved.transforms);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Points3 p0 = worldPoints(target, ball), p1 = worldPoints(moved, ball);
  for (int v = 0; v < p0.rows(); ++v) {
    const Eigen::Vector3d want = kLeftEye + r * (p0.row(v).transpose() - kLeftEye);
    EXPECT_LT((p1.row(v).transpose() - want).norm(), 1e-12);
  }
  const int skin = *target.findMesh("Skin");
  EXPECT_TRUE(worldPoints(moved, skin).isApprox(worldPoints(target, skin), 1e-12));
}

TEST(CloneRigid, TeethAndTongueTranslationsScaleByMns0) {
  const FaceModel source = syntheticFace();                        // MNS0 = 0.03
  FaceModel target = syntheticFace({.scale = 1.5, .mns0 = 0.04});  // MNS0 = 1.5 * 0.04
  const double ratio = (1.5 * 0.04) / 0.03;                        // 2, not the size ratio 1.5
  FaceShape open = copyOf(source, "open jaw");
  const Eigen::Vector3d jawMove(0, -0.006, 0.001), tongueMove(0, 0, 0.004);
  open.transforms[transformIndex(source, "JawX")].translation += jawMove;
  open.transforms[transformIndex(source, "TongueX")].translation += tongueMove;
  const std::vector<FaceShape> copies = {open};
  const RigidPartMap map = matchRigidParts(source, copies, target);
  ASSERT_EQ(map.parts.size(), 2u);
  FaceModel moved = target;
  cloneRigidMotion(map, source, measureFapu(source), open, target, measureFapu(target),
                   moved.transforms);
  const auto shift = [&](const char* mesh) {
    const int m = *target.findMesh(mesh);
    const Points3 d = worldPoints(moved, m) - worldPoints(target, m);
    for (int v = 1; v < d.rows(); ++v) EXPECT_LT((d.row(v) - d.row(0)).norm(), 1e-12);
    return Eigen::Vector3d(d.row(0).transpose());
  };
  EXPECT_LT((shift("LowerTeeth") - ratio * jawMove).norm(), 1e-12);
  EXPECT_LT((shift("LowerGum") - ratio * jawMove).norm(), 1e-12);
  EXPECT_LT((shift("Tongue") - ratio * tongueMove).norm(), 1e-12);
  EXPECT_LT(shift("UpperTeeth").norm(), 1e-12);
  EXPECT_LT(shift("Skin").norm(), 1e-12);
  // Without MNS0 in either face the size ratio (1.5) scales instead.
  FaceModel unmeasured = target;
  FapuMeasurement none;
  unmeasured = target;
  cloneRigidMotion(map, source, none, open, target, none, unmeasured.transforms);
  const int lower = *target.findMesh("LowerTeeth");
  const Points3 d = worldPoints(unmeasured, lower) - worldPoints(target, lower);
  EXPECT_LT((d.row(0).transpose() - 1.5 * jawMove).norm(), 1e-12);
}

TEST(CloneRigid, MissingPartIsSkippedWithAWarning) {
  const FaceModel source = syntheticFace();
  FaceShape c = copyOf(source, "tongue and jaw");
  c.transforms[transformIndex(source, "TongueX")].translation += Eigen::Vector3d(0, 0, 0.004);
  c.transforms[transformIndex(source, "JawX")].translation += Eigen::Vector3d(0, -0.004, 0);
  const std::vector<FaceShape> copies = {c};
  // Target without tongue feature points: the tongue's motion is skipped, the jaw's is not.
  FaceModel target = syntheticFace({.tonguePoints = false});
  const RigidPartMap map = matchRigidParts(source, copies, target);
  ASSERT_EQ(map.parts.size(), 1u);
  EXPECT_EQ(map.parts[0].kind, Kind::LowerTeeth);
  ASSERT_EQ(map.warnings.size(), 1u);
  EXPECT_TRUE(mentions(map.warnings, "tongue")) << map.warnings[0];
  EXPECT_TRUE(mentions(map.warnings, "6.1")) << map.warnings[0];
  FaceModel moved = target;
  cloneRigidMotion(map, source, measureFapu(source), c, target, measureFapu(target),
                   moved.transforms);
  const int tongue = *target.findMesh("Tongue"), lower = *target.findMesh("LowerTeeth");
  EXPECT_TRUE(worldPoints(moved, tongue).isApprox(worldPoints(target, tongue), 1e-12));
  EXPECT_FALSE(worldPoints(moved, lower).isApprox(worldPoints(target, lower), 1e-6));

  // Source without eye feature points but a moving eye Transform: warned, skipped.
  const FaceModel blind = syntheticFace({.eyePoints = false});
  FaceShape look = copyOf(blind, "look");
  look.transforms[transformIndex(blind, "EyeL")].rotation =
      Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY());
  FaceModel target2 = syntheticFace();
  const std::vector<FaceShape> looks = {look};
  const RigidPartMap m2 = matchRigidParts(blind, looks, target2);
  EXPECT_TRUE(m2.parts.empty());
  ASSERT_EQ(m2.warnings.size(), 1u);
  EXPECT_TRUE(mentions(m2.warnings, "'EyeL'")) << m2.warnings[0];
}

// CANDIDE-like: one mesh holding every feature point under one Transform.
FaceModel oneMeshFace() {
  FaceModel m;
  IndexedFaceSet mesh = box("Candide", {0, 0, 0}, {0.1, 0.12, 0.05});
  m.addMeshWithTransform(mesh);
  const char* ids[] = {"3.5", "3.6", "9.10", "9.11", "6.1", "9.15", "2.2", "7.2"};
  for (int i = 0; i < 8; ++i) m.featurePoints[ids[i]] = {0, i, Eigen::Vector3d::Zero()};
  return m;
}

TEST(CloneRigid, OneMeshFaceHasNoRigidParts) {
  const FaceModel source = oneMeshFace();
  FaceShape smile = copyOf(source, "smile");
  smile.transforms.clear();  // vertex motion only
  smile.meshes.push_back({0, {0}, Points3(Eigen::RowVector3d(0.01, 0, 0))});
  FaceModel target = oneMeshFace();
  const std::vector<FaceShape> copies = {smile};
  const RigidPartMap map = matchRigidParts(source, copies, target);
  EXPECT_TRUE(map.parts.empty());
  EXPECT_TRUE(map.sourceRigidMeshes.empty());
  EXPECT_TRUE(map.targetRigidMeshes.empty());
  EXPECT_TRUE(map.warnings.empty());
  // The synthetic eyes onto the one-mesh face: no separate eye there, so a warning.
  const FaceModel eyes = syntheticFace();
  FaceShape look = copyOf(eyes, "look");
  look.transforms[transformIndex(eyes, "EyeL")].rotation =
      Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY());
  const std::vector<FaceShape> looks = {look};
  const RigidPartMap m2 = matchRigidParts(eyes, looks, target);
  EXPECT_TRUE(m2.parts.empty());
  ASSERT_EQ(m2.warnings.size(), 1u);
  EXPECT_TRUE(mentions(m2.warnings, "left eye")) << m2.warnings[0];
  EXPECT_TRUE(mentions(m2.warnings, "also holds")) << m2.warnings[0];
}

TEST(CloneRigid, MakeHumanGroupsAreFoundFromAFewFeaturePoints) {
  FaceModel human = readModel(test::kData / "makehuman" / "base.obj");
  // Bind a few points by picking vertices of the groups: the front-most (largest z) vertex of
  // each eye and of the tongue, the lowest of the upper teeth, the highest of the lower teeth.
  const auto pick = [&](const char* id, const char* group, int axis, bool largest) {
    const int mesh = *human.findMesh(group);
    const auto& c = human.meshes[mesh].coord.col(axis);
    Eigen::Index v;
    largest ? c.maxCoeff(&v) : c.minCoeff(&v);
    human.featurePoints[id] = {mesh, static_cast<int>(v), Eigen::Vector3d::Zero()};
  };
  pick("3.5", "helper-l-eye", 2, true);
  pick("3.6", "helper-r-eye", 2, true);
  pick("9.10", "helper-upper-teeth", 1, false);
  pick("9.11", "helper-lower-teeth", 1, true);
  pick("6.1", "helper-tongue", 2, true);
  pick("9.15", "body", 2, true);
  human.featurePoints["7.2"] = {-1, -1, {0, 6.0, 0}};
  const FaceModel source = syntheticFace();
  FaceShape turn = copyOf(source, "turn");
  const double angle = 0.25;
  turn.transforms[transformIndex(source, "EyeL")].rotation =
      Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX());
  const std::vector<FaceShape> copies = {turn};
  FaceModel target = human;
  const RigidPartMap map = matchRigidParts(source, copies, target);
  EXPECT_TRUE(map.warnings.empty()) << map.warnings.front();
  EXPECT_EQ(meshNames(target, map.targetRigidMeshes),
            (std::vector<std::string>{"helper-l-eye", "helper-lower-teeth", "helper-r-eye",
                                      "helper-tongue", "helper-upper-teeth"}));
  ASSERT_EQ(map.parts.size(), 1u);
  const RigidPart& eye = map.parts[0];
  EXPECT_EQ(target.transforms[eye.targetTransform].name, "helper-l-eye");
  // The eyeball centre: inside the eye, near its bounding-box centre (the helper is a
  // sphere-like cage, 0.28 units across).
  Eigen::AlignedBox3d bounds;
  const Points3 p0 = worldPoints(human, *human.findMesh("helper-l-eye"));
  for (int v = 0; v < p0.rows(); ++v) bounds.extend(p0.row(v).transpose());
  EXPECT_LT((eye.targetCentre - bounds.center()).norm(), 0.02) << eye.targetCentre.transpose();
  FaceModel moved = target;
  cloneRigidMotion(map, source, measureFapu(source), turn, target, measureFapu(target),
                   moved.transforms);
  const Points3 p1 = worldPoints(moved, *human.findMesh("helper-l-eye"));
  const Eigen::Matrix3d r = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (int v = 0; v < p0.rows(); ++v) {
    const Eigen::Vector3d want = eye.targetCentre + r * (p0.row(v).transpose() - eye.targetCentre);
    EXPECT_LT((p1.row(v).transpose() - want).norm(), 1e-9) << v;
  }
}

}  // namespace
