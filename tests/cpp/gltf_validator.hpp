// SPDX-License-Identifier: GPL-3.0-or-later
// Runs the Khronos glTF validator from a C++ test (shared by test_gltf and test_fat_gltf).
#pragma once

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace mpeg4face::test {

// The command in MPEG4FACE_GLTF_VALIDATOR, e.g. "node tests/tools/validate_gltf.mjs"
// (npm install --prefix tests/tools first), or "" when it is not set.
inline std::string gltfValidator() {
  const char* validator = std::getenv("MPEG4FACE_GLTF_VALIDATOR");
  return validator == nullptr ? "" : validator;
}

#define MPEG4FACE_SKIP_WITHOUT_GLTF_VALIDATOR()                                          \
  if (mpeg4face::test::gltfValidator().empty()) {                                        \
    GTEST_SKIP() << "set MPEG4FACE_GLTF_VALIDATOR to e.g. \"node "                       \
                    "tests/tools/validate_gltf.mjs\" to run the Khronos glTF validator"; \
  }

// Runs the validator with --strict on `files`; expects exit status 0 and "0 errors, 0
// warnings" for each file. Prints the validator's report.
inline void expectValidGltf(const std::vector<std::filesystem::path>& files) {
  std::string command = gltfValidator() + " --strict";
  for (const auto& file : files) command += " '" + file.string() + "'";
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[4096];
  while (size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) output.append(buffer, n);
  const int status = ::pclose(pipe);
  std::printf("%s", output.c_str());
  EXPECT_EQ(status, 0) << output;
  for (const auto& file : files) {
    EXPECT_NE(output.find(file.filename().string() + ": 0 errors, 0 warnings"), std::string::npos)
        << output;
  }
}

}  // namespace mpeg4face::test
