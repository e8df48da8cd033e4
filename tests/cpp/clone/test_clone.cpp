// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <numbers>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "clone/clone_internal.hpp"
#include "fat_test_face.hpp"
#include "mpeg4face/clone/clone.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/obj.hpp"
#include "mpeg4face/io/wfm.hpp"
#include "mpeg4face/spec.hpp"
#include "test_support.hpp"

using namespace mpeg4face;
using mpeg4face::test::errorOf;

namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

struct Candide {
  CandideModel file;
  FaceModel neutral;
};

Candide candide() {
  const std::filesystem::path dir = mpeg4face::test::kData / "candide3";
  Candide c{readWfm(dir / "candide3.wfm"), {}};
  c.neutral = c.file.model;
  c.neutral.featurePoints =
      readFeaturePointCsv(dir / "feature_points.csv", c.neutral).featurePoints;
  return c;
}

// CANDIDE's MPEG-4 action units as copies at `amplitude`, moved as the file says (a unit's
// displacement is in its FAPU: docs/fat.md).
std::vector<FaceShape> candideCopies(const Candide& c, int amplitude) {
  const FapuMeasurement fapu = measureFapu(c.neutral);
  std::vector<FaceShape> copies;
  for (const CandideUnit& u : c.file.animationUnits) {
    if (u.fap == 0) continue;
    double unit = fapu.unit(fapInfo(u.fap).fapu);
    for (const FapuInfo& info : fapuTable()) {
      if (info.name == u.fapu) unit = fapu.unit(info.kind);
    }
    FaceShape& copy = copies.emplace_back();
    copy.name = u.name;
    copy.fapID = u.fap;
    copy.amplitude = amplitude;
    Points3 motion = Points3::Zero(c.neutral.meshes[0].coord.rows(), 3);
    for (std::size_t i = 0; i < u.vertices.size(); ++i) {
      motion.row(u.vertices[i]) +=
          amplitude * unit * u.displacements.row(static_cast<Eigen::Index>(i));
    }
    copy.meshes.push_back(sparseDisplacement(0, motion));
  }
  return copies;
}

Points3 motionOf(const FaceShape& copy, const FaceModel& neutral, int mesh = 0) {
  return denseDisplacement(copy, mesh,
                           neutral.meshes[static_cast<std::size_t>(mesh)].vertexCount());
}

const FaceShape& copyOf(std::span<const FaceShape> copies, int fap) {
  return *std::find_if(copies.begin(), copies.end(),
                       [&](const FaceShape& c) { return c.fapID == fap; });
}

double maxRowNorm(const Points3& p) { return p.rows() == 0 ? 0.0 : p.rowwise().norm().maxCoeff(); }

}  // namespace

TEST(Clone, MappingDoesNotNeedEyeCentres) {
  const auto ids = cloneFeaturePoints();
  for (const char* rigidOnly : {"3.5", "3.6", "7.2"}) {
    EXPECT_EQ(std::find(ids.begin(), ids.end(), rigidOnly), ids.end()) << rigidOnly;
  }
  const Candide c = candide();
  EXPECT_FALSE(c.neutral.featurePointPosition("3.5"));
  EXPECT_TRUE(missingCloneFeaturePoints(c.neutral).empty());
}

// Quality (a): a head cloned onto itself, and onto a copy scaled and moved, gets its own
// motion back: every one of CANDIDE's 54 MPEG-4 units, the eyes' too (the eyeballs lie under
// the lids in CANDIDE's one mesh: a target vertex at a source vertex's place takes that
// vertex's motion, not the outer surface's).
TEST(Clone, CloningAHeadOntoItselfReproducesItsMotion) {
  const Candide c = candide();
  const std::vector<FaceShape> copies = candideCopies(c, 600);
  ASSERT_EQ(copies.size(), 54u);
  const double s = 2.5;
  FaceModel moved = c.neutral;
  moved.meshes[0].coord = (moved.meshes[0].coord * s).rowwise() + Eigen::RowVector3d(1, -2, 3);
  // Default options (the adaptive filter: a face is as dense as itself, so nothing is
  // filtered), the filter off, and the paper's fixed filter, which blurs single-vertex peaks
  // and is printed for comparison only.
  CloneOptions off, fixed;
  off.filterSupport = 0;
  fixed.adaptiveFilter = false;
  for (const auto& [label, options, exact] :
       {std::tuple{"default options", CloneOptions{}, true}, std::tuple{"filter off", off, true},
        std::tuple{"fixed filter 0.02", fixed, false}}) {
    for (const auto& [target, scale] :
         {std::pair{&c.neutral, 1.0}, std::pair{static_cast<const FaceModel*>(&moved), s}}) {
      const CloneResult r = cloneDeformedCopies(c.neutral, copies, *target, options);
      ASSERT_EQ(r.copies.size(), copies.size());
      double worst = 0;
      for (std::size_t i = 0; i < copies.size(); ++i) {
        EXPECT_EQ(r.copies[i].name, copies[i].name);
        EXPECT_EQ(r.copies[i].fapID, copies[i].fapID);
        EXPECT_EQ(r.copies[i].amplitude, copies[i].amplitude);
        const Points3 expected = scale * motionOf(copies[i], c.neutral);
        const double error = maxRowNorm(motionOf(r.copies[i], *target) - expected);
        worst = std::max(worst, error / maxRowNorm(expected));
        if (exact) {
          EXPECT_LE(error, 0.02 * maxRowNorm(expected))
              << label << ", scale " << scale << ": " << copies[i].name;
        }
      }
      std::printf("%s, scale %.1f: worst error %.3f%% of the copy's largest displacement\n", label,
                  scale, 100 * worst);
    }
  }
}

