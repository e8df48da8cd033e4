// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face clone` end to end: CANDIDE-3 with named FAP copies cloned onto a scaled CANDIDE-3
// (where the cloned motion must be the source's, scaled), then the result used as a source
// in turn (tables in glTF, tables in .wrl); missing feature points and bad arguments.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "mpeg4face/clone/clone.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/io/fat_gltf.hpp"
#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/gltf.hpp"
#include "mpeg4face/io/vrml.hpp"
#include "mpeg4face/io/wfm.hpp"
#include "mpeg4face/spec.hpp"
#include "test_support.hpp"

namespace {

using namespace mpeg4face;
using mpeg4face::test::runCli;

const std::filesystem::path kCandideDir = mpeg4face::test::kData / "candide3";
const std::string kCandideCsv = (kCandideDir / "feature_points.csv").string();
constexpr double kScale = 1.6;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// CANDIDE-3 with a copy per MPEG-4 unit (FAP 3..68) at +300 FAPU (and -200 for the
// bidirectional ones of the mouth), and an expression made of two units: what a modeler hands
// over as shape keys.
struct SourceHead {
  FaceModel model;                       // with the morph targets
  std::set<std::pair<int, int>> tables;  // (fapID, highLevelSelect) it has copies of
};
SourceHead sourceHead() {
  const CandideModel candide = readWfm(kCandideDir / "candide3.wfm");
  SourceHead out{candide.model, {}};
  FaceModel& head = out.model;
  head.featurePoints = readFeaturePointCsv(kCandideCsv, head).featurePoints;
  const FapuMeasurement fapu = measureFapu(head);
  IndexedFaceSet& mesh = head.meshes[0];
  const auto unitMotion = [&](const CandideUnit& u) {
    double unit = fapu.unit(fapInfo(u.fap).fapu);
    for (const FapuInfo& info : fapuTable()) {
      if (info.name == u.fapu) unit = fapu.unit(info.kind);
    }
    Points3 d = Points3::Zero(mesh.vertexCount(), 3);
    for (size_t i = 0; i < u.vertices.size(); ++i) {
      d.row(u.vertices[i]) = unit * u.displacements.row(static_cast<Eigen::Index>(i));
    }
    return d;
  };
  Points3 smile = Points3::Zero(mesh.vertexCount(), 3);
  for (const CandideUnit& u : candide.animationUnits) {
    if (u.fap < 3) continue;
    std::vector<int> amplitudes{300};
    if (u.fap <= 13 && fapInfo(u.fap).bidirectional) amplitudes.push_back(-200);
    for (int a : amplitudes) {
      mesh.morphTargets.push_back(
          {"fap" + std::to_string(u.fap) + "@" + std::to_string(a), a * unitMotion(u)});
    }
    out.tables.insert({u.fap, 0});
    if (u.fap == 12 || u.fap == 13) smile += 250 * unitMotion(u);
  }
  mesh.morphTargets.push_back({"expression1_joy", smile});
  out.tables.insert({2, 1});
  mesh.weights.assign(mesh.morphTargets.size(), 0.0);
  return out;
}

// CANDIDE-3 scaled by kScale about a point off the origin, as glTF: the same vertex numbers
// (an OBJ would drop CANDIDE's unused vertices), so the same feature-point CSV binds it.
std::filesystem::path writeScaledCandide(const std::filesystem::path& dir) {
  FaceModel model = readWfm(kCandideDir / "candide3.wfm").model;
  Points3& p = model.meshes[0].coord;
  p = (kScale * p).rowwise() + Eigen::RowVector3d(0.3, -0.2, 0.5);
  const std::filesystem::path path = dir / "scaled.glb";
  writeGltf(model, path);
  return path;
}

std::set<std::pair<int, int>> tablesOf(const MpegFace& face) {
  std::set<std::pair<int, int>> out;
  for (const FaceDefTables& t : face.faceDefTables) {
    out.insert({t.fapID, t.fapID <= 2 ? t.highLevelSelect : 0});
  }
  return out;
}

// The mesh's motion (model space) when `frame` drives the face.
Points3 motion(const MpegFace& face, const FapuMeasurement& fapu, const FapFrame& frame) {
  const FatEvaluator evaluator(face, fapu);
  return evaluator.evaluate(frame).coord[0] - face.faceSceneGraph.meshes[0].coord;
}

}  // namespace

