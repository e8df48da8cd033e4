// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face fat generate`, `export` and `apply`, end to end: a glTF head whose morph targets
// are named FAP copies -> tables (.wrl) -> a .fap stream played on them (OBJ frame, baked
// glTF), checked against the morph targets interpolated here by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "mpeg4face/fit/fit.hpp"
#include "mpeg4face/fit/json.hpp"
#include "mpeg4face/fit/presets.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/gltf.hpp"
#include "mpeg4face/io/obj.hpp"
#include "mpeg4face/io/vrml.hpp"
#include "mpeg4face/io/wfm.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/spec.hpp"
#include "test_support.hpp"

namespace {

using namespace mpeg4face;
using mpeg4face::test::runCli;

const std::filesystem::path kCandideDir = mpeg4face::test::kData / "candide3";

double boundingDiagonal(const Points3& p) {
  return (p.colwise().maxCoeff() - p.colwise().minCoeff()).norm();
}

// The FAPs the head has copies of, and the amplitudes of their copies.
const std::map<int, std::vector<int>> kCopies = {
    {3, {-200, 400, 900}}, {4, {-300, 300}},  {6, {500}}, {7, {500}},
    {31, {-150, 250}},     {32, {-150, 250}},
};

// A head as a modeler would make it: CANDIDE-3's neutral face with one morph target per
// copy, the unit's motion bent (not linear in the value) so interpolation matters.
std::filesystem::path writeHead(const std::filesystem::path& dir) {
  const CandideModel candide = readWfm(kCandideDir / "candide3.wfm");
  FaceModel head = candide.model;
  head.featurePoints = readFeaturePointCsv(kCandideDir / "feature_points.csv", head).featurePoints;
  const FapuMeasurement fapu = measureFapu(head);
  for (const CandideUnit& u : candide.animationUnits) {
    const auto it = kCopies.find(u.fap);
    if (it == kCopies.end()) continue;
    double unit = fapu.unit(fapInfo(u.fap).fapu);
    for (const FapuInfo& info : fapuTable()) {
      if (info.name == u.fapu) unit = fapu.unit(info.kind);
    }
    for (int a : it->second) {
      MorphTarget& t = head.meshes[0].morphTargets.emplace_back();
      t.name = "fap" + std::to_string(u.fap) + "@" + std::to_string(a);
      t.displacements = Points3::Zero(head.meshes[0].vertexCount(), 3);
      const double bent = a * (1 + std::abs(a) / 1500.0);
      for (size_t i = 0; i < u.vertices.size(); ++i) {
        t.displacements.row(u.vertices[i]) =
            bent * unit * u.displacements.row(static_cast<Eigen::Index>(i));
      }
    }
  }
  head.meshes[0].weights.assign(head.meshes[0].morphTargets.size(), 0.0);
  const std::filesystem::path path = dir / "head.glb";
  writeGltf(head, path);
  return path;
}

// The head's vertices at FAP values `values`, straight from its morph targets: per FAP the
// piecewise-linear curve through (0, basis) and its copies, continued beyond the outermost
// ones; one copy at a: value / a of it.
Points3 expectedVertices(const FaceModel& head, const std::map<int, int>& values) {
  const IndexedFaceSet& mesh = head.meshes[0];
  Points3 out = mesh.coord;
  for (const auto& [fap, value] : values) {
    std::map<int, Points3> curve{{0, Points3::Zero(mesh.vertexCount(), 3)}};
    for (const MorphTarget& t : mesh.morphTargets) {
      const std::string prefix = "fap" + std::to_string(fap) + "@";
      if (t.name.starts_with(prefix))
        curve[std::stoi(t.name.substr(prefix.size()))] = t.displacements;
    }
    if (curve.size() < 2) throw std::runtime_error("no copies of FAP " + std::to_string(fap));
    auto upper = curve.upper_bound(value);
    if (upper == curve.end()) --upper;
    if (upper == curve.begin()) ++upper;
    const auto lower = std::prev(upper);
    const double s = double(value - lower->first) / (upper->first - lower->first);
    out += lower->second + s * (upper->second - lower->second);
  }
  out = (out * head.meshWorldMatrices()[0].linear().transpose()).rowwise() +
        head.meshWorldMatrices()[0].translation().transpose();
  return out;
}

// The frames of the stream: numbers as sent and the values a decoder holds after each.
struct TestFrame {
  int number;
  std::map<int, int> sent;
};
const std::vector<TestFrame> kFrames = {
    {0, {{3, 650}, {4, -300}, {6, 200}, {7, 200}, {31, -100}, {32, -100}}},
    {2, {{3, -350}, {4, 150}, {31, 300}, {32, 100}}},  // beyond the outermost copies
    {3, {{3, 1200}, {6, -250}, {7, 700}}},             // 4, 31, 32 held
    {7, {{3, 0}, {4, -10}}}                            // 4..6 skipped,
};

}  // namespace

