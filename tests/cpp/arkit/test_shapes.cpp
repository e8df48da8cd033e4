// SPDX-License-Identifier: GPL-3.0-or-later
// ARKit shapes -> FAP keys: name matching, the NNLS mapping on a head whose answer is known
// (arkit_test_head.hpp), left/right separation, eyeball turns, and the keys made.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "arkit_test_head.hpp"
#include "mpeg4face/arkit/shapes.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/fit/fit.hpp"
#include "mpeg4face/fit/presets.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

namespace {

using namespace mpeg4face;
using mpeg4face::test::addTestShape;
using mpeg4face::test::arkitTestHead;
using mpeg4face::test::arkitTestHeadWithShapes;

// The key of FAP `fap` with the sign of `sign`, or nullptr.
const ArkitFapKey* findKey(const ArkitMapping& mapping, int fap, int sign) {
  for (const ArkitFapKey& k : mapping.keys) {
    if (k.fap == fap && (k.amplitude > 0) == (sign > 0)) return &k;
  }
  return nullptr;
}

// The weight of the shape named `name` in a key (0 if it has none).
double weightOf(const ArkitFapKey& key, const ArkitShapes& shapes, const std::string& name) {
  for (const auto& [shape, weight] : key.weights) {
    if (shapes.shapes[static_cast<std::size_t>(shape)].name == name) return weight;
  }
  return 0;
}

const ArkitShapes& testShapes() {
  static const ArkitShapes shapes = findArkitShapes(arkitTestHeadWithShapes());
  return shapes;
}
const ArkitMapping& testMapping() {
  static const FaceModel head = arkitTestHeadWithShapes();
  static const ArkitMapping mapping = mapArkitToFaps(head, testShapes(), measureFapu(head));
  return mapping;
}

TEST(Arkit, NamesAreLiveLinksColumnsSpelledAsApple) {
  const auto names = arkitShapeNames();
  ASSERT_EQ(names.size(), 52u);
  EXPECT_EQ(names.front(), "eyeBlinkLeft");
  EXPECT_EQ(names[17], "jawOpen");
  EXPECT_EQ(names.back(), "tongueOut");
  EXPECT_EQ(arkitKnownShapeNames().size(), 56u);
  EXPECT_EQ(arkitKnownShapeNames()[54], "pupilDilateLeft");
}

TEST(Arkit, MatchesTheUsualSpellings) {
  struct Case {
    const char* name;
    int shape;  // -1: not an ARKit shape
    FaceSide half = FaceSide::Centre;
  };
  const Case cases[] = {
      {"eyeBlinkLeft", 0},
      {"eyeBlink_L", 0},
      {"EyeBlinkLeft", 0},
      {"blendShape1.eyeBlinkLeft", 0},
      {"eye_blink_left", 0},
      {"EYEBLINK.L", 0},
      {"Face:eyeBlink_L", 0},
      {"eyeBlinkRight", 7},
      {"eyeBlink_R", 7},
      {"jawOpen", 17},
      {"JawOpen", 17},
      {"jaw_left", 16},
      {"mouthLeft", 22},
      {"browInnerUp_L", 43, FaceSide::Left},
      {"browInnerUp_R", 43, FaceSide::Right},
      {"cheekPuff_R", 46, FaceSide::Right},
      {"tongueOut", 51},
      {"cheekRaiser_L", 52},
      {"PupilDilate_R", 55},
      {"eyeBlink", -1},
      {"fap3_open_jaw@100", -1},
      {"jawOpen_X", -1},
      {"", -1},
      {"_L", -1},
      {"eyeBlinkLeft_L", -1},
  };
  for (const Case& c : cases) {
    const std::optional<ArkitShapeRef> ref = arkitShapeIndex(c.name);
    if (c.shape < 0) {
      EXPECT_FALSE(ref) << c.name;
      continue;
    }
    ASSERT_TRUE(ref) << c.name;
    EXPECT_EQ(ref->shape, c.shape) << c.name;
    EXPECT_EQ(ref->half, c.half) << c.name;
  }
  EXPECT_EQ(arkitShapeSide({16}), FaceSide::Centre);  // jawLeft moves the whole jaw
  EXPECT_EQ(arkitShapeSide({0}), FaceSide::Left);
  EXPECT_EQ(arkitShapeSide({43, FaceSide::Right}), FaceSide::Right);
  EXPECT_EQ(arkitShapeLabel({43, FaceSide::Left}), "browInnerUp (left half)");
}

TEST(Arkit, FindsTheShapesInOrderAndRefusesAHeadWithout) {
  const ArkitShapes& shapes = testShapes();
  ASSERT_EQ(shapes.shapes.size(), 8u);
  EXPECT_EQ(shapes.shapes[0].name, "eyeBlink_L");
  EXPECT_EQ(shapes.shapes[1].name, "jawOpen");
  EXPECT_TRUE(shapes.find({43, FaceSide::Left}));
  EXPECT_FALSE(shapes.find({43}));

  try {
    findArkitShapes(arkitTestHead());
    FAIL() << "a head without ARKit shapes";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "morph targets");
    for (const char* name : {"eyeBlinkLeft", "jawOpen", "tongueOut", "pupilDilateLeft"}) {
      EXPECT_NE(e.reason().find(name), std::string::npos) << e.what();
    }
  }
  FaceModel twice = arkitTestHeadWithShapes();
  addTestShape(twice, "eyeBlinkLeft", {});
  EXPECT_THROW(findArkitShapes(twice), Error);
}