// Quality (b): onto a uniformly scaled copy every motion scales by the same factor, whether
// the scale is in the vertices or in the Transform above them (motion in the mesh's frame).
TEST(Clone, CloningOntoAScaledCopyScalesTheMotion) {
  const Candide c = candide();
  const auto copies = candideCopies(c, 500);
  const double s = 2.5;
  FaceModel scaled = c.neutral;
  scaled.meshes[0].coord *= s;
  const CloneResult a = cloneDeformedCopies(c.neutral, copies, scaled);
  FaceModel transformed = c.neutral;
  transformed.transforms[static_cast<std::size_t>(transformed.roots[0])].scale.setConstant(s);
  transformed.transforms[static_cast<std::size_t>(transformed.roots[0])].translation = {1, -2, 3};
  const CloneResult b = cloneDeformedCopies(c.neutral, copies, transformed);
  const CloneResult same = cloneDeformedCopies(c.neutral, copies, c.neutral);
  for (std::size_t i = 0; i < copies.size(); ++i) {
    const Points3 reference = motionOf(same.copies[i], c.neutral);
    const double tolerance = 1e-9 * (1 + maxRowNorm(reference));
    EXPECT_LE(maxRowNorm(motionOf(a.copies[i], scaled) - s * reference), s * tolerance)
        << copies[i].name;
    EXPECT_LE(maxRowNorm(motionOf(b.copies[i], transformed) - reference), tolerance)
        << copies[i].name;
    EXPECT_GT(maxRowNorm(reference), 0) << copies[i].name;
  }
}

namespace {

// A UV sphere of `rings` x `segments` quads (triangulated), poles included, about `centre`.
IndexedFaceSet sphere(const std::string& name, const Eigen::Vector3d& centre, double radius) {
  constexpr int rings = 6, segments = 8;
  IndexedFaceSet mesh;
  mesh.name = name;
  mesh.coord.resize(2 + (rings - 1) * segments, 3);
  mesh.coord.row(0) = (centre + radius * Eigen::Vector3d::UnitZ()).transpose();  // the front
  mesh.coord.row(1) = (centre - radius * Eigen::Vector3d::UnitZ()).transpose();
  // Vertex k of ring r (ring 0 and `rings` are the poles).
  const auto ring = [&](int r, int k) {
    return r == 0 ? 0 : r == rings ? 1 : 2 + (r - 1) * segments + k % segments;
  };
  for (int r = 1; r < rings; ++r) {
    const double polar = r * std::numbers::pi / rings;
    for (int k = 0; k < segments; ++k) {
      const double around = k * 2 * std::numbers::pi / segments;
      mesh.coord.row(ring(r, k)) =
          (centre + radius * Eigen::Vector3d(std::sin(polar) * std::cos(around),
                                             std::sin(polar) * std::sin(around), std::cos(polar)))
              .transpose();
    }
  }
  for (int r = 0; r < rings; ++r) {
    for (int k = 0; k < segments; ++k) {
      const int a = ring(r, k), b = ring(r, k + 1), c = ring(r + 1, k), d = ring(r + 1, k + 1);
      if (r > 0) mesh.coordIndex.insert(mesh.coordIndex.end(), {a, c, b, -1});
      if (r + 1 < rings) mesh.coordIndex.insert(mesh.coordIndex.end(), {b, c, d, -1});
    }
  }
  return mesh;
}

// CANDIDE-3 with an eyeball of its own behind each eye: a sphere under a Transform that turns
// about its centre, the pupil (3.5, 3.6) its front vertex, as a modelled head has them.
FaceModel withEyeballs(const Candide& c) {
  FaceModel out = c.neutral;
  const double radius =
      0.3 * (*out.featurePointPosition("3.7") - *out.featurePointPosition("3.11")).norm();
  for (const auto& [name, pupil, lids] :
       {std::tuple{"LeftEyeball", "3.5", std::array{"3.1", "3.3", "3.7", "3.11"}},
        std::tuple{"RightEyeball", "3.6", std::array{"3.2", "3.4", "3.8", "3.12"}}}) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const char* id : lids) centre += *out.featurePointPosition(id) / 4;
    centre.z() -= radius;
    const int mesh = out.addMeshWithTransform(sphere(name, centre, radius));
    out.transforms[static_cast<std::size_t>(*out.findTransform(name))].center = centre;
    out.featurePoints[pupil] = {mesh, 0, Eigen::Vector3d::Zero()};
  }
  return out;
}

