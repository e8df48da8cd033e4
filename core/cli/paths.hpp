// SPDX-License-Identifier: GPL-3.0-or-later
// What the subcommands infer from a file name.
#pragma once

#include <cctype>
#include <filesystem>
#include <string>

namespace mpeg4face::cli {

// The extension in lower case, with its dot ("" if none).
inline std::string extensionOf(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

inline bool isGltf(const std::string& path) {
  const std::string ext = extensionOf(path);
  return ext == ".glb" || ext == ".gltf";
}

}  // namespace mpeg4face::cli
