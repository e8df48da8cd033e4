// SPDX-License-Identifier: GPL-3.0-or-later
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "mpeg4face/io/wfm.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::CandideModel;
using mpeg4face::CandideUnit;
using mpeg4face::Error;

using mpeg4face::test::errorOf;
using mpeg4face::test::kData;
const std::filesystem::path kCandide = kData / "candide3" / "candide3.wfm";

Error malformed(const std::string& name) {
  return errorOf([&] { mpeg4face::readWfm(kData / "malformed" / name); });
}

bool contains(const Error& e, const std::string& text) {
  return std::string(e.what()).find(text) != std::string::npos;
}

const CandideUnit& fapUnit(const CandideModel& c, int fap) {
  for (const CandideUnit& u : c.animationUnits) {
    if (u.fap == fap) return u;
  }
  throw std::runtime_error("no unit for FAP " + std::to_string(fap));
}

// A small valid file; tests splice broken parts into it.
const std::string kTriangle = "# VERTEX LIST:\n3\n0 0 0\n1 0 0\n0 1 0\n\n# FACE LIST:\n1\n0 1 2\n";

TEST(Wfm, Candide3Geometry) {
  const CandideModel c = mpeg4face::readWfm(kCandide);
  ASSERT_EQ(c.model.meshes.size(), 1u);
  const auto& mesh = c.model.meshes[0];
  EXPECT_EQ(mesh.name, "candide3");
  EXPECT_EQ(mesh.vertexCount(), 113);
  EXPECT_EQ(mesh.faceCount(), 184);
  EXPECT_EQ(mesh.coordIndex.size(), 184u * 4);
  EXPECT_EQ(std::vector<int>(mesh.coordIndex.begin(), mesh.coordIndex.begin() + 4),
            (std::vector<int>{0, 11, 1, -1}));
  EXPECT_DOUBLE_EQ(mesh.coord(0, 1), 1.061);
  EXPECT_DOUBLE_EQ(mesh.coord(0, 2), -0.371);
  EXPECT_DOUBLE_EQ(mesh.coord(112, 0), -0.12);
  EXPECT_TRUE(mesh.morphTargets.empty());
  EXPECT_EQ(c.model.transforms.size(), 1u);
  EXPECT_NO_THROW(c.model.validate());
}

TEST(Wfm, Candide3Units) {
  const CandideModel c = mpeg4face::readWfm(kCandide);
  ASSERT_EQ(c.animationUnits.size(), 70u);
  EXPECT_EQ(c.shapeUnits.size(), 38u);

  std::set<int> faps;
  for (const CandideUnit& u : c.animationUnits) {
    if (u.fap != 0) faps.insert(u.fap);
    EXPECT_EQ(static_cast<size_t>(u.displacements.rows()), u.vertices.size()) << u.name;
  }
  EXPECT_EQ(faps.size(), 54u);
  std::set<int> expected;
  for (int f = 3; f <= 42; ++f) expected.insert(f);
  for (int f = 51; f <= 64; ++f) expected.insert(f);
  EXPECT_EQ(faps, expected);

  const CandideUnit& openJaw = fapUnit(c, 3);
  EXPECT_EQ(openJaw.name, "FAP 3 open_jaw");
  EXPECT_EQ(openJaw.fapu, "MNS");
  EXPECT_EQ(openJaw.vertices, (std::vector<int>{10, 32, 65}));
  EXPECT_EQ(openJaw.displacements(0, 1), -1.0);
  EXPECT_EQ(fapUnit(c, 10).name, "FAP10 raise_b_lip_lm");  // no space after "FAP"
  EXPECT_EQ(fapUnit(c, 10).fapu, "MNS");
  EXPECT_EQ(fapUnit(c, 6).fapu, "MW");
  EXPECT_EQ(fapUnit(c, 19).fapu, "IRISD");
  EXPECT_EQ(fapUnit(c, 31).fapu, "ENS");
  EXPECT_EQ(fapUnit(c, 37).fapu, "ES");
  EXPECT_EQ(fapUnit(c, 61).name, "FAP61 strecth_l_nose");  // CANDIDE's spelling, kept
  EXPECT_EQ(fapUnit(c, 61).fapu, "ENS");
  for (int eye = 23; eye <= 30; ++eye) EXPECT_EQ(fapUnit(c, eye).fapu, "") << eye;
  for (int f : faps) {
    if (f < 23 || f > 30) {
      EXPECT_FALSE(fapUnit(c, f).fapu.empty()) << f;
    }
  }

  const CandideUnit& first = c.animationUnits.front();
  EXPECT_EQ(first.name, "Nose wrinkler");
  EXPECT_EQ(first.fap, 0);
  EXPECT_EQ(first.fapu, "");
  EXPECT_EQ(first.vertices.size(), 26u);
  EXPECT_EQ(first.vertices[0], 25);
  EXPECT_DOUBLE_EQ(first.displacements(0, 1), 0.1);
  EXPECT_EQ(c.animationUnits[6].name, "AUV0   Upper lip raiser (AU10)");
  EXPECT_EQ(c.shapeUnits.front().name, "Head height");
  EXPECT_EQ(c.shapeUnits.front().vertices.size(), 17u);
  EXPECT_EQ(c.shapeUnits.back().name, "Jaw z-position");
  EXPECT_EQ(c.shapeUnits.back().vertices.size(), 20u);
}

