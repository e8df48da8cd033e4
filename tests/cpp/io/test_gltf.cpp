// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include "gltf_validator.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/gltf.hpp"
#include "mpeg4face/io/obj.hpp"
#include "mpeg4face/model/face_model.hpp"
#include "test_support.hpp"

using namespace mpeg4face;
namespace fs = std::filesystem;

namespace {

using mpeg4face::test::kData;

// glTF stores 32-bit floats.
constexpr double kTolerance = 1e-5;

Eigen::Quaterniond rotationAbout(const Eigen::Vector3d& axis, double degrees) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(degrees * std::numbers::pi / 180, axis.normalized()));
}

// A model with everything the writer handles: two meshes in one transform, a mesh instanced
// twice, a hierarchy with rotation / scale / centre, quads, UV seams (texCoordIndex),
// per-vertex UVs, non-unit normals, named morph targets, weights, animations with all three
// interpolations, Transform channels (translation, rotation about a centre, cubic scale) and
// feature points on vertices and in free space.
FaceModel fullModel() {
  FaceModel model;

  IndexedFaceSet face;
  face.name = "face";
  face.coord.resize(9, 3);
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) face.coord.row(3 * j + i) << 0.1 * i, 0.1 * j, 0.01 * i * j;
  }
  face.coordIndex = {0, 1, 4, 3, -1, 1, 2, 5, 4, -1, 3, 4, 7, 6, -1, 4, 5, 8, 7, -1, 2, 8, 5, -1};
  // Grid UVs for the left column of quads; the right column has its own UVs for the middle
  // vertices 1, 4, 7 (a seam).
  face.texCoord.resize(12, 2);
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) face.texCoord.row(3 * j + i) << 0.25 * i, 0.5 * j;
  }
  face.texCoord.row(9) << 0.6, 0.0;
  face.texCoord.row(10) << 0.6, 0.5;
  face.texCoord.row(11) << 0.6, 1.0;
  face.texCoordIndex = {0, 1, 4,  3,  -1, 9, 2,  5,  10, -1, 3, 4,
                        7, 6, -1, 10, 5,  8, 11, -1, 2,  8,  5, -1};
  face.normal = Points3::Zero(9, 3);
  face.normal.col(2).setConstant(2.0);  // not unit: the writer normalizes
  face.normal.row(4) << 0.3, 0.0, 1.5;
  MorphTarget jaw{"jawOpen", Points3::Zero(9, 3)};
  for (int i = 0; i < 3; ++i) jaw.displacements(i, 1) = -0.02;
  MorphTarget smile{"smile", Points3::Zero(9, 3)};
  smile.displacements(6, 0) = -0.01;
  smile.displacements(8, 0) = 0.01;
  smile.displacements(8, 1) = 0.005;
  face.morphTargets = {jaw, smile};
  face.weights = {0.3, 0.0};

  IndexedFaceSet eye;
  eye.name = "eye";
  eye.coord.resize(4, 3);
  eye.coord << 0, 0, 0, 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01;
  eye.coordIndex = {0, 2, 1, -1, 0, 1, 3, -1, 0, 3, 2, -1, 1, 2, 3, -1};
  MorphTarget blink{"blink", Points3::Zero(4, 3)};
  blink.displacements(2, 1) = -0.008;
  eye.morphTargets = {blink};
  eye.weights = {0.0};

  IndexedFaceSet teeth;
  teeth.name = "teeth";
  teeth.coord.resize(4, 3);
  teeth.coord << -0.02, 0, 0, 0.02, 0, 0, 0.02, 0.01, 0, -0.02, 0.01, 0;
  teeth.coordIndex = {0, 1, 2, 3, -1};
  teeth.texCoord.resize(4, 2);
  teeth.texCoord << 0, 0, 1, 0, 1, 1, 0, 1;

  model.meshes = {face, eye, teeth};

  Transform head;
  head.name = "head";
  head.translation = {0, 1.6, 0.05};
  head.rotation = rotationAbout({1, 0, 0}, 20);
  head.scale = {1.1, 1.1, 1.1};
  head.center = {0, 0.2, 0};
  head.meshes = {0, 2};  // two meshes: the writer adds a node per mesh
  head.children = {1, 2};
  Transform left;
  left.name = "leftEye";
  left.translation = {0.03, 0.05, 0.02};
  left.rotation = rotationAbout({0, 1, 0}, 10);
  left.scale = {1, 1, 0.9};
  left.center = {0.005, 0, 0};
  left.meshes = {1};
  Transform right;
  right.name = "rightEye";
  right.translation = {-0.03, 0.05, 0.02};
  right.meshes = {1};  // the same mesh again
  model.transforms = {head, left, right};
  model.roots = {0};

  model.featurePoints["2.1"] = {.mesh = 0, .vertex = 1};
  model.featurePoints["3.5"] = {.mesh = 1, .vertex = 3};
  model.featurePoints["11.1"] = {.mesh = -1, .vertex = -1, .position = {0.1, 0.2, 0.3}};

  MorphWeightAnimation talk;
  talk.name = "talk";
  MorphWeightChannel mouth;
  mouth.mesh = 0;
  mouth.times = {0, 0.5, 1.25};
  mouth.weights = {0, 0, 1, 0.5, 0.2, 1};
  MorphWeightChannel eyes;
  eyes.mesh = 1;
  eyes.interpolation = MorphWeightChannel::Interpolation::Step;
  eyes.times = {0, 1};
  eyes.weights = {0, 1};
  talk.channels = {mouth, eyes};
  MorphWeightAnimation cubic;
  cubic.name = "cubic";
  MorphWeightChannel smooth;
  smooth.mesh = 1;
  smooth.interpolation = MorphWeightChannel::Interpolation::CubicSpline;
  smooth.times = {0, 2};
  smooth.weights = {0, 0, 0.5, 0.1, 1, 0};
  cubic.channels = {smooth};
  // The left eye (centre 0.005 0 0) turns; the head (one translation key) nods forward and
  // grows along a cubic spline.
  TransformChannel turn;
  turn.transform = 1;
  turn.times = {0, 0.5, 1.25};
  for (double degrees : {0.0, 25.0, -10.0}) {
    const Eigen::Quaterniond q = left.rotation * rotationAbout({0, 1, 0}, degrees);
    turn.values.insert(turn.values.end(), {q.x(), q.y(), q.z(), q.w()});
  }
  talk.transformChannels = {turn};
  TransformChannel nod{.transform = 0,
                       .path = TransformChannel::Path::Translation,
                       .interpolation = MorphWeightChannel::Interpolation::Step,
                       .times = {0.25},
                       .values = {0, 1.55, 0.08}};
  TransformChannel grow{.transform = 0,
                        .path = TransformChannel::Path::Scale,
                        .interpolation = MorphWeightChannel::Interpolation::CubicSpline,
                        .times = {0, 2},
                        .values = {0, 0, 0, 1.1, 1.1, 1.1, 0.1, 0, 0,  //
                                   0, 0, 0, 1.2, 1.1, 1.1, 0, 0, 0}};
  cubic.transformChannels = {nod, grow};
  model.animations = {talk, cubic};
  model.validate();
  return model;
}

