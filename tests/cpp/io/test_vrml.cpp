// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/tables.hpp"
#include "mpeg4face/fit/presets.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "mpeg4face/io/vrml.hpp"
#include "mpeg4face/spec.hpp"
#include "test_support.hpp"

using namespace mpeg4face;
namespace fs = std::filesystem;

namespace {

using mpeg4face::test::errorOf;
using mpeg4face::test::kData;

// The documented bound on a Transform rotation after the axis-angle round trip (docs/vrml.md).
constexpr double kRotationTolerance = 1e-15;

Eigen::Quaterniond rotationAbout(const Eigen::Vector3d& axis, double radians) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(radians, axis.normalized()));
}

// A face with everything the format carries: a hierarchy with translation, rotation, scale
// and centre; quads and triangles; UVs with a seam (texCoordIndex) and per vertex; normals;
// a mesh held by two transforms and one held by none; names that are not VRML identifiers
// and names shared by a mesh and a transform; feature points on vertices, free, outside the
// 84 (7.2) and unbound; tables with several intervals, all three FaceDefTransform fields and
// FAP 1 / 2 with highLevelSelect; numbers that need all 17 digits.
MpegFace richFace() {
  MpegFace face;
  FaceModel& model = face.faceSceneGraph;

  IndexedFaceSet skin;  // a 3 x 2 grid of vertices: two quads and a triangle
  skin.name = "Face";
  skin.coord.resize(6, 3);
  skin.coord << 0.1, 0.2, 0.3,   //
      1.0 / 3, 0, -0.0,          //
      2, 1e-300, 0.7,            //
      0, 1, 12345.678901234567,  //
      1, 1, -2.5e-7,             //
      2, 1, 0.1 + 0.2;
  skin.coordIndex = {0, 1, 4, 3, -1, 1, 2, 5, 4, -1, 0, 4, 3, -1};
  skin.normal.resize(6, 3);
  for (int i = 0; i < 6; ++i) skin.normal.row(i) << 0, 0.6, 0.8 + i * 1e-3;
  skin.texCoord.resize(7, 2);
  skin.texCoord << 0, 0, 0.5, 0, 1, 0, 0, 1, 0.5, 1, 1, 1, 0.25, 0.75;
  skin.texCoordIndex = {0, 1, 4, 3, -1, 1, 2, 5, 4, -1, 0, 6, 3, -1};
  // Not part of an MPEG-4 face: dropped by the writer (docs/vrml.md).
  skin.morphTargets.push_back({"smile", Points3::Constant(6, 3, 0.5)});
  skin.weights = {0.25};

  IndexedFaceSet eye;
  eye.name = "eye ball.001";  // a space and a dot: escaped in the DEF name
  eye.coord.resize(4, 3);
  eye.coord << -0.1, -0.1, 0, 0.1, -0.1, 0, 0.1, 0.1, 0, -0.1, 0.1, 0.05;
  eye.coordIndex = {0, 1, 2, 3, -1};
  eye.texCoord.resize(4, 2);
  eye.texCoord << 0, 0, 1, 0, 1, 1, 0, 1;

  IndexedFaceSet teeth;  // held by no transform
  teeth.name = "";
  teeth.coord.resize(3, 3);
  teeth.coord << 0, -0.5, 0.2, 0.2, -0.5, 0.2, 0.1, -0.4, 0.25;
  teeth.coordIndex = {0, 1, 2, -1};

  model.meshes = {skin, eye, teeth};

  Transform head;
  head.name = "Head";
  head.translation = {0.5, 1.25, -3};
  head.rotation = rotationAbout({1, 2, 3}, 0.7);
  head.scale = {1.5, 1.5, 2};
  head.center = {0, 1.7, 0.1};
  head.meshes = {0};
  head.children = {1, 2, 3};
  Transform jaw;
  jaw.name = "Face";  // the same name as the mesh
  jaw.center = {0, 1.2, 0.3};
  jaw.rotation = rotationAbout({1, 0, 0}, -0.05);
  Transform leftEye;
  leftEye.name = "1st eye";  // a leading digit
  leftEye.translation = {0.3, 0.4, 0.1};
  leftEye.rotation = Eigen::Quaterniond(-0.5, 0.5, 0.5, 0.5);  // w < 0: comes back as -q
  leftEye.meshes = {1};
  Transform rightEye;
  rightEye.name = "TRUE";  // a VRML keyword
  rightEye.translation = {-0.3, 0.4, 0.1};
  rightEye.meshes = {1};
  rightEye.children = {4};
  Transform lid;
  lid.name = "50% lid";
  model.transforms = {head, jaw, leftEye, rightEye, lid};
  model.roots = {0};

  FeaturePointBinding onSkin;
  onSkin.mesh = 0;
  onSkin.vertex = 4;
  model.featurePoints["2.1"] = onSkin;
  FeaturePointBinding onEye;
  onEye.mesh = 1;
  onEye.vertex = 2;
  model.featurePoints["3.5"] = onEye;
  FeaturePointBinding onTeeth;
  onTeeth.mesh = 2;
  onTeeth.vertex = 0;
  model.featurePoints["9.10"] = onTeeth;
  FeaturePointBinding free;
  free.position = {0.1, 1.0 / 7, -2e-20};
  model.featurePoints["9.3"] = free;
  free.position = {0, -1.25, -0.5};
  model.featurePoints["7.2"] = free;

  FaceDefTables openJaw;
  openJaw.fapID = 3;
  FaceDefMesh skinMotion;
  skinMotion.mesh = 0;
  skinMotion.intervalBorders = {-1000, 0, 500, 1000};
  skinMotion.coordIndex = {3, 4, 5};
  skinMotion.displacements.resize(9, 3);
  for (int r = 0; r < 9; ++r) skinMotion.displacements.row(r) << r * 0.1, -1.0 / (r + 3), 1e-5 * r;
  FaceDefMesh teethMotion;
  teethMotion.mesh = 2;
  teethMotion.intervalBorders = {0, 1080};  // one interval, no negative side
  teethMotion.coordIndex = {0, 1, 2};
  teethMotion.displacements = Points3::Constant(3, 3, -0.001);
  FaceDefTransform jawRotation;
  jawRotation.transform = 1;
  jawRotation.fieldId = FaceDefTransform::Field::Rotation;
  jawRotation.rotationDef = {1, 0, 0, 1e-5};
  openJaw.faceDefMesh = {skinMotion, teethMotion};
  openJaw.faceDefTransform = {jawRotation};

  FaceDefTables yaw;
  yaw.fapID = 23;
  FaceDefTransform eyeYaw;
  eyeYaw.transform = 2;
  eyeYaw.rotationDef = {0, -2, 0, 1};  // not normalized: kept as written
  eyeYaw.scaleDef = {1, 1, 0.5};       // unused by a rotation, still kept
  yaw.faceDefTransform = {eyeYaw};

  FaceDefTables pitch;
  pitch.fapID = 48;
  FaceDefTransform headMove;
  headMove.transform = 0;
  headMove.fieldId = FaceDefTransform::Field::Translation;
  headMove.translationDef = {0, -1e-6, 2e-6};
  FaceDefTransform headScale;
  headScale.transform = 0;
  headScale.fieldId = FaceDefTransform::Field::Scale;
  headScale.scaleDef = {1e-4, 0, -1e-4};
  pitch.faceDefTransform = {headMove, headScale};

  FaceDefTables viseme;
  viseme.fapID = 1;
  viseme.highLevelSelect = 5;
  FaceDefMesh visemeMotion;
  visemeMotion.mesh = 0;
  visemeMotion.intervalBorders = {0, 63};
  visemeMotion.coordIndex = {0};
  visemeMotion.displacements.resize(1, 3);
  visemeMotion.displacements << 0, 0.01, 0;
  viseme.faceDefMesh = {visemeMotion};

  FaceDefTables expression;
  expression.fapID = 2;
  expression.highLevelSelect = 0;
  FaceDefMesh expressionMotion = visemeMotion;
  expressionMotion.mesh = 1;
  expressionMotion.coordIndex = {3};
  expression.faceDefMesh = {expressionMotion};

  face.faceDefTables = {openJaw, yaw, pitch, viseme, expression};
  // A FAP Interpolation Table with impulses, a non-linear term and coefficients without a
  // short decimal form.
  face.fit = mergedFitTables(expressionFitTable(), innerOuterLipFitTable(977));
  return face;
}

