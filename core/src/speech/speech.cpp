// SPDX-License-Identifier: GPL-3.0-or-later
// Phones to visemes, bookmarks, and text to a FAP stream. docs/speech.md.
#include "mpeg4face/speech/speech.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <map>
#include <optional>

#include "io/text_reader.hpp"
#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

// CMU US English (flite's cmu_us_kal / slt phone set) to the 15 MPEG-4 visemes (spec.cpp).
constexpr std::array<PhoneViseme, 40> kPhoneVisemes{{
    {"pau", 0, "silence"}, {"p", 1, "put"},    {"b", 1, "bed"},    {"m", 1, "mill"},
    {"f", 2, "far"},       {"v", 2, "voice"},  {"th", 3, "think"}, {"dh", 3, "that"},
    {"t", 4, "tip"},       {"d", 4, "doll"},   {"k", 5, "call"},   {"g", 5, "gas"},
    {"ng", 5, "sing"},     {"ch", 6, "chair"}, {"jh", 6, "join"},  {"sh", 6, "she"},
    {"zh", 6, "measure"},  {"s", 7, "sir"},    {"z", 7, "zeal"},   {"n", 8, "not"},
    {"l", 8, "lot"},       {"r", 9, "red"},    {"er", 9, "bird"},  {"axr", 9, "butter"},
    {"aa", 10, "car"},     {"ah", 10, "but"},  {"aw", 10, "how"},  {"ay", 10, "my"},
    {"ae", 11, "bat"},     {"eh", 11, "bed"},  {"ey", 11, "say"},  {"ax", 11, "about"},
    {"ih", 12, "tip"},     {"iy", 12, "see"},  {"y", 12, "yes"},   {"ao", 13, "top"},
    {"ow", 13, "go"},      {"oy", 13, "boy"},  {"uh", 14, "book"}, {"uw", 14, "blue"},
}};
// "w" rounds the lips as /u/ does.
constexpr PhoneViseme kW{"w", 14, "wet"};
// /hh/ has no lip shape of its own: it takes the next phone's (the coarticulation rule).
constexpr std::string_view kAnticipating = "hh";

}  // namespace

std::span<const PhoneViseme> phoneVisemeTable() { return kPhoneVisemes; }

int phoneViseme(std::string_view phone) {
  if (phone == kW.phone) return kW.viseme;
  if (phone == kAnticipating) return 0;
  for (const PhoneViseme& p : kPhoneVisemes) {
    if (p.phone == phone) return p.viseme;
  }
  throw Error({}, 0, "phone", "unknown phone '" + std::string(phone) + "'");
}

std::vector<std::string> speechWords(std::string_view text) {
  std::vector<std::string> words;
  std::string word;
  for (char c : text) {
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '\'') {
      word += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else if (!word.empty()) {
      words.push_back(std::move(word));
      word.clear();
    }
  }
  if (!word.empty()) words.push_back(std::move(word));
  return words;
}