struct Corner {
  int vertex;
  Eigen::Vector2d uv;
};

// The corners of the fan-triangulated polygons with the UV each one uses.
std::vector<Corner> triangleCorners(const IndexedFaceSet& mesh) {
  std::vector<Corner> out;
  auto uvOf = [&](int corner) -> Eigen::Vector2d {
    if (!mesh.texCoordIndex.empty()) return mesh.texCoord.row(mesh.texCoordIndex[corner]);
    if (mesh.texCoord.rows() > 0) return mesh.texCoord.row(mesh.coordIndex[corner]);
    return Eigen::Vector2d::Zero();
  };
  for (auto [begin, end] : mesh.faceRanges()) {
    for (int k = begin + 1; k + 1 < end; ++k) {
      for (int c : {begin, k, k + 1}) out.push_back({mesh.coordIndex[c], uvOf(c)});
    }
  }
  return out;
}

bool near(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double tolerance = kTolerance) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         (a.rows() == 0 || (a - b).cwiseAbs().maxCoeff() <= tolerance);
}

void expectSameMesh(const IndexedFaceSet& a, const IndexedFaceSet& b) {
  SCOPED_TRACE("mesh " + a.name);
  EXPECT_EQ(a.name, b.name);
  ASSERT_EQ(a.vertexCount(), b.vertexCount());
  EXPECT_TRUE(near(a.coord, b.coord, kTolerance * std::max(1.0, a.coord.cwiseAbs().maxCoeff())));
  EXPECT_EQ(a.triangles(), b.triangles());
  EXPECT_EQ(a.texCoord.rows() > 0, b.texCoord.rows() > 0);
  const std::vector<Corner> ca = triangleCorners(a);
  const std::vector<Corner> cb = triangleCorners(b);
  ASSERT_EQ(ca.size(), cb.size());
  for (size_t i = 0; i < ca.size(); ++i) {
    EXPECT_EQ(ca[i].vertex, cb[i].vertex);
    EXPECT_TRUE(ca[i].uv.isApprox(cb[i].uv, kTolerance) ||
                (ca[i].uv - cb[i].uv).norm() < kTolerance)
        << "corner " << i << ": " << ca[i].uv.transpose() << " vs " << cb[i].uv.transpose();
  }
  ASSERT_EQ(a.normal.rows(), b.normal.rows());
  for (int v = 0; v < a.normal.rows(); ++v) {
    EXPECT_TRUE(near(a.normal.row(v).normalized(), b.normal.row(v).normalized())) << "normal " << v;
  }
  ASSERT_EQ(a.morphTargets.size(), b.morphTargets.size());
  for (size_t t = 0; t < a.morphTargets.size(); ++t) {
    EXPECT_EQ(a.morphTargets[t].name, b.morphTargets[t].name);
    EXPECT_TRUE(near(a.morphTargets[t].displacements, b.morphTargets[t].displacements))
        << a.morphTargets[t].name;
  }
  ASSERT_EQ(a.weights.size(), b.weights.size());
  for (size_t i = 0; i < a.weights.size(); ++i) EXPECT_NEAR(a.weights[i], b.weights[i], 1e-12);
}

