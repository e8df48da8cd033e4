// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/obj.hpp"
#include "mpeg4face/io/wfm.hpp"
#include "mpeg4face/spec.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::Error;
using mpeg4face::FaceModel;
using mpeg4face::FeaturePointCsv;

using mpeg4face::test::errorOf;
using mpeg4face::test::kData;

bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

const FaceModel& candide() {
  static const FaceModel model =
      mpeg4face::candideToFaceModel(mpeg4face::readWfm(kData / "candide3" / "candide3.wfm"));
  return model;
}

Error malformed(const std::string& name) {
  return errorOf([&] { mpeg4face::readFeaturePointCsv(kData / "malformed" / name, candide()); });
}

FeaturePointCsv parse(const std::string& text, const FaceModel& model = candide()) {
  return mpeg4face::parseFeaturePointCsv(text, "t.csv", model);
}

TEST(FeaturePointCsv, CandideBindings) {
  const FeaturePointCsv csv =
      mpeg4face::readFeaturePointCsv(kData / "candide3" / "feature_points.csv", candide());
  // 66 rows, 11.1 twice (vertices 1 and 34): the first wins.
  EXPECT_EQ(csv.featurePoints.size(), 65u);
  ASSERT_EQ(csv.warnings.size(), 1u);
  EXPECT_TRUE(contains(csv.warnings[0], "feature_points.csv:28: feature point 11.1"))
      << csv.warnings[0];
  EXPECT_TRUE(contains(csv.warnings[0], "first on line 3")) << csv.warnings[0];
  EXPECT_EQ(csv.featurePoints.at("11.1").vertex, 1);
  EXPECT_EQ(csv.featurePoints.at("2.1").mesh, 0);
  EXPECT_EQ(csv.featurePoints.at("2.1").vertex, 10);
  EXPECT_EQ(csv.featurePoints.at("2.10").vertex, 9);  // not the same id as 2.1
  EXPECT_EQ(csv.featurePoints.at("9.4").vertex, 112);
  for (const auto& [id, fp] : csv.featurePoints) {
    EXPECT_NE(mpeg4face::findFeaturePoint(id), nullptr) << id;
    EXPECT_EQ(fp.mesh, 0) << id;
  }

  FaceModel model = candide();
  model.featurePoints = csv.featurePoints;
  EXPECT_NO_THROW(model.validate());
  const auto noseTip = model.featurePointPosition("9.3");
  ASSERT_TRUE(noseTip);
  EXPECT_EQ(*noseTip, Eigen::Vector3d(model.meshes[0].coord.row(5).transpose()));
}

TEST(FeaturePointCsv, LayoutsWithoutHeader) {
  const FeaturePointCsv csv = parse(
      "# comment\n\n2.1,10\n9.3 , candide3 , 5\n11.4,0.5,1.5,-2\n"
      "2.2,\"87\"\n");
  ASSERT_EQ(csv.featurePoints.size(), 4u);
  EXPECT_EQ(csv.featurePoints.at("2.1").vertex, 10);
  EXPECT_EQ(csv.featurePoints.at("9.3").vertex, 5);
  EXPECT_EQ(csv.featurePoints.at("11.4").mesh, -1);
  EXPECT_EQ(csv.featurePoints.at("11.4").position, Eigen::Vector3d(0.5, 1.5, -2));
  EXPECT_EQ(csv.featurePoints.at("2.2").vertex, 87);
  EXPECT_TRUE(csv.warnings.empty());
}