template <typename A, typename B>
bool sameExactly(const A& a, const B& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && (a.array() == b.array()).all();
}

template <typename A, typename B>
bool sameWithin(const A& a, const B& b, double relative) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    const double x = a.data()[i], y = b.data()[i];
    if (std::abs(x - y) > relative * std::max(1.0, std::abs(x))) return false;
  }
  return true;
}

// `read` is `written` as VRML carries it: no morph targets or weights, numbers within
// `relative` (0: exactly), rotations within `angle`.
void expectSameFace(const MpegFace& written, const MpegFace& read, double relative, double angle) {
  const auto same = [&](const auto& a, const auto& b) {
    return relative == 0 ? sameExactly(a, b) : sameWithin(a, b, relative);
  };
  const FaceModel& a = written.faceSceneGraph;
  const FaceModel& b = read.faceSceneGraph;
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  for (std::size_t m = 0; m < a.meshes.size(); ++m) {
    SCOPED_TRACE("mesh " + std::to_string(m));
    const IndexedFaceSet& x = a.meshes[m];
    const IndexedFaceSet& y = b.meshes[m];
    EXPECT_EQ(x.name, y.name);
    EXPECT_TRUE(same(x.coord, y.coord));
    EXPECT_EQ(x.coordIndex, y.coordIndex);
    EXPECT_TRUE(same(x.normal, y.normal));
    EXPECT_TRUE(same(x.texCoord, y.texCoord));
    EXPECT_EQ(x.texCoordIndex, y.texCoordIndex);
    EXPECT_TRUE(y.morphTargets.empty());
    EXPECT_TRUE(y.weights.empty());
  }
  ASSERT_EQ(a.transforms.size(), b.transforms.size());
  for (std::size_t t = 0; t < a.transforms.size(); ++t) {
    SCOPED_TRACE("transform " + std::to_string(t));
    const Transform& x = a.transforms[t];
    const Transform& y = b.transforms[t];
    EXPECT_EQ(x.name, y.name);
    EXPECT_TRUE(same(x.translation, y.translation));
    EXPECT_TRUE(same(x.scale, y.scale));
    EXPECT_TRUE(same(x.center, y.center));
    EXPECT_LE(x.rotation.angularDistance(y.rotation), angle);
    EXPECT_EQ(x.children, y.children);
    EXPECT_EQ(x.meshes, y.meshes);
  }
  EXPECT_EQ(a.roots, b.roots);
  ASSERT_EQ(a.featurePoints.size(), b.featurePoints.size());
  for (const auto& [id, fp] : a.featurePoints) {
    SCOPED_TRACE("feature point " + id);
    ASSERT_EQ(b.featurePoints.count(id), 1u);
    const FeaturePointBinding& other = b.featurePoints.at(id);
    EXPECT_EQ(fp.mesh, other.mesh);
    EXPECT_EQ(fp.vertex, other.vertex);
    if (fp.mesh < 0) {
      EXPECT_TRUE(same(fp.position, other.position));
    }
  }
  ASSERT_EQ(written.faceDefTables.size(), read.faceDefTables.size());
  for (std::size_t i = 0; i < written.faceDefTables.size(); ++i) {
    SCOPED_TRACE("table " + std::to_string(i));
    const FaceDefTables& x = written.faceDefTables[i];
    const FaceDefTables& y = read.faceDefTables[i];
    EXPECT_EQ(x.fapID, y.fapID);
    EXPECT_EQ(x.highLevelSelect, y.highLevelSelect);
    ASSERT_EQ(x.faceDefMesh.size(), y.faceDefMesh.size());
    for (std::size_t j = 0; j < x.faceDefMesh.size(); ++j) {
      EXPECT_EQ(x.faceDefMesh[j].mesh, y.faceDefMesh[j].mesh);
      EXPECT_EQ(x.faceDefMesh[j].intervalBorders, y.faceDefMesh[j].intervalBorders);
      EXPECT_EQ(x.faceDefMesh[j].coordIndex, y.faceDefMesh[j].coordIndex);
      EXPECT_TRUE(same(x.faceDefMesh[j].displacements, y.faceDefMesh[j].displacements));
    }
    ASSERT_EQ(x.faceDefTransform.size(), y.faceDefTransform.size());
    for (std::size_t j = 0; j < x.faceDefTransform.size(); ++j) {
      const FaceDefTransform& p = x.faceDefTransform[j];
      const FaceDefTransform& q = y.faceDefTransform[j];
      EXPECT_EQ(p.transform, q.transform);
      EXPECT_EQ(p.fieldId, q.fieldId);
      EXPECT_TRUE(same(p.rotationDef, q.rotationDef));
      EXPECT_TRUE(same(p.scaleDef, q.scaleDef));
      EXPECT_TRUE(same(p.translationDef, q.translationDef));
    }
  }
  ASSERT_EQ(written.fit.has_value(), read.fit.has_value());
  if (!written.fit) return;
  const FitTable& x = *written.fit;
  const FitTable& y = *read.fit;
  EXPECT_EQ(x.nodes, y.nodes);
  ASSERT_EQ(x.links.size(), y.links.size());
  for (std::size_t k = 0; k < x.links.size(); ++k) {
    EXPECT_EQ(x.links[k].parent, y.links[k].parent);
    EXPECT_EQ(x.links[k].child, y.links[k].child);
    ASSERT_EQ(x.links[k].functions.size(), y.links[k].functions.size());
    for (std::size_t f = 0; f < x.links[k].functions.size(); ++f) {
      for (const auto& [p, q] :
           {std::pair{&x.links[k].functions[f].numerator, &y.links[k].functions[f].numerator},
            std::pair{&x.links[k].functions[f].denominator,
                      &y.links[k].functions[f].denominator}}) {
        ASSERT_EQ(p->size(), q->size());
        for (std::size_t t = 0; t < p->size(); ++t) {
          EXPECT_EQ((*p)[t].exponents, (*q)[t].exponents);
          EXPECT_EQ((*p)[t].impulseSelect, (*q)[t].impulseSelect);
          EXPECT_EQ((*p)[t].impulseValue, (*q)[t].impulseValue);
          const double u = (*p)[t].coefficient, v = (*q)[t].coefficient;
          if (relative == 0) {
            EXPECT_EQ(u, v);
          } else {
            EXPECT_LE(std::abs(u - v), relative * std::max(1.0, std::abs(u)));
          }
        }
      }
    }
  }
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

TEST(Vrml, RoundTripIsExact) {
  const MpegFace face = richFace();
  const fs::path path = test::scratchDir() / "face.wrl";
  writeVrml(face, path);
  const MpegFace read = readVrml(path);
  expectSameFace(face, read, 0, kRotationTolerance);
  // The bits too: -0.0 stays negative, 1e-300 is not flushed.
  EXPECT_TRUE(std::signbit(read.faceSceneGraph.meshes[0].coord(1, 2)));
  EXPECT_EQ(read.faceSceneGraph.meshes[0].coord(2, 1), 1e-300);
  // Writing what was read gives the same file but for the last digits of rotations.
  EXPECT_NO_THROW(read.faceSceneGraph.validate());
}

TEST(Vrml, FileLayout) {
  const std::string text = vrmlText(richFace());
  EXPECT_EQ(text.rfind("#VRML V2.0 utf8\n", 0), 0u);
  for (const char* proto : {"PROTO Face [", "PROTO FDP [", "PROTO FaceDefTables [",
                            "PROTO FaceDefMesh [", "PROTO FaceDefTransform [", "PROTO FAP [",
                            "PROTO Viseme [", "PROTO Expression [", "PROTO FIT ["}) {
    EXPECT_TRUE(contains(text, proto)) << proto;
  }
  // One SFInt32 per FAP 3..68 under its BIFS field name.
  for (int fap = 3; fap <= kFapCount; ++fap) {
    const std::string field = "exposedField SFInt32 " + std::string(fapInfo(fap).bifsName) + " 0\n";
    EXPECT_TRUE(contains(text, field)) << field;
  }
  // DEF names, escaped by hand from io/vrml_names.hpp's rule: the mesh keeps "Face", the
  // transform of the same name gets the suffix; ' ' is %20, '.' %2E, '1' %31,
  // '5' %35 (leading digits), '%' %25.
  EXPECT_TRUE(contains(text, "DEF Face IndexedFaceSet"));
  EXPECT_TRUE(contains(text, "DEF Face%_2 Transform"));
  EXPECT_TRUE(contains(text, "DEF eye%20ball%2E001 IndexedFaceSet"));
  EXPECT_TRUE(contains(text, "DEF %31st%20eye Transform"));
  EXPECT_TRUE(contains(text, "DEF %54RUE Transform"));
  EXPECT_TRUE(contains(text, "DEF %350%25%20lid Transform"));
  EXPECT_TRUE(contains(text, "DEF %_1 IndexedFaceSet"));                   // the unnamed mesh
  EXPECT_TRUE(contains(text, "Shape { geometry USE eye%20ball%2E001 }"));  // the second holder
  EXPECT_TRUE(contains(text, "faceSceneGraphNode USE Face\n"));
  EXPECT_TRUE(contains(text, "faceSceneGraphNode USE Face%_2\n"));
  // Feature points: 2.1 and 3.5 on vertices, 9.3 free, 7.2 outside the 84, the rest none.
  EXPECT_TRUE(contains(text, "\"2.1 mesh Face vertex 4\""));
  EXPECT_TRUE(contains(text, "\"3.5 mesh eye%20ball%2E001 vertex 2\""));
  EXPECT_TRUE(contains(text, "\"7.2 position 0 -1.25 -0.5\""));
  EXPECT_TRUE(contains(text, "\"2.2 none\""));
  EXPECT_FALSE(contains(text, "\"9.3 "));
  EXPECT_TRUE(contains(text, "0.1 0.14285714285714285 -2e-20,  # 9.3\n"));
  // Shortest round-trip numbers.
  EXPECT_TRUE(contains(text, "0.3333333333333333 0 -0,"));
  EXPECT_TRUE(contains(text, "2 1 0.30000000000000004,"));
  EXPECT_FALSE(contains(text, "smile"));
}

// featurePointsCoord holds the 84 points in group/index order: model-space positions for
// points on vertices, the coordinate for free ones, 0 0 0 for unbound ones.
TEST(Vrml, FeaturePointsCoordInStandardOrder) {
  const MpegFace face = richFace();
  const std::string text = vrmlText(face);
  const std::size_t begin = text.find("featurePointsCoord Coordinate {");
  ASSERT_NE(begin, std::string::npos);
  std::vector<std::string> ids;
  std::vector<Eigen::Vector3d> points;
  std::size_t pos = text.find("point [\n", begin) + 8;
  while (true) {
    const std::size_t end = text.find('\n', pos);
    const std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    if (line.find(']') != std::string::npos) break;
    Eigen::Vector3d p;
    char comma;
    std::string hash, id;
    std::istringstream(line) >> p.x() >> p.y() >> p.z() >> comma >> hash >> id;
    ids.push_back(id);
    points.push_back(p);
  }
  ASSERT_EQ(ids.size(), 84u);
  std::vector<std::string> expected;
  for (const FeaturePointInfo& info : featurePointTable()) {
    if (info.inStandard) expected.emplace_back(info.id);
  }
  EXPECT_EQ(ids, expected);
  const auto at = [&](const std::string& id) {
    return points[static_cast<std::size_t>(std::find(ids.begin(), ids.end(), id) - ids.begin())];
  };
  // 2.1 is skin vertex 4 under Head: T C R S -C p, computed here step by step.
  const Transform& head = face.faceSceneGraph.transforms[0];
  const Eigen::Vector3d p = face.faceSceneGraph.meshes[0].coord.row(4).transpose();
  const Eigen::Vector3d expected21 =
      head.translation + head.center +
      head.rotation.toRotationMatrix() * (head.scale.cwiseProduct(p - head.center));
  EXPECT_LT((at("2.1") - expected21).norm(), 1e-12);
  EXPECT_EQ(at("9.3"), Eigen::Vector3d(0.1, 1.0 / 7, -2e-20));
  EXPECT_EQ(at("2.2"), Eigen::Vector3d::Zero());
}

TEST(Vrml, QuaternionRoundTripTolerance) {
  // Many random rotations (and w < 0) through the text: the documented bound holds.
  MpegFace face;
  std::mt19937 random(7);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 2000; ++i) {
    Transform t;
    t.name = "t" + std::to_string(i);
    Eigen::Quaterniond q(normal(random), normal(random), normal(random), normal(random));
    if (i % 100 == 0) q = Eigen::Quaterniond(1, 1e-9 * i, 0, 0);  // tiny angles
    t.rotation = q.normalized();
    face.faceSceneGraph.roots.push_back(i);
    face.faceSceneGraph.transforms.push_back(t);
  }
  const MpegFace read = parseVrml(vrmlText(face), "rotations.wrl");
  double worst = 0;
  for (std::size_t i = 0; i < face.faceSceneGraph.transforms.size(); ++i) {
    worst = std::max(worst, face.faceSceneGraph.transforms[i].rotation.angularDistance(
                                read.faceSceneGraph.transforms[i].rotation));
  }
  std::printf("largest rotation round-trip error: %.3g rad\n", worst);
  EXPECT_LE(worst, kRotationTolerance);
}