// Every vertex in model space (meshes one after another).
Points3 worldPositions(const FaceModel& model) {
  const auto world = model.meshWorldMatrices();
  Eigen::Index rows = 0;
  for (const IndexedFaceSet& m : model.meshes) rows += m.vertexCount();
  Points3 out(rows, 3);
  Eigen::Index r = 0;
  for (std::size_t m = 0; m < model.meshes.size(); ++m) {
    for (int v = 0; v < model.meshes[m].vertexCount(); ++v, ++r) {
      out.row(r) = (world[m] * model.meshes[m].coord.row(v).transpose()).transpose();
    }
  }
  return out;
}

// A copy's motion of every vertex in model space: Transforms' and vertices' together.
Points3 worldMotion(const FaceModel& neutral, const FaceShape& shape) {
  return worldPositions(deformedModel(neutral, shape)) - worldPositions(neutral);
}

}  // namespace

// Quality (b'): placement does not matter. A head placed away from the origin has its mesh
// coordinates themselves moved and scaled (not only a Transform above them), and a file or
// Blender keeps them in single precision. Cloned onto such a copy of itself, every unit the
// source moves, the eyes' too (lids 19 - 22, eyeball yaw and pitch 23 - 26, thrust 27 - 28,
// pupils 29 - 30: CANDIDE's own units, which move the eyeball vertices of its one mesh, and
// turns of eyeballs of their own), moves as the source's times the scale, within 2% of the
// unit's largest displacement times the scale; each turn is the source's (axis and angle).
TEST(Clone, CloningOntoAMovedScaledCopyKeepsEveryUnit) {
  const Candide c = candide();
  const FaceModel source = withEyeballs(c);
  std::vector<FaceShape> copies = candideCopies(c, 600);
  ASSERT_EQ(copies.size(), 54u);
  for (int fap = 19; fap <= 30; ++fap) {
    ASSERT_GT(maxRowNorm(motionOf(copyOf(copies, fap), c.neutral)), 0) << "FAP " << fap;
  }
  // The eyeballs' turns, as FaceDefTransforms make them: yaw about y, pitch about x.
  for (const auto& [fap, eye, axis, angle] :
       {std::tuple{23, "LeftEyeball", Eigen::Vector3d::UnitY(), 0.3},
        std::tuple{24, "RightEyeball", Eigen::Vector3d::UnitY(), 0.3},
        std::tuple{25, "LeftEyeball", Eigen::Vector3d::UnitX(), 0.2},
        std::tuple{26, "RightEyeball", Eigen::Vector3d::UnitX(), 0.2}}) {
    FaceModel turned = source;
    turned.transforms[static_cast<std::size_t>(*turned.findTransform(eye))].rotation =
        Eigen::AngleAxisd(angle, axis);
    FaceShape& turn = copies.emplace_back(
        shapeFromDeformedModel(source, turned, "fap" + std::to_string(fap) + " turn"));
    turn.fapID = fap;
    turn.amplitude = 600;
  }
  // Near the origin (single precision rounds the coordinates by about 1e-7 of ES0) and far
  // from it (about 2e-6 of ES0).
  for (const auto& [shift, s] :
       {std::pair{Eigen::Vector3d(0.3, -0.2, 0.5), 1.8},
        std::pair{Eigen::Vector3d(0.3, -0.2, 0.5), 2.0},
        std::pair{Eigen::Vector3d(30, -20, 50), 1.8}}) {
    for (const bool single : {false, true}) {
      FaceModel moved = source;
      for (IndexedFaceSet& mesh : moved.meshes) {
        mesh.coord = (mesh.coord * s).rowwise() + shift.transpose();
        if (single) mesh.coord = mesh.coord.cast<float>().cast<double>();
      }
      // The eyes' Transforms still turn about the source's eyeball centres: the target's
      // are found from its own eyeballs (clone/rigid.hpp).
      const CloneResult r = cloneDeformedCopies(source, copies, moved);
      ASSERT_EQ(r.copies.size(), copies.size());
      char label[96];
      std::snprintf(label, sizeof label, "moved by (%g, %g, %g), scale %.1f, %s precision",
                    shift.x(), shift.y(), shift.z(), s, single ? "single" : "double");
      std::string figures;
      double worst = 0;
      for (std::size_t i = 0; i < copies.size(); ++i) {
        const Points3 expected = s * worldMotion(source, copies[i]);
        const double largest = maxRowNorm(expected);
        ASSERT_GT(largest, 0) << copies[i].name;
        const double ratio =
            maxRowNorm(worldMotion(r.targetNeutral, r.copies[i]) - expected) / largest;
        worst = std::max(worst, ratio);
        char line[80];
        std::snprintf(line, sizeof line, "  FAP %2d %-28s %8.3f%%\n", copies[i].fapID,
                      copies[i].name.c_str(), 100 * ratio);
        figures += line;
        EXPECT_LE(ratio, 0.02) << label << ", FAP " << copies[i].fapID << " (" << copies[i].name
                               << "): " << 100 * ratio << "% of its largest displacement";
        // Each Transform turns as the source's does (axis and angle).
        const auto& from = shapeTransforms(source, copies[i]);
        for (std::size_t t = 0; t < from.size(); ++t) {
          const Eigen::Quaterniond sourceTurn =
              source.transforms[t].rotation.inverse() * from[t].rotation;
          const Eigen::Quaterniond clonedTurn =
              r.targetNeutral.transforms[t].rotation.inverse() * r.copies[i].transforms[t].rotation;
          EXPECT_LE(sourceTurn.angularDistance(clonedTurn), 1e-9)
              << label << ", " << copies[i].name << ", Transform " << t;
        }
      }
      std::printf("%s: worst unit %.3f%% of its largest displacement\n", label, 100 * worst);
      if (worst > 0.02) std::printf("%s", figures.c_str());
    }
  }
}

