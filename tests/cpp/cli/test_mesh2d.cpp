// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face mesh2d`: the steps a user chains, and bad input named by the tool.
#include <gtest/gtest.h>

#include <fstream>

#include "mesh2d_fixture.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/mesh2d/json.hpp"
#include "mpeg4face/mesh2d/render.hpp"
#include "test_support.hpp"

namespace mpeg4face {
namespace {

using test::has;
using test::runCli;

std::string imageFile(const std::string& name, int w, int h) {
  const auto path = test::scratchDir() / name;
  writeImage(path, test::testTexture(w, h));
  return path.string();
}

TEST(CliMesh2d, DesignEncodeDecodeRender) {
  const auto dir = test::scratchDir();
  const std::string image = imageFile("t.png", 96, 64);
  auto r = runCli("mesh2d design " + image + " --uniform 6x4 --topology 2 -o " +
                  (dir / "u.json").string());
  ASSERT_EQ(r.status, 0) << r.out;
  // A moving sequence from the designed mesh.
  Mesh2dSequence s = readMesh2dJson(dir / "u.json");
  EXPECT_EQ(s.uniform.topology, 2);
  test::addSmoothFrames(s, 5);
  writeMesh2dJson(dir / "seq.json", s);
  r = runCli("mesh2d encode " + (dir / "seq.json").string() + " -o " + (dir / "s.m2d").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(has(r.out, "bits/node/frame")) << r.out;
  r = runCli("mesh2d decode " + (dir / "s.m2d").string() + " -o " + (dir / "d.json").string());
  ASSERT_EQ(r.status, 0) << r.out;
  const Mesh2dSequence d = readMesh2dJson(dir / "d.json");
  ASSERT_EQ(d.frames.size(), 5u);
  EXPECT_LE((d.frames[4] - s.frames[4]).cwiseAbs().maxCoeff(), 0.25 + 1e-6);
  r = runCli("mesh2d render " + image + " " + (dir / "d.json").string() + " -o " +
             (dir / "frames").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(std::filesystem::exists(dir / "frames" / "frame_00004.png"));
  // Delaunay design inside a mask, tracked through a folder of frames.
  Image mask(96, 64, 3);
  for (int y = 10; y < 54; ++y) std::fill_n(mask.row(y) + 10 * 3, 76 * 3, uint8_t{255});
  writeImage(dir / "mask.png", mask);
  r = runCli("mesh2d design " + image + " --delaunay 40 --mask " + (dir / "mask.png").string() +
             " -o " + (dir / "m.json").string());
  ASSERT_EQ(r.status, 0) << r.out;
  r = runCli("mesh2d track " + (dir / "frames").string() + " --mesh " + (dir / "m.json").string() +
             " -o " + (dir / "tracked.json").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(readMesh2dJson(dir / "tracked.json").frames.size(), 5u);
  // The frames' folder as the texture: its first frame, the intra plane's.
  r = runCli("mesh2d render " + (dir / "frames").string() + " " + (dir / "d.json").string() +
             " -o " + (dir / "again").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(readImage(dir / "again" / "frame_00003.png").pixels,
            readImage(dir / "frames" / "frame_00003.png").pixels);
}

TEST(CliMesh2d, PortraitToMp4WithAudio) {
  const auto dir = test::scratchDir();
  const std::string image = imageFile("face.png", 160, 200);
  const std::string csv = test::writeScratchFile(
      "fp.csv",
      "fp,x,y\n3.5,100,80\n3.6,60,80\n9.15,80,115\n2.2,80,140\n2.3,80,148\n2.4,98,144\n"
      "2.5,62,144\n2.1,80,175\n");
  // Two seconds of a 440 Hz tone as the audio.
  std::string wav = "RIFF____WAVEfmt ";
  auto put = [&](uint32_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) wav += static_cast<char>((v >> (8 * i)) & 255);
  };
  put(16, 4), put(1, 2), put(1, 2), put(16000, 4), put(32000, 4), put(2, 2), put(16, 2);
  wav += "data";
  put(64000, 4);
  for (int i = 0; i < 32000; ++i) {
    put(static_cast<uint16_t>(static_cast<int16_t>(8000 * std::sin(i * 2 * 3.14159 * 440 / 16000))),
        2);
  }
  const std::string audio = test::writeScratchFile("a.wav", wav);
  const auto r = runCli("mesh2d portrait " + image + " --feature-points " + csv + " " +
                        (test::kData / "xface-fap" / "joy.fap").string() + " -o " +
                        (dir / "out.mp4").string() + " --audio " + audio);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_GT(std::filesystem::file_size(dir / "out.mp4"), 1000u);
  EXPECT_FALSE(std::filesystem::exists(dir / "out.mp4.part.mp4"));
}

TEST(CliMesh2d, PortraitAlongTracksKeepsTheBitstream) {
  const auto dir = test::scratchDir();
  const std::string image = imageFile("face.png", 160, 200);
  const std::string csv = test::writeScratchFile(
      "fp.csv", "fp,x,y\n3.5,100,80\n3.6,60,80\n9.15,80,115\n2.2,80,140\n2.1,80,175\n");
  const std::string tracks = test::writeScratchFile(
      "tracks.csv",
      "frame,fp,x,y\n0,3.5,100,80\n0,3.6,60,80\n0,9.15,80,115\n0,2.2,80,140\n0,2.1,80,175\n"
      "1,3.5,100,80\n1,3.6,60,80\n1,9.15,80,115\n1,2.2,80,139\n1,2.1,80,180\n");
  const std::string m2d = (dir / "p.m2d").string();
  auto r = runCli("mesh2d portrait " + image + " --feature-points " + csv + " --tracks " + tracks +
                  " --m2d " + m2d + " -o " + (dir / "frames").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(std::filesystem::exists(dir / "frames" / "frame_00001.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "frames" / "frame_00002.png"));
  r = runCli("mesh2d decode " + m2d + " -o " + (dir / "p.json").string());
  ASSERT_EQ(r.status, 0) << r.out;
  const Mesh2dSequence s = readMesh2dJson(dir / "p.json");
  ASSERT_EQ(s.frames.size(), 2u);
  EXPECT_GT((s.frames[1] - s.frames[0]).cwiseAbs().maxCoeff(), 4);
  r = runCli("mesh2d portrait " + image + " --feature-points " + csv + " --tracks " + tracks + " " +
             tracks + " -o " + (dir / "x").string());
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_TRUE(has(r.out, "IMAGE only with --tracks")) << r.out;
}

TEST(CliMesh2d, BadInputIsNamed) {
  const auto dir = test::scratchDir();
  const std::string image = imageFile("t.png", 64, 64);
  auto expectError = [&](const std::string& args, const std::string& part) {
    const auto r = runCli(args);
    EXPECT_EQ(r.status, 1) << args << "\n" << r.out;
    EXPECT_TRUE(has(r.out, part)) << args << "\n" << r.out;
  };
  const std::string broken =
      test::writeScratchFile("broken.json", "{\"width\": 64,\n\"height\": ]");
  expectError("mesh2d encode " + broken + " -o " + (dir / "x.m2d").string(), "broken.json:2");
  const std::string range = test::writeScratchFile(
      "range.json", R"({"width": 64, "height": 64, "mesh": "delaunay", "boundary": 3,
      "triangles": [[0, 1, 7]], "frames": [[[1, 1], [50, 1], [1, 50]]]})");
  expectError("mesh2d encode " + range + " -o " + (dir / "x.m2d").string(), "triangles[0][2]");
  const std::string crossed = test::writeScratchFile(
      "crossed.json", R"({"width": 64, "height": 64, "mesh": "delaunay", "boundary": 4,
      "frames": [[[1, 1], [50, 50], [50, 1], [1, 50]]]})");
  expectError("mesh2d encode " + crossed + " -o " + (dir / "x.m2d").string(), "intersects itself");
  const std::string good = test::writeScratchFile(
      "good.json", R"({"width": 64, "height": 64, "mesh": "delaunay", "boundary": 3,
      "frames": [[[1, 1], [50, 1], [1, 50]], [[2, 1], [50, 2], [1, 51]]]})");
  ASSERT_EQ(runCli("mesh2d encode " + good + " -o " + (dir / "g.m2d").string()).status, 0);
  std::string bytes = readFile(dir / "g.m2d");
  const std::string cut = test::writeScratchFile("cut.m2d", bytes.substr(0, bytes.size() - 3));
  expectError("mesh2d decode " + cut + " -o " + (dir / "x.json").string(), "cut.m2d");
  const std::string notImage = test::writeScratchFile("not.png", "hello");
  expectError("mesh2d render " + notImage + " " + good + " -o " + (dir / "f").string(),
              "not.png: image: does not load");
  EXPECT_FALSE(std::filesystem::exists(dir / "x.m2d"));
  EXPECT_FALSE(std::filesystem::exists(dir / "x.json"));
}

}  // namespace
}  // namespace mpeg4face