TEST(CliClone, CandideOntoScaledCandideAndBack) {
  const std::filesystem::path dir = mpeg4face::test::scratchDir();
  const SourceHead source = sourceHead();
  const std::filesystem::path sourcePath = dir / "candide_keys.glb";
  writeGltf(source.model, sourcePath);
  const std::filesystem::path target = writeScaledCandide(dir);

  // Shape keys -> scaled CANDIDE, no filter, vertex motion only: each vertex lands on its own
  // twin, so the motion must be the source's times kScale.
  const std::filesystem::path out = dir / "scaled_clone.glb";
  auto r = runCli("clone " + sourcePath.string() + " " + target.string() +
                  " --source-feature-points " + kCandideCsv + " --target-feature-points " +
                  kCandideCsv + " --filter-support 0 --no-rigid -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(contains(r.out, "shape keys")) << r.out;
  // Progress goes to stderr, so that stdout stays clean for a pipe. runCli appends stderr to
  // stdout in `out`.
  const std::string stderrOnly = r.out.substr(r.stdoutOnly.size());
  EXPECT_TRUE(contains(stderrOnly, "clone: ")) << r.out;
  EXPECT_FALSE(contains(r.stdoutOnly, "clone: ")) << r.stdoutOnly;
  EXPECT_TRUE(contains(r.out, "wrote " + out.string())) << r.out;
  const FatGltf cloned = readFatGltf(out);
  EXPECT_EQ(tablesOf(cloned.face), source.tables);
  // The copies are shape keys of the output too, named as in the source.
  std::set<std::string> sourceKeys, outputKeys;
  for (const MorphTarget& t : source.model.meshes[0].morphTargets) sourceKeys.insert(t.name);
  for (const MorphTarget& t : cloned.face.faceSceneGraph.meshes[0].morphTargets) {
    outputKeys.insert(t.name);
  }
  EXPECT_EQ(outputKeys, sourceKeys);

  // Motion: each shape key at 300, scaled, at every vertex a face uses. CANDIDE-3's eyeballs
  // (the vertices of FAPs 23..30) lie behind the lids in the same mesh: the method's
  // projection gives them the lids' motion (Pandzic's eyes are meshes of their own, moved as
  // rigid parts), so they and their FAPs are left out.
  std::vector<bool> compare(static_cast<size_t>(source.model.meshes[0].vertexCount()), false);
  for (int v : source.model.meshes[0].triangles()) compare[static_cast<size_t>(v)] = true;
  const std::set<int> eyeFaps{23, 24, 25, 26, 27, 28, 29, 30};
  for (const MorphTarget& key : source.model.meshes[0].morphTargets) {
    if (!key.name.starts_with("fap") || !eyeFaps.contains(std::stoi(key.name.substr(3)))) continue;
    for (int v = 0; v < key.displacements.rows(); ++v) {
      if (!key.displacements.row(v).isZero(0)) compare[static_cast<size_t>(v)] = false;
    }
  }
  int compared = 0;
  for (const MorphTarget& key : source.model.meshes[0].morphTargets) {
    if (!key.name.starts_with("fap") || !key.name.ends_with("@300")) continue;
    const int fap = std::stoi(key.name.substr(3));
    if (eyeFaps.contains(fap)) continue;
    const Points3 expected = kScale * key.displacements;
    FapFrame frame;
    frame.set(fap, 300);
    const Points3 got = motion(cloned.face, cloned.fapu, frame);
    const double largest = expected.rowwise().norm().maxCoeff();
    for (int v = 0; v < got.rows(); ++v) {
      if (!compare[static_cast<size_t>(v)]) continue;
      ++compared;
      EXPECT_LE((got.row(v) - expected.row(v)).norm(), 1e-3 * largest)
          << key.name << " vertex " << v << ": " << got.row(v) << ", expected " << expected.row(v);
    }
  }
  EXPECT_GT(compared, 40 * 90);

  // The result as a source (tables in glTF) onto CANDIDE-3 itself, written as .wrl; with
  // the filter and rigid parts on. Then that .wrl as a source again.
  const std::filesystem::path back = dir / "back.wrl";
  r = runCli("clone " + out.string() + " " + (kCandideDir / "candide3.wfm").string() +
             " --target-feature-points " + kCandideCsv + " -o " + back.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(contains(r.out, "(from tables)")) << r.out;
  const MpegFace backFace = readVrml(back);
  EXPECT_EQ(tablesOf(backFace), source.tables);
  const std::filesystem::path again = dir / "again.wrl";
  r = runCli("clone " + back.string() + " " + target.string() + " --target-feature-points " +
             kCandideCsv + " -o " + again.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(tablesOf(readVrml(again)), source.tables);
}

// The adaptive filter leaves a clone onto an equally dense face unfiltered (the same shape keys
// as with the filter off); --fixed-filter filters every vertex, as the paper does.
TEST(CliClone, FixedFilterFiltersEveryVertex) {
  const std::filesystem::path dir = mpeg4face::test::scratchDir();
  const auto source = sourceHead();
  const std::filesystem::path sourcePath = dir / "candide_keys_filter.glb";
  writeGltf(source.model, sourcePath);
  const std::filesystem::path target = writeScaledCandide(dir);
  const auto keys = [&](const std::string& options) {
    const std::filesystem::path out = dir / "filter_clone.glb";
    const auto r = runCli("clone " + sourcePath.string() + " " + target.string() +
                          " --source-feature-points " + kCandideCsv + " --target-feature-points " +
                          kCandideCsv + " --no-rigid " + options + " -o " + out.string());
    EXPECT_EQ(r.status, 0) << options << "\n" << r.out;
    return readFatGltf(out).face.faceSceneGraph.meshes[0].morphTargets;
  };
  const auto off = keys("--filter-support 0"), adaptive = keys(""), fixed = keys("--fixed-filter");
  ASSERT_EQ(off.size(), adaptive.size());
  ASSERT_EQ(off.size(), fixed.size());
  double fixedChange = 0;
  for (std::size_t k = 0; k < off.size(); ++k) {
    EXPECT_TRUE(off[k].displacements.isApprox(adaptive[k].displacements, 1e-9)) << off[k].name;
    fixedChange = std::max(fixedChange,
                           (fixed[k].displacements - off[k].displacements).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(fixedChange, 0);
}

TEST(CliClone, CandideOntoMakeHuman) {
  const std::filesystem::path dir = mpeg4face::test::scratchDir();
  const SourceHead source = sourceHead();
  const std::filesystem::path sourcePath = dir / "candide_keys.glb";
  writeGltf(source.model, sourcePath);
  const std::filesystem::path makehuman = mpeg4face::test::kData / "makehuman";
  const std::filesystem::path out = dir / "makehuman_clone.glb";
  const auto r = runCli("clone " + sourcePath.string() + " " + (makehuman / "base.obj").string() +
                        " --target-feature-points " + (makehuman / "feature_points.csv").string() +
                        " -o " + out.string());
  ASSERT_EQ(r.status, 0) << r.out;
  const FatGltf cloned = readFatGltf(out);
  EXPECT_EQ(tablesOf(cloned.face), source.tables);
  // open_jaw: CANDIDE-3's unit moves the chin (2.1) straight down by 1 MNS unit per FAP
  // unit; cloned, the MakeHuman chin goes down by about 300 of its own MNS units.
  const FeaturePointBinding chin = cloned.face.faceSceneGraph.featurePoints.at("2.1");
  ASSERT_GE(chin.mesh, 0);
  FapFrame frame;
  frame.set(3, 300);
  const FatEvaluator evaluator(cloned.face, cloned.fapu);
  const FatState state = evaluator.evaluate(frame);
  const Eigen::Vector3d moved =
      cloned.face.faceSceneGraph.meshWorldMatrices()[static_cast<size_t>(chin.mesh)].linear() *
      (state.coord[static_cast<size_t>(chin.mesh)].row(chin.vertex) -
       cloned.face.faceSceneGraph.meshes[static_cast<size_t>(chin.mesh)].coord.row(chin.vertex))
          .transpose();
  const double expected = 300 * cloned.fapu.MNS0.value / 1024;
  EXPECT_NEAR(moved.y(), -expected, 0.25 * expected) << moved.transpose();
  EXPECT_LE(std::hypot(moved.x(), moved.z()), 0.25 * expected) << moved.transpose();
}

TEST(CliClone, MissingFeaturePoints) {
  const std::filesystem::path dir = mpeg4face::test::scratchDir();
  const std::filesystem::path sourcePath = dir / "candide_keys.glb";
  writeGltf(sourceHead().model, sourcePath);
  const std::string wfm = (kCandideDir / "candide3.wfm").string();
  // No feature points on the target at all: every one the cloning needs is listed.
  auto r = runCli("clone " + sourcePath.string() + " " + wfm + " --source-feature-points " +
                  kCandideCsv + " -o " + (dir / "o.glb").string());
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_TRUE(contains(r.out, "candide3.wfm")) << r.out;
  EXPECT_TRUE(contains(r.out, "--target-feature-points")) << r.out;
  for (std::string_view id : cloneFeaturePoints()) {
    EXPECT_TRUE(contains(r.out, " " + std::string(id))) << id << "\n" << r.out;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "o.glb"));
  // One point left out of the CSV: exactly it is named.
  std::ifstream in(kCandideCsv);
  std::stringstream kept;
  for (std::string line; std::getline(in, line);) {
    if (!line.starts_with("10,2.1,")) kept << line << "\n";
  }
  const std::string csv = mpeg4face::test::writeScratchFile("no_2_1.csv", kept.str());
  r = runCli("clone " + sourcePath.string() + " " + wfm + " --source-feature-points " +
             kCandideCsv + " --target-feature-points " + csv + " -o " + (dir / "o.glb").string());
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_TRUE(contains(r.out, "feature points that cloning needs: 2.1 (")) << r.out;
  // The source without its feature points: the source is named.
  FaceModel bare = sourceHead().model;
  bare.featurePoints.clear();
  writeGltf(bare, dir / "bare_keys.glb");
  r = runCli("clone " + (dir / "bare_keys.glb").string() + " " + wfm + " --target-feature-points " +
             kCandideCsv + " -o " + (dir / "o.glb").string());
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_TRUE(contains(r.out, "bare_keys.glb")) << r.out;
  EXPECT_TRUE(contains(r.out, "--source-feature-points")) << r.out;
}

TEST(CliClone, BadInputAndUsage) {
  const std::filesystem::path dir = mpeg4face::test::scratchDir();
  const std::string wfm = (kCandideDir / "candide3.wfm").string();
  // Bad arguments: exit 2 with the usage.
  for (const std::string args :
       {"clone", "clone a.glb b.obj", "clone a.glb -o c.glb", "clone a.glb b.obj c.obj -o c.glb",
        "clone a.glb b.obj -o c.obj", "clone a.obj b.obj -o c.glb", "clone a.glb b.obj -o",
        "clone a.glb b.obj --filter-support -1 -o c.glb",
        "clone a.glb b.obj --filter-support x -o c.glb",
        "clone a.glb b.obj --frobnicate -o c.glb"}) {
    const auto r = runCli(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.out;
    EXPECT_TRUE(contains(r.out, "usage: mpeg4face clone")) << args << "\n" << r.out;
  }
  // A source with neither tables nor named shape keys; a missing file; a malformed .wrl.
  writeGltf(readWfm(wfm).model, dir / "plain.glb");
  auto r = runCli("clone " + (dir / "plain.glb").string() + " " + wfm + " -o " +
                  (dir / "o.wrl").string());
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_TRUE(contains(r.out, "plain.glb")) << r.out;
  EXPECT_TRUE(contains(r.out, "shape key named as a FAP")) << r.out;
  r = runCli("clone " + (dir / "none.wrl").string() + " " + wfm + " -o " +
             (dir / "o.wrl").string());
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_TRUE(contains(r.out, "none.wrl")) << r.out;
  const std::string bad =
      mpeg4face::test::writeScratchFile("bad.wrl", "#VRML V2.0 utf8\nTransform { scale 1 }\n");
  r = runCli("clone " + bad + " " + wfm + " -o " + (dir / "o.wrl").string());
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_TRUE(contains(r.out, "bad.wrl")) << r.out;
  // A face without tables as .wrl.
  writeVrml(MpegFace{readWfm(wfm).model, {}}, dir / "still.wrl");
  r = runCli("clone " + (dir / "still.wrl").string() + " " + wfm + " -o " +
             (dir / "o.wrl").string());
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_TRUE(contains(r.out, "no Face Animation Tables")) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "o.wrl"));
}