void expectSameModel(const FaceModel& a, const FaceModel& b) {
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  for (size_t m = 0; m < a.meshes.size(); ++m) expectSameMesh(a.meshes[m], b.meshes[m]);

  ASSERT_EQ(a.transforms.size(), b.transforms.size());
  for (size_t t = 0; t < a.transforms.size(); ++t) {
    const Transform& ta = a.transforms[t];
    const Transform& tb = b.transforms[t];
    SCOPED_TRACE("transform " + ta.name);
    EXPECT_EQ(ta.name, tb.name);
    EXPECT_EQ(ta.children, tb.children);
    EXPECT_EQ(ta.meshes, tb.meshes);
    EXPECT_TRUE(near(ta.localMatrix().matrix(), tb.localMatrix().matrix(), 1e-9));
    EXPECT_TRUE(near(ta.center, tb.center, 1e-12)) << "kept in a centre node";
  }
  EXPECT_EQ(a.roots, b.roots);
  const auto wa = a.meshWorldMatrices();
  const auto wb = b.meshWorldMatrices();
  for (size_t m = 0; m < wa.size(); ++m) EXPECT_TRUE(near(wa[m].matrix(), wb[m].matrix(), 1e-9));

  ASSERT_EQ(a.featurePoints.size(), b.featurePoints.size());
  for (const auto& [id, fa] : a.featurePoints) {
    SCOPED_TRACE("feature point " + id);
    ASSERT_TRUE(b.featurePoints.contains(id));
    const FeaturePointBinding& fb = b.featurePoints.at(id);
    EXPECT_EQ(fa.mesh, fb.mesh);
    if (fa.mesh >= 0) {
      EXPECT_EQ(fa.vertex, fb.vertex);
    } else {
      EXPECT_TRUE(near(fa.position, fb.position, 1e-12));
    }
  }

  ASSERT_EQ(a.animations.size(), b.animations.size());
  for (size_t i = 0; i < a.animations.size(); ++i) {
    const MorphWeightAnimation& aa = a.animations[i];
    const MorphWeightAnimation& ab = b.animations[i];
    SCOPED_TRACE("animation " + aa.name);
    EXPECT_EQ(aa.name, ab.name);
    ASSERT_EQ(aa.channels.size(), ab.channels.size());
    for (size_t c = 0; c < aa.channels.size(); ++c) {
      EXPECT_EQ(aa.channels[c].mesh, ab.channels[c].mesh);
      EXPECT_EQ(aa.channels[c].interpolation, ab.channels[c].interpolation);
      ASSERT_EQ(aa.channels[c].times.size(), ab.channels[c].times.size());
      for (size_t k = 0; k < aa.channels[c].times.size(); ++k) {
        EXPECT_NEAR(aa.channels[c].times[k], ab.channels[c].times[k], kTolerance);
      }
      ASSERT_EQ(aa.channels[c].weights.size(), ab.channels[c].weights.size());
      for (size_t k = 0; k < aa.channels[c].weights.size(); ++k) {
        EXPECT_NEAR(aa.channels[c].weights[k], ab.channels[c].weights[k], kTolerance);
      }
    }
    ASSERT_EQ(aa.transformChannels.size(), ab.transformChannels.size());
    for (size_t c = 0; c < aa.transformChannels.size(); ++c) {
      const TransformChannel& ca = aa.transformChannels[c];
      const TransformChannel& cb = ab.transformChannels[c];
      EXPECT_EQ(ca.transform, cb.transform);
      EXPECT_EQ(ca.path, cb.path);
      EXPECT_EQ(ca.interpolation, cb.interpolation);
      EXPECT_TRUE(near(Eigen::Map<const Eigen::VectorXd>(ca.times.data(), std::ssize(ca.times)),
                       Eigen::Map<const Eigen::VectorXd>(cb.times.data(), std::ssize(cb.times))));
      EXPECT_TRUE(near(Eigen::Map<const Eigen::VectorXd>(ca.values.data(), std::ssize(ca.values)),
                       Eigen::Map<const Eigen::VectorXd>(cb.values.data(), std::ssize(cb.values))));
    }
  }
}

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void spit(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string base64(const std::string& bytes) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    uint32_t chunk = 0;
    for (size_t k = 0; k < 3; ++k) {
      chunk = chunk << 8 | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    }
    for (size_t k = 0; k < 4; ++k) out += k <= n ? digits[(chunk >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

// Floats as little-endian bytes.
std::string floatBytes(const std::vector<float>& values) {
  std::string out(values.size() * sizeof(float), '\0');
  std::memcpy(out.data(), values.data(), out.size());
  return out;
}

// A one-primitive glTF (positions only, no indices) with the given mode; `extra` is spliced
// into the top-level object.
std::string singlePrimitiveGltf(const std::vector<float>& positions, int mode,
                                const std::string& bufferUri, const std::string& extra = "") {
  const size_t count = positions.size() / 3;
  const std::string n = std::to_string(count);
  return R"({"asset":{"version":"2.0"},"meshes":[{"name":"m","primitives":[{"attributes":)"
         R"({"POSITION":0},"mode":)" +
         std::to_string(mode) +
         R"(}]}],"nodes":[{"name":"a","mesh":0}],"accessors":[{"bufferView":0,)"
         R"("componentType":5126,"count":)" +
         n + R"(,"type":"VEC3"}],"bufferViews":[{"buffer":0,"byteLength":)" +
         std::to_string(4 * positions.size()) + R"(}],"buffers":[{"byteLength":)" +
         std::to_string(4 * positions.size()) + R"(,"uri":")" + bufferUri + "\"}]" + extra + "}";
}

std::string dataUri(const std::vector<float>& values) {
  return "data:application/octet-stream;base64," + base64(floatBytes(values));
}

class GltfTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = mpeg4face::test::scratchDir(); }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
};