void assignWords(std::vector<TimedPhone>& phones,
                 const std::vector<std::vector<std::string>>& wordPhones) {
  std::vector<TimedPhone*> spoken;  // the sentence's phones, pauses aside
  for (TimedPhone& p : phones) {
    p.word = -1;
    if (p.phone != "pau") spoken.push_back(&p);
  }
  std::vector<const std::string*> said;  // the words' phones, concatenated, and their word
  std::vector<int> saidWord;
  for (std::size_t w = 0; w < wordPhones.size(); ++w) {
    for (const std::string& ph : wordPhones[w]) {
      if (ph == "pau") continue;
      said.push_back(&ph);
      saidWord.push_back(static_cast<int>(w));
    }
  }
  if (said.empty()) return;
  // Edit distance: two rows of costs, and per cell the moves that reach it at least cost.
  const std::size_t n = spoken.size(), m = said.size();
  enum : unsigned char { kMatch = 1, kSubstitute = 2, kSpokenOnly = 4, kSaidOnly = 8 };
  std::vector<unsigned char> moves((n + 1) * (m + 1));
  std::vector<std::size_t> above(m + 1), row(m + 1);
  for (std::size_t j = 0; j <= m; ++j) above[j] = j, moves[j] = kSaidOnly;
  for (std::size_t i = 1; i <= n; ++i) {
    row[0] = i;
    moves[i * (m + 1)] = kSpokenOnly;
    for (std::size_t j = 1; j <= m; ++j) {
      const bool same = spoken[i - 1]->phone == *said[j - 1];
      const std::size_t pair = above[j - 1] + (same ? 0 : 1);
      const std::size_t spokenOnly = above[j] + 1, saidOnly = row[j - 1] + 1;
      const std::size_t best = std::min({pair, spokenOnly, saidOnly});
      row[j] = best;
      moves[i * (m + 1) + j] = static_cast<unsigned char>(
          (pair == best ? (same ? kMatch : kSubstitute) : 0) |
          (spokenOnly == best ? kSpokenOnly : 0) | (saidOnly == best ? kSaidOnly : 0));
    }
    std::swap(above, row);
  }
  // Back from the end, preferring a match, then passing over a phone of the words alone (so a
  // substitution pairs phones as early as it can), then a substitution.
  for (std::size_t i = n, j = m; i > 0;) {
    const unsigned char at = moves[i * (m + 1) + j];
    if (!(at & kMatch) && (at & kSaidOnly)) {
      --j;
      continue;
    }
    // Paired with said phone j - 1; a phone of the sentence alone joins the word before it.
    spoken[i - 1]->word = saidWord[j > 0 ? j - 1 : 0];
    const bool paired = at & (kMatch | kSubstitute);
    --i;
    if (paired) --j;
  }
}

FapStream visemeStream(std::span<const TimedPhone> phones, double frameRate,
                       const VisemeOptions& options) {
  if (!(frameRate > 0)) throw Error({}, 0, "frame rate", "the frame rate must be > 0");
  for (std::size_t i = 0; i < phones.size(); ++i) {
    const TimedPhone& p = phones[i];
    if (!(std::isfinite(p.start) && std::isfinite(p.end) && p.start >= 0 && p.end >= p.start) ||
        (i > 0 && p.start < phones[i - 1].end - 1e-9)) {
      throw Error({}, 0, "phones[" + std::to_string(i) + "]",
                  "phone '" + p.phone + "' from " + std::to_string(p.start) + " to " +
                      std::to_string(p.end) + " s is not after the one before it");
    }
  }
  std::vector<int> visemes;
  for (std::size_t i = 0; i < phones.size(); ++i) visemes.push_back(phoneViseme(phones[i].phone));
  // Anticipation: /hh/ shows the following phone's viseme (0 at the end).
  for (std::size_t i = phones.size(); i-- > 0;) {
    if (phones[i].phone == kAnticipating) visemes[i] = i + 1 < phones.size() ? visemes[i + 1] : 0;
  }
  // Lip rounding spreads onto the consonants the tongue alone makes (their lips are free):
  // ahead from a rounded phone after them ("two", "cool"), else back from one before them
  // ("boot"); a run of such consonants takes it whole ("clue").
  const auto tongueOnly = [](int v) { return v == 3 || v == 4 || v == 5 || v == 8; };
  const auto rounded = [](int v) { return v == 13 || v == 14; };
  const std::vector<int> own = visemes;
  for (std::size_t i = phones.size(); i-- > 0;) {
    if (tongueOnly(own[i]) && i + 1 < phones.size() && rounded(visemes[i + 1])) {
      visemes[i] = visemes[i + 1];
    }
  }
  for (std::size_t i = 1; i < phones.size(); ++i) {
    if (tongueOnly(own[i]) && visemes[i] == own[i] && rounded(visemes[i - 1])) {
      visemes[i] = visemes[i - 1];
    }
  }
  FapStream stream;
  stream.frameRate = frameRate;
  const double end = phones.empty() ? 0 : phones.back().end;
  const int frames = static_cast<int>(std::floor(end * frameRate)) + 1;
  std::size_t i = 0;
  for (int n = 0; n < frames; ++n) {
    const double t = n / frameRate;
    while (i + 1 < phones.size() && t >= phones[i].end) ++i;
    FapFrame& frame = stream.frames.emplace_back();
    frame.number = n;
    frame.set(1, 0);
    Viseme v{visemes.empty() ? 0 : visemes[i], visemes.empty() ? 0 : visemes[i], 63, false};
    // The nearest boundary: before this phone's end, or after its start.
    const auto blendAt = [&](std::size_t a, std::size_t b) {
      if (visemes[a] == visemes[b]) return false;
      const double boundary = phones[a].end;
      const double half = std::min({options.transition / 2, (phones[a].end - phones[a].start) / 2,
                                    (phones[b].end - phones[b].start) / 2});
      if (half <= 0 || std::abs(t - boundary) >= half) return false;
      // From phone a (blend 63: select1 fully) to phone b (blend 0).
      const double s = (t - (boundary - half)) / (2 * half);
      v = {visemes[a], visemes[b], static_cast<int>(std::lround(63 * (1 - s))), false};
      return true;
    };
    if (!phones.empty()) {
      if (!(i + 1 < phones.size() && blendAt(i, i + 1)) && i > 0) blendAt(i - 1, i);
    }
    frame.viseme = v;
  }
  return stream;
}