// Transforms come back numbered depth-first and meshes in order of first use; the references
// (children, meshes, tables, feature points) follow them.
TEST(Vrml, ReaderNumbersDepthFirst) {
  MpegFace face;
  FaceModel& model = face.faceSceneGraph;
  for (const char* name : {"a", "b"}) {
    IndexedFaceSet mesh;
    mesh.name = name;
    mesh.coord = Points3::Identity(3, 3);
    mesh.coordIndex = {0, 1, 2, -1};
    model.meshes.push_back(mesh);
  }
  Transform child;
  child.name = "child";
  child.meshes = {1};
  Transform root;
  root.name = "root";
  root.children = {0};
  root.meshes = {0};
  model.transforms = {child, root};  // child before its parent, meshes in reverse use order
  model.roots = {1};
  FeaturePointBinding fp;
  fp.mesh = 0;
  fp.vertex = 2;
  model.featurePoints["2.1"] = fp;
  FaceDefTables table;
  table.fapID = 48;
  FaceDefTransform def;
  def.transform = 0;
  table.faceDefTransform = {def};
  face.faceDefTables = {table};

  const MpegFace read = parseVrml(vrmlText(face), "order.wrl");
  const FaceModel& m = read.faceSceneGraph;
  ASSERT_EQ(m.transforms.size(), 2u);
  EXPECT_EQ(m.transforms[0].name, "root");
  EXPECT_EQ(m.transforms[0].children, std::vector<int>{1});
  EXPECT_EQ(m.transforms[1].name, "child");
  EXPECT_EQ(m.roots, std::vector<int>{0});
  ASSERT_EQ(m.meshes.size(), 2u);
  EXPECT_EQ(m.meshes[0].name, "a");
  EXPECT_EQ(m.transforms[1].meshes, std::vector<int>{1});
  EXPECT_EQ(m.featurePoints.at("2.1").mesh, 0);
  EXPECT_EQ(read.faceDefTables[0].faceDefTransform[0].transform, 1);
}