TEST(Arkit, NnlsSolvesAndKeepsWeightsNonNegative) {
  Eigen::MatrixXd a(3, 2);
  a << 1, 0, 0, 1, 1, 1;
  // Unconstrained: x = (2, -1); with x >= 0 the best is (1.5, 0).
  const Eigen::VectorXd x = nonNegativeLeastSquares(a, Eigen::Vector3d(2, -1, 1));
  EXPECT_NEAR(x(0), 1.5, 1e-12);
  EXPECT_EQ(x(1), 0.0);
  const Eigen::VectorXd exact = nonNegativeLeastSquares(a, Eigen::Vector3d(1, 2, 3));
  EXPECT_NEAR(exact(0), 1, 1e-12);
  EXPECT_NEAR(exact(1), 2, 1e-12);
}

TEST(Arkit, MappingFindsTheKnownCombinations) {
  const ArkitMapping& mapping = testMapping();
  const ArkitShapes& shapes = testShapes();
  // FAP 3: jawOpen alone (2.3 rides with the jaw), at full weight: 10 mm = 341 MNS units.
  const ArkitFapKey* jaw = findKey(mapping, 3, 1);
  ASSERT_TRUE(jaw);
  EXPECT_EQ(jaw->amplitude, 341);
  ASSERT_EQ(jaw->weights.size(), 1u);
  EXPECT_NEAR(weightOf(*jaw, shapes, "jawOpen"), 341 / 341.333, 1e-6);
  EXPECT_LT(jaw->residual, 1e-3);
  // FAP 12: smile and press together cancel the sideways motion: straight up 4 mm.
  const ArkitFapKey* corner = findKey(mapping, 12, 1);
  ASSERT_TRUE(corner);
  EXPECT_NEAR(corner->amplitude, 136, 1);
  EXPECT_NEAR(weightOf(*corner, shapes, "mouthSmile_L"), 1, 0.03);
  EXPECT_NEAR(weightOf(*corner, shapes, "mouthPress_L"), 1, 0.1);
  EXPECT_LT(corner->residual, 0.05);
  EXPECT_GT(corner->reached, 0.95);
  // Eyelid and brow halves.
  const ArkitFapKey* lid = findKey(mapping, 19, 1);
  ASSERT_TRUE(lid);
  EXPECT_EQ(lid->amplitude, 853);
  const ArkitFapKey* brow = findKey(mapping, 32, 1);
  ASSERT_TRUE(brow);
  EXPECT_EQ(brow->amplitude, 102);
  EXPECT_GT(weightOf(*brow, shapes, "browInnerUp_R"), 0.99);
  // Nothing lowers the lid: the other sign is missed with its reason.
  EXPECT_FALSE(findKey(mapping, 19, -1));
  const auto missed = [&](int fap, int sign) {
    return std::any_of(mapping.missed.begin(), mapping.missed.end(), [&](const ArkitMissedFap& m) {
      return m.fap == fap && m.sign == sign && !m.reason.empty();
    });
  };
  EXPECT_TRUE(missed(19, -1));
  EXPECT_TRUE(missed(27, 0));  // eyeball thrust
  EXPECT_TRUE(missed(23, 1));  // no eyeball mesh under its own Transform
  EXPECT_TRUE(missed(48, 0));  // head pitch
  EXPECT_TRUE(missed(44, 0));  // 6.1 is not bound
  EXPECT_TRUE(missed(29, 0));  // no pupilDilate
}

