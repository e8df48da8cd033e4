// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/obj.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::Error;
using mpeg4face::FaceModel;
using mpeg4face::IndexedFaceSet;
using mpeg4face::Points3;

using mpeg4face::test::errorOf;
using mpeg4face::test::kData;
const std::filesystem::path kBaseObj = kData / "makehuman" / "base.obj";

Error malformed(const std::string& name) {
  return errorOf([&] { mpeg4face::readObj(kData / "malformed" / name); });
}

const IndexedFaceSet& mesh(const FaceModel& model, const std::string& name) {
  const auto index = model.findMesh(name);
  if (!index) throw std::runtime_error("no mesh " + name);
  return model.meshes[*index];
}

// The OBJ's v lines read the slow, obvious way, to check the parser against.
std::vector<Eigen::Vector3d> objVertices(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::vector<Eigen::Vector3d> out;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string keyword;
    Eigen::Vector3d p;
    if (s >> keyword && keyword == "v" && s >> p.x() >> p.y() >> p.z()) out.push_back(p);
  }
  return out;
}

TEST(Obj, MakeHumanGroupsBecomeSeparateMeshes) {
  const FaceModel model = mpeg4face::readObj(kBaseObj);
  EXPECT_NO_THROW(model.validate());
  // 172 g lines, 139 distinct names (the eyelash groups and others repeat).
  ASSERT_EQ(model.meshes.size(), 139u);
  EXPECT_EQ(model.transforms.size(), 139u);
  EXPECT_EQ(model.roots.size(), 139u);
  EXPECT_EQ(model.meshes[0].name, "body");
  EXPECT_EQ(model.meshes[1].name, "helper-tights");

  const IndexedFaceSet& body = mesh(model, "body");
  EXPECT_EQ(body.faceCount(), 13378);
  EXPECT_EQ(body.vertexCount(), 13380);
  EXPECT_EQ(body.texCoord.rows(), 14517);
  EXPECT_EQ(body.texCoordIndex.size(), body.coordIndex.size());
  EXPECT_EQ(body.normal.rows(), 0);  // the file has no vn

  EXPECT_EQ(mesh(model, "helper-tights").faceCount(), 2650);
  EXPECT_EQ(mesh(model, "helper-tights").vertexCount(), 2674);
  EXPECT_EQ(mesh(model, "helper-l-eye").faceCount(), 70);
  EXPECT_EQ(mesh(model, "helper-l-eye").vertexCount(), 72);
  EXPECT_EQ(mesh(model, "helper-tongue").faceCount(), 224);
  EXPECT_EQ(mesh(model, "helper-tongue").vertexCount(), 226);
  EXPECT_EQ(mesh(model, "helper-hair").faceCount(), 198);
  // Its g line appears several times; the faces are merged into one mesh.
  EXPECT_EQ(mesh(model, "helper-l-eyelashes-1").faceCount(), 44);
  EXPECT_EQ(mesh(model, "helper-l-eyelashes-1").vertexCount(), 60);
  EXPECT_EQ(mesh(model, "joint-jaw").faceCount(), 6);

  int faces = 0;
  int vertices = 0;
  std::set<std::string> names;
  for (const IndexedFaceSet& m : model.meshes) {
    faces += m.faceCount();
    vertices += m.vertexCount();
    names.insert(m.name);
    // All quads, in VRML form.
    EXPECT_EQ(m.coordIndex.size(), 5u * static_cast<size_t>(m.faceCount())) << m.name;
    EXPECT_EQ(m.coordIndex.back(), -1) << m.name;
  }
  EXPECT_EQ(faces, 18486);
  EXPECT_EQ(vertices, 19158);  // every vertex of base.obj is in exactly one group
  EXPECT_EQ(names.size(), model.meshes.size());
}