// Reads `path` expecting an Error whose field contains `field` and whose message contains
// `message`.
void expectReadError(const fs::path& path, const std::string& field, const std::string& message) {
  SCOPED_TRACE(path.filename().string());
  try {
    (void)readGltf(path);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.file(), path.string());
    EXPECT_NE(e.field().find(field), std::string::npos) << "field: " << e.field();
    if (field.empty()) {
      EXPECT_EQ(e.field(), "");
    }
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(Base64, MatchesKnownVectors) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
}

TEST_F(GltfTest, RoundTripKeepsEverything) {
  const FaceModel model = fullModel();
  for (const char* name : {"full.gltf", "full.glb", "FULL.GLB"}) {
    SCOPED_TRACE(name);
    const fs::path path = dir_ / name;
    writeGltf(model, path);
    const FaceModel back = readGltf(path);
    expectSameModel(model, back);
    // The eye mesh is one IndexedFaceSet used by two transforms.
    EXPECT_EQ(back.transforms[1].meshes, std::vector<int>{1});
    EXPECT_EQ(back.transforms[2].meshes, std::vector<int>{1});
    EXPECT_EQ(back.animations[0].channels.size(), 2u);
    // The mesh that had texCoordIndex keeps one; the seam vertices stay welded.
    EXPECT_EQ(back.meshes[0].vertexCount(), 9);
    EXPECT_EQ(back.meshes[0].texCoordIndex.size(), 9u * 4) << "4 quads and a triangle";
    // The feature points are where they were.
    for (const auto& [id, fp] : model.featurePoints) {
      EXPECT_TRUE(model.featurePointPosition(id)->isApprox(*back.featurePointPosition(id), 1e-6));
    }
    EXPECT_FALSE(fs::exists(path.string() + ".part"));
  }
  const std::string json = slurp(dir_ / "full.gltf");
  EXPECT_NE(json.find("\"generator\": \"mpeg4face\""), std::string::npos);
  EXPECT_NE(json.find("data:application/octet-stream;base64,"), std::string::npos);
  EXPECT_NE(json.find("_MPEG4FACE_VERTEX"), std::string::npos);
  const std::string glb = slurp(dir_ / "full.glb");
  ASSERT_GT(glb.size(), 28u);
  EXPECT_EQ(glb.substr(0, 4), "glTF");
  EXPECT_EQ(glb.find("data:application"), std::string::npos) << "a .glb keeps its buffer in BIN";
}

