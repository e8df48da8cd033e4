// SPDX-License-Identifier: GPL-3.0-or-later
// Text to a talking head: phones to visemes, time curves, bookmarks, flite, and a spoken
// sentence animating a face.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <fstream>
#include <set>

#include "fat_test_face.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/speech/speech.hpp"
#include "test_support.hpp"
#include "wav_test.hpp"

namespace {

using namespace mpeg4face;
using mpeg4face::test::errorOf;
using mpeg4face::test::readWav;
using mpeg4face::test::scratchDir;
using mpeg4face::test::Wav;

using mpeg4face::test::has;

// The viseme a frame shows most of (viseme_blend 63 is select1 fully).
int dominant(const Viseme& v) { return v.blend >= 32 ? v.select1 : v.select2; }

// Phones laid end to end from their durations in ms, in the words given (-1: a pause). Times
// are whole ms / 1000, so that a boundary falls exactly on a frame's time (n / fps).
std::vector<TimedPhone> phonesOf(const std::vector<std::tuple<std::string, int, int>>& list) {
  std::vector<TimedPhone> out;
  int ms = 0;
  for (const auto& [phone, duration, word] : list) {
    out.push_back({phone, ms / 1000.0, (ms + duration) / 1000.0, word});
    ms += duration;
  }
  return out;
}

// "pau m aa m aa pau" (mama), with a 30 ms /m/ shorter than the transition window.
const std::vector<TimedPhone> kMama = phonesOf({{"pau", 200, -1},
                                                {"m", 70, 0},
                                                {"aa", 160, 0},
                                                {"m", 30, 0},
                                                {"aa", 210, 0},
                                                {"pau", 250, -1}});

TEST(PhoneViseme, EveryPhoneOfFlitesSetHasOneAndEveryVisemeIsUsed) {
  // cmu_us_kal's phone set, as flite's lexicon prints it.
  const std::vector<std::string> flitePhones = {
      "aa", "ae", "ah", "ao", "aw", "ax", "axr", "ay", "b", "ch", "d", "dh", "eh", "er",
      "ey", "f",  "g",  "hh", "ih", "iy", "jh",  "k",  "l", "m",  "n", "ng", "ow", "oy",
      "p",  "r",  "s",  "sh", "t",  "th", "uh",  "uw", "v", "w",  "y", "z",  "zh", "pau"};
  std::set<int> used;
  for (const std::string& p : flitePhones) {
    const int v = phoneViseme(p);
    EXPECT_GE(v, 0) << p;
    EXPECT_LE(v, 14) << p;
    used.insert(v);
  }
  for (int v = 0; v <= 14; ++v) EXPECT_TRUE(used.count(v)) << "viseme " << v << " unused";
  EXPECT_EQ(phoneViseme("p"), 1);
  EXPECT_EQ(phoneViseme("f"), 2);
  EXPECT_EQ(phoneViseme("pau"), 0);
  for (const PhoneViseme& row : phoneVisemeTable()) EXPECT_EQ(phoneViseme(row.phone), row.viseme);
  EXPECT_TRUE(has(errorOf([] { phoneViseme("xx"); }).what(), "unknown phone 'xx'"));
}

TEST(VisemeStream, TheVisemeChangesWithinOneFrameOfEachPhoneBoundary) {
  for (const double fps : {25.0, 30.0, 60.0}) {
    const FapStream s = visemeStream(kMama, fps);
    ASSERT_EQ(s.frames.size(), static_cast<std::size_t>(std::floor(kMama.back().end * fps)) + 1);
    for (std::size_t b = 0; b + 1 < kMama.size(); ++b) {
      const int before = phoneViseme(kMama[b].phone), after = phoneViseme(kMama[b + 1].phone);
      ASSERT_NE(before, after);
      const double boundary = kMama[b].end;
      // The first frame after the middle of the phone before that shows the next one's viseme.
      std::optional<double> change;
      for (const FapFrame& f : s.frames) {
        const double t = frameTime(s, f);
        if (t > (kMama[b].start + kMama[b].end) / 2 && dominant(f.viseme) == after) {
          change = t;
          break;
        }
      }
      ASSERT_TRUE(change) << "boundary " << b << " at " << fps << " Hz";
      EXPECT_LE(std::abs(*change - boundary), 1 / fps + 1e-9)
          << "boundary " << b << " at " << boundary << " s, change at " << *change << " s, " << fps
          << " Hz";
    }
    for (const FapFrame& f : s.frames) EXPECT_TRUE(f.has(1));
  }
}

TEST(VisemeStream, TransitionsBlendTheTwoNeighboursAndPausesAreVisemeZero) {
  const double fps = 200;  // fine enough to see inside a transition
  const FapStream s = visemeStream(kMama, fps, {.transition = 0.08});
  for (const FapFrame& f : s.frames) {
    const double t = frameTime(s, f);
    const Viseme& v = f.viseme;
    if (t < 0.16 || t > kMama.back().start + 0.04) {
      EXPECT_EQ(v, (Viseme{0, 0, 63, false})) << t;  // silence, away from any transition
    }
    // Into /aa/ at 0.27 s: from /m/ (1) to /aa/ (10), blend falling, over 70 ms (half of the
    // 70 ms /m/ on either side of the boundary is less than the 80 ms asked for).
    if (t > 0.236 && t < 0.304) {
      EXPECT_EQ(v.select1, 1) << t;
      EXPECT_EQ(v.select2, 10) << t;
      EXPECT_NEAR(v.blend, 63 * (1 - (t - 0.235) / 0.07), 1) << t;
    }
    // The 30 ms /m/ (0.43..0.46 s) keeps half a phone to itself: its window is 30 ms wide,
    // so it is fully closed at its middle.
    if (std::abs(t - 0.445) < 1e-9) {
      EXPECT_EQ(dominant(v), 1);
    }
  }
}

TEST(VisemeStream, LipRoundingSpreadsOntoTongueConsonants) {
  // The viseme shown in the middle of each phone, at 1000 Hz.
  const auto middles = [](const std::vector<TimedPhone>& phones) {
    const FapStream s = visemeStream(phones, 1000);
    std::vector<int> out;
    for (const TimedPhone& p : phones) {
      out.push_back(dominant(s.frames[static_cast<std::size_t>((p.start + p.end) * 500)].viseme));
    }
    return out;
  };
  // "two": /t/ already rounded for /uw/ (anticipation).
  EXPECT_EQ(middles(phonesOf({{"pau", 100, -1}, {"t", 100, 0}, {"uw", 200, 0}, {"pau", 100, -1}})),
            (std::vector<int>{0, 14, 14, 0}));
  // "clue": the run /k l/ takes it whole.
  EXPECT_EQ(middles(phonesOf({{"k", 100, 0}, {"l", 100, 0}, {"uw", 200, 0}})),
            (std::vector<int>{14, 14, 14}));
  // "boot": /t/ keeps /uw/'s rounding after it (carry-over); "go", /ow/ likewise.
  EXPECT_EQ(middles(phonesOf({{"b", 100, 0}, {"uw", 200, 0}, {"t", 100, 0}, {"pau", 100, -1}})),
            (std::vector<int>{1, 14, 14, 0}));
  EXPECT_EQ(middles(phonesOf({{"ow", 200, 0}, {"n", 100, 0}, {"aa", 200, 0}})),
            (std::vector<int>{13, 13, 10}));
  // Unrounded neighbours, or lips that shape the consonant (/s/, /p/): their own viseme.
  EXPECT_EQ(middles(phonesOf({{"t", 100, 0}, {"aa", 200, 0}, {"s", 100, 0}, {"uw", 200, 0}})),
            (std::vector<int>{4, 10, 7, 14}));
  EXPECT_EQ(middles(phonesOf({{"p", 100, 0}, {"uw", 200, 0}})), (std::vector<int>{1, 14}));
}

TEST(VisemeStream, HhTakesTheNextPhonesVisemeAndBadInputIsNamed) {
  const auto phones = phonesOf({{"pau", 100, -1}, {"hh", 100, 0}, {"uw", 200, 0}});
  const FapStream s = visemeStream(phones, 100);
  EXPECT_EQ(s.frames[15].viseme, (Viseme{14, 14, 63, false}));  // middle of /hh/: /uw/ already
  EXPECT_TRUE(has(errorOf([&] { visemeStream(phones, 0); }).what(), "frame rate"));
  const auto unknown = phonesOf({{"pau", 100, -1}, {"qq", 100, 0}});
  EXPECT_TRUE(has(errorOf([&] { visemeStream(unknown, 25); }).what(), "unknown phone 'qq'"));
}

TEST(TimeCurve, EachCurveAtStartMiddleAndEnd) {
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Linear, 0), 0);
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Linear, 0.5), 0.5);
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Linear, 1), 1);
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Linear, 0.25), 0.25);
  // Triangular: up to the target at the middle and back to the start.
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Triangular, 0), 0);
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Triangular, 0.5), 1);
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Triangular, 1), 0);
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Triangular, 0.25), 0.5);
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Triangular, 0.75), 0.5);
  // Hermite (cubic, zero slope at both ends).
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Hermite, 0), 0);
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Hermite, 0.5), 0.5);
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Hermite, 1), 1);
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Hermite, 0.25), 0.15625);
  EXPECT_LT(timeCurveValue(TimeCurve::Hermite, 0.01), 0.001);
  EXPECT_GT(timeCurveValue(TimeCurve::Hermite, 0.99), 0.999);
  // Before the start and after the end a curve holds.
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Hermite, 1.5), 1);
  EXPECT_DOUBLE_EQ(timeCurveValue(TimeCurve::Linear, -1), 0);
}

