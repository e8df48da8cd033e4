// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face decode`: an FBA bitstream back to a .fap stream.
#include <cstdio>
#include <optional>
#include <string>

#include "arguments.hpp"
#include "commands.hpp"
#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fit/fit.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/files.hpp"

namespace mpeg4face::cli {

int runDecode(const std::vector<std::string>& args) {
  std::string input, output, fit;
  bool strict = false;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--strict") {
      strict = true;
    } else if (args[i] == "-o") {
      output = optionValue(args, i, "an output file");
    } else if (args[i] == "--fit") {
      fit = optionValue(args, i, "a FAP Interpolation Table (.json)");
    } else if (args[i].starts_with("-")) {
      throw UsageError("unknown option '" + args[i] + "'");
    } else if (input.empty()) {
      input = args[i];
    } else {
      throw UsageError("more than one input given ('" + input + "' and '" + args[i] + "')");
    }
  }
  if (input.empty()) throw UsageError("no input .fba file given");
  if (output.empty()) throw UsageError("no output given (-o OUT.fap)");

  const std::optional<FitTable> table =
      fit.empty() ? std::nullopt : std::optional(readFitTableFile(fit));
  FapStream stream;
  if (strict) {
    const std::string bytes = readFile(input);
    FbaDecodeLimits limits;
    limits.strict = true;
    stream = decodeFba({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, input,
                       limits);
    stream.name = std::filesystem::path(input).stem().string();
  } else {
    stream = readFbaFile(input);
  }
  if (table) {
    try {
      const int computed = interpolateFitStream(*table, stream);
      std::printf("%s: %d FAP values interpolated\n", fit.c_str(), computed);
    } catch (const Error& e) {
      throw Error(fit, 0, e.field(), e.reason());
    }
  }
  writeFapFile(output, stream);
  std::printf("%s: %zu frames at %g Hz -> %s\n", input.c_str(), stream.frames.size(),
              stream.frameRate, output.c_str());
  return 0;
}

}  // namespace mpeg4face::cli