// glTF has no centre: the node is T + C, R, S over a helper node -C, so glTF viewers and
// modellers rotate and scale the node about the centre, and readGltf gets the centre back.
TEST_F(GltfTest, CentreIsKeptInAHelperNode) {
  FaceModel model;
  IndexedFaceSet mesh;
  mesh.name = "m";
  mesh.coord.resize(3, 3);
  mesh.coord << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  mesh.coordIndex = {0, 1, 2, -1};
  model.addMeshWithTransform(mesh);
  model.addMeshWithTransform(mesh);
  model.transforms[0].meshes.push_back(1);  // two meshes under a centre node
  model.transforms[0].children.push_back(1);
  model.roots = {0};
  Transform& t = model.transforms[0];
  t.center = {1, 2, 3};
  t.rotation = rotationAbout({0, 0, 1}, 90);
  t.scale = {2, 1, 1};
  t.translation = {0, 0, 5};
  model.transforms[1].center = {0, 1, 0};
  writeGltf(model, dir_ / "c.gltf");
  const FaceModel back = readGltf(dir_ / "c.gltf");
  ASSERT_EQ(back.transforms.size(), 2u);
  const Transform& b = back.transforms[0];
  EXPECT_TRUE(near(b.center, t.center, 1e-12));
  EXPECT_TRUE(near(b.translation, t.translation, 1e-12));
  EXPECT_TRUE(b.rotation.isApprox(t.rotation, 1e-12));
  EXPECT_EQ(b.meshes, (std::vector<int>{0, 1}));
  EXPECT_EQ(b.children, std::vector<int>{1});
  EXPECT_TRUE(near(back.transforms[1].center, Eigen::Vector3d(0, 1, 0), 1e-12));
  EXPECT_EQ(back.transforms[1].meshes, std::vector<int>{1});
  // In the file: node 0 = T + C, R, S; its only child "m.center" = -C.
  const std::string json = slurp(dir_ / "c.gltf");
  EXPECT_NE(json.find("\"m.center\""), std::string::npos);
  EXPECT_NE(json.find("\"center\": true"), std::string::npos);
}