// Inputs on which fuzz_vrml once failed (tests/fuzz_regressions/vrml/README.md): meshes that
// a Transform holds between its child Transforms, and a top-level Shape ahead of the first
// Transform, came back in the order the writer grouped them in, not the order read.
TEST(Vrml, FuzzRegressionsKeepMeshOrder) {
  const fs::path dir = kData.parent_path() / "fuzz_regressions" / "vrml";
  const std::pair<const char*, std::vector<std::string>> cases[] = {
      {"vrml-roundtrip-mesh-order.wrl", {"Chin", "Brow", "HeadMesh"}},
      {"vrml-roundtrip-mesh-order-2.wrl", {"HeadMesh", "Brow", "HeadMesh", "Brow"}}};
  for (const auto& [file, names] : cases) {
    SCOPED_TRACE(file);
    const MpegFace face = readVrml(dir / file);
    std::vector<std::string> read;
    for (const IndexedFaceSet& mesh : face.faceSceneGraph.meshes) read.push_back(mesh.name);
    EXPECT_EQ(read, names);
    expectSameFace(face, parseVrml(vrmlText(face), "again.wrl"), 0, kRotationTolerance);
  }
}

// The writer keeps the mesh order, and so the tables' and feature points' references, of a
// model whose meshes are interleaved with child Transforms, and of one whose order no
// interleaving gives (meshes numbered against the depth-first order of their transforms).
TEST(Vrml, MeshOrderSurvivesARoundTrip) {
  // Meshes 0 .. count - 1, each with a table entry; a root t0 whose children are t1, t2 ...;
  // transform t holds meshesOf[t]; a mesh no list names is held by none (top level).
  const auto makeFace = [](int count, const std::vector<std::vector<int>>& meshesOf) {
    MpegFace face;
    FaceModel& model = face.faceSceneGraph;
    FaceDefTables table;
    table.fapID = 3;
    for (int m = 0; m < count; ++m) {
      IndexedFaceSet mesh;
      mesh.name = "m" + std::to_string(m);
      mesh.coord = Points3::Identity(3 + m, 3);
      mesh.coordIndex = {0, 1, 2, -1};
      model.meshes.push_back(mesh);
      FaceDefMesh def;
      def.mesh = m;
      def.intervalBorders = {0, 1};
      def.coordIndex = {m % 3};
      def.displacements = Points3::Constant(1, 3, m);
      table.faceDefMesh.push_back(def);
    }
    for (std::size_t t = 0; t < meshesOf.size(); ++t) {
      Transform tr;
      tr.name = "t" + std::to_string(t);
      tr.meshes = meshesOf[t];
      if (t > 0) model.transforms[0].children.push_back(static_cast<int>(t));
      model.transforms.push_back(tr);
    }
    model.roots = {0};
    FeaturePointBinding fp;
    fp.mesh = count - 1;
    fp.vertex = count + 1;  // its last vertex
    model.featurePoints["2.1"] = fp;
    face.faceDefTables = {table};
    return face;
  };
  // Mesh 0 is held by none; t0 holds meshes 1 and 4 around its children t1 (mesh 2) and t2
  // (mesh 3): the top level is written as m0, t0 and t0's children as m1, t1, t2, m4.
  const MpegFace interleaved = makeFace(5, {{1, 4}, {2}, {3}});
  const std::string text = vrmlText(interleaved);
  EXPECT_LT(text.find("DEF m0 "), text.find("DEF t0 "));
  EXPECT_LT(text.find("DEF t2 "), text.find("DEF m4 "));
  expectSameFace(interleaved, parseVrml(text, "interleaved.wrl"), 0, kRotationTolerance);
  // t1 holds mesh 2 and t2 mesh 1: no interleaving numbers them in order.
  const MpegFace reversed = makeFace(4, {{0}, {2}, {1}});
  expectSameFace(reversed, parseVrml(vrmlText(reversed), "reversed.wrl"), 0, kRotationTolerance);
}