TEST(Wfm, CandideToFaceModelHasOneMorphTargetPerUnit) {
  const CandideModel c = mpeg4face::readWfm(kCandide);
  const mpeg4face::FaceModel model = mpeg4face::candideToFaceModel(c);
  EXPECT_NO_THROW(model.validate());
  ASSERT_EQ(model.meshes.size(), 1u);
  const auto& mesh = model.meshes[0];
  ASSERT_EQ(mesh.morphTargets.size(), 70u);
  for (size_t i = 0; i < 70; ++i) {
    EXPECT_EQ(mesh.morphTargets[i].name, c.animationUnits[i].name);
    EXPECT_EQ(mesh.morphTargets[i].displacements.rows(), 113);
  }
  const auto it = std::find_if(mesh.morphTargets.begin(), mesh.morphTargets.end(),
                               [](const auto& t) { return t.name == "FAP 3 open_jaw"; });
  ASSERT_NE(it, mesh.morphTargets.end());
  EXPECT_EQ(Eigen::Vector3d(it->displacements.row(10).transpose()), Eigen::Vector3d(0, -1, 0));
  EXPECT_EQ(it->displacements.row(0).norm(), 0.0);
  EXPECT_EQ(it->displacements.cwiseAbs().sum(), 3.0);  // only vertices 10, 32, 65

  const mpeg4face::FaceModel viaReadModel = mpeg4face::readModel(kCandide);
  EXPECT_EQ(viaReadModel.meshes.at(0).morphTargets.size(), 70u);
}

TEST(Wfm, UnitComments) {
  const std::string text = kTriangle +
                           "# ANIMATION UNITS LIST:\n3\n\n"
                           "# Jaw drop\n# a second comment line\n1\n1 0 -1 0\n\n"
                           "# FAP 5 some_unknown_name\n# MNS\n# more notes\n0\n\n"
                           "#\n# FAP10\n# MW\n2\n2 0 1 0\n2 0 1 0\n"
                           "# FAPs not implemented:\n# FAP43 shift_tongue_tip\n"
                           "# SHAPE UNITS LIST:\n1\n# Head height\n1\n0 0 0.2 0\n"
                           "# GLOBAL MOTION:\n0 0 0\n1 1 1\n# END OF FILE\nanything\n";
  const CandideModel c = mpeg4face::parseWfm(text, "t.wfm");
  ASSERT_EQ(c.animationUnits.size(), 3u);
  EXPECT_EQ(c.animationUnits[0].name, "Jaw drop");
  EXPECT_EQ(c.animationUnits[0].fap, 0);
  EXPECT_EQ(c.animationUnits[1].fap, 5);  // unknown name: the number wins
  EXPECT_EQ(c.animationUnits[1].fapu, "MNS");
  EXPECT_EQ(c.animationUnits[2].name, "FAP10");
  EXPECT_EQ(c.animationUnits[2].fapu, "MW");
  ASSERT_EQ(c.shapeUnits.size(), 1u);
  // A vertex listed twice moves by the sum.
  const auto model = mpeg4face::candideToFaceModel(c);
  EXPECT_EQ(model.meshes[0].morphTargets[2].displacements(2, 1), 2.0);
}

