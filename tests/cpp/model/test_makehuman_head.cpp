// SPDX-License-Identifier: GPL-3.0-or-later
// tests/data/makehuman/feature_points.csv on base.obj: complete for cloning and FAPU, and
// plausible by relations that hold on any face, whatever rule picked each point.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/obj.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/spec.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::FaceModel;
using mpeg4face::test::kData;

struct Head {
  FaceModel model;
  std::vector<std::string> warnings;
};

const Head& head() {
  static const Head h = [] {
    Head out;
    out.model = mpeg4face::readObj(kData / "makehuman" / "base.obj");
    auto csv =
        mpeg4face::readFeaturePointCsv(kData / "makehuman" / "feature_points.csv", out.model);
    out.model.featurePoints = csv.featurePoints;
    out.warnings = csv.warnings;
    return out;
  }();
  return h;
}

Eigen::Vector3d at(const std::string& id) {
  const auto p = head().model.featurePointPosition(id);
  if (!p) throw std::runtime_error("feature point " + id + " not bound");
  return *p;
}

// Every point CANDIDE-3's CSV binds (tests/data/candide3/feature_points.csv), plus what
// cloning needs beyond the face surface (Pandzic 2003, Figure 7: 3.5, 3.6, 7.2) and the
// points of the eye, teeth, tongue and head FAPs.
const std::vector<std::string> kRequired = {
    // CANDIDE-3
    "2.1", "2.2", "2.3", "2.4", "2.5", "2.6", "2.7", "2.8", "2.9", "2.10", "2.11", "2.12", "2.13",
    "2.14", "3.1", "3.2", "3.3", "3.4", "3.7", "3.8", "3.9", "3.10", "3.11", "3.12", "3.13", "3.14",
    "4.1", "4.2", "4.3", "4.4", "4.5", "4.6", "5.1", "5.2", "5.3", "5.4", "8.1", "8.2", "8.3",
    "8.4", "8.5", "8.6", "8.7", "8.8", "8.9", "8.10", "9.1", "9.2", "9.3", "9.4", "9.5", "9.6",
    "9.7", "9.12", "9.13", "9.14", "9.15", "10.7", "10.8", "10.9", "10.10", "11.1", "11.2", "11.3",
    "11.4",
    // beyond the surface
    "3.5", "3.6", "7.1", "7.2", "9.9", "9.10", "9.11", "6.1", "6.2", "6.3", "6.4"};

TEST(MakeHumanHead, EveryRequiredPointIsBoundWithoutWarnings) {
  EXPECT_TRUE(head().warnings.empty());
  for (const std::string& id : kRequired) {
    EXPECT_TRUE(head().model.featurePoints.count(id)) << id;
  }
  ASSERT_NO_THROW(head().model.validate());
}

TEST(MakeHumanHead, AllFapuMeasured) {
  const auto fapu = mpeg4face::measureFapu(head().model);
  for (const auto& d : fapu.distances()) {
    EXPECT_TRUE(d.distance->measured) << d.name << ": " << d.distance->method;
    EXPECT_GT(d.distance->value, 0.0) << d.name;
  }
  EXPECT_TRUE(fapu.missing().empty());
}

TEST(MakeHumanHead, PointsOnTheirParts) {
  const FaceModel& m = head().model;
  const auto meshOf = [&](const std::string& id) {
    return m.meshes[static_cast<size_t>(m.featurePoints.at(id).mesh)].name;
  };
  EXPECT_EQ(meshOf("3.5"), "helper-l-eye");
  EXPECT_EQ(meshOf("3.6"), "helper-r-eye");
  EXPECT_EQ(meshOf("9.10"), "helper-upper-teeth");
  EXPECT_EQ(meshOf("9.8"), "helper-upper-teeth");
  EXPECT_EQ(meshOf("9.9"), "helper-lower-teeth");
  EXPECT_EQ(meshOf("9.11"), "helper-lower-teeth");
  for (const char* id : {"6.1", "6.2", "6.3", "6.4"}) EXPECT_EQ(meshOf(id), "helper-tongue") << id;
  for (const char* id : {"2.1", "8.1", "9.3", "3.1", "10.1", "11.4"}) {
    EXPECT_EQ(meshOf(id), "body") << id;
  }
}