TEST(CliFat, GenerateExportApplyEndToEnd) {
  const std::filesystem::path dir = mpeg4face::test::scratchDir();
  const std::filesystem::path headPath = writeHead(dir);
  const FaceModel head = readGltf(headPath);  // what the CLI reads: float positions
  const double tolerance = 1e-5 * boundingDiagonal(head.meshes[0].coord);
  const std::string fp = (kCandideDir / "feature_points.csv").string();

  // generate: one table per FAP with borders at its copies' amplitudes and 0.
  const std::filesystem::path wrl = dir / "face.wrl";
  auto r = runCli("fat generate " + headPath.string() + " --feature-points " + fp + " -o " +
                  wrl.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("FAP 3 open_jaw"), std::string::npos) << r.out;
  const MpegFace face = readVrml(wrl);
  EXPECT_TRUE(face.faceSceneGraph.meshes[0].morphTargets.empty());
  ASSERT_EQ(face.faceDefTables.size(), kCopies.size());
  for (const FaceDefTables& t : face.faceDefTables) {
    ASSERT_TRUE(kCopies.contains(t.fapID)) << t.fapID;
    std::set<int> borders(kCopies.at(t.fapID).begin(), kCopies.at(t.fapID).end());
    borders.insert(0);
    ASSERT_EQ(t.faceDefMesh.size(), 1u);
    EXPECT_EQ(t.faceDefMesh[0].intervalBorders, std::vector<int>(borders.begin(), borders.end()));
  }
  EXPECT_EQ(face.faceSceneGraph.meshes[0].coord, head.meshes[0].coord);
  EXPECT_TRUE(face.faceSceneGraph.featurePoints.contains("2.1"));  // from the CSV
  // The .wrl re-imports identically: written again, it is the same text.
  EXPECT_EQ(vrmlText(readVrml(wrl)), readFile(wrl));

  // A stream of those FAPs.
  FapStream stream;
  stream.name = "e2e";
  for (const TestFrame& tf : kFrames) {
    FapFrame& f = stream.frames.emplace_back();
    f.number = tf.number;
    for (const auto& [fap, v] : tf.sent) f.set(fap, v);
  }
  const std::filesystem::path fap = dir / "stream.fap";
  writeFapFile(fap, stream);
  std::map<int, int> held;
  std::vector<Points3> expected;
  for (const TestFrame& tf : kFrames) {
    for (const auto& [id, v] : tf.sent) held[id] = v;
    expected.push_back(expectedVertices(head, held));
  }

  // apply --frame N -o OUT.obj: each frame's vertices.
  for (size_t i = 0; i < kFrames.size(); ++i) {
    const std::filesystem::path obj = dir / ("frame" + std::to_string(i) + ".obj");
    r = runCli("apply " + wrl.string() + " " + fap.string() + " --frame " +
               std::to_string(kFrames[i].number) + " -o " + obj.string());
    ASSERT_EQ(r.status, 0) << r.out;
    const FaceModel frame = readObj(obj);
    ASSERT_EQ(frame.meshes.size(), 1u);
    const IndexedFaceSet& mesh = frame.meshes[0];
    double error = 0;
    for (int v = 0; v < mesh.vertexCount(); ++v) {
      error = std::max(error, (mesh.coord.row(v) - expected[i].row(mesh.sourceIndex[v])).norm());
    }
    EXPECT_LE(error, tolerance) << "frame " << kFrames[i].number;
  }

  // apply -o OUT.glb: the baked weights of each frame give the same vertices.
  const std::filesystem::path glb = dir / "animated.glb";
  r = runCli("apply " + wrl.string() + " " + fap.string() + " -o " + glb.string());
  ASSERT_EQ(r.status, 0) << r.out;
  const FaceModel baked = readGltf(glb);
  ASSERT_EQ(baked.animations.size(), 1u);
  ASSERT_EQ(baked.animations[0].channels.size(), 1u);
  const MorphWeightChannel& channel = baked.animations[0].channels[0];
  const IndexedFaceSet& mesh = baked.meshes[0];
  const size_t targets = mesh.morphTargets.size();
  for (size_t i = 0; i < kFrames.size(); ++i) {
    const double time = kFrames[i].number / stream.frameRate;
    const auto key =
        std::ranges::find_if(channel.times, [&](double t) { return std::abs(t - time) < 1e-6; });
    ASSERT_NE(key, channel.times.end()) << "no key at " << time;
    const auto k = static_cast<size_t>(key - channel.times.begin());
    Points3 coord = mesh.coord;
    for (size_t j = 0; j < targets; ++j) {
      coord += channel.weights[k * targets + j] * mesh.morphTargets[j].displacements;
    }
    coord = (coord * baked.meshWorldMatrices()[0].linear().transpose()).rowwise() +
            baked.meshWorldMatrices()[0].translation().transpose();
    EXPECT_LE((coord - expected[i]).rowwise().norm().maxCoeff(), tolerance)
        << "frame " << kFrames[i].number;
  }

  // export: the same targets, no animation.
  const std::filesystem::path exported = dir / "face.gltf";
  r = runCli("export " + wrl.string() + " -o " + exported.string());
  ASSERT_EQ(r.status, 0) << r.out;
  const FaceModel still = readGltf(exported);
  EXPECT_TRUE(still.animations.empty());
  EXPECT_EQ(still.meshes[0].morphTargets.size(), targets);
}