TEST(Wfm, CrLfAndLatin1) {
  std::string text = "# J\xf6rgen\n" + kTriangle +
                     "# ANIMATION UNITS LIST:\n1\n# L\xe4ppar\n1\n0 1 0 0";  // no final newline
  for (size_t i = 0; (i = text.find('\n', i)) != std::string::npos; i += 2) text.insert(i, "\r");
  const CandideModel c = mpeg4face::parseWfm(text, "crlf.wfm");
  ASSERT_EQ(c.animationUnits.size(), 1u);
  EXPECT_EQ(c.animationUnits[0].name, "L\xc3\xa4ppar");  // Latin-1 read as such, kept as UTF-8
  EXPECT_EQ(c.model.meshes[0].faceCount(), 1);
}

TEST(Wfm, MalformedTruncated) {
  // The real file cut at line 250, inside the face list.
  const Error e = malformed("wfm_truncated.wfm");
  EXPECT_EQ(e.file(), (kData / "malformed" / "wfm_truncated.wfm").string());
  EXPECT_EQ(e.line(), 250);
  EXPECT_EQ(e.field(), "FACE LIST");
  EXPECT_TRUE(contains(e, "count says 184 rows, but the file ends after 95")) << e.what();
}

TEST(Wfm, TruncatedAnywhereFailsCleanly) {
  // A cut may fall between lists (the unit lists are optional) or inside the last number of a
  // row and still parse; it must never yield a list shorter than its count.
  const std::string text = mpeg4face::readFile(kCandide);
  for (size_t cut = 0; cut < text.size(); cut += 53) {
    const std::string part = text.substr(0, cut);
    try {
      const CandideModel c = mpeg4face::parseWfm(part, "cut.wfm");
      EXPECT_EQ(c.model.meshes[0].faceCount(), 184) << cut;
      EXPECT_TRUE(c.animationUnits.empty() || c.animationUnits.size() == 70) << cut;
      EXPECT_TRUE(c.shapeUnits.empty() || c.shapeUnits.size() == 38) << cut;
      if (!c.animationUnits.empty()) {
        EXPECT_EQ(c.animationUnits.back().vertices.size(), 3u) << cut;  // FAP64 bend_nose
      }
    } catch (const Error& e) {
      EXPECT_EQ(e.file(), "cut.wfm");
      EXPECT_LE(e.line(), std::count(part.begin(), part.end(), '\n') + 1) << cut;
    }
  }
}

TEST(Wfm, MalformedNumbersAndIndices) {
  const Error number = malformed("wfm_bad_number.wfm");
  EXPECT_EQ(number.line(), 4);
  EXPECT_EQ(number.field(), "VERTEX LIST");
  EXPECT_TRUE(contains(number, "'0.5x'")) << number.what();

  const Error face = malformed("wfm_bad_face_index.wfm");
  EXPECT_EQ(face.line(), 10);
  EXPECT_EQ(face.field(), "FACE LIST");
  EXPECT_TRUE(contains(face, "vertex 3 out of range (the model has 3 vertices)")) << face.what();

  const Error unit = malformed("wfm_bad_unit_vertex.wfm");
  EXPECT_EQ(unit.line(), 18);
  EXPECT_EQ(unit.field(), "ANIMATION UNITS LIST");
  EXPECT_TRUE(contains(unit, "vertex 99 out of range")) << unit.what();

  const Error huge = malformed("wfm_huge_count.wfm");
  EXPECT_EQ(huge.line(), 2);
  EXPECT_TRUE(contains(huge, "out of range: '4000000000'")) << huge.what();

  // A count that fits an int must not reserve memory for that many rows.
  const Error big =
      errorOf([] { mpeg4face::parseWfm("# VERTEX LIST:\n2000000000\n0 0 0\n", "big.wfm"); });
  EXPECT_EQ(big.line(), 3);
  EXPECT_TRUE(contains(big, "count says 2000000000 rows, but the file ends after 1"));

  const Error shortRow =
      errorOf([] { mpeg4face::parseWfm("# VERTEX LIST:\n2\n0 0 0\n0 0\n", "short.wfm"); });
  EXPECT_EQ(shortRow.line(), 4);
  EXPECT_TRUE(contains(shortRow, "3 values (x y z) expected, found 2 in '0 0'"));

  const Error negative = errorOf([] { mpeg4face::parseWfm("# VERTEX LIST:\n-1\n", "n.wfm"); });
  EXPECT_EQ(negative.line(), 2);
}