TEST(Bookmarks, ThePapersFormAndLowLevelFaps) {
  const MarkedText m =
      parseBookmarks("Hello <FAP 2 1 40 1 40 800 3> happy world<FAP 3 120 500 2> again");
  EXPECT_EQ(speechWords(m.text), (std::vector<std::string>{"hello", "happy", "world", "again"}));
  ASSERT_EQ(m.bookmarks.size(), 2u);
  const Bookmark& joy = m.bookmarks[0];
  EXPECT_EQ(joy.fap, 2);
  EXPECT_EQ(joy.expression, (Expression{1, 40, 1, 40, false, false}));
  EXPECT_DOUBLE_EQ(joy.duration, 0.8);
  EXPECT_EQ(joy.curve, TimeCurve::Hermite);
  EXPECT_EQ(joy.word, 1);  // starts with "happy"
  EXPECT_EQ(joy.position, 6u);
  const Bookmark& jaw = m.bookmarks[1];
  EXPECT_EQ(jaw.fap, 3);
  EXPECT_EQ(jaw.value, 120);
  EXPECT_DOUBLE_EQ(jaw.duration, 0.5);
  EXPECT_EQ(jaw.curve, TimeCurve::Triangular);
  EXPECT_EQ(jaw.word, 3);  // a bookmark ends the word before it
}