TEST(MakeHumanHead, AnatomyHolds) {
  const double mw = mpeg4face::measureFapu(head().model).MW0.value;
  const double es = mpeg4face::measureFapu(head().model).ES0.value;
  // The face's left is +x (MPEG-4): left-side points at larger x than their right partners.
  const std::vector<std::pair<std::string, std::string>> pairs = {
      {"3.5", "3.6"},    {"8.3", "8.4"},   {"2.4", "2.5"},   {"3.7", "3.12"},  {"4.5", "4.6"},
      {"10.1", "10.2"},  {"9.1", "9.2"},   {"2.6", "2.7"},   {"2.8", "2.9"},   {"2.11", "2.12"},
      {"2.13", "2.14"},  {"3.1", "3.2"},   {"3.3", "3.4"},   {"3.9", "3.10"},  {"3.11", "3.8"},
      {"3.13", "3.14"},  {"4.1", "4.2"},   {"4.3", "4.4"},   {"5.1", "5.2"},   {"5.3", "5.4"},
      {"6.3", "6.4"},    {"8.5", "8.6"},   {"8.7", "8.8"},   {"8.10", "8.9"},  {"9.5", "9.4"},
      {"9.7", "9.6"},    {"9.13", "9.14"}, {"10.3", "10.4"}, {"10.5", "10.6"}, {"10.7", "10.8"},
      {"10.9", "10.10"}, {"11.3", "11.2"}};
  for (const auto& [left, right] : pairs) {
    EXPECT_GT(at(left).x(), 0.0) << left;
    EXPECT_GT(at(left).x(), at(right).x()) << left << " " << right;
  }
  // Lip corners mirror each other within 5% of MW0.
  EXPECT_NEAR(at("8.3").x(), -at("8.4").x(), 0.05 * mw);
  EXPECT_NEAR(at("8.3").y(), at("8.4").y(), 0.05 * mw);
  // The chin bottom is below every mouth and chin point.
  for (const char* id : {"2.2", "2.3", "2.4", "2.5", "2.10", "2.11", "2.12", "8.1", "8.2", "8.3",
                         "8.4", "8.7", "8.8"}) {
    EXPECT_LT(at("2.1").y(), at(id).y()) << id;
  }
  // The nose tip is the most forward point of the face surface.
  for (const auto& [id, fp] : head().model.featurePoints) {
    if (id != "9.3") {
      EXPECT_LT(at(id).z(), at("9.3").z()) << id;
    }
  }
  // Vertical order down the midline.
  const std::vector<std::string> down = {"11.4", "11.1", "9.3", "9.15", "8.1",
                                         "2.2",  "2.3",  "8.2", "2.10", "2.1"};
  for (size_t i = 0; i + 1 < down.size(); ++i) {
    EXPECT_GT(at(down[i]).y(), at(down[i + 1]).y()) << down[i] << " above " << down[i + 1];
  }
  // Eyes: upper lid above lower lid, pupil between the eye corners, brows above the eye.
  EXPECT_GT(at("3.1").y(), at("3.3").y());
  EXPECT_GT(at("3.5").x(), at("3.11").x());
  EXPECT_LT(at("3.5").x(), at("3.7").x());
  EXPECT_GT(at("4.3").y(), at("3.13").y());
  // Teeth: upper incisors' bottom above the lower ones' top... or touching (closed jaw).
  EXPECT_GE(at("9.10").y(), at("9.11").y() - 0.05 * es);
  EXPECT_GT(at("9.8").y(), at("9.10").y());
  EXPECT_GT(at("9.11").y(), at("9.9").y());
  // Head rotation centres on the midline, 7.2 (neck base) below 7.1, both behind the face.
  EXPECT_EQ(at("7.1").x(), 0.0);
  EXPECT_LT(at("7.2").y(), at("7.1").y());
  EXPECT_LT(at("7.1").z(), at("2.1").z());
  // Every point with a Table 6 "=7.1.x" constraint is on the midline (the mesh is symmetric).
  for (const auto& info : mpeg4face::featurePointTable()) {
    const std::string id(info.id);
    if (info.constraintX == "=7.1.x" && head().model.featurePoints.count(id)) {
      EXPECT_NEAR(at(id).x(), 0.0, 1e-9) << id;
    }
  }
}

}  // namespace
