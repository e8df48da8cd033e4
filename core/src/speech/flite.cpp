// SPDX-License-Identifier: GPL-3.0-or-later
// The flite phoneme source: flite run as a program (posix_spawn, no shell), its phones read
// from its -psdur output. docs/speech.md.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <sstream>

#include "io/text_reader.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/speech/speech.hpp"

extern char** environ;

namespace mpeg4face {
namespace {

// Runs `argv` and returns its standard output; throws naming the program if it cannot be run
// or fails.
std::string run(const std::vector<std::string>& argv) {
  int out[2];
  if (pipe(out) != 0) throw Error(argv[0], 0, "speech", "cannot make a pipe");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, out[0]);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int status = posix_spawnp(&pid, argv[0].c_str(), &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(out[1]);
  if (status != 0) {
    close(out[0]);
    throw Error(argv[0], 0, "speech",
                "cannot run '" + argv[0] + "' (" + std::strerror(status) +
                    "): install Debian's flite package (scripts/setup.sh does)");
  }
  std::string text;
  char buffer[4096];
  for (ssize_t n; (n = read(out[0], buffer, sizeof buffer)) > 0;)
    text.append(buffer, static_cast<std::size_t>(n));
  close(out[0]);
  int code = 0;
  while (waitpid(pid, &code, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(code) || WEXITSTATUS(code) != 0) {
    throw Error(argv[0], 0, "speech",
                "'" + argv[0] + "' failed (exit status " +
                    std::to_string(WIFEXITED(code) ? WEXITSTATUS(code) : -1) + ")");
  }
  return text;
}

std::vector<std::string> tokens(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> out;
  for (std::string t; in >> t;) out.push_back(t);
  return out;
}

}  // namespace

std::vector<TimedPhone> parseFlitePhones(std::string_view output, const std::string& program) {
  std::vector<TimedPhone> phones;
  double start = 0;
  for (const std::string& t : tokens(std::string(output))) {
    const std::size_t colon = t.rfind(':');
    double end = 0;
    if (colon == std::string::npos ||
        !text::tryParseDouble(std::string_view(t).substr(colon + 1), end) || end < start) {
      throw Error(program, 0, "speech",
                  "unreadable phone timing '" + t + "' (phone:end, ends in time order)");
    }
    TimedPhone p{t.substr(0, colon), start, end, -1};
    phoneViseme(p.phone);  // a phone set other than the one the table knows fails here, by name
    start = end;
    phones.push_back(std::move(p));
  }
  return phones;
}

std::vector<std::string> FlitePhonemeSource::command(std::vector<std::string> args) const {
  std::vector<std::string> argv{program_};
  if (!voice_.empty()) argv.insert(argv.end(), {"-voice", voice_});
  argv.insert(argv.end(), args.begin(), args.end());
  return argv;
}

SynthesizedSpeech FlitePhonemeSource::synthesize(const std::string& text,
                                                 const std::filesystem::path& audio) const {
  const std::filesystem::path folder = audio.parent_path();
  if (!folder.empty() && !std::filesystem::is_directory(folder)) {
    throw Error(audio.string(), 0, "audio", "the folder " + folder.string() + " does not exist");
  }
  // The audio goes through a temporary name, so that a failure leaves no half-written file.
  std::filesystem::path part = audio;
  part += ".part.wav";
  struct RemoveOnFailure {
    const std::filesystem::path& path;
    bool keep = false;
    ~RemoveOnFailure() {
      std::error_code ignored;
      if (!keep) std::filesystem::remove(path, ignored);
    }
  } guard{part};

  SynthesizedSpeech speech;
  speech.words = speechWords(text);
  speech.phones =
      parseFlitePhones(run(command({"-psdur", "-o", part.string(), "-t", text})), program_);
  if (speech.phones.empty())
    throw Error(program_, 0, "speech", "'" + program_ + "' reported no phones");
  std::vector<std::vector<std::string>> wordPhones;
  for (const std::string& w : speech.words) {
    wordPhones.push_back(tokens(run(command({"-ps", "-o", "none", "-t", w}))));
  }
  assignWords(speech.phones, wordPhones);
  std::filesystem::rename(part, audio);
  guard.keep = true;
  return speech;
}

}  // namespace mpeg4face