TEST(Vrml, EmptyFaceRoundTrips) {
  const MpegFace read = parseVrml(vrmlText(MpegFace{}), "empty.wrl");
  EXPECT_TRUE(read.faceSceneGraph.meshes.empty());
  EXPECT_TRUE(read.faceSceneGraph.transforms.empty());
  EXPECT_TRUE(read.faceSceneGraph.featurePoints.empty());
  EXPECT_TRUE(read.faceDefTables.empty());
}

TEST(Vrml, ReadModelReturnsTheSceneGraph) {
  const fs::path path = test::scratchDir() / "face.WRL";
  writeVrml(richFace(), path);
  const FaceModel model = readModel(path);
  EXPECT_EQ(model.meshes.size(), 3u);
  EXPECT_EQ(model.transforms.size(), 5u);
  EXPECT_EQ(model.featurePoints.size(), 5u);
}

TEST(Vrml, WriterRejectsWhatItCannotWrite) {
  {
    MpegFace face = richFace();
    face.faceDefTables[0].faceDefMesh[0].mesh = 7;
    const Error e = errorOf([&] { vrmlText(face); });
    EXPECT_EQ(e.field(), "faceDefTables[0].faceDefMesh[0].mesh");
  }
  {
    MpegFace face = richFace();
    face.faceDefTables[0].faceDefMesh[0].displacements.conservativeResize(8, 3);
    EXPECT_EQ(errorOf([&] { vrmlText(face); }).field(),
              "faceDefTables[0].faceDefMesh[0].displacements");
  }
  {
    MpegFace face = richFace();
    face.faceDefTables[1].faceDefMesh = {face.faceDefTables[0].faceDefMesh[0]};
    face.faceDefTables[1].faceDefMesh[0].intervalBorders = {-5, 5, 10};
    EXPECT_EQ(errorOf([&] { vrmlText(face); }).field(),
              "faceDefTables[1].faceDefMesh[0].intervalBorders");
  }
  {
    MpegFace face = richFace();
    face.faceSceneGraph.transforms.push_back(Transform{});  // reachable from no root
    EXPECT_TRUE(contains(errorOf([&] { vrmlText(face); }).what(), "not reachable"));
  }
  {
    MpegFace face = richFace();
    face.faceSceneGraph.meshes[1].coord(0, 0) = std::nan("");
    EXPECT_EQ(errorOf([&] { vrmlText(face); }).field(), "meshes[1] 'eye ball.001' coord");
  }
  {
    MpegFace face = richFace();
    face.faceSceneGraph.featurePoints["12.1"] = FeaturePointBinding{};
    EXPECT_EQ(errorOf([&] { vrmlText(face); }).field(), "featurePoints");
  }
  {
    // A vertex bound to a feature point, finite itself, that the transforms take beyond the
    // range of double: featurePointsCoord would hold 'inf'.
    MpegFace face;
    IndexedFaceSet mesh;
    mesh.coord = Points3::Constant(3, 3, 1e300);
    mesh.coordIndex = {0, 1, 2, -1};
    face.faceSceneGraph.addMeshWithTransform(mesh);
    face.faceSceneGraph.transforms[0].scale.setConstant(1e300);
    FeaturePointBinding fp;
    fp.mesh = 0;
    fp.vertex = 2;
    face.faceSceneGraph.featurePoints["2.1"] = fp;
    EXPECT_EQ(errorOf([&] { vrmlText(face); }).field(),
              "featurePoints 2.1 (its vertex through the transforms)");
  }
  {
    const fs::path path = test::scratchDir() / "bad.wrl";
    MpegFace face = richFace();
    face.faceDefTables[0].fapID = 0;
    const Error e = errorOf([&] { writeVrml(face, path); });
    EXPECT_EQ(e.file(), path.string());
    EXPECT_FALSE(fs::exists(path));
  }
}