TEST_F(GltfTest, KhronosStyleMorphCube) {
  const FaceModel cube = readGltf(kData / "gltf/morph_cube.gltf");
  ASSERT_EQ(cube.meshes.size(), 1u);
  const IndexedFaceSet& mesh = cube.meshes[0];
  EXPECT_EQ(mesh.name, "Cube");
  EXPECT_EQ(mesh.vertexCount(), 24);
  EXPECT_EQ(mesh.faceCount(), 12);  // 5 faces x 2 triangles + a 4-vertex strip
  EXPECT_TRUE(mesh.texCoordIndex.empty());
  ASSERT_EQ(mesh.texCoord.rows(), 24);
  // glTF (0, 1) is the bottom left, (0, 0) in VRML orientation.
  EXPECT_TRUE(near(mesh.texCoord.row(0), Eigen::RowVector2d(0, 0)));
  EXPECT_TRUE(near(mesh.texCoord.row(2), Eigen::RowVector2d(1, 1)));
  ASSERT_EQ(mesh.normal.rows(), 24);
  ASSERT_EQ(mesh.morphTargets.size(), 2u);
  EXPECT_EQ(mesh.morphTargets[0].name, "thin");
  EXPECT_EQ(mesh.morphTargets[1].name, "angle");
  EXPECT_EQ(mesh.weights, (std::vector<double>{0.25, 0.0}));
  for (int v = 0; v < 24; ++v) {
    const double x = mesh.coord(v, 0);
    const bool top = mesh.coord(v, 1) > 0;
    EXPECT_TRUE(
        near(mesh.morphTargets[0].displacements.row(v), Eigen::RowVector3d(-0.5 * x, 0, 0)));
    // "angle" is a sparse accessor without a buffer view.
    EXPECT_TRUE(
        near(mesh.morphTargets[1].displacements.row(v), Eigen::RowVector3d(top ? 0.5 : 0.0, 0, 0)))
        << v;
  }
  // The strip a b d c makes (a b d) and (b c d), both facing +Y.
  const std::vector<int> tri = mesh.triangles();
  ASSERT_EQ(tri.size(), 36u);
  EXPECT_EQ(std::vector<int>(tri.end() - 6, tri.end()), (std::vector<int>{20, 21, 22, 21, 23, 22}));
  for (size_t i = 30; i < 36; i += 3) {
    const Eigen::Vector3d a = mesh.coord.row(tri[i]);
    const Eigen::Vector3d b = mesh.coord.row(tri[i + 1]);
    const Eigen::Vector3d c = mesh.coord.row(tri[i + 2]);
    EXPECT_GT((b - a).cross(c - a).y(), 0) << "triangle " << i / 3;
  }

  ASSERT_EQ(cube.transforms.size(), 3u);
  EXPECT_EQ(cube.transforms[0].name, "AnimatedMorphCube");
  EXPECT_EQ(cube.transforms[0].children, (std::vector<int>{1, 2}));
  EXPECT_EQ(cube.transforms[1].meshes, std::vector<int>{0});
  EXPECT_EQ(cube.roots, std::vector<int>{0});
  const Eigen::Affine3d expected = Eigen::Translation3d(0, 0, 0) * rotationAbout({0, 1, 0}, 30) *
                                   Eigen::Translation3d(0, 0.5, 0) *
                                   Eigen::Scaling(Eigen::Vector3d(1, 2, 1));
  EXPECT_TRUE(near(cube.meshWorldMatrices()[0].matrix(), expected.matrix(), 1e-9));
  // The marker's matrix decomposes into T R S.
  const Transform& marker = cube.transforms[2];
  EXPECT_EQ(marker.name, "Marker");
  EXPECT_TRUE(near(marker.translation, Eigen::Vector3d(0, 2, 0), 1e-12));
  EXPECT_TRUE(near(marker.scale, Eigen::Vector3d(0.5, 0.5, 0.5), 1e-12));
  EXPECT_TRUE(marker.rotation.isApprox(rotationAbout({0, 0, 1}, 90), 1e-12));

  ASSERT_EQ(cube.animations.size(), 1u);
  EXPECT_EQ(cube.animations[0].name, "Square");
  ASSERT_EQ(cube.animations[0].channels.size(), 1u);
  ASSERT_EQ(cube.animations[0].transformChannels.size(), 1u);
  const TransformChannel& turn = cube.animations[0].transformChannels[0];
  EXPECT_EQ(turn.transform, 0);
  EXPECT_EQ(turn.path, TransformChannel::Path::Rotation);
  EXPECT_EQ(turn.times, (std::vector<double>{0, 4}));
  const double half = std::sqrt(0.5);
  EXPECT_TRUE(near(Eigen::Map<const Eigen::Vector<double, 8>>(turn.values.data()),
                   Eigen::Vector<double, 8>(0, 0, 0, 1, 0, half, 0, half)));
  const MorphWeightChannel& channel = cube.animations[0].channels[0];
  EXPECT_EQ(channel.mesh, 0);
  EXPECT_EQ(channel.interpolation, MorphWeightChannel::Interpolation::Linear);
  EXPECT_EQ(channel.times, (std::vector<double>{0, 1, 2, 3, 4}));
  EXPECT_EQ(channel.weights, (std::vector<double>{0, 0, 1, 0, 1, 1, 0, 1, 0, 0}));

  for (const char* name : {"cube.gltf", "cube.glb"}) {
    SCOPED_TRACE(name);
    writeGltf(cube, dir_ / name);
    expectSameModel(cube, readGltf(dir_ / name));
  }
}

TEST_F(GltfTest, MakeHumanObjRoundTripsThroughGlb) {
  const FaceModel human = readObj(kData / "makehuman/base.obj");
  ASSERT_FALSE(human.meshes.empty());
  bool seams = false;
  for (const IndexedFaceSet& mesh : human.meshes) seams |= !mesh.texCoordIndex.empty();
  EXPECT_TRUE(seams) << "the MakeHuman meshes should have texCoordIndex";
  writeGltf(human, dir_ / "base.glb");
  const FaceModel back = readGltf(dir_ / "base.glb");
  ASSERT_EQ(back.meshes.size(), human.meshes.size());
  for (size_t m = 0; m < human.meshes.size(); ++m) {
    // sourceIndex (OBJ numbering) has no place in glTF.
    IndexedFaceSet expected = human.meshes[m];
    expected.sourceIndex.clear();
    expectSameMesh(expected, back.meshes[m]);
  }
}

