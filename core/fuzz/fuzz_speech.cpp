// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for what speech/speech.hpp reads: text with bookmarks, and a synthesiser's phone
// timings (input starting with '#'). mpeg4face::Error is the expected outcome for malformed
// input; what is read must make a stream with every field in range.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "mpeg4face/error.hpp"
#include "mpeg4face/speech/speech.hpp"

namespace {

using namespace mpeg4face;

void check(const FapStream& stream) {
  for (const FapFrame& f : stream.frames) {
    const Viseme& v = f.viseme;
    const Expression& e = f.expression;
    if (v.select1 < 0 || v.select1 > 14 || v.select2 < 0 || v.select2 > 14 || v.blend < 0 ||
        v.blend > 63 || e.select1 < 0 || e.select1 > 6 || e.select2 < 0 || e.select2 > 6 ||
        e.intensity1 < 0 || e.intensity1 > 63 || e.intensity2 < 0 || e.intensity2 > 63) {
      std::abort();
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  SynthesizedSpeech speech;
  MarkedText marked;
  try {
    if (text.starts_with("#")) {
      speech.phones = parseFlitePhones(std::string_view(text).substr(1), "fuzz");
      if (speech.phones.size() > 2000 ||
          (!speech.phones.empty() && speech.phones.back().end > 60)) {
        return 0;  // a stream of hours: no finding, only slow
      }
      assignWords(speech.phones, {{"w", "ah", "n"}, {"t", "uw"}});
    } else {
      marked = parseBookmarks(text);
      for (const Bookmark& b : marked.bookmarks) {
        if (b.fap < 2 || b.fap > kFapCount || !(b.duration >= 0) || b.word < 0) std::abort();
      }
      // Each word a 100 ms phone after a pause.
      speech.words = speechWords(marked.text);
      speech.phones.push_back({"pau", 0, 0.1, -1});
      for (std::size_t w = 0; w < speech.words.size() && w < 200; ++w) {
        speech.phones.push_back({"aa", 0.1 * (w + 1), 0.1 * (w + 2), static_cast<int>(w)});
      }
    }
  } catch (const Error&) {
    return 0;
  }
  for (const TimedPhone& p : speech.phones) {
    if (p.word < -1 || p.word > 1000) std::abort();
  }
  FapStream stream = visemeStream(speech.phones, 25);
  applyBookmarks(stream, marked.bookmarks, speech);
  check(stream);
  return 0;
}