// A file written the way modellers export VRML97 (tests/data/vrml/handwritten.wrl): the
// expectations below are read off the file by hand.
TEST(Vrml, ReadsAnOrdinaryScene) {
  const MpegFace face = readVrml(kData / "vrml" / "handwritten.wrl");
  const FaceModel& m = face.faceSceneGraph;
  EXPECT_TRUE(face.faceDefTables.empty());
  EXPECT_TRUE(m.featurePoints.empty());
  ASSERT_EQ(m.transforms.size(), 3u);
  EXPECT_EQ(m.roots, (std::vector<int>{0, 2}));
  EXPECT_EQ(m.transforms[0].name, "Head");
  EXPECT_EQ(m.transforms[0].translation, Eigen::Vector3d(0, 1.5, 0));
  EXPECT_LT(
      m.transforms[0].rotation.angularDistance(rotationAbout({0, 1, 0}, std::numbers::pi / 2)),
      1e-15);
  EXPECT_EQ(m.transforms[0].children, std::vector<int>{1});
  EXPECT_EQ(m.transforms[0].meshes, std::vector<int>{0});
  EXPECT_EQ(m.transforms[1].name, "");
  EXPECT_EQ(m.transforms[1].translation, Eigen::Vector3d(0.3, 0.2, 0.1));
  EXPECT_EQ(m.transforms[1].scale, Eigen::Vector3d(2, 2, 2));
  EXPECT_EQ(m.transforms[1].meshes, std::vector<int>{1});
  EXPECT_EQ(m.transforms[2].name, "Instances");  // a Group: an identity transform
  EXPECT_EQ(m.transforms[2].meshes, std::vector<int>{0});
  EXPECT_TRUE(m.transforms[2].rotation.isApprox(Eigen::Quaterniond::Identity(), 0));

  ASSERT_EQ(m.meshes.size(), 3u);
  const IndexedFaceSet& head = m.meshes[0];
  EXPECT_EQ(head.name, "HeadMesh");
  Points3 shared(5, 3);
  shared << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 1;
  EXPECT_TRUE(sameExactly(head.coord, shared));
  EXPECT_EQ(head.coordIndex, (std::vector<int>{0, 1, 2, 3, -1, 0, 1, 4, -1}));
  Points2 uv(4, 2);
  uv << 0, 0, 1, 0, 1, 1, 0, 1;
  EXPECT_TRUE(sameExactly(head.texCoord, uv));
  EXPECT_EQ(head.texCoordIndex, (std::vector<int>{0, 1, 2, 3, -1, 0, 1, 2, -1}));
  EXPECT_EQ(head.normal.rows(), 0);

  const IndexedFaceSet& brow = m.meshes[1];  // its coord is a USE of the head's
  EXPECT_EQ(brow.name, "Brow");
  EXPECT_TRUE(sameExactly(brow.coord, shared));
  EXPECT_EQ(brow.coordIndex, (std::vector<int>{2, 3, 4}));  // ccw FALSE: 4 3 2 reversed
  EXPECT_TRUE(
      sameExactly(brow.normal, Points3::Constant(5, 3, 0).rowwise() + Eigen::RowVector3d(0, 0, 1)));
  const IndexedFaceSet& chin = m.meshes[2];  // top-level Shape: held by no transform
  EXPECT_EQ(chin.name, "Chin");
  EXPECT_EQ(chin.coordIndex, (std::vector<int>{0, 1, 2, -1}));  // given in hexadecimal
  // texCoord without texCoordIndex and not one per vertex: indexed by coordIndex.
  EXPECT_EQ(chin.texCoord.rows(), 4);
  EXPECT_EQ(chin.texCoordIndex, chin.coordIndex);
  EXPECT_NO_THROW(m.validate());
}