TEST(Bookmarks, MalformedOnesNameTheirPositionInTheText) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"Hi <FAP 2 1 40 1 40 800 3", "character 4: a bookmark without '>'"},
      {"Hi there <SMILE 3>", "character 10: a bookmark must start with FAP"},
      {"<FAP 2 1 40 1 40 800>", "character 1: FAP 2 takes select1 intensity1 select2"},
      {"a <FAP 3 10 x 1>", "character 3: 'x' is not a whole number"},
      {"a <FAP 1 3 100 1>", "character 3: visemes come from the speech"},
      {"a <FAP 69 3 100 1>", "character 3: FAP 69 does not exist"},
      {"a <FAP 2 7 40 1 40 800 3>", "character 3: expression_select1 7 is outside 0..6"},
      {"a <FAP 2 1 64 1 40 800 3>", "expression_intensity1 64 is outside 0..63"},
      {"a <FAP 4 10 100 4>", "the time curve 4 is outside 1..3"},
      {"a <FAP 4 10 -5 1>", "the duration (ms) -5 is outside"},
      {"a <FAP>", "character 3: no FAP number"},
      {"smile > frown", "character 7: '>' without a bookmark before it"},
      {"a <FAP 3 99999999999999999999 1 1>", "is not a whole number"},
  };
  for (const auto& [text, message] : cases) {
    const Error e = errorOf([text = text] { parseBookmarks(text); });
    EXPECT_TRUE(has(e.what(), message)) << text << " -> " << e.what();
    EXPECT_EQ(e.field(), "bookmark");
  }
}

