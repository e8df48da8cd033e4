// SPDX-License-Identifier: GPL-3.0-or-later
// Text to a talking head (Tekalp-Ostermann 2.3): a speech synthesiser gives phones with their
// timing, a converter turns them into visemes with transitions, and bookmarks in the text
// start expressions and other FAPs. docs/speech.md.
#pragma once

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face {

// One phone as the synthesiser spoke it: seconds from the start of the audio; `word` is the
// index of the text's word it belongs to, -1 for a pause.
struct TimedPhone {
  std::string phone;
  double start = 0;
  double end = 0;
  int word = -1;
};

struct SynthesizedSpeech {
  std::vector<TimedPhone> phones;  // in time order, covering the whole audio
  std::vector<std::string> words;  // the text's words, in order
};

// What synthesises speech and reports its phones; another synthesiser can implement it.
class PhonemeSource {
 public:
  virtual ~PhonemeSource() = default;
  // Speaks `text` (plain, without bookmarks) into the .wav file `audio` and returns its
  // phones in the phone set phoneViseme() knows. Throws mpeg4face::Error on failure.
  virtual SynthesizedSpeech synthesize(const std::string& text,
                                       const std::filesystem::path& audio) const = 0;
};

// Debian's flite (CMU US English phones), run as a program: `flite -psdur` gives each phone
// with its end time; words are found by saying each word alone and aligning (assignWords).
// `voice` is flite's -voice (kal, kal16, awb, rms, slt; empty: flite's default).
// Throws mpeg4face::Error naming the program when it cannot be run (not installed).
class FlitePhonemeSource : public PhonemeSource {
 public:
  explicit FlitePhonemeSource(std::string program = "flite", std::string voice = {})
      : program_(std::move(program)), voice_(std::move(voice)) {}
  SynthesizedSpeech synthesize(const std::string& text,
                               const std::filesystem::path& audio) const override;

 private:
  std::vector<std::string> command(std::vector<std::string> args) const;  // argv with the voice
  std::string program_;
  std::string voice_;
};

// The phones of flite's -psdur output ("pau:0.220 hh:0.295 ..."; each phone with its end
// time, in seconds); words unset. Throws mpeg4face::Error naming `program` and the token
// for an unreadable or out-of-order time, and an unknown phone.
std::vector<TimedPhone> parseFlitePhones(std::string_view output, const std::string& program);

// Sets each phone's `word`: `wordPhones[w]` are word w's phones as the synthesiser says the
// word alone. The sentence's phones (pauses aside, which keep word -1) are aligned with their
// concatenation by the fewest substitutions, insertions and deletions, since a word may be
// said a little differently in context ("the" is /dh ax/ alone, /dh iy/ before a vowel); a
// phone with no counterpart belongs to the word before it. A word that gets no phone starts
// with the next word's first phone.
void assignWords(std::vector<TimedPhone>& phones,
                 const std::vector<std::vector<std::string>>& wordPhones);

// The words of a text as the synthesiser counts them: runs of letters, digits and
// apostrophes.
std::vector<std::string> speechWords(std::string_view text);

// The MPEG-4 viseme (0..14) of a phone of the CMU US English set (flite's); "pau" is 0.
// Throws mpeg4face::Error naming an unknown phone.
int phoneViseme(std::string_view phone);
struct PhoneViseme {
  std::string_view phone;
  int viseme;
  std::string_view example;
};
std::span<const PhoneViseme> phoneVisemeTable();

// Phones to FAP 1 frames at `frameRate` from time 0 to the last phone's end. Coarticulation
// (docs/speech.md): an /hh/ takes the viseme of the phone after it (the lips already shape
// the next sound); every change of viseme is a transition through viseme_blend over a window
// centred on the phone boundary, `transition` seconds wide at most and never more than half
// of either phone; elsewhere the phone's viseme alone. Pauses are viseme 0.
struct VisemeOptions {
  double transition = 0.08;
};
FapStream visemeStream(std::span<const TimedPhone> phones, double frameRate,
                       const VisemeOptions& options = {});

// --- Bookmarks ---------------------------------------------------------------------------
// <FAP 2 select1 intensity1 select2 intensity2 duration curve> (expressions: two shown at
// once, whose motions add; one expression leaves select2 intensity2 at 0 0) or
// <FAP n value duration curve> (a low-level FAP 3..68); duration in ms, curve 1 linear,
// 2 triangular (up to the value and back), 3 Hermite (the paper's Fig. 14 uses 3).
enum class TimeCurve { Linear = 1, Triangular = 2, Hermite = 3 };
struct Bookmark {
  int fap = 2;
  Expression expression;  // for FAP 2
  int value = 0;          // for FAPs 3..68
  double duration = 0;    // seconds
  TimeCurve curve = TimeCurve::Linear;
  int word = 0;              // starts at the first phone of this word (index into the words)
  std::size_t position = 0;  // where it was in the text (for messages)
};
struct MarkedText {
  std::string text;  // without the bookmarks
  std::vector<Bookmark> bookmarks;
};
// Throws mpeg4face::Error naming the character position (1-based) and what is wrong.
MarkedText parseBookmarks(std::string_view text);

// The fraction (0..1) of the way from the start value to the target a curve has gone at
// `s` (0..1) of its duration; the triangular curve is back at 0 when s = 1.
double timeCurveValue(TimeCurve curve, double s);

// Adds the bookmarks' FAPs to `stream` (frames as visemeStream made them). A bookmark starts
// at the first phone of its word (the end if there is none); a bookmark for a FAP whose
// previous transition has not ended starts from the value then reached.
void applyBookmarks(FapStream& stream, std::span<const Bookmark> bookmarks,
                    const SynthesizedSpeech& speech);

// Text with bookmarks to a FAP stream and the audio (.wav) at `audio`.
FapStream speak(const std::string& markedText, const PhonemeSource& source,
                const std::filesystem::path& audio, double frameRate,
                const VisemeOptions& options = {});

}  // namespace mpeg4face