// A small file cannot make the reader copy a USE'd Coordinate without bound.
TEST(Vrml, CopiesOfAUsedCoordinateAreBounded) {
  const int points = 100000;  // 300,000 numbers per further copy: 56 copies exceed 2^24
  std::string text =
      "#VRML V2.0 utf8\nShape { geometry IndexedFaceSet { coord DEF C Coordinate { point [";
  for (int i = 0; i < points; ++i) text += " 0 0 0";
  text += " ] } } }\n";
  const std::string use = "Shape { geometry IndexedFaceSet { coord USE C } }\n";
  std::string fits = text;
  for (int i = 0; i < 55; ++i) fits += use;
  EXPECT_EQ(parseVrml(fits, "fits.wrl").faceSceneGraph.meshes.size(), 56u);
  const Error e = errorOf([&] { parseVrml(fits + use, "too_many.wrl"); });
  EXPECT_EQ(e.line(), 2);
  EXPECT_EQ(e.field(), "Coordinate");
  EXPECT_TRUE(contains(e.reason(), "more than 16777216 numbers")) << e.what();
}

// VRML97 syntax that our writer does not use but other files do.
TEST(Vrml, ParserDetails) {
  // An MF field given as one value without brackets; a node body with a ROUTE and a PROTO;
  // a DEF name redefined (the later one counts for USE); fields of unknown nodes of every
  // kind; an empty file but for the header.
  const MpegFace face = parseVrml(
      "#VRML V2.0 utf8\n"
      "DEF P Coordinate { point 9 9 9 }\n"
      "DEF P Coordinate { point 1 2 3 }\n"
      "Transform {\n"
      "  PROTO Inner [ ] { Group {} }\n"
      "  children Shape { geometry IndexedFaceSet { coord USE P coordIndex 0 } }\n"
      "  ROUTE a.b TO c.d\n"
      "}\n"
      "Unknown { s \"x\" m [ \"a\" \"b\" ] v 1 2 3 r [ 1 2, 3 4 ] b TRUE n NULL c Box {}\n"
      "  d [ Group {} USE P ] i 0x10 }\n",
      "details.wrl");
  const FaceModel& m = face.faceSceneGraph;
  ASSERT_EQ(m.meshes.size(), 1u);
  EXPECT_EQ(m.meshes[0].coord, (Points3(1, 3) << 1, 2, 3).finished());
  EXPECT_EQ(m.meshes[0].coordIndex, std::vector<int>{0});
  EXPECT_EQ(m.transforms.size(), 1u);
  EXPECT_TRUE(parseVrml("#VRML V2.0 utf8\n", "empty.wrl").faceSceneGraph.meshes.empty());
  // Texture coordinates that are not one per vertex, on a mesh without faces: nothing to
  // index them with, so they are dropped (found by fuzz_vrml).
  const MpegFace noFaces = parseVrml(
      "#VRML V2.0 utf8\nShape { geometry IndexedFaceSet {\n"
      "  coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] }\n"
      "  texCoord TextureCoordinate { point [ 0 0, 1 0, 0 1, 1 1 ] } } }\n",
      "no_faces.wrl");
  EXPECT_EQ(noFaces.faceSceneGraph.meshes.at(0).texCoord.rows(), 0);
  EXPECT_NO_THROW(noFaces.faceSceneGraph.validate());
  // A UTF-8 byte-order mark and CRLF line endings; lines still count.
  const Error e = errorOf([] {
    parseVrml("\xEF\xBB\xBF#VRML V2.0 utf8\r\n\r\nTransform { scale 1 x 1 }\r\n", "crlf.wrl");
  });
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.field(), "Transform.scale");
  // Decoding of DEF names from other files: a '%' not followed by two hex digits stays.
  const MpegFace named = parseVrml(
      "#VRML V2.0 utf8\nDEF off%_x%2 Transform {}\nDEF a%_2b Group {}\n"
      "DEF Left%20Eye%_3 Group {}\n",
      "n.wrl");
  EXPECT_EQ(named.faceSceneGraph.transforms[0].name, "off%_x%2");
  EXPECT_EQ(named.faceSceneGraph.transforms[1].name, "a%_2b");
  EXPECT_EQ(named.faceSceneGraph.transforms[2].name, "Left Eye");
}