// Words: "one" 0.1-0.4 s, "two" 0.5-0.8 s, "three" 0.8-1.2 s, pauses around.
SynthesizedSpeech threeWords() {
  SynthesizedSpeech s;
  s.words = {"one", "two", "three"};
  s.phones = phonesOf({{"pau", 100, -1},
                       {"w", 100, 0},
                       {"ah", 100, 0},
                       {"n", 100, 0},
                       {"pau", 100, -1},
                       {"t", 100, 1},
                       {"uw", 200, 1},
                       {"th", 100, 2},
                       {"r", 100, 2},
                       {"iy", 200, 2},
                       {"pau", 200, -1}});
  return s;
}

FapStream withBookmarks(const std::string& text, double fps = 100) {
  const SynthesizedSpeech speech = threeWords();
  FapStream stream = visemeStream(speech.phones, fps);
  applyBookmarks(stream, parseBookmarks(text).bookmarks, speech);
  return stream;
}

const FapFrame& at(const FapStream& s, double t) {
  return s.frames[static_cast<std::size_t>(std::lround(t * s.frameRate))];
}

TEST(Bookmarks, StartAtTheFirstPhoneOfTheFollowingWordAndFollowTheirCurve) {
  const FapStream s = withBookmarks("one <FAP 2 1 40 1 40 400 3> two three");
  EXPECT_FALSE(at(s, 0.49).has(2));
  ASSERT_TRUE(at(s, 0.5).has(2));  // "two" starts at 0.5 s
  EXPECT_EQ(at(s, 0.5).expression, (Expression{1, 0, 1, 0, false, false}));
  EXPECT_EQ(at(s, 0.7).expression.intensity1, 20);  // Hermite, half way
  EXPECT_EQ(at(s, 0.6).expression.intensity1, std::lround(40 * 0.15625));
  EXPECT_EQ(at(s, 0.9).expression.intensity1, 40);
  EXPECT_EQ(at(s, 1.4).expression.intensity1, 40);  // held at the end
  // A low-level FAP: linear, triangular.
  const FapStream jaw = withBookmarks("one two <FAP 3 200 300 1> three <FAP 5 -100 200 2>");
  EXPECT_FALSE(at(jaw, 0.79).has(3));
  EXPECT_EQ(at(jaw, 0.8).value(3), 0);
  EXPECT_EQ(at(jaw, 0.95).value(3), 100);
  EXPECT_EQ(at(jaw, 1.1).value(3), 200);
  // The last bookmark has no word after it: it starts at the end of the speech.
  EXPECT_FALSE(at(jaw, 1.39).has(5));
  EXPECT_EQ(at(jaw, 1.4).value(5), 0);
}