// Pandzic's cylindrical projection (docs/clone.md): the axis is placed so that the mouth
// corners are 60 degrees apart, the nose tip is at angle 0, and v is the normalised height;
// alignment space does not change with the head's size or place.
TEST(Clone, ProjectionFixesTheMouthsAngleAndPutsTheNoseTipAtZero) {
  const Candide c = candide();
  const auto alignment = [](const FaceModel& model) {
    const clone::FaceFrame frame = clone::faceFrame(model, measureFapu(model));
    std::map<std::string, Eigen::Vector2d> uv;
    for (const char* id : {"8.3", "8.4", "9.3", "9.15", "2.1", "4.1"}) {
      uv[id] = clone::project(frame, *model.featurePointPosition(id));
    }
    return std::make_pair(frame, uv);
  };
  const auto [frame, uv] = alignment(c.neutral);
  EXPECT_NEAR(uv.at("9.3").x(), 0, 1e-12);  // the nose tip
  EXPECT_NEAR((uv.at("8.3").x() - uv.at("8.4").x()) / frame.radius, std::numbers::pi / 3, 1e-12);
  EXPECT_NEAR(uv.at("9.15").y(), 0, 1e-12);  // v: height from 9.15 in ENS0
  const FapuMeasurement fapu = measureFapu(c.neutral);
  EXPECT_NEAR(
      uv.at("2.1").y(),
      (c.neutral.featurePointPosition("2.1")->y() - c.neutral.featurePointPosition("9.15")->y()) /
          fapu.ENS0.value,
      1e-12);
  EXPECT_GT(uv.at("8.3").x(), 0);  // the face's left is on the +u side
  // Scaled by 2.5 and moved: the same alignment space.
  FaceModel moved = c.neutral;
  moved.meshes[0].coord = (moved.meshes[0].coord * 2.5).rowwise() + Eigen::RowVector3d(1, -2, 3);
  const auto [movedFrame, movedUv] = alignment(moved);
  for (const auto& [id, point] : uv) EXPECT_LE((movedUv.at(id) - point).norm(), 1e-12) << id;
}

// The lip rule: on CANDIDE's closed mouth the inner upper lip (2.2) and inner lower lip (2.3)
// are two vertices at one place; CANDIDE's FAP 4 moves 2.2 only, FAP 5 2.3 only.
TEST(Clone, LipRegionsAreKeptApart) {
  const Candide c = candide();
  const auto copies = candideCopies(c, 800);
  const int upper = c.neutral.featurePoints.at("2.2").vertex;
  const int lower = c.neutral.featurePoints.at("2.3").vertex;
  ASSERT_EQ(c.neutral.meshes[0].coord.row(upper), c.neutral.meshes[0].coord.row(lower));
  // A target whose lips are slightly apart and forward, so that the two are not matched
  // trivially (a target vertex at a source vertex's place takes its motion exactly).
  FaceModel target = c.neutral;
  target.meshes[0].coord(upper, 1) += 0.002;
  target.meshes[0].coord(lower, 1) -= 0.002;
  target.meshes[0].coord(upper, 2) += 0.002;
  target.meshes[0].coord(lower, 2) += 0.002;
  // The paper's fixed filter, so that samples near one lip reach over to the other (with the
  // adaptive one a face this close to the source is not filtered at all).
  CloneOptions keptOptions;
  keptOptions.adaptiveFilter = false;
  const CloneResult kept = cloneDeformedCopies(c.neutral, copies, target, keptOptions);
  CloneOptions mixedOptions = keptOptions;
  mixedOptions.separateLips = false;
  const CloneResult mixed = cloneDeformedCopies(c.neutral, copies, target, mixedOptions);
  for (const auto& [fap, moving, still] :
       {std::tuple{4, upper, lower}, std::tuple{5, lower, upper}}) {
    const Points3 source = motionOf(copyOf(copies, fap), c.neutral);
    const double size = source.row(moving).norm();
    ASSERT_GT(size, 0);
    ASSERT_EQ(source.row(still).norm(), 0);
    const Points3 motion = motionOf(copyOf(kept.copies, fap), target);
    EXPECT_GT(motion.row(moving).norm(), 0.8 * size) << fap;
    EXPECT_LT(motion.row(still).norm(), 0.05 * size) << fap;
    // Without the rule the lip that should stay is pulled along.
    EXPECT_GT(motionOf(copyOf(mixed.copies, fap), target).row(still).norm(), 0.05 * size) << fap;
  }
}