TEST(Arkit, LeftFapsUseNoRightShapes) {
  const ArkitMapping& mapping = testMapping();
  const ArkitShapes& shapes = testShapes();
  // mouthPress_R drags 2.4 right too, but FAP 12 is the left corner's.
  for (const ArkitFapKey& key : mapping.keys) {
    const FapInfo& info = fapInfo(key.fap);
    const bool left = std::string_view(info.name).find("_l_") != std::string_view::npos;
    const bool right = std::string_view(info.name).find("_r_") != std::string_view::npos;
    for (const auto& [shape, weight] : key.weights) {
      const FaceSide side = arkitShapeSide(shapes.shapes[static_cast<std::size_t>(shape)].ref);
      if (left) {
        EXPECT_NE(side, FaceSide::Right) << info.name;
      }
      if (right) {
        EXPECT_NE(side, FaceSide::Left) << info.name;
      }
    }
  }
  const ArkitFapKey* mirrored = findKey(mapping, 13, 1);
  ASSERT_TRUE(mirrored);
  EXPECT_NEAR(mirrored->amplitude, 136, 1);
}

// depress_chin raises the chin boss 2.10, and the chin's bottom 2.1 and the lower lip ride on
// it: the key is the shape that does that (mouthShrugLower), not one with mouthLowerDown
// holding the lip still and jawOpen the chin's bottom.
TEST(Arkit, TheChinsRaiseCarriesTheLowerLip) {
  FaceModel head = arkitTestHead();
  IndexedFaceSet& skin = head.meshes[0];
  const int v = static_cast<int>(skin.coord.rows());
  skin.coord.conservativeResize(v + 2, 3);
  skin.coord.row(v) << 0, -0.058, 0.092;      // 8.2, below 2.3
  skin.coord.row(v + 1) << 0, -0.075, 0.088;  // 2.10, above the chin 2.1
  skin.coordIndex.insert(skin.coordIndex.end(), {0, v, v + 1, -1});
  head.featurePoints["8.2"] = {0, v, Eigen::Vector3d::Zero()};
  head.featurePoints["2.10"] = {0, v + 1, Eigen::Vector3d::Zero()};
  const auto V = [](double x, double y, double z) { return Eigen::Vector3d(x, y, z); };
  addTestShape(head, "mouthShrugLower",
               {{"2.10", V(0, 0.004, 0)},
                {"2.1", V(0, 0.003, 0)},
                {"8.2", V(0, 0.003, 0)},
                {"2.3", V(0, 0.002, 0)}});
  addTestShape(head, "jawOpen", {{"2.1", V(0, -0.01, 0)}, {"2.3", V(0, -0.01, 0)}});
  addTestShape(head, "mouthLowerDown_L", {{"8.2", V(0, -0.0015, 0)}, {"2.3", V(0, -0.001, 0)}});
  addTestShape(head, "mouthLowerDown_R", {{"8.2", V(0, -0.0015, 0)}, {"2.3", V(0, -0.001, 0)}});
  const ArkitKeys keys = arkitFapKeys(head);
  const ArkitFapKey* chin = findKey(keys.mapping, 18, 1);
  ASSERT_TRUE(chin);
  EXPECT_NEAR(chin->amplitude, 136, 1);  // 4 mm in MNS units (MNS0 / 1024 = 0.0293 mm)
  ASSERT_EQ(chin->weights.size(), 1u);
  EXPECT_EQ(keys.shapes.shapes[static_cast<std::size_t>(chin->weights[0].first)].name,
            "mouthShrugLower");
  // The lip FAPs still hold the chin still: mouthShrugLower raises 2.10 more than 8.2, so
  // raise_b_midlip_o has no key, while lowering 8.2 is mouthLowerDown's.
  EXPECT_FALSE(findKey(keys.mapping, 52, 1));
  const ArkitFapKey* lip = findKey(keys.mapping, 52, -1);
  ASSERT_TRUE(lip);
  EXPECT_EQ(weightOf(*lip, keys.shapes, "mouthShrugLower"), 0);
}