TEST(Obj, SourceIndexMapsBackToObjCoordinates) {
  const FaceModel model = mpeg4face::readObj(kBaseObj);
  const std::vector<Eigen::Vector3d> v = objVertices(kBaseObj);
  ASSERT_EQ(v.size(), 19158u);
  for (const IndexedFaceSet& m : model.meshes) {
    ASSERT_EQ(m.sourceIndex.size(), static_cast<size_t>(m.vertexCount())) << m.name;
    for (int i = 0; i < m.vertexCount(); ++i) {
      const int source = m.sourceIndex[i];
      ASSERT_GE(source, 0);
      ASSERT_LT(source, 19158);
      if (i > 0) {
        ASSERT_LT(m.sourceIndex[i - 1], source) << "increasing OBJ order";
      }
      ASSERT_EQ(Eigen::Vector3d(m.coord.row(i).transpose()), v[source]) << m.name << " " << i;
    }
  }
  const IndexedFaceSet& body = mesh(model, "body");
  // "f 4849/1 1/2 2/3 4848/4" is the file's first face.
  EXPECT_EQ(body.sourceIndex[body.coordIndex[0]], 4848);
  EXPECT_EQ(body.sourceIndex[body.coordIndex[1]], 0);
  EXPECT_DOUBLE_EQ(body.coord(0, 0), -0.3492);
  EXPECT_DOUBLE_EQ(body.texCoord(body.texCoordIndex[0], 0), body.texCoord(0, 0));
}

TEST(Obj, ReadModelDispatchesByExtension) {
  EXPECT_EQ(mpeg4face::readModel(kBaseObj).meshes.size(), 139u);
}

