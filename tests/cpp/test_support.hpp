// SPDX-License-Identifier: GPL-3.0-or-later
// Small helpers shared by the C++ tests.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "mpeg4face/error.hpp"

namespace mpeg4face::test {

// tests/data, set by tests/CMakeLists.txt.
inline const std::filesystem::path kData = MPEG4FACE_TEST_DATA;

// The mpeg4face::Error that `f` throws; fails the test if it throws none.
template <typename F>
Error errorOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e;
  }
  ADD_FAILURE() << "no mpeg4face::Error thrown";
  return Error("none");
}

// A folder of the running test's own: ctest runs every test in a process of its own, in
// parallel, so fixed temporary names would collide.
inline std::filesystem::path scratchDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const auto dir = std::filesystem::temp_directory_path() /
                   ("mpeg4face_" + std::string(info->test_suite_name()) + "_" + info->name() + "_" +
                    std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

// Whether `text` (a command's output, a message) contains `part`.
inline bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The `mpeg4face` tool run as a user runs it: `args` go through the shell.
struct CliResult {
  int status;
  std::string out;         // stdout and stderr together
  std::string stdoutOnly;  // for --json
};
inline CliResult runCli(const std::string& args) {
  CliResult r{};
  const std::filesystem::path err = scratchDir() / "cli_stderr.txt";
  const std::string command = std::string(MPEG4FACE_CLI) + " " + args + " 2>" + err.string();
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return {-1, "popen failed", ""};
  std::array<char, 4096> buffer{};
  for (size_t n; (n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0;) {
    r.stdoutOnly.append(buffer.data(), n);
  }
  const int status = pclose(pipe);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream in(err);
  r.out = r.stdoutOnly + std::string(std::istreambuf_iterator<char>(in), {});
  return r;
}

// Writes `text` to a file of that name in the running test's scratch folder; returns its path.
inline std::string writeScratchFile(const std::string& name, const std::string& text) {
  const auto path = scratchDir() / name;
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

}  // namespace mpeg4face::test