TEST(Bookmarks, ABookmarkBeforeThePreviousTransitionEndsStartsFromTheCurrentValue) {
  // Fig. 14: joy to 40 over 1 s from "one"; at "two" (0.4 s later) joy to 10.
  const FapStream s = withBookmarks("<FAP 2 1 40 1 40 1000 1> one <FAP 2 1 10 1 10 200 1> two");
  const int reached = at(s, 0.49).expression.intensity1;
  EXPECT_EQ(at(s, 0.5).expression.intensity1, 16);  // 40 * 0.4 s / 1 s: where it was
  EXPECT_NEAR(reached, 16, 1);
  EXPECT_EQ(at(s, 0.6).expression.intensity1, 13);  // half way from 16 to 10
  EXPECT_EQ(at(s, 0.7).expression.intensity1, 10);
  EXPECT_EQ(at(s, 1.3).expression.intensity1, 10);  // the first transition never resumes
  // The same for a low-level FAP, Hermite then triangular.
  const FapStream jaw = withBookmarks("<FAP 3 400 1000 3> one <FAP 3 0 400 2> two");
  const double current = 400 * timeCurveValue(TimeCurve::Hermite, 0.4);
  EXPECT_EQ(at(jaw, 0.5).value(3), std::lround(current));
  EXPECT_EQ(at(jaw, 0.7).value(3), 0);                     // the triangle's peak: the new target, 0
  EXPECT_EQ(at(jaw, 0.9).value(3), std::lround(current));  // and back where it started
  // Another expression does not continue joy's intensity: it starts from 0.
  const FapStream other = withBookmarks("<FAP 2 1 40 1 40 1000 1> one <FAP 2 3 50 3 50 200 1> two");
  EXPECT_EQ(at(other, 0.5).expression, (Expression{3, 0, 3, 0, false, false}));
  EXPECT_EQ(at(other, 0.7).expression.intensity1, 50);
}

TEST(AssignWords, AlignsTheSentenceWithEachWordSaidAlone) {
  SynthesizedSpeech s = threeWords();
  for (TimedPhone& p : s.phones) p.word = 99;
  assignWords(s.phones, {{"pau", "w", "ah", "n", "pau"}, {"t", "uw"}, {"th", "r", "iy"}});
  std::vector<int> words;
  for (const TimedPhone& p : s.phones) words.push_back(p.word);
  EXPECT_EQ(words, (std::vector<int>{-1, 0, 0, 0, -1, 1, 1, 2, 2, 2, -1}));
  // Said differently in context: "one" alone with an extra phone, "two" with another vowel,
  // and a word that lost its only phone.
  assignWords(s.phones, {{"w", "ah", "n", "d"}, {"t", "ih"}, {"zz"}, {"th", "r", "iy"}});
  words.clear();
  for (const TimedPhone& p : s.phones) words.push_back(p.word);
  EXPECT_EQ(words, (std::vector<int>{-1, 0, 0, 0, -1, 1, 1, 3, 3, 3, -1}));
  // A phone of the sentence that no word has belongs to the word before it.
  auto extra =
      phonesOf({{"pau", 100, -1}, {"t", 100, 0}, {"uw", 100, 0}, {"s", 100, 0}, {"th", 100, 1}});
  assignWords(extra, {{"t", "uw"}, {"th"}});
  EXPECT_EQ(extra[3].word, 0);
  EXPECT_EQ(extra[4].word, 1);
}

// A stand-in for flite: a shell script printing `output` for -psdur and -ps.
std::string fakeFlite(const std::string& output, int status = 0) {
  const std::string path = mpeg4face::test::writeScratchFile(
      "fake_flite",
      "#!/bin/sh\n"
      "for a; do case \"$prev\" in -o) [ \"$a\" = none ] || : > \"$a\";; esac; prev=$a; done\n"
      "echo '" +
          output + "'\nexit " + std::to_string(status) + "\n");
  chmod(path.c_str(), 0755);
  return path;
}