TEST(Arkit, WorksOnASubset) {
  FaceModel head = arkitTestHead();
  addTestShape(head, "blendShape1.jawOpen", {{"2.1", {0, -0.01, 0}}, {"2.3", {0, -0.01, 0}}});
  const ArkitKeys keys = arkitFapKeys(head);
  ASSERT_EQ(keys.shapes.shapes.size(), 1u);
  ASSERT_TRUE(findKey(keys.mapping, 3, 1));
  EXPECT_GT(keys.mapping.missed.size(), 50u);
}

TEST(Arkit, EyeballTurnsAreRotationsOfTheEyesTransform) {
  FaceModel head = arkitTestHeadWithShapes();
  // A left eyeball: a ring of points about its centre, under its own Transform there.
  IndexedFaceSet eye;
  eye.name = "eye_left";
  eye.coord.resize(12, 3);
  for (int i = 0; i < 12; ++i) {
    const double a = 2 * M_PI * i / 12;
    eye.coord.row(i) << 0.012 * std::cos(a), 0.012 * std::sin(a), 0.004 * (i % 3);
  }
  eye.coordIndex = {0, 4, 8, -1};
  const int mesh = head.addMeshWithTransform(eye);
  head.transforms.back().translation = {0.03, 0.03, 0.07};
  head.featurePoints["3.5"] = {mesh, 0, Eigen::Vector3d::Zero()};
  // eyeLookOut_L turns it 0.3 rad to the left (about +y); eyeLookUp_L moves the lid only.
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
  MorphTarget look{"eyeLookOut_L", Points3(12, 3)};
  for (int i = 0; i < 12; ++i) {
    look.displacements.row(i) =
        (turn * eye.coord.row(i).transpose() - eye.coord.row(i).transpose()).transpose();
  }
  head.meshes[static_cast<std::size_t>(mesh)].morphTargets.push_back(look);
  addTestShape(head, "eyeLookOut_L", {{"3.1", {0.001, 0, 0}}});
  addTestShape(head, "eyeLookUp_L", {{"3.1", {0, 0.002, 0}}});
  const ArkitKeys keys = arkitFapKeys(head, {false, false});
  const ArkitFapKey* yaw = findKey(keys.mapping, 23, 1);
  ASSERT_TRUE(yaw);
  EXPECT_EQ(yaw->amplitude, 30000);  // 0.3 rad in AU
  EXPECT_EQ(yaw->transform, static_cast<int>(head.transforms.size()) - 1);
  EXPECT_LT(yaw->residual, 1e-6);
  EXPECT_NEAR(Eigen::AngleAxisd(yaw->rotation).angle(), 0.3, 1e-9);
  // eyeLookUp does not turn this eyeball: the nominal 0.44 rad, negative pitch (up).
  const ArkitFapKey* up = findKey(keys.mapping, 25, -1);
  ASSERT_TRUE(up);
  EXPECT_EQ(up->amplitude, -44000);
  // The key is a pose of the eye's Transform plus the lid's motion, under one name.
  const std::string name = "fap23_yaw_l_eyeball@30000";
  const auto pose = std::find_if(keys.head.animations.begin(), keys.head.animations.end(),
                                 [&](const MorphWeightAnimation& a) { return a.name == name; });
  ASSERT_NE(pose, keys.head.animations.end());
  ASSERT_EQ(pose->transformChannels.size(), 1u);
  EXPECT_EQ(pose->transformChannels[0].path, TransformChannel::Path::Rotation);
  const auto& skinTargets = keys.head.meshes[0].morphTargets;
  EXPECT_TRUE(std::any_of(skinTargets.begin(), skinTargets.end(),
                          [&](const MorphTarget& t) { return t.name == name; }));
  for (const MorphTarget& t : keys.head.meshes[static_cast<std::size_t>(mesh)].morphTargets) {
    EXPECT_NE(t.name, name) << "the eyeball turns by its Transform, not by a morph target";
  }
}