TEST_F(GltfTest, ExternalBufferNextToTheFile) {
  const std::vector<float> triangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  spit(dir_ / "t.bin", floatBytes(triangle));
  spit(dir_ / "t.gltf", singlePrimitiveGltf(triangle, 4, "t.bin"));
  const FaceModel model = readGltf(dir_ / "t.gltf");
  ASSERT_EQ(model.meshes.size(), 1u);
  EXPECT_EQ(model.meshes[0].triangles(), (std::vector<int>{0, 1, 2}));

  // From memory without a base folder no file may be read.
  EXPECT_THROW(parseGltf(slurp(dir_ / "t.gltf"), "t.gltf"), Error);
  // Nor from outside the file's folder.
  fs::create_directories(dir_ / "sub");
  spit(dir_ / "sub/t.gltf", singlePrimitiveGltf(triangle, 4, "../t.bin"));
  expectReadError(dir_ / "sub/t.gltf", "buffers[0]", "only files in the glTF file's folder");
}

TEST_F(GltfTest, FeaturePointsOnUnnamedOrSameNamedMeshes) {
  FaceModel model = fullModel();
  model.meshes[2].name = "face";  // two meshes named "face"
  model.meshes[1].name = "";      // read back as "mesh1"
  model.featurePoints["8.1"] = {.mesh = 2, .vertex = 3};
  writeGltf(model, dir_ / "names.glb");
  const FaceModel back = readGltf(dir_ / "names.glb");
  EXPECT_EQ(back.meshes[1].name, "mesh1");
  EXPECT_EQ(back.featurePoints.at("8.1").mesh, 2);
  EXPECT_EQ(back.featurePoints.at("8.1").vertex, 3);
  EXPECT_EQ(back.featurePoints.at("3.5").mesh, 1);
  EXPECT_EQ(back.featurePoints.at("2.1").mesh, 0);
}

TEST_F(GltfTest, FansStripsPointsAndNoScene) {
  // A fan of 5 vertices: (1 2 0) (2 3 0) (3 4 0).
  const std::vector<float> fan = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, -1, 1, 0};
  FaceModel model = parseGltf(singlePrimitiveGltf(fan, 6, dataUri(fan)), "fan.gltf");
  EXPECT_EQ(model.meshes[0].triangles(), (std::vector<int>{1, 2, 0, 2, 3, 0, 3, 4, 0}));
  // No scenes: the parentless nodes are the roots.
  EXPECT_EQ(model.roots, std::vector<int>{0});
  // Points keep their vertices but make no faces.
  model = parseGltf(singlePrimitiveGltf(fan, 0, dataUri(fan)), "points.gltf");
  EXPECT_EQ(model.meshes[0].vertexCount(), 5);
  EXPECT_EQ(model.meshes[0].faceCount(), 0);
  // ...and a mesh without faces is written as points.
  writeGltf(model, dir_ / "points.glb");
  EXPECT_EQ(readGltf(dir_ / "points.glb").meshes[0].vertexCount(), 5);
  // Unknown modes are errors.
  try {
    parseGltf(singlePrimitiveGltf(fan, 9, dataUri(fan)), "mode.gltf");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "meshes[0].primitives[0].mode");
  }
}

TEST_F(GltfTest, WriteErrorsLeaveNothingBehind) {
  const FaceModel model = fullModel();
  EXPECT_THROW(writeGltf(model, dir_ / "x.obj"), Error);
  EXPECT_FALSE(fs::exists(dir_ / "x.obj"));
  EXPECT_THROW(writeGltf(model, dir_ / "missing/x.glb"), Error);

  // glTF animates the weights of nodes, so a mesh no transform holds cannot be animated.
  FaceModel loose = model;
  loose.transforms[1].meshes.clear();
  loose.transforms[2].meshes.clear();
  try {
    writeGltf(loose, dir_ / "loose.glb");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_EQ(e.file(), (dir_ / "loose.glb").string());
    EXPECT_NE(std::string(e.what()).find("not held by any transform"), std::string::npos);
  }
  EXPECT_FALSE(fs::exists(dir_ / "loose.glb"));

  FaceModel broken = model;
  broken.meshes[0].coord(0, 0) = std::nan("");
  EXPECT_THROW(writeGltf(broken, dir_ / "nan.gltf"), Error);
  EXPECT_FALSE(fs::exists(dir_ / "nan.gltf"));
}