MarkedText parseBookmarks(std::string_view text) {
  MarkedText out;
  std::size_t words = 0, counted = 0;  // the words of out.text[0, counted)
  std::size_t i = 0;
  while (i < text.size()) {
    if (text[i] == '>') {
      throw Error({}, 0, "bookmark",
                  "character " + std::to_string(i + 1) + ": '>' without a bookmark before it");
    }
    if (text[i] != '<') {
      out.text += text[i++];
      continue;
    }
    const std::size_t open = i;
    const std::size_t close = text.find('>', open);
    const auto fail = [&](const std::string& what) {
      throw Error(
          {}, 0, "bookmark",
          "character " + std::to_string(open + 1) + ": " + what + " in '" +
              std::string(text.substr(open, close == std::string_view::npos ? std::string_view::npos
                                                                            : close - open + 1)) +
              "'");
    };
    if (close == std::string_view::npos) fail("a bookmark without '>'");
    std::vector<std::string> tokens;
    std::string token;
    for (char c : text.substr(open + 1, close - open - 1)) {
      if (std::isspace(static_cast<unsigned char>(c))) {
        if (!token.empty()) tokens.push_back(std::move(token));
        token.clear();
      } else {
        token += c;
      }
    }
    if (!token.empty()) tokens.push_back(std::move(token));
    if (tokens.empty() || tokens[0] != "FAP") fail("a bookmark must start with FAP");
    std::vector<int> numbers;
    for (std::size_t k = 1; k < tokens.size(); ++k) {
      int v = 0;
      if (!text::tryParseInt(tokens[k], v)) fail("'" + tokens[k] + "' is not a whole number");
      numbers.push_back(v);
    }
    if (numbers.empty()) fail("no FAP number");
    Bookmark b;
    b.position = open;
    // The text before the last bookmark ends in the ' ' it left: no word runs across it.
    words += speechWords(std::string_view(out.text).substr(counted)).size();
    b.word = static_cast<int>(words);
    const int fap = numbers[0];
    const auto range = [&](int v, int lo, int hi, const char* what) {
      if (v < lo || v > hi) {
        fail(std::string(what) + " " + std::to_string(v) + " is outside " + std::to_string(lo) +
             ".." + std::to_string(hi));
      }
      return v;
    };
    std::size_t rest = 0;
    if (fap == 2) {
      if (numbers.size() != 7)
        fail("FAP 2 takes select1 intensity1 select2 intensity2 duration curve");
      b.expression = {range(numbers[1], 0, 6, "expression_select1"),
                      range(numbers[2], 0, 63, "expression_intensity1"),
                      range(numbers[3], 0, 6, "expression_select2"),
                      range(numbers[4], 0, 63, "expression_intensity2"),
                      false,
                      false};
      rest = 5;
    } else if (fap >= 3 && fap <= kFapCount) {
      if (numbers.size() != 4) fail("FAP " + std::to_string(fap) + " takes value duration curve");
      b.value = range(numbers[1], -100000, 100000, "the value");
      rest = 2;
    } else if (fap == 1) {
      fail("visemes come from the speech, not from bookmarks (FAP 1)");
    } else {
      fail("FAP " + std::to_string(fap) + " does not exist");
    }
    b.fap = fap;
    b.duration = range(numbers[rest], 0, 3600000, "the duration (ms)") / 1000.0;
    b.curve = static_cast<TimeCurve>(range(numbers[rest + 1], 1, 3, "the time curve"));
    out.bookmarks.push_back(b);
    out.text += ' ';  // a bookmark separates words
    counted = out.text.size();
    i = close + 1;
  }
  return out;
}

