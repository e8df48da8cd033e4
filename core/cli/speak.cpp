// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face speak`: text with bookmarks to a FAP stream and the speech's audio, in step.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "arguments.hpp"
#include "commands.hpp"
#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/speech/speech.hpp"
#include "paths.hpp"

namespace mpeg4face::cli {

int runSpeak(const std::vector<std::string>& args) {
  std::string text, output, audio, voice;
  bool haveText = false;
  double fps = 25;
  VisemeOptions options;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-o") {
      output = optionValue(args, i, "an output file");
    } else if (a == "--audio") {
      audio = optionValue(args, i, "a .wav file");
    } else if (a == "--fps") {
      fps = numberArgument(args, i, "a frame rate", 1);
    } else if (a == "--transition") {
      options.transition = numberArgument(args, i, "seconds", 0);
    } else if (a == "--voice") {
      voice = optionValue(args, i, "a flite voice");
    } else if (a == "--text-file") {
      if (haveText) throw UsageError("give the text once (TEXT or --text-file)");
      text = readFile(optionValue(args, i, "a text file"));
      haveText = true;
    } else if (a.starts_with("-") && a.size() > 1) {
      throw UsageError("unknown option '" + a + "'");
    } else if (!haveText) {
      text = a;
      haveText = true;
    } else {
      throw UsageError("give the text as one argument, in quotes");
    }
  }
  if (!haveText) throw UsageError("no text given");
  if (output.empty()) throw UsageError("no output given (-o OUT.fap or OUT.fba)");
  const std::string ext = extensionOf(output);
  if (ext != ".fap" && ext != ".fba") {
    throw UsageError("the output must be .fap or .fba, not '" + output + "'");
  }
  if (audio.empty()) audio = std::filesystem::path(output).replace_extension(".wav").string();

  // MPEG4FACE_FLITE names another flite binary (tests use it to stand in for a missing one).
  const char* program = std::getenv("MPEG4FACE_FLITE");
  const FlitePhonemeSource flite(program ? program : "flite", voice);
  FapStream stream = speak(text, flite, audio, fps, options);
  stream.name = std::filesystem::path(output).stem().string();
  if (ext == ".fba") {
    const FbaEncoding enc = encodeFba(stream);
    writeFileAtomically(output, std::string(enc.bytes.begin(), enc.bytes.end()));
  } else {
    writeFapFile(output, stream);
  }
  std::printf("%s: %zu frames at %g Hz (%.2f s) -> %s; audio -> %s\n", stream.name.c_str(),
              stream.frames.size(), fps, streamDuration(stream), output.c_str(), audio.c_str());
  return 0;
}

}  // namespace mpeg4face::cli