TEST(Arkit, KeysAreInTheGrammarAndReplaceOldOnes) {
  FaceModel head = arkitTestHeadWithShapes();
  addTestShape(head, "fap3_open_jaw@100", {{"2.1", {0, -0.001, 0}}});
  head.animations.push_back({"viseme1", {}, {}});
  const ArkitKeys keys = arkitFapKeys(head);
  std::set<std::string> names;
  for (const MorphTarget& t : keys.head.meshes[0].morphTargets) {
    if (arkitShapeIndex(t.name)) continue;
    ASSERT_NO_THROW(parseShapeKeyName(t.name)) << t.name;
    ASSERT_TRUE(parseShapeKeyName(t.name)) << t.name;
    names.insert(t.name);
  }
  EXPECT_TRUE(names.contains("fap3_open_jaw@341"));
  EXPECT_TRUE(names.contains("fap12_raise_l_cornerlip@" +
                             std::to_string(findKey(keys.mapping, 12, 1)->amplitude)));
  EXPECT_FALSE(names.contains("fap3_open_jaw@100"));
  EXPECT_TRUE(std::any_of(names.begin(), names.end(),
                          [](const std::string& n) { return n.starts_with("viseme"); }));
  EXPECT_TRUE(names.contains("expression6_surprise"));
  for (const MorphWeightAnimation& a : keys.head.animations) EXPECT_NE(a.name, "viseme1");
  // Ready for the tables: every FAP key reproduces its feature point's motion.
  const ShapeKeyFace face = faceFromShapeKeys(keys.head);
  EXPECT_EQ(face.copies, names.size());
}