double timeCurveValue(TimeCurve curve, double s) {
  s = std::clamp(s, 0.0, 1.0);
  switch (curve) {
    case TimeCurve::Linear:
      return s;
    case TimeCurve::Triangular:
      return s <= 0.5 ? 2 * s : 2 * (1 - s);
    case TimeCurve::Hermite:
      return s * s * (3 - 2 * s);
  }
  return s;
}

void applyBookmarks(FapStream& stream, std::span<const Bookmark> bookmarks,
                    const SynthesizedSpeech& speech) {
  // Each bookmark's start: the first phone of its word, the end of the speech if none.
  std::vector<double> starts;
  for (const Bookmark& b : bookmarks) {
    const auto first = std::find_if(speech.phones.begin(), speech.phones.end(),
                                    [&](const TimedPhone& p) { return p.word >= b.word; });
    starts.push_back(first != speech.phones.end() ? first->start
                     : speech.phones.empty()      ? 0.0
                                                  : speech.phones.back().end);
  }
  // Per track (a low-level FAP, or the expression's two intensities), the transitions in
  // time order; a value at time t is the last started transition's.
  struct Transition {
    double start, duration;
    double from, to;  // the value at the start and the target
    TimeCurve curve;
  };
  const auto valueAt = [](const std::vector<Transition>& track, double t) -> std::optional<double> {
    const Transition* last = nullptr;
    for (const Transition& x : track) {
      if (x.start <= t) last = &x;
    }
    if (last == nullptr) return std::nullopt;
    const double s = last->duration > 0 ? (t - last->start) / last->duration : 1.0;
    return last->from + (last->to - last->from) * timeCurveValue(last->curve, s);
  };
  std::map<int, std::vector<Transition>> tracks;  // FAP 3..68; -1, -2 the intensities
  std::vector<std::pair<double, Expression>> selects;
  std::vector<std::size_t> order(bookmarks.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return starts[a] < starts[b]; });
  for (std::size_t k : order) {
    const Bookmark& b = bookmarks[k];
    const double t0 = starts[k];
    const auto add = [&](int track, double target, bool sameSelect) {
      auto& list = tracks[track];
      const double from = sameSelect ? valueAt(list, t0).value_or(0.0) : 0.0;
      list.push_back({t0, b.duration, from, target, b.curve});
    };
    if (b.fap == 2) {
      const Expression previous = selects.empty() ? Expression{} : selects.back().second;
      add(-1, b.expression.intensity1, previous.select1 == b.expression.select1);
      add(-2, b.expression.intensity2, previous.select2 == b.expression.select2);
      selects.emplace_back(t0, b.expression);
    } else {
      add(b.fap, b.value, true);
    }
  }
  for (FapFrame& frame : stream.frames) {
    const double t = frameTime(stream, frame);
    const Expression* current = nullptr;  // the selects of the last expression started
    for (const auto& [start, e] : selects) {
      if (start <= t) current = &e;
    }
    for (const auto& [track, list] : tracks) {
      const std::optional<double> v = valueAt(list, t);
      if (!v) continue;
      if (track > 0) {
        frame.set(track, static_cast<int>(std::lround(*v)));
        continue;
      }
      if (current == nullptr) continue;
      frame.set(2, 0);
      frame.expression.select1 = current->select1;
      frame.expression.select2 = current->select2;
      (track == -1 ? frame.expression.intensity1 : frame.expression.intensity2) =
          std::clamp(static_cast<int>(std::lround(*v)), 0, 63);
    }
  }
}

FapStream speak(const std::string& markedText, const PhonemeSource& source,
                const std::filesystem::path& audio, double frameRate,
                const VisemeOptions& options) {
  const MarkedText marked = parseBookmarks(markedText);
  if (speechWords(marked.text).empty()) throw Error({}, 0, "text", "nothing to say");
  const SynthesizedSpeech speech = source.synthesize(marked.text, audio);
  FapStream stream = visemeStream(speech.phones, frameRate, options);
  applyBookmarks(stream, marked.bookmarks, speech);
  stream.name = "speech";
  return stream;
}

}  // namespace mpeg4face