TEST(GltfMalformed, ErrorsNameTheProblem) {
  const fs::path dir = kData / "malformed";
  expectReadError(dir / "gltf_empty.gltf", "", "empty");
  expectReadError(dir / "gltf_garbage.glb", "", "not glTF");
  expectReadError(dir / "gltf_garbage_magic.glb", "GLB header", "version");
  expectReadError(dir / "gltf_truncated.glb", "GLB header", "truncated");
  expectReadError(dir / "gltf_glb_bin_overrun.glb", "GLB chunk 1", "truncated");
  expectReadError(dir / "gltf_truncated.gltf", "JSON", "parse error");
  expectReadError(dir / "gltf_accessor_past_buffer.gltf",
                  "meshes[0].primitives[0].attributes.POSITION", "past the end of buffer view");
  expectReadError(dir / "gltf_index_out_of_range.gltf", "meshes[0].primitives[0].indices",
                  "index 7 at position 2 is out of range");
  expectReadError(dir / "gltf_position_wrong_type.gltf",
                  "meshes[0].primitives[0].attributes.POSITION", "UNSIGNED_SHORT");
  expectReadError(dir / "gltf_missing_buffer.gltf", "buffers[0]", "gltf_missing_buffer.bin");
  expectReadError(dir / "gltf_shear_matrix.gltf", "nodes[0].matrix", "'Triangle'");
  expectReadError(dir / "gltf_shear_matrix.gltf", "nodes[0].matrix", "shear");
  expectReadError(dir / "gltf_does_not_exist.gltf", "", "cannot open");
}

TEST(GltfMalformed, TruncatedJsonHasALine) {
  try {
    (void)readGltf(kData / "malformed/gltf_truncated.gltf");
    FAIL();
  } catch (const Error& e) {
    EXPECT_GT(e.line(), 1);
  }
}

TEST(GltfMalformed, HostileJson) {
  auto expectError = [](const std::string& json, const std::string& field) {
    SCOPED_TRACE(json.substr(0, 80));
    try {
      (void)parseGltf(json, "x.gltf");
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      EXPECT_EQ(e.field(), field) << e.what();
    }
  };
  expectError(R"({"a":)" + std::string(5000, '[') + std::string(5000, ']') + "}", "JSON");
  expectError(R"({"asset":{"version":"2.0"},"extras":)" + std::string(500, '[') +
                  std::string(500, ']') + "}",
              "JSON");
  expectError(R"({"asset":{"version":"1.0"}})", "asset.version");
  expectError(R"({"asset":{"version":"2.0"},"extensionsRequired":["KHR_draco_mesh_compression"]})",
              "extensionsRequired[0]");
  // An accessor with no buffer view and a huge count.
  expectError(
      R"({"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
      R"("accessors":[{"componentType":5126,"count":4000000000,"type":"VEC3"}]})",
      "meshes[0].primitives[0].attributes.POSITION");
  // A byte offset so large that offset + element size wraps around.
  expectError(
      R"({"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
      R"("accessors":[{"bufferView":0,"byteOffset":18446744073709551612,"componentType":5126,)"
      R"("count":1,"type":"VEC3"}],"bufferViews":[{"buffer":0,"byteLength":12}],"buffers":)"
      R"([{"byteLength":12,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAA"}]})",
      "meshes[0].primitives[0].attributes.POSITION");
  // Node cycles and shared children.
  expectError(R"({"asset":{"version":"2.0"},"nodes":[{"children":[1]},{"children":[0]}]})",
              "nodes[1].children");
  expectError(R"({"asset":{"version":"2.0"},"nodes":[{"children":[2]},{"children":[2]},{}]})",
              "nodes[1].children");
  expectError(R"({"asset":{"version":"2.0"},"scene":3,"scenes":[{}]})", "scene");
}

// Runs the Khronos glTF validator when MPEG4FACE_GLTF_VALIDATOR names a command, e.g.
//   MPEG4FACE_GLTF_VALIDATOR="node tests/tools/validate_gltf.mjs"
// (npm install --prefix tests/tools first): no errors and no warnings.
TEST_F(GltfTest, KhronosValidatorAcceptsOurFiles) {
  MPEG4FACE_SKIP_WITHOUT_GLTF_VALIDATOR();
  const FaceModel model = fullModel();
  writeGltf(model, dir_ / "full.gltf");
  writeGltf(model, dir_ / "full.glb");
  mpeg4face::test::expectValidGltf({dir_ / "full.gltf", dir_ / "full.glb"});
}