// The lip rule at the mouth corners (CANDIDE-3 onto the MakeHuman head): every lip feature
// point is in the lip the standard says (MakeHuman's 2.3, in an open slit, too); the corners
// belong to both lips, so each triangle through one is its other corners' lip and the lower
// lip, not only the upper, takes the corners' motion.
TEST(Clone, LipCornersBelongToBothLips) {
  const std::filesystem::path dir = mpeg4face::test::kData / "makehuman";
  const Candide c = candide();
  FaceModel human = readObj(dir / "base.obj");
  human.featurePoints = readFeaturePointCsv(dir / "feature_points.csv", human).featurePoints;
  const clone::Surface source = clone::gatherSurface(c.neutral, {});
  const clone::Surface target = clone::gatherSurface(human, {});
  const clone::Mapping map = clone::buildMapping(c.neutral, source, human, target, {});
  for (const auto& [face, surface, lips] :
       {std::tuple{&c.neutral, &source, &map.sourceLips},
        std::tuple{static_cast<const FaceModel*>(&human), &target, &map.targetLips}}) {
    for (const auto& [id, lip] : clone::lipFeaturePoints()) {
      const auto it = face->featurePoints.find(std::string(id));
      if (it == face->featurePoints.end()) continue;
      const auto row = static_cast<std::size_t>(
          surface->firstRow[static_cast<std::size_t>(it->second.mesh)] + it->second.vertex);
      EXPECT_EQ((*lips)[row], lip) << id << (face == &c.neutral ? " CANDIDE-3" : " MakeHuman");
    }
  }
  int upper = 0, lower = 0;
  for (const char* corner : {"2.4", "2.5"}) {
    const int v = c.neutral.featurePoints.at(corner).vertex;
    for (std::size_t t = 0; t < source.triangles.size(); t += 3) {
      if (source.triangles[t] != v && source.triangles[t + 1] != v && source.triangles[t + 2] != v)
        continue;
      bool up = false, down = false;
      for (std::size_t k = 0; k < 3; ++k) {
        const auto lip = map.sourceLips[static_cast<std::size_t>(source.triangles[t + k])];
        up = up || lip == clone::LipRegion::Upper;
        down = down || lip == clone::LipRegion::Lower;
      }
      EXPECT_FALSE(up && down) << "a triangle through " << corner << " holds both lips";
      upper += up;
      lower += down;
    }
  }
  EXPECT_GT(upper, 0);
  EXPECT_GT(lower, 0);
  // stretch_l_cornerlip moves CANDIDE's corner 2.4: on MakeHuman the lower lip follows as the
  // upper does (their largest motion).
  const auto copies = candideCopies(c, 600);
  const std::vector<FaceShape> stretch{copyOf(copies, 6)};
  const FaceShape cloned = cloneDeformedCopies(c.neutral, stretch, human).copies[0];
  std::vector<Points3> motion;
  for (std::size_t m = 0; m < human.meshes.size(); ++m) {
    motion.push_back(motionOf(cloned, human, static_cast<int>(m)));
  }
  double upperMotion = 0, lowerMotion = 0;
  for (std::size_t r = 0; r < target.owner.size(); ++r) {
    const auto [mesh, vertex] = target.owner[r];
    const double m = motion[static_cast<std::size_t>(mesh)].row(vertex).norm();
    if (map.targetLips[r] == clone::LipRegion::Upper) upperMotion = std::max(upperMotion, m);
    if (map.targetLips[r] == clone::LipRegion::Lower) lowerMotion = std::max(lowerMotion, m);
  }
  std::printf("FAP 6 onto MakeHuman: largest motion of the upper lip %.5f, of the lower %.5f\n",
              upperMotion, lowerMotion);
  EXPECT_GT(lowerMotion, 0.5 * upperMotion);
}

