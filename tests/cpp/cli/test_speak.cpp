// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face speak`, run as a user runs it.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/files.hpp"
#include "test_support.hpp"
#include "wav_test.hpp"

namespace {

using namespace mpeg4face;
using mpeg4face::test::runCli;
using mpeg4face::test::scratchDir;

using mpeg4face::test::has;

TEST(CliSpeak, WritesTheStreamAndTheAudioInStep) {
  const auto dir = scratchDir();
  const std::string fap = (dir / "hello.fap").string(), wav = (dir / "hello.wav").string();
  const auto r = runCli("speak 'Hello <FAP 2 1 40 1 40 400 3> world' -o " + fap + " --audio " +
                        wav + " --fps 30");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(has(r.out, "frames at 30 Hz")) << r.out;
  const FapStream s = readFapFile(fap);
  EXPECT_EQ(s.frameRate, 30);
  ASSERT_GT(s.frames.size(), 15u);
  EXPECT_TRUE(s.frames.front().has(1));
  EXPECT_TRUE(s.frames.back().has(2));
  EXPECT_EQ(s.frames.back().expression.intensity1, 40);
  // In step: the stream lasts as long as the audio, and one frame more at the most (flite
  // cuts the final pause a little short, docs/speech.md).
  const double audio = mpeg4face::test::readWav(wav).seconds();
  EXPECT_GT(audio, 0.5);
  EXPECT_GE(streamDuration(s), audio);
  EXPECT_LE(streamDuration(s), audio + 0.3);

  // .fba: the same stream, coded (predictive, fap_quant 1); the audio beside it by default.
  const std::string fba = (dir / "hello.fba").string();
  const auto coded = runCli("speak 'Hello <FAP 2 1 40 1 40 400 3> world' -o " + fba + " --fps 30");
  ASSERT_EQ(coded.status, 0) << coded.out;
  EXPECT_TRUE(std::filesystem::exists(dir / "hello.wav"));
  const std::string bytes = readFile(fba);
  const FapStream decoded =
      decodeFba({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()});
  ASSERT_EQ(decoded.frames.size(), s.frames.size());
  for (std::size_t i = 0; i < s.frames.size(); ++i) {
    EXPECT_EQ(decoded.frames[i].viseme, s.frames[i].viseme) << i;
    EXPECT_EQ(decoded.frames[i].expression.intensity1, s.frames[i].expression.intensity1) << i;
  }
}

TEST(CliSpeak, ErrorsWriteNothing) {
  const auto dir = scratchDir();
  const std::string fap = (dir / "bad.fap").string();
  const auto bookmark = runCli("speak 'Hello <FAP 2 1 40 1 40 800> world' -o " + fap);
  EXPECT_EQ(bookmark.status, 1);
  EXPECT_TRUE(has(bookmark.out, "character 7: FAP 2 takes select1")) << bookmark.out;
  // No flite: the message says what to install.
  setenv("MPEG4FACE_FLITE", "/no/flite", 1);
  const auto noFlite = runCli("speak hello -o " + fap);
  unsetenv("MPEG4FACE_FLITE");
  EXPECT_EQ(noFlite.status, 1);
  EXPECT_TRUE(has(noFlite.out, "cannot run '/no/flite'")) << noFlite.out;
  EXPECT_TRUE(has(noFlite.out, "install Debian's flite package")) << noFlite.out;
  const auto wrongType = runCli("speak hello -o " + (dir / "bad.txt").string());
  EXPECT_EQ(wrongType.status, 2);
  EXPECT_TRUE(has(wrongType.out, "must be .fap or .fba")) << wrongType.out;
  EXPECT_TRUE(has(runCli("speak -o " + fap).out, "no text given"));
  EXPECT_TRUE(has(runCli("speak hello -o " + fap + " --fps 0").out, "--fps takes a number >= 1"));
  EXPECT_TRUE(has(runCli("speak hello there -o " + fap).out, "one argument, in quotes"));
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {  // runCli's stderr only
    EXPECT_EQ(entry.path().filename(), "cli_stderr.txt") << "an error left a file behind";
  }
}

TEST(CliSpeak, ReadsTheTextFromAFile) {
  const auto dir = scratchDir();
  const std::string text =
      mpeg4face::test::writeScratchFile("text.txt", "One. <FAP 3 200 400 2> Two.\n");
  const std::string fap = (dir / "t.fap").string();
  const auto r = runCli("speak --text-file " + text + " -o " + fap + " --voice slt");
  ASSERT_EQ(r.status, 0) << r.out;
  const FapStream s = readFapFile(fap);
  bool jaw = false;
  for (const FapFrame& f : s.frames) jaw |= f.has(3) && f.value(3) > 100;
  EXPECT_TRUE(jaw);
}

}  // namespace