// A VRML reader that is not ours accepts the file without a warning, and what it writes back
// (single precision, its own layout) reads as the same face.
TEST(Vrml, ThirdPartyReaderAcceptsTheFile) {
  if (std::system("command -v tovrmlx3d >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "tovrmlx3d (Debian package view3dscene) is not installed";
  }
  const fs::path dir = test::scratchDir();
  const MpegFace face = richFace();
  writeVrml(face, dir / "face.wrl");
  const std::string command =
      "cd '" + dir.string() + "' && tovrmlx3d face.wrl > converted.wrl 2> stderr.txt";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  const std::string stderrText = slurp(dir / "stderr.txt");
  const std::string converted = slurp(dir / "converted.wrl");
  EXPECT_EQ(stderrText, "");
  EXPECT_FALSE(contains(converted, "Warning"));
  EXPECT_FALSE(contains(converted, "Error"));
  ASSERT_TRUE(contains(converted, "Face {"));
  expectSameFace(face, parseVrml(converted, "converted.wrl"), 1e-6, 1e-6);
}

// Each malformed sample stops with an error naming the file, the line and the field.
struct Malformed {
  const char* file;
  int line;
  const char* field;
  const char* message;
};

class VrmlMalformed : public testing::TestWithParam<Malformed> {};

TEST_P(VrmlMalformed, ClearError) {
  const Malformed& m = GetParam();
  const fs::path path = kData / "malformed" / m.file;
  const Error e = errorOf([&] { readVrml(path); });
  EXPECT_EQ(e.file(), path.string());
  EXPECT_EQ(e.line(), m.line);
  EXPECT_EQ(e.field(), m.field);
  EXPECT_TRUE(contains(e.reason(), m.message)) << e.what();
}

INSTANTIATE_TEST_SUITE_P(
    Files, VrmlMalformed,
    testing::Values(
        Malformed{"vrml_empty.wrl", 1, "", "not a VRML97 file"},
        Malformed{"vrml_garbage.wrl", 1, "", "not a VRML97 file"},
        Malformed{"vrml_gzip.wrl", 1, "", "gzip"},
        Malformed{"vrml_vrml1.wrl", 1, "", "VRML 1.0 is not supported"},
        Malformed{"vrml_truncated.wrl", 7, "IndexedFaceSet.coordIndex",
                  "found the end of the file"},
        Malformed{"vrml_unterminated_string.wrl", 2, "", "string not closed"},
        Malformed{"vrml_unclosed_proto.wrl", 2, "PROTO Marker", "not closed"},
        Malformed{"vrml_bad_number.wrl", 3, "Transform.translation", "'1.5x'"},
        Malformed{"vrml_unknown_field.wrl", 3, "Transform.translatoin", "no such field"},
        Malformed{"vrml_unknown_use.wrl", 4, "IndexedFaceSet.coord", "USE 'Points'"},
        Malformed{"vrml_coord_index.wrl", 5, "IndexedFaceSet.coordIndex", "vertex 3 out of range"},
        Malformed{"vrml_tex_layout.wrl", 7, "IndexedFaceSet.texCoordIndex", "does not end a face"},
        Malformed{"vrml_shear.wrl", 4, "Transform.scaleOrientation", "shear"},
        Malformed{"vrml_deep_nesting.wrl", 2, "Group.children", "nested more than 256"},
        Malformed{"vrml_transform_used_twice.wrl", 2, "Transform", "used a second time"},
        Malformed{"vrml_two_faces.wrl", 9, "Face", "a second Face"},
        Malformed{"vrml_fdm_target.wrl", 14, "FaceDefMesh.faceSceneGraphNode",
                  "an IndexedFaceSet expected, found Transform"},
        Malformed{"vrml_fdm_displacements.wrl", 17, "FaceDefMesh.displacements",
                  "2 displacements, expected 3"},
        Malformed{"vrml_fdm_borders.wrl", 15, "FaceDefMesh.intervalBorders", "exactly one"},
        Malformed{"vrml_fap_id.wrl", 12, "FaceDefTables.fapID", "99 is not a FAP number"},
        Malformed{"vrml_feature_point_count.wrl", 4, "FDP.featurePointsCoord",
                  "3 points; expected the 84"},
        Malformed{"vrml_feature_point_info.wrl", 16, "WorldInfo.info",
                  "vertex '9' is not a vertex of that mesh"},
        // Written, its position in featurePointsCoord would be 'inf', which no reader takes.
        Malformed{"vrml_feature_point_overflow.wrl", 17, "WorldInfo.info",
                  "entry 1 '2.1 mesh Skin vertex 0': the vertex's position in the face"}),
    [](const testing::TestParamInfo<Malformed>& param) {
      std::string name = fs::path(param.param.file).stem().string();
      std::replace(name.begin(), name.end(), '.', '_');
      return name;
    });

// A FIT node whose fields do not fit together: the file, the FIT node's line and the field.
TEST(Vrml, MalformedFitNodeIsNamed) {
  const auto face = [](const std::string& fit) {
    return "#VRML V2.0 utf8\nFace {\n  fdp FDP {}\n  fit FIT {\n" + fit + "\n  }\n}\n";
  };
  const std::string good =
      "FAPs [ 33 -1 31 -1 ] Graph [ 0 1 ] numeratorTerms [ 1 ] denominatorTerms [ 1 ]\n"
      "numeratorExp [ 1 ] denominatorExp [ 0 ] numeratorImpulse [ 0 0 ]\n"
      "numeratorCoefs [ 0.5 ] denominatorCoefs [ 1 ]";
  const MpegFace read = parseVrml(face(good), "fit.wrl");
  ASSERT_TRUE(read.fit.has_value());
  EXPECT_EQ(read.fit->links[0].functions[0].numerator[0].coefficient, 0.5);
  Error e = errorOf([&] {
    parseVrml(
        face("FAPs [ 33 -1 31 -1 ] Graph [ 0 1 ] numeratorTerms [ 2 ] denominatorTerms [ 1 ]\n"
             "numeratorExp [ 1 ] denominatorExp [ 0 ] numeratorImpulse [ 0 0 ]\n"
             "numeratorCoefs [ 0.5 ] denominatorCoefs [ 1 ]"),
        "fit.wrl");
  });
  EXPECT_EQ(e.file(), "fit.wrl");
  EXPECT_EQ(e.line(), 4);
  EXPECT_EQ(e.field(), "FIT.numeratorExp");
  e = errorOf([&] { parseVrml(face("FAPs [ 33 -1 31 ] Graph [ 0 1 ]"), "fit.wrl"); });
  EXPECT_EQ(e.field(), "FIT.FAPs");
  e = errorOf([&] { parseVrml(face("FAPs [ 33 -1 31 -1 ] Graph [ 0 7 ]"), "fit.wrl"); });
  EXPECT_EQ(e.field(), "FIT.Graph");
  e = errorOf([&] { parseVrml(face(good + " numeratorCoefs [ 0.5 2 ]"), "fit.wrl"); });
  EXPECT_EQ(e.field(), "FIT.numeratorCoefs");
  e = errorOf([&] { parseVrml(face(good + " bogus [ 1 ]"), "fit.wrl"); });
  EXPECT_EQ(e.line(), 7);
  e = errorOf([&] {
    parseVrml(
        face("FAPs [ 99 -1 31 -1 ] Graph [ 0 1 ] numeratorTerms [ 1 ] denominatorTerms [ 1 ]\n"
             "numeratorExp [ 1 ] denominatorExp [ 0 ] numeratorImpulse [ 0 0 ]\n"
             "numeratorCoefs [ 0.5 ] denominatorCoefs [ 1 ]"),
        "fit.wrl");
  });
  EXPECT_EQ(e.field(), "FIT");
  EXPECT_TRUE(contains(e.reason(), "node 0 has unknown FAP 99")) << e.what();
}