// Quality (c): CANDIDE-3 onto the MakeHuman head. open_jaw moves 2.1 down by the same number
// of MNS units on both faces; the forehead stays.
TEST(Clone, OpenJawOntoMakeHumanMovesTheChinByFapuAndLeavesTheForehead) {
  const std::filesystem::path dir = mpeg4face::test::kData / "makehuman";
  if (!std::filesystem::exists(dir / "feature_points.csv")) {
    GTEST_SKIP() << "tests/data/makehuman/feature_points.csv not there yet";
  }
  const Candide c = candide();
  std::vector<FaceShape> copies = candideCopies(c, 512);
  copies = {copyOf(copies, 3)};
  FaceModel human = readObj(dir / "base.obj");
  human.featurePoints = readFeaturePointCsv(dir / "feature_points.csv", human).featurePoints;
  ASSERT_EQ(missingCloneFeaturePoints(human), std::vector<std::string>{});
  const CloneResult r = cloneDeformedCopies(c.neutral, copies, human);
  const FapuMeasurement sourceFapu = measureFapu(c.neutral), targetFapu = measureFapu(human);
  const double sourceDrop =
      motionOf(copies[0], c.neutral)(c.neutral.featurePoints.at("2.1").vertex, 1);
  const double expected = sourceDrop / sourceFapu.MNS0.value * targetFapu.MNS0.value;
  ASSERT_LT(expected, 0);
  const FeaturePointBinding chin = human.featurePoints.at("2.1");
  const double drop = motionOf(r.copies[0], human, chin.mesh)(chin.vertex, 1);
  std::printf("2.1 moves %.5f, FAPU-scaled source motion %.5f (%.1f%%)\n", drop, expected,
              100 * drop / expected);
  // Feature points move exactly by the FAPU-scaled source motion (the smoothing of a coarse
  // source's motion narrows to nothing at them).
  EXPECT_NEAR(drop, expected, 1e-9 * std::abs(expected));
  // The forehead: vertices above the eyebrows' top, between the outer brow corners, in front
  // of the eye corners.
  const Eigen::Vector3d brow = *human.featurePointPosition("4.3");
  const Eigen::Vector3d leftBrow = *human.featurePointPosition("4.5");
  const Eigen::Vector3d rightBrow = *human.featurePointPosition("4.6");
  const Eigen::Vector3d hair = *human.featurePointPosition("11.3");
  const double frontZ = human.featurePointPosition("3.7")->z();
  const auto world = human.meshWorldMatrices();
  int forehead = 0;
  double moved = 0;
  for (std::size_t m = 0; m < human.meshes.size(); ++m) {
    const Points3 motion = motionOf(r.copies[0], human, static_cast<int>(m));
    for (int v = 0; v < human.meshes[m].vertexCount(); ++v) {
      const Eigen::Vector3d p = world[m] * human.meshes[m].coord.row(v).transpose();
      if (p.y() > brow.y() + 0.1 * (hair.y() - brow.y()) && p.y() < hair.y() && p.z() > frontZ &&
          p.x() < std::max(leftBrow.x(), rightBrow.x()) &&
          p.x() > std::min(leftBrow.x(), rightBrow.x())) {
        ++forehead;
        moved = std::max(moved, motion.row(v).norm());
      }
    }
  }
  std::printf("forehead: %d vertices, largest motion %.2e\n", forehead, moved);
  // Far below the chin (neck and body) nothing moves: the motion fades out beyond CANDIDE's
  // edge (CloneOptions::outsideFalloff).
  double body = 0;
  for (std::size_t m = 0; m < human.meshes.size(); ++m) {
    const Points3 motion = motionOf(r.copies[0], human, static_cast<int>(m));
    for (int v = 0; v < human.meshes[m].vertexCount(); ++v) {
      const Eigen::Vector3d p = world[m] * human.meshes[m].coord.row(v).transpose();
      if (p.y() < human.featurePointPosition("2.1")->y() - 5 * targetFapu.MNS0.value) {
        body = std::max(body, motion.row(v).norm());
      }
    }
  }
  std::printf("body (5 MNS0 below 2.1): largest motion %.5f\n", body);
  EXPECT_EQ(body, 0);
  EXPECT_GT(forehead, 20);
  EXPECT_LT(moved, 0.01 * std::abs(expected));
}

TEST(Clone, MissingFeaturePointsAreAllListed) {
  const Candide c = candide();
  FaceModel source = c.neutral, target = c.neutral;
  source.featurePoints.erase("2.1");
  source.featurePoints.erase("3.1");
  target.featurePoints.erase("9.12");
  const auto copies = candideCopies(c, 300);
  EXPECT_EQ(missingCloneFeaturePoints(source), (std::vector<std::string>{"2.1", "3.1"}));
  const std::string message = errorOf([&] { cloneDeformedCopies(source, copies, target); }).what();
  EXPECT_TRUE(contains(message, "source face lacks feature points 2.1, 3.1")) << message;
  EXPECT_TRUE(contains(message, "target face lacks feature points 9.12")) << message;
}

TEST(Clone, ACopyOfOtherTopologyIsNamed) {
  const Candide c = candide();
  // A whole deformed model becomes a shape at the edge (shapeFromDeformedModel), which checks
  // it against the neutral.
  FaceModel broken = c.neutral;
  broken.meshes[0].coord.conservativeResize(100, 3);
  Error e = errorOf([&] { shapeFromDeformedModel(c.neutral, broken, "broken shape"); });
  EXPECT_EQ(e.field(), "copy 'broken shape' mesh 'candide3'");
  EXPECT_TRUE(contains(e.what(), "100 vertices")) << e.what();
  FaceModel nan = c.neutral;
  nan.meshes[0].coord(5, 0) = NAN;
  e = errorOf([&] { shapeFromDeformedModel(c.neutral, nan, "nan shape"); });
  EXPECT_EQ(e.field(), "copy 'nan shape' mesh 'candide3'");
  EXPECT_TRUE(contains(e.what(), "vertex 5 is not a finite number")) << e.what();
  // Vertices renumbered (the faces with them): the counts agree, the faces do not.
  FaceModel renumbered = c.neutral;
  IndexedFaceSet& mesh = renumbered.meshes[0];
  const int n = mesh.vertexCount();
  mesh.coord = mesh.coord.colwise().reverse().eval();
  for (int& corner : mesh.coordIndex) {
    if (corner >= 0) corner = n - 1 - corner;
  }
  e = errorOf([&] { shapeFromDeformedModel(c.neutral, renumbered, "renumbered shape"); });
  EXPECT_EQ(e.field(), "copy 'renumbered shape' mesh 'candide3'");
  EXPECT_TRUE(contains(e.what(), "other faces")) << e.what();
  // The clone checks the shapes it is given.
  auto copies = candideCopies(c, 300);
  copies[2].name = "nan shape";
  copies[2].meshes[0].displacement(0, 0) = NAN;
  e = errorOf([&] { cloneDeformedCopies(c.neutral, copies, c.neutral); });
  EXPECT_EQ(e.field(), "copy 'nan shape' mesh 'candide3'");
  EXPECT_TRUE(contains(e.what(), "vertex " + std::to_string(copies[2].meshes[0].vertices[0]) +
                                     " is not a finite number"))
      << e.what();
  copies = candideCopies(c, 300);
  copies[4].name = "broken shape";
  copies[4].meshes[0].vertices.back() = c.neutral.meshes[0].vertexCount();
  e = errorOf([&] { cloneDeformedCopies(c.neutral, copies, c.neutral); });
  EXPECT_EQ(e.field(), "copy 'broken shape' mesh 'candide3'");
}