TEST(Wfm, MalformedSections) {
  const Error missing = malformed("wfm_missing_faces.wfm");
  EXPECT_EQ(missing.field(), "FACE LIST");
  EXPECT_EQ(missing.line(), 0);
  EXPECT_TRUE(contains(missing, "no '# FACE LIST:' section"));

  const Error shortList = malformed("wfm_short_unit_list.wfm");
  EXPECT_EQ(shortList.line(), 18);
  EXPECT_EQ(shortList.field(), "ANIMATION UNITS LIST");
  EXPECT_TRUE(contains(shortList, "count says 3 units, but only 1 come before"))
      << shortList.what();

  const Error extra = errorOf([] { mpeg4face::parseWfm(kTriangle + "1 2 0\n", "x.wfm"); });
  EXPECT_EQ(extra.line(), 10);
  EXPECT_EQ(extra.field(), "FACE LIST");
  EXPECT_TRUE(contains(extra, "does the count match?"));

  const Error order =
      errorOf([] { mpeg4face::parseWfm("# FACE LIST:\n1\n0 1 2\n# VERTEX LIST:\n0\n", "o.wfm"); });
  EXPECT_EQ(order.line(), 1);

  const Error twice = errorOf([] { mpeg4face::parseWfm(kTriangle + kTriangle, "d.wfm"); });
  EXPECT_EQ(twice.line(), 10);
  EXPECT_TRUE(contains(twice, "second '# VERTEX LIST:'"));

  const Error mismatch = errorOf([] {
    mpeg4face::parseWfm(kTriangle + "# ANIMATION UNITS LIST:\n1\n# FAP 3 raise_b_midlip\n0\n",
                        "m.wfm");
  });
  EXPECT_EQ(mismatch.line(), 12);
  EXPECT_TRUE(contains(mismatch, "raise_b_midlip is FAP 5")) << mismatch.what();

  const Error noFap = errorOf([] {
    mpeg4face::parseWfm(kTriangle + "# ANIMATION UNITS LIST:\n1\n# FAP 99 x\n0\n", "m.wfm");
  });
  EXPECT_TRUE(contains(noFap, "FAP 99 does not exist"));

  const Error noName =
      errorOf([] { mpeg4face::parseWfm(kTriangle + "# ANIMATION UNITS LIST:\n1\n0\n", "m.wfm"); });
  EXPECT_EQ(noName.line(), 12);
}

TEST(Wfm, MalformedEmptyAndGarbage) {
  const Error empty = malformed("wfm_empty.wfm");
  EXPECT_EQ(empty.file(), (kData / "malformed" / "wfm_empty.wfm").string());
  EXPECT_EQ(empty.line(), 0);
  EXPECT_TRUE(contains(empty, "no '# VERTEX LIST:' section"));

  const Error garbage = malformed("wfm_garbage.wfm");
  EXPECT_EQ(garbage.file(), (kData / "malformed" / "wfm_garbage.wfm").string());
  EXPECT_EQ(garbage.line(), 1);
  EXPECT_TRUE(contains(garbage, "'# VERTEX LIST:' expected, found '?7}4")) << garbage.what();

  // An OBJ given as .wfm.
  const Error obj = errorOf([] { mpeg4face::parseWfm("# an OBJ\nv 0 0 0\n", "obj.wfm"); });
  EXPECT_EQ(obj.line(), 2);
}

}  // namespace