TEST(FeaturePointCsv, HeaderSelectsColumnsByName) {
  // BOM, CRLF, columns in any order, extra columns, quoted fields with commas, "" and a line
  // break; rows with a vertex or with x,y,z.
  const FeaturePointCsv csv = parse(
      "\xEF\xBB\xBFnote,Z,x,Feature_Point,y,my_vertex,mesh\r\n"
      "\"a, \"\"quoted\"\"\nnote\",,,2.1,,10,candide3\r\n"
      "plain,3,1,9.3,2,,\r\n"
      "x,,,8.1,,7\r\n");
  ASSERT_EQ(csv.featurePoints.size(), 3u);
  EXPECT_EQ(csv.featurePoints.at("2.1").vertex, 10);
  EXPECT_EQ(csv.featurePoints.at("9.3").mesh, -1);
  EXPECT_EQ(csv.featurePoints.at("9.3").position, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(csv.featurePoints.at("8.1").vertex, 7);
}

TEST(FeaturePointCsv, VerticesOfSeveralMeshes) {
  // OBJ groups: vertex numbers are the OBJ's (0-based), a shared vertex binds to the first mesh.
  const FaceModel obj = mpeg4face::parseObj(
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 2 2\ng a\nf 1 2 3\ng b\nf 3 4 5\n", "x.obj");
  const FeaturePointCsv byFile = parse("fp,vertex\n2.1,4\n2.2,2\n9.3,0\n", obj);
  EXPECT_EQ(byFile.featurePoints.at("2.1").mesh, 1);
  EXPECT_EQ(byFile.featurePoints.at("2.1").vertex, 2);
  EXPECT_EQ(byFile.featurePoints.at("2.2").mesh, 0);
  EXPECT_EQ(byFile.featurePoints.at("2.2").vertex, 2);
  const FeaturePointCsv byMesh = parse("fp,mesh,vertex\n2.1,b,0\n", obj);
  EXPECT_EQ(byMesh.featurePoints.at("2.1").mesh, 1);
  EXPECT_EQ(byMesh.featurePoints.at("2.1").vertex, 0);

  // Without sourceIndex the meshes' vertices are counted one after the other.
  FaceModel plain = obj;
  for (auto& m : plain.meshes) m.sourceIndex.clear();
  const FeaturePointCsv counted = parse("2.1,4\n2.2,2\n", plain);
  EXPECT_EQ(counted.featurePoints.at("2.1").mesh, 1);
  EXPECT_EQ(counted.featurePoints.at("2.1").vertex, 1);
  EXPECT_EQ(counted.featurePoints.at("2.2").mesh, 0);
  const Error past = errorOf([&] { parse("2.1,6\n", plain); });
  EXPECT_TRUE(contains(past.what(), "6 vertices in all")) << past.what();

  const Error notHeld = errorOf([&] {
    FaceModel holes = obj;
    holes.meshes[1].sourceIndex = {2, 3, 7};
    parse("2.1,4\n", holes);
  });
  EXPECT_TRUE(contains(notHeld.what(), "no mesh holds vertex 4")) << notHeld.what();
}

TEST(FeaturePointCsv, OneMeshObjCountsTheFilesVertices) {
  // Vertex 2 is used by no face, so the reader drops it; the CSV's 3 is still the file's
  // fourth vertex (0-based 3), which is the mesh's vertex 2.
  const FaceModel obj =
      mpeg4face::parseObj("v 0 0 0\nv 1 0 0\nv 9 9 9\nv 0 1 0\nf 1 2 4\n", "one.obj");
  ASSERT_EQ(obj.meshes.size(), 1u);
  ASSERT_EQ(obj.meshes[0].vertexCount(), 3);
  const FeaturePointCsv csv = parse("fp,vertex\n2.1,3\n", obj);
  EXPECT_EQ(csv.featurePoints.at("2.1").mesh, 0);
  EXPECT_EQ(csv.featurePoints.at("2.1").vertex, 2);
  const Error dropped = errorOf([&] { parse("fp,vertex\n2.1,2\n", obj); });
  EXPECT_TRUE(contains(dropped.what(), "no mesh holds vertex 2")) << dropped.what();
}

TEST(FeaturePointCsv, MalformedUnknownFeaturePoint) {
  const Error e = malformed("csv_unknown_fp.csv");
  EXPECT_EQ(e.file(), (kData / "malformed" / "csv_unknown_fp.csv").string());
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.field(), "mpeg4_fp");
  EXPECT_TRUE(contains(e.what(), "unknown feature point '12.1'")) << e.what();
}

TEST(FeaturePointCsv, MalformedVertex) {
  const Error range = malformed("csv_bad_vertex.csv");
  EXPECT_EQ(range.line(), 4);
  EXPECT_EQ(range.field(), "candide_vertex");
  EXPECT_TRUE(contains(range.what(), "vertex 500 out of range (mesh 'candide3' has 113"))
      << range.what();
  const Error number = malformed("csv_bad_number.csv");
  EXPECT_EQ(number.line(), 3);
  EXPECT_EQ(number.field(), "vertex");
  EXPECT_TRUE(contains(number.what(), "'5x'")) << number.what();
  const Error negative = errorOf([] { parse("2.1,-1\n"); });
  EXPECT_EQ(negative.field(), "vertex");
  const Error nan = errorOf([] { parse("2.1,nan,0,0\n"); });
  EXPECT_EQ(nan.field(), "x");
  const Error mesh = malformed("csv_unknown_mesh.csv");
  EXPECT_EQ(mesh.line(), 3);
  EXPECT_EQ(mesh.field(), "mesh");
  EXPECT_TRUE(contains(mesh.what(), "unknown mesh 'body'")) << mesh.what();
  const Error noMesh = errorOf([] { parse("2.1,1\n", FaceModel{}); });
  EXPECT_TRUE(contains(noMesh.what(), "no mesh")) << noMesh.what();
}

TEST(FeaturePointCsv, MalformedQuoting) {
  // The quote opened on line 3 is never closed: the error names the line it starts on.
  const Error open = malformed("csv_unterminated_quote.csv");
  EXPECT_EQ(open.line(), 3);
  EXPECT_EQ(open.field(), "description");
  EXPECT_TRUE(contains(open.what(), "quoted field not closed")) << open.what();
  const Error after = errorOf([] { parse("fp,vertex\n\"2.1\"x,10\n"); });
  EXPECT_EQ(after.line(), 2);
  EXPECT_EQ(after.field(), "fp");
  EXPECT_TRUE(contains(after.what(), "',' expected after the closing quote, found 'x'"));
  // A quote left open in the middle of the file is only noticed where the next one closes it.
  const Error spanned = errorOf([] { parse("fp,vertex,note\n2.1,10,\"open\n9.3,5,\"x\"\n"); });
  EXPECT_EQ(spanned.line(), 3);
  EXPECT_TRUE(contains(spanned.what(), "is the quote opened on line 2 not closed?"))
      << spanned.what();
}

TEST(FeaturePointCsv, MalformedColumns) {
  const Error noFp = malformed("csv_no_fp_column.csv");
  EXPECT_EQ(noFp.line(), 1);
  EXPECT_TRUE(contains(noFp.what(), "no feature point column")) << noFp.what();
  const Error width = malformed("csv_wrong_width.csv");
  EXPECT_EQ(width.line(), 2);
  EXPECT_TRUE(contains(width.what(), "found 5")) << width.what();
  const Error noVertex = errorOf([] { parse("fp,mesh\n2.1,candide3\n"); });
  EXPECT_EQ(noVertex.line(), 1);
  const Error missing = errorOf([] { parse("fp,vertex\n2.1\n"); });
  EXPECT_EQ(missing.line(), 2);
  EXPECT_EQ(missing.field(), "vertex");
  const Error emptyId = errorOf([] { parse("fp,vertex\n,10\n"); });
  EXPECT_EQ(emptyId.field(), "fp");
}

TEST(FeaturePointCsv, MalformedEmptyHeaderOnlyAndGarbage) {
  for (const char* name : {"csv_empty.csv", "csv_header_only.csv"}) {
    const Error e = malformed(name);
    EXPECT_EQ(e.file(), (kData / "malformed" / name).string());
    EXPECT_EQ(e.line(), 0);
    EXPECT_TRUE(contains(e.what(), "no feature point rows")) << e.what();
  }
  const Error garbage = malformed("csv_garbage.csv");
  EXPECT_EQ(garbage.file(), (kData / "malformed" / "csv_garbage.csv").string());
  EXPECT_EQ(garbage.line(), 1);
  EXPECT_TRUE(contains(garbage.what(), "no feature point column")) << garbage.what();
}

}  // namespace