// FAPs, a viseme and an expression: cloneFace gives each copy its table (visemes as FAP 1 and
// expressions as FAP 2, their number in highLevelSelect), which reproduces the cloned copy.
TEST(Clone, CloneFaceMakesTablesThatReproduceTheCopies) {
  const Candide c = candide();
  auto copies = candideCopies(c, 400);
  // Made of CANDIDE's units, as a modeler would sculpt them: viseme 10 ("A:") opens the jaw
  // and stretches the lip corners, expression 1 (joy) raises and stretches them.
  const auto made = [&](std::string name, int fap, int select,
                        std::initializer_list<std::pair<int, double>> units) {
    Points3 motion = Points3::Zero(c.neutral.meshes[0].coord.rows(), 3);
    for (const auto& [unit, weight] : units)
      motion += weight * motionOf(copyOf(copies, unit), c.neutral);
    return FaceShape{std::move(name), fap, select, 63, {sparseDisplacement(0, motion)}, {}};
  };
  const FaceShape viseme = made("viseme10_A", 1, 10, {{3, 1.0}, {6, 0.5}, {7, 0.5}});
  const FaceShape joy = made("expression1_joy", 2, 1, {{12, 1.0}, {13, 1.0}, {6, 0.3}, {7, 0.3}});
  copies.push_back(viseme);
  copies.push_back(joy);
  FaceModel scaled = c.neutral;
  scaled.meshes[0].coord *= 1.7;
  const ClonedFace f = cloneFace(c.neutral, copies, scaled);
  EXPECT_EQ(f.copies.size(), copies.size());
  EXPECT_EQ(f.face.faceDefTables.size(), copies.size());
  EXPECT_EQ(f.face.faceSceneGraph.meshes[0].coord, scaled.meshes[0].coord);
  for (const auto& [fap, select] : {std::pair{1, 10}, std::pair{2, 1}}) {
    EXPECT_EQ(std::ranges::count_if(f.face.faceDefTables,
                                    [&, fap = fap, select = select](const FaceDefTables& t) {
                                      return t.fapID == fap && t.highLevelSelect == select;
                                    }),
              1)
        << "FAP " << fap << " select " << select;
  }
  // The high-level copies carry their own motion over: the source's, scaled with the face
  // (a scaled copy is cloned exactly, CloningOntoAScaledCopyScalesTheMotion).
  for (const FaceShape* source : {&viseme, &joy}) {
    const FaceShape& cloned = copyOf(f.copies, source->fapID);
    EXPECT_EQ(cloned.highLevelSelect, source->highLevelSelect);
    EXPECT_EQ(cloned.amplitude, 63);
    const Points3 expected = 1.7 * motionOf(*source, c.neutral);
    ASSERT_GT(maxRowNorm(expected), 0) << source->name;
    EXPECT_LE(maxRowNorm(motionOf(cloned, scaled) - expected), 1e-9 * maxRowNorm(expected))
        << source->name;
  }
  // Each table, evaluated at its copy's amplitude (viseme_blend or expression intensity for
  // the high-level ones), moves the target as the cloned copy does.
  const FatEvaluator eval(f.face, measureFapu(scaled));
  for (const FaceShape& copy : f.copies) {
    const double largest = maxRowNorm(motionOf(copy, scaled));
    EXPECT_LE(
        mpeg4face::test::farthest(eval.evaluate(mpeg4face::test::frameFor(copy)), scaled, copy),
        1e-4 * std::max(largest, 1e-9))
        << copy.name;
  }
}