TEST(Flite, AMissingOrFailingSynthesiserIsAClearErrorAndLeavesNoAudio) {
  const auto dir = scratchDir();
  const auto wav = dir / "out.wav";
  const Error missing =
      errorOf([&] { FlitePhonemeSource("/nonexistent/flite").synthesize("hello", wav); });
  EXPECT_TRUE(has(missing.what(), "cannot run '/nonexistent/flite'")) << missing.what();
  EXPECT_TRUE(has(missing.what(), "install Debian's flite package")) << missing.what();
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"pau:0.1 hh:zero", "unreadable phone timing 'hh:zero'"},
      {"pau:0.3 hh:0.2", "unreadable phone timing 'hh:0.2'"},
      {"pau:0.1 qq:0.2", "unknown phone 'qq'"},
      {"", "reported no phones"},
  };
  for (const auto& [output, message] : bad) {
    const Error e = errorOf([&, output = output] { FlitePhonemeSource(fakeFlite(output)).synthesize("hi", wav); });
    EXPECT_TRUE(has(e.what(), message)) << output << " -> " << e.what();
  }
  const Error failed =
      errorOf([&] { FlitePhonemeSource(fakeFlite("pau:0.1", 3)).synthesize("hi", wav); });
  EXPECT_TRUE(has(failed.what(), "failed (exit status 3)")) << failed.what();
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    EXPECT_NE(entry.path().extension(), ".wav") << entry.path();
  }
}

void checkSentence(const std::string& voice) {
  const auto wav = scratchDir() / (voice + ".wav");
  const SynthesizedSpeech s = FlitePhonemeSource("flite", voice)
                                  .synthesize("Hello world, the end is 25 seconds away.", wav);
  EXPECT_EQ(s.words, (std::vector<std::string>{"hello", "world", "the", "end", "is", "25",
                                               "seconds", "away"}));
  ASSERT_GT(s.phones.size(), 20u);
  EXPECT_EQ(s.phones.front().phone, "pau");
  EXPECT_EQ(s.phones.back().phone, "pau");
  int lastWord = -1;
  for (std::size_t i = 0; i < s.phones.size(); ++i) {
    EXPECT_LE(s.phones[i].start, s.phones[i].end);
    if (i > 0) {
      EXPECT_DOUBLE_EQ(s.phones[i].start, s.phones[i - 1].end);
    }
    if (s.phones[i].word >= 0) {
      EXPECT_GE(s.phones[i].word, lastWord);  // words in order
      lastWord = s.phones[i].word;
    }
  }
  EXPECT_EQ(lastWord, 7);
  // "25" is said as "twenty five": its phones are one word's.
  std::string twentyFive;
  for (const TimedPhone& p : s.phones) {
    if (p.word == 5) twentyFive += p.phone + " ";
  }
  EXPECT_EQ(twentyFive, "t w eh n t iy f ay v ");
  // The audio is in step with the phones: it starts with the first pause (quiet), is loud in
  // the middle of every vowel and ends within the last pause (flite cuts that one short).
  const Wav audio = readWav(wav);
  EXPECT_GT(audio.seconds(), s.phones.back().start);
  EXPECT_LE(audio.seconds(), s.phones.back().end);
  const double silence = audio.loudness(0.05, s.phones.front().end - 0.05);
  int vowels = 0;
  for (const TimedPhone& p : s.phones) {
    if (std::string("aeiou").find(p.phone[0]) == std::string::npos) continue;
    const double middle = (p.start + p.end) / 2, half = 0.2 * (p.end - p.start);
    EXPECT_GT(audio.loudness(middle - half, middle + half), 20 * silence + 100)
        << p.phone << " at " << p.start << " s";
    ++vowels;
  }
  EXPECT_GE(vowels, 10);
  EXPECT_FALSE(std::filesystem::exists(wav.string() + ".part.wav"));
}

TEST(Flite, ASentenceGivesTimedPhonesWordsAndTheAudio) {
  // A diphone voice (kal, flite's default) and two clustergen voices.
  for (const std::string voice : {"kal", "slt", "rms"}) {
    SCOPED_TRACE(voice);
    checkSentence(voice);
  }
}