TEST(Obj, CornerFormsAndNegativeIndices) {
  const FaceModel model = mpeg4face::parseObj(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
      "vn 0 0 1\n"
      "o plane\n"
      "f 1/1/1 2/2/1 3/3/1\n"
      "f -4/-4/-1 -2/-2/-1 -1/-1/-1\n",
      "plane.obj");
  ASSERT_EQ(model.meshes.size(), 1u);
  const IndexedFaceSet& m = model.meshes[0];
  EXPECT_EQ(m.name, "plane");
  EXPECT_EQ(m.coordIndex, (std::vector<int>{0, 1, 2, -1, 0, 2, 3, -1}));
  EXPECT_EQ(m.texCoordIndex, m.coordIndex);
  ASSERT_EQ(m.texCoord.rows(), 4);
  EXPECT_EQ(m.texCoord(2, 0), 1.0);
  ASSERT_EQ(m.normal.rows(), 4);  // one vn per vertex: kept
  EXPECT_EQ(m.normal(3, 2), 1.0);
  EXPECT_EQ(m.sourceIndex, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_NO_THROW(model.validate());
}

TEST(Obj, SplitNormalsAndPartialUvsAreDropped) {
  const FaceModel model = mpeg4face::parseObj(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nvn 0 0 -1\n"
      "f 1//1 2//1 3//1\n"
      "f 1//2 3//2 4//2\n"  // vertices 1 and 3 get a second normal
      "g b\n"
      "f 1/1 2/1 3/1\n"
      "f 1 3 4\n",  // no vt here, so b keeps no UVs
      "x.obj");
  ASSERT_EQ(model.meshes.size(), 2u);
  EXPECT_EQ(model.meshes[0].name, "x");  // faces before any g: named after the file
  EXPECT_EQ(model.meshes[0].normal.rows(), 0);
  EXPECT_EQ(model.meshes[1].texCoord.rows(), 0);
  EXPECT_TRUE(model.meshes[1].texCoordIndex.empty());
  EXPECT_NO_THROW(model.validate());
}

TEST(Obj, GroupsKeepOnlyTheirVerticesAndRepeatedNamesMerge) {
  const FaceModel model = mpeg4face::parseObj(
      "# comment\nmtllib x.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 2 2\n"
      "g a\nusemtl skin\ns 1\nf 4 3 2\n"
      "g b\nl 1 2\np 3\nvp 0.5\ncurv 0 1 1 2\nf 5 4 3\n"
      "g a\nf 2 1 4\n"
      "g\nf 1 2 3\n",
      "/some/dir/head.obj");
  ASSERT_EQ(model.meshes.size(), 3u);
  const IndexedFaceSet& a = model.meshes[0];
  EXPECT_EQ(a.name, "a");
  EXPECT_EQ(a.sourceIndex, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(a.coordIndex, (std::vector<int>{3, 2, 1, -1, 1, 0, 3, -1}));
  const IndexedFaceSet& b = model.meshes[1];
  EXPECT_EQ(b.sourceIndex, (std::vector<int>{2, 3, 4}));
  EXPECT_EQ(b.coordIndex, (std::vector<int>{2, 1, 0, -1}));
  EXPECT_EQ(b.coord(2, 0), 2.0);
  EXPECT_EQ(model.meshes[2].name, "head");  // a bare g returns to the default group
  EXPECT_EQ(model.transforms[1].name, "b");
  EXPECT_EQ(model.transforms[1].meshes, std::vector<int>{1});
}

TEST(Obj, LineEndingsAndExtraVertexValues) {
  // \r\n, no final newline, v with w and with r g b, vt with one and three values.
  const FaceModel model = mpeg4face::parseObj(
      "v 0 0 0 1\r\nv 1 0 0 0.5 0.5 0.5\r\nv 1 1 0\r\nvt 0.5\r\nvt 1 1 0\r\nvt 1 0\r\n"
      "f 1/1 2/2 3/3",
      "t.obj");
  const IndexedFaceSet& m = model.meshes.at(0);
  EXPECT_EQ(m.faceCount(), 1);
  EXPECT_EQ(m.coord(1, 0), 1.0);
  EXPECT_EQ(m.texCoord(0, 0), 0.5);
  EXPECT_EQ(m.texCoord(0, 1), 0.0);
}

TEST(Obj, MalformedBadIndex) {
  const Error e = malformed("obj_bad_index.obj");
  EXPECT_EQ(e.file(), (kData / "malformed" / "obj_bad_index.obj").string());
  EXPECT_EQ(e.line(), 7);
  EXPECT_EQ(e.field(), "f");
  EXPECT_NE(std::string(e.what()).find("vertex index 7 out of range: 4 defined so far"),
            std::string::npos)
      << e.what();
  EXPECT_NE(std::string(e.what()).find("obj_bad_index.obj:7: f: "), std::string::npos);
}

TEST(Obj, MalformedZeroAndNegativeIndex) {
  const Error zero = malformed("obj_zero_index.obj");
  EXPECT_EQ(zero.line(), 4);
  EXPECT_NE(zero.reason().find("index 0 is invalid"), std::string::npos) << zero.what();
  const Error negative = malformed("obj_negative_index.obj");
  EXPECT_EQ(negative.line(), 5);  // -1 -2 -3 on line 4 is fine, -4 is not
  EXPECT_NE(negative.reason().find("index -4 out of range"), std::string::npos) << negative.what();
}

TEST(Obj, MalformedTruncatedFace) {
  const Error e = malformed("obj_truncated.obj");
  EXPECT_EQ(e.line(), 12);
  EXPECT_EQ(e.field(), "f");
  EXPECT_NE(e.reason().find("at least 3 corners, found 2"), std::string::npos) << e.what();
}

TEST(Obj, MalformedNumbers) {
  const Error bad = malformed("obj_bad_number.obj");
  EXPECT_EQ(bad.line(), 2);
  EXPECT_EQ(bad.field(), "v");
  EXPECT_NE(bad.reason().find("'0x'"), std::string::npos) << bad.what();
  const Error shortV = malformed("obj_short_vertex.obj");
  EXPECT_EQ(shortV.line(), 2);
  EXPECT_NE(shortV.reason().find("3 coordinates expected, found 2"), std::string::npos);

  for (const char* value : {"nan", "inf", "-inf", "1e999", "1,5", "0x1p3", "--1"}) {
    const std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 " + std::string(value) + " 7\nf 1 2 3\n";
    const Error e = errorOf([&] { mpeg4face::parseObj(text, "n.obj"); });
    EXPECT_EQ(e.line(), 3) << value;
    EXPECT_EQ(e.file(), "n.obj");
  }
  const Error corner = errorOf([] { mpeg4face::parseObj("v 0 0 0\nf 1 1x 1\n", "c.obj"); });
  EXPECT_NE(corner.reason().find("'1x'"), std::string::npos) << corner.what();
  const Error parts = errorOf([] { mpeg4face::parseObj("v 0 0 0\nf 1/1/1/1 1 1\n", "c.obj"); });
  EXPECT_NE(parts.reason().find("more than 3 parts"), std::string::npos) << parts.what();
  const Error vt = errorOf([] { mpeg4face::parseObj("v 0 0 0\nf 1/1 1/1 1/1\n", "c.obj"); });
  EXPECT_NE(vt.reason().find("texture coordinate index 1 out of range"), std::string::npos)
      << vt.what();
  const Error huge = errorOf([] { mpeg4face::parseObj("v 0 0 0\nf 1 1 99999999999\n", "c.obj"); });
  EXPECT_EQ(huge.line(), 2);
}

TEST(Obj, MalformedNoFacesEmptyAndGarbage) {
  for (const char* name : {"obj_no_faces.obj", "obj_empty.obj", "obj_garbage.obj"}) {
    const Error e = malformed(name);
    EXPECT_EQ(e.file(), (kData / "malformed" / name).string());
    EXPECT_EQ(e.line(), 0) << name;  // the whole file is at fault
    EXPECT_NE(e.reason().find("no faces"), std::string::npos) << e.what();
  }
  const Error missing = errorOf([] { mpeg4face::readObj(kData / "malformed" / "nope.obj"); });
  EXPECT_NE(missing.reason().find("cannot open"), std::string::npos) << missing.what();
}

TEST(Obj, GarbageMessagesAreReadable) {
  const Error e =
      errorOf([] { mpeg4face::parseObj(std::string("v 0 0 \x01\xff\0z\n", 11), "bin.obj"); });
  EXPECT_NE(std::string(e.what()).find("'\\x01\\xff\\x00z'"), std::string::npos) << e.what();
}

}  // namespace

// Two meshes, one under a rotated and translated Transform: the file holds model-space
// positions (computed here by hand) and reads back as the same meshes and faces.
TEST(Obj, WriteReadRoundTripInModelSpace) {
  FaceModel model;
  IndexedFaceSet quad;
  quad.name = "skin";
  quad.coord.resize(4, 3);
  quad.coord << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0.1, 1, 1e-7;
  quad.coordIndex = {0, 1, 2, 3, -1};
  IndexedFaceSet tri;
  tri.name = "eye left";
  tri.coord.resize(3, 3);
  tri.coord << 1, 0, 0, 0, 1, 0, 0, 0, 1;
  tri.coordIndex = {2, 1, 0, -1};
  model.addMeshWithTransform(quad);
  const int eye = model.addMeshWithTransform(tri);
  model.transforms[static_cast<size_t>(eye)].translation = {10, 20, 30};
  // 90 degrees about z: (x, y, z) -> (-y, x, z).
  model.transforms[static_cast<size_t>(eye)].rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(std::acos(-1.0) / 2, Eigen::Vector3d::UnitZ()));
  const std::filesystem::path path = mpeg4face::test::scratchDir() / "round_trip.obj";
  mpeg4face::writeObj(model, path);
  const FaceModel back = mpeg4face::readObj(path);
  ASSERT_EQ(back.meshes.size(), 2u);
  EXPECT_EQ(back.meshes[0].name, "skin");
  EXPECT_EQ(back.meshes[1].name, "eye left");
  EXPECT_EQ(back.meshes[0].coordIndex, quad.coordIndex);
  EXPECT_EQ(back.meshes[0].coord, quad.coord);  // identity: bit-exact
  EXPECT_EQ(back.meshes[1].coordIndex, tri.coordIndex);
  Points3 expected(3, 3);
  expected << 10, 21, 30, 9, 20, 30, 10, 20, 31;
  EXPECT_LE((back.meshes[1].coord - expected).cwiseAbs().maxCoeff(), 1e-12);
  // File numbering continues across meshes: the triangle's corners are 7 6 5.
  EXPECT_NE(mpeg4face::readFile(path).find("f 7 6 5\n"), std::string::npos);
}

TEST(Obj, WriteRejectsNonFinitePositions) {
  FaceModel model;
  IndexedFaceSet tri;
  tri.coord.resize(3, 3);
  tri.coord << 0, 0, 0, 1, 0, 0, 0, std::nan(""), 0;
  tri.coordIndex = {0, 1, 2, -1};
  model.addMeshWithTransform(tri);
  const std::string message = errorOf([&] { mpeg4face::objText(model); }).what();
  EXPECT_NE(message.find("meshes[0].coord[2]"), std::string::npos) << message;
}
