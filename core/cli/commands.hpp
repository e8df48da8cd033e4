// SPDX-License-Identifier: GPL-3.0-or-later
// The subcommands of the `mpeg4face` tool. Each takes its arguments (without the program and
// subcommand names) and returns the exit status; errors are thrown (mpeg4face::Error for bad
// input, UsageError for bad arguments) and reported by main().
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace mpeg4face::cli {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Command {
  const char* name;
  const char* summary;
  const char* usage;
  int (*run)(const std::vector<std::string>& args);
};

int runInfo(const std::vector<std::string>& args);
int runPsnr(const std::vector<std::string>& args);
int runEncode(const std::vector<std::string>& args);
int runDecode(const std::vector<std::string>& args);
int runRd(const std::vector<std::string>& args);
int runFat(const std::vector<std::string>& args);
int runExport(const std::vector<std::string>& args);
int runApply(const std::vector<std::string>& args);
int runClone(const std::vector<std::string>& args);
int runFit(const std::vector<std::string>& args);
int runSpeak(const std::vector<std::string>& args);
int runCheck(const std::vector<std::string>& args);
int runArkit(const std::vector<std::string>& args);
int runArkitToFap(const std::vector<std::string>& args);
int runArkitFromFap(const std::vector<std::string>& args);
int runMesh2d(const std::vector<std::string>& args);
int runLandmarks(const std::vector<std::string>& args);
int runAnimate(const std::vector<std::string>& args);

}  // namespace mpeg4face::cli

namespace mpeg4face {
struct FitTable;
}

namespace mpeg4face::cli {

// A FAP Interpolation Table from its JSON form, or the FIT node of a face's .wrl (the --fit
// option of encode and decode, and fit try).
FitTable readFitTableFile(const std::string& path);

}  // namespace mpeg4face::cli
