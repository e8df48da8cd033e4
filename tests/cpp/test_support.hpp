// SPDX-License-Identifier: GPL-3.0-or-later
// Small helpers shared by the C++ tests.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
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

}  // namespace mpeg4face::test