// The clone's output is the generator's input as it is (cloneFace hands its shapes over
// without making whole models of them), and the tables are those that going through whole
// models (the neutral moved by each shape, read back) gives.
TEST(Clone, TheClonedShapesFeedTheGeneratorAsTheyAre) {
  static_assert(std::is_same_v<decltype(CloneResult::copies), std::vector<FaceShape>>);
  static_assert(std::is_same_v<decltype(ClonedFace::copies), std::vector<FaceShape>>);
  const Candide c = candide();
  const auto copies = candideCopies(c, 400);
  FaceModel target = c.neutral;
  target.meshes[0].coord *= 1.3;
  const CloneResult r = cloneDeformedCopies(c.neutral, copies, target);
  const FapuMeasurement fapu = measureFapu(r.targetNeutral);
  const GeneratedTables direct = generateFaceDefTables(r.targetNeutral, fapu, r.copies);
  std::vector<FaceShape> viaModels;
  for (const FaceShape& s : r.copies) {
    FaceShape back =
        shapeFromDeformedModel(r.targetNeutral, deformedModel(r.targetNeutral, s), s.name);
    back.fapID = s.fapID;
    back.highLevelSelect = s.highLevelSelect;
    back.amplitude = s.amplitude;
    viaModels.push_back(std::move(back));
  }
  const GeneratedTables before = generateFaceDefTables(r.targetNeutral, fapu, viaModels);
  const ClonedFace f = cloneFace(c.neutral, copies, target);
  ASSERT_EQ(direct.faceDefTables.size(), copies.size());
  ASSERT_EQ(before.faceDefTables.size(), direct.faceDefTables.size());
  ASSERT_EQ(f.face.faceDefTables.size(), direct.faceDefTables.size());
  for (std::size_t i = 0; i < direct.faceDefTables.size(); ++i) {
    const FaceDefTables& a = direct.faceDefTables[i];
    const FaceDefTables& b = before.faceDefTables[i];
    const FaceDefTables& g = f.face.faceDefTables[i];
    EXPECT_EQ(a.fapID, b.fapID);
    ASSERT_EQ(a.faceDefMesh.size(), b.faceDefMesh.size()) << a.fapID;
    ASSERT_EQ(a.faceDefMesh.size(), g.faceDefMesh.size()) << a.fapID;
    for (std::size_t m = 0; m < a.faceDefMesh.size(); ++m) {
      const FaceDefMesh& x = a.faceDefMesh[m];
      const FaceDefMesh& y = b.faceDefMesh[m];
      EXPECT_EQ(x.mesh, y.mesh);
      EXPECT_EQ(x.intervalBorders, y.intervalBorders);
      EXPECT_EQ(x.coordIndex, y.coordIndex) << a.fapID;
      ASSERT_EQ(x.displacements.rows(), y.displacements.rows());
      EXPECT_LE((x.displacements - y.displacements).cwiseAbs().maxCoeff(),
                1e-9 * x.displacements.cwiseAbs().maxCoeff())
          << a.fapID;
      EXPECT_EQ(g.faceDefMesh[m].coordIndex, x.coordIndex);  // cloneFace: the same path
      EXPECT_EQ(g.faceDefMesh[m].displacements, x.displacements);
    }
  }
}

// The rigid parts are wired: an eye mesh under its own Transform is left out of the vertex
// mapping and its rotation is carried over (clone/rigid.hpp does the matching).
TEST(Clone, EyeRotationGoesThroughTheRigidParts) {
  const Candide c = candide();
  FaceModel source = c.neutral;
  IndexedFaceSet eye;
  eye.name = "LeftEye";
  eye.coord.resize(4, 3);
  eye.coord << 0, 0, 0.03, 0.03, 0, 0, -0.03, 0, 0, 0, 0.03, 0;
  eye.coordIndex = {0, 1, 2, -1, 0, 2, 3, -1, 0, 3, 1, -1};
  const int eyeMesh = source.addMeshWithTransform(eye);
  const int eyeTransform = *source.findTransform("LeftEye");
  source.transforms[static_cast<std::size_t>(eyeTransform)].translation = {0.304, 0.16, -0.03};
  source.featurePoints["3.5"] = {eyeMesh, 0, Eigen::Vector3d::Zero()};
  FaceModel looking = source;
  looking.transforms[static_cast<std::size_t>(eyeTransform)].rotation =
      Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY());
  FaceShape look = shapeFromDeformedModel(source, looking, "look left");
  look.fapID = 23;
  look.amplitude = 20000;
  FaceModel target = source;
  target.meshes[0].coord *= 1.5;
  target.transforms[static_cast<std::size_t>(eyeTransform)].translation *= 1.5;
  const std::vector<FaceShape> copies{look};
  const CloneResult r = cloneDeformedCopies(source, copies, target);
  const FaceModel out = deformedModel(r.targetNeutral, r.copies[0]);
  const Eigen::AngleAxisd turn(
      out.transforms[static_cast<std::size_t>(eyeTransform)].rotation *
      r.targetNeutral.transforms[static_cast<std::size_t>(eyeTransform)].rotation.inverse());
  EXPECT_NEAR(turn.angle(), 0.2, 1e-9);
  EXPECT_EQ(out.meshes[static_cast<std::size_t>(eyeMesh)].coord,
            r.targetNeutral.meshes[static_cast<std::size_t>(eyeMesh)].coord);
  EXPECT_EQ(out.meshes[0].coord, r.targetNeutral.meshes[0].coord);
  CloneOptions noRigid;
  noRigid.rigidParts = false;
  const CloneResult plain = cloneDeformedCopies(source, copies, target, noRigid);
  EXPECT_TRUE(plain.copies[0].transforms[static_cast<std::size_t>(eyeTransform)].rotation.isApprox(
      target.transforms[static_cast<std::size_t>(eyeTransform)].rotation));
}