TEST(Arkit, VisemeKeysAreShapesNearEachVisemeAloneFromTheNeutral) {
  const ArkitKeys keys = arkitFapKeys(arkitTestHeadWithShapes());
  const std::vector<MorphTarget>& targets = keys.head.meshes[0].morphTargets;
  const int chin = keys.head.featurePoints.at("2.1").vertex;
  // The chin's motion in each FAP key, by FAP and sign: (amplitude, motion); not the copies
  // that hold it past its reach.
  std::map<std::pair<int, bool>, std::pair<int, double>> keyed;
  for (const MorphTarget& t : targets) {
    const std::optional<ShapeKeyName> k = parseShapeKeyName(t.name);
    if (k && k->fapID >= 3 && !k->label.ends_with("_reach") && !k->label.ends_with("_held"))
      keyed[{k->fapID, k->amplitude > 0}] = {k->amplitude, t.displacements(chin, 1)};
  }
  // The viseme keys are made from the area FAPs' keys localised by Shepard's inverse-square
  // shares over the area FAPs' feature points (docs/arkit.md): the chin's share of each.
  const auto isArea = [](int f) {
    return (f >= 4 && f <= 13) || (f >= 16 && f <= 18) || (f >= 31 && f <= 42) ||
           (f >= 51 && f <= 64);
  };
  const Eigen::RowVector3d chinAt = keys.head.meshes[0].coord.row(chin);
  std::map<std::string, double> inverseSquare;
  double total = 0;
  for (int f = 3; f <= kFapCount; ++f) {
    const std::string id(fapInfo(f).featurePoint);
    const auto b = keys.head.featurePoints.find(id);
    if (!isArea(f) || b == keys.head.featurePoints.end() || b->second.mesh != 0 ||
        inverseSquare.contains(id)) {
      continue;
    }
    inverseSquare[id] =
        1 / (keys.head.meshes[0].coord.row(b->second.vertex) - chinAt).squaredNorm();
    total += inverseSquare[id];
  }
  const auto share = [&](int f) {
    return isArea(f) ? inverseSquare.at(std::string(fapInfo(f).featurePoint)) / total : 1.0;
  };
  // The shapes' displacements on the mesh, one column each.
  const ArkitShapes found = findArkitShapes(keys.head);
  Eigen::MatrixXd shapes = Eigen::MatrixXd::Zero(3 * keys.head.meshes[0].vertexCount(),
                                                 static_cast<Eigen::Index>(found.shapes.size()));
  for (std::size_t c = 0; c < found.shapes.size(); ++c) {
    for (const ArkitTarget& t : found.shapes[c].targets) {
      if (t.mesh == 0)
        shapes.col(static_cast<Eigen::Index>(c)) =
            targets[static_cast<std::size_t>(t.target)].displacements.reshaped<Eigen::RowMajor>();
    }
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> shapesQr(shapes);
  const FitTable fit = visemeFitTable();
  int moving = 0;
  for (int v = 1; v <= 14; ++v) {
    // What the preset gives viseme v alone (and the left/right partners of it), through the
    // FAP keys' linear tables: nothing of viseme v - 1 may be held.
    FapFrame frame;
    frame.mask.set(0);
    frame.viseme = {v, 0, 63, false};
    interpolateFitFrame(fit, frame);
    FapState state;
    applyFrame(state, frame);
    // Each FAP through its key's linear table, held at the key's amplitude (the shapes reach
    // no further), 0 on a side without a key.
    double expected = 0;
    for (int f = 3; f <= kFapCount; ++f) {
      if (!state.has(f) || state.value(f) == 0) continue;
      const auto it = keyed.find({f, state.value(f) > 0});
      if (it == keyed.end()) continue;
      const auto [amplitude, motion] = it->second;
      expected +=
          std::min(1.0, static_cast<double>(state.value(f)) / amplitude) * motion * share(f);
    }
    const std::string name = "viseme" + std::to_string(v);
    const auto key = std::find_if(targets.begin(), targets.end(),
                                  [&](const MorphTarget& t) { return t.name == name; });
    if (expected == 0) continue;
    ASSERT_NE(key, targets.end()) << name;
    // The key is made of the head's ARKit shapes (the combination nearest to that motion
    // over the whole head, weights 0..1: docs/arkit.md), so the chin moves the same way as
    // through the FAP keys but not by the same amount: within 60% on this test head, whose
    // five shapes fit a viseme only roughly (the sample heads' visemes: test_samples.py).
    EXPECT_NEAR(key->displacements(chin, 1), expected, 0.6 * std::abs(expected)) << name;
    const Eigen::VectorXd made = key->displacements.reshaped<Eigen::RowMajor>();
    EXPECT_LT((shapes * shapesQr.solve(made) - made).norm(), 1e-9 * made.norm())
        << name << " is not a combination of the shapes";
    ++moving;
  }
  EXPECT_GT(moving, 3);
}

}  // namespace