// The test face with a viseme that opens its mouth (each viseme by its own amount: 1, /p b
// m/, keeps it shut) and joy, which raises the mouth corners.
MpegFace talkingFace() {
  const FaceModel neutral = test::testFace();
  std::vector<FaceShape> copies;
  const auto copy = [&](int fap, int select, double open, double corners) {
    FaceShape c;
    c.name = (fap == 1 ? "viseme" : "expression") + std::to_string(select);
    c.fapID = fap;
    c.highLevelSelect = select;
    c.amplitude = 63;
    const Points3& p = neutral.meshes[0].coord;
    Points3 d = Points3::Zero(p.rows(), 3);
    for (Eigen::Index v = 0; v < p.rows(); ++v) {
      const double dx = p(v, 0), dy = p(v, 1) + 0.05, r = std::hypot(dx, dy);
      if (r < 0.04) d(v, 1) -= open * (1 - r / 0.04) * (dy < 0 ? 1 : 0.2);
      if (r < 0.04) d(v, 1) += corners * std::abs(dx) / 0.04;
    }
    c.meshes.push_back(sparseDisplacement(0, d));
    copies.push_back(std::move(c));
  };
  for (int v = 2; v <= 14; ++v) copy(1, v, 0.001 * v, 0);
  copy(2, 1, 0, 0.004);
  const FapuMeasurement fapu = measureFapu(neutral);
  return {neutral, generateFaceDefTables(neutral, fapu, copies).faceDefTables};
}

double mouthOpening(const FatState& state, const FaceModel& neutral) {
  double most = 0;
  for (Eigen::Index v = 0; v < state.coord[0].rows(); ++v) {
    most = std::max(most, neutral.meshes[0].coord(v, 1) - state.coord[0](v, 1));
  }
  return most;
}

TEST(Speech, TextWithABookmarkAnimatesAFace) {
  const auto wav = scratchDir() / "speech.wav";
  const FapStream stream = speak("Hello world! <FAP 2 1 60 1 60 600 3> How are you today?",
                                 FlitePhonemeSource(), wav, 25);
  // The stream lasts as long as the phones: the audio and one more frame at the most.
  const double audio = readWav(wav).seconds();
  EXPECT_GE(streamDuration(stream), audio);
  EXPECT_LE(streamDuration(stream), audio + 0.3);
  const MpegFace face = talkingFace();
  const FatEvaluator eval(face, measureFapu(face.faceSceneGraph));
  const std::vector<FapState> states = resolveFapStream(stream);
  std::vector<double> opening;
  int smiling = 0, firstSmile = -1;
  for (const FapState& state : states) {
    const FatState animated = eval.evaluate(state);
    opening.push_back(mouthOpening(animated, face.faceSceneGraph));
    if (state.has(2) && state.expression.intensity1 > 0) {
      ++smiling;
      if (firstSmile < 0) firstSmile = state.number;
    }
  }
  // Silent at both ends, the mouth opens and closes while speaking.
  EXPECT_LT(opening.front(), 1e-9);
  EXPECT_LT(opening.back(), 1e-9);
  const double widest = *std::max_element(opening.begin(), opening.end());
  EXPECT_GT(widest, 0.008);
  int changes = 0;
  for (std::size_t i = 1; i < opening.size(); ++i) {
    changes += (opening[i] > 0.5 * widest) != (opening[i - 1] > 0.5 * widest);
  }
  EXPECT_GE(changes, 6) << "the mouth should open and close with the syllables";
  // Joy starts with "How", after "world" and its pause, and stays.
  EXPECT_GT(smiling, 10);
  EXPECT_GT(firstSmile, 20);
  EXPECT_EQ(states.back().expression.intensity1, 60);
}

TEST(Speech, NothingToSayIsAnError) {
  const auto wav = scratchDir() / "none.wav";
  EXPECT_TRUE(
      has(errorOf([&] { speak("<FAP 3 10 100 1> ...", FlitePhonemeSource(), wav, 25); }).what(),
          "nothing to say"));
  EXPECT_FALSE(std::filesystem::exists(wav));
}

}  // namespace