TEST(CliFat, ErrorsAndUsage) {
  const std::filesystem::path dir = mpeg4face::test::scratchDir();
  // Bad arguments: exit 2 with the usage.
  EXPECT_EQ(runCli("fat").status, 2);
  EXPECT_EQ(runCli("fat frobnicate x.glb -o y.wrl").status, 2);
  EXPECT_EQ(runCli("fat generate head.glb").status, 2);           // no -o
  EXPECT_EQ(runCli("fat generate head.obj -o y.wrl").status, 2);  // not glTF
  EXPECT_EQ(runCli("fat generate h.glb --threshold -1 -o y.wrl").status, 2);
  EXPECT_EQ(runCli("apply f.wrl s.fap -o out.obj").status, 2);  // OBJ needs --frame
  EXPECT_EQ(runCli("apply f.wrl s.fap --frame x -o out.obj").status, 2);
  EXPECT_EQ(runCli("export f.wrl -o out.obj").status, 2);
  // Bad input: exit 1 naming the file and what is wrong.
  const std::filesystem::path wrl = dir / "bad.wrl";
  std::ofstream(wrl) << "#VRML V2.0 utf8\nTransform { translation 1 2 }\n";
  auto r = runCli("export " + wrl.string() + " -o " + (dir / "o.glb").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("bad.wrl"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Transform.translation"), std::string::npos) << r.out;
  // A head without named targets.
  FaceModel plain = readWfm(kCandideDir / "candide3.wfm").model;
  writeGltf(plain, dir / "plain.glb");
  r = runCli("fat generate " + (dir / "plain.glb").string() + " -o " + (dir / "p.wrl").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("morph targets"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "p.wrl"));
}

namespace {

// The mesh of `apply FACE STREAM --frame N -o OBJ`, checking the command's output.
Points3 appliedFrame(const std::filesystem::path& face, const std::filesystem::path& stream,
                     int frame, const std::string& expectOut) {
  const std::filesystem::path obj = mpeg4face::test::scratchDir() / "frame.obj";
  const auto r = runCli("apply " + face.string() + " " + stream.string() + " --frame " +
                        std::to_string(frame) + " -o " + obj.string());
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find(expectOut), std::string::npos) << r.out;
  return readObj(obj).meshes.at(0).coord;
}

}  // namespace

// CANDIDE-3's units as tables, with the viseme FIT in the Face node: a stream that sends
// only visemes (as `speak` writes them) moves the mouth exactly as the FAPs the FIT derives.
TEST(CliFat, CandideUnitsWithAVisemeFitSpeakAVisemeStream) {
  const std::filesystem::path dir = mpeg4face::test::scratchDir();
  const std::string csv = (kCandideDir / "feature_points.csv").string();
  const std::string wfm = (kCandideDir / "candide3.wfm").string();
  const std::filesystem::path fit = dir / "viseme.json", face = dir / "face.wrl";
  ASSERT_EQ(runCli("fit preset viseme -o " + fit.string()).status, 0);
  auto r = runCli("fat generate " + wfm + " --feature-points " + csv + " --fit " + fit.string() +
                  " -o " + face.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("FAP 3 open_jaw"), std::string::npos) << r.out;
  const MpegFace read = readVrml(face);
  EXPECT_EQ(read.faceDefTables.size(), 54u);
  ASSERT_TRUE(read.fit.has_value());
  EXPECT_EQ(*read.fit, readFitJson(fit));

  FapStream visemes;  // neutral, then A: fully, as an .fba
  visemes.frames.resize(2);
  for (int n : {0, 1}) {
    visemes.frames[n].number = n;
    visemes.frames[n].set(1, 0);
    visemes.frames[n].viseme = {n == 0 ? 0 : 10, 0, 63};
  }
  writeFapFile(dir / "visemes.fap", visemes);
  const std::filesystem::path fba = dir / "visemes.fba";
  ASSERT_EQ(runCli("encode " + (dir / "visemes.fap").string() + " -o " + fba.string()).status, 0);
  FapStream faps;  // the same mouth sent as the FAPs the viseme preset gives A:
  faps.frames.resize(2);
  FapFrame aa;
  aa.set(1, 0);
  aa.viseme = {10, 0, 63};
  interpolateFitFrame(visemeFitTable(), aa);
  for (int n : {0, 1}) {
    faps.frames[n].number = n;
    for (int fap : visemeFitFaps()) faps.frames[n].set(fap, n == 0 ? 0 : aa.value(fap));
  }
  writeFapFile(dir / "faps.fap", faps);
  const Points3 neutral = appliedFrame(face, fba, 0, "the face's FIT derived");
  const Points3 spoken = appliedFrame(face, fba, 1, "the face's FIT derived");
  const Points3 sent = appliedFrame(face, dir / "faps.fap", 1, "wrote");
  EXPECT_GT((spoken - neutral).cwiseAbs().maxCoeff(), 0.01);  // the jaw opened
  EXPECT_LE((spoken - sent).cwiseAbs().maxCoeff(), 1e-6);

  // Without the FIT the face has no viseme tables: the viseme stream leaves it still.
  const std::filesystem::path plain = dir / "plain.wrl";
  ASSERT_EQ(
      runCli("fat generate " + wfm + " --feature-points " + csv + " -o " + plain.string()).status,
      0);
  EXPECT_EQ(appliedFrame(plain, fba, 1, "wrote"), appliedFrame(plain, fba, 0, "wrote"));

  // A FIT that fails on the stream (f = 100 / F at F = 0) names the face and the frame;
  // nothing is written.
  FitTable divides;
  const int link = addFitLink(divides, addFitNode(divides, {33}), addFitNode(divides, {31}));
  setFitFunction(divides, link, 31, {{FitTerm{100, {0}}}, {FitTerm{1, {1}}}});
  writeFitJson(divides, dir / "divides.json");
  const std::filesystem::path divided = dir / "divided.wrl";
  ASSERT_EQ(runCli("fat generate " + wfm + " --feature-points " + csv + " --fit " +
                   (dir / "divides.json").string() + " -o " + divided.string())
                .status,
            0);
  FapStream brows;
  brows.frames.resize(1);
  brows.frames[0].set(33, 0);
  writeFapFile(dir / "brows.fap", brows);
  r = runCli("apply " + divided.string() + " " + (dir / "brows.fap").string() + " -o " +
             (dir / "brows.glb").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("divided.wrl"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Face.fit frame 0"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("denominator is 0"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "brows.glb"));

  // The units need the FAPU: without feature points the file and the unit are named.
  r = runCli("fat generate " + wfm + " -o " + (dir / "none.wrl").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("candide3.wfm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("is not measured"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "none.wrl"));
}
