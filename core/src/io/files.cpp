// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/io/files.hpp"

#include <fstream>
#include <sstream>
#include <system_error>

#include "mpeg4face/error.hpp"

namespace mpeg4face {

void rejectFolder(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw Error(path.string(), 0, {}, "is a folder, not a file");
  }
}

std::string readFile(const std::filesystem::path& path) {
  rejectFolder(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string(), 0, {}, "cannot open for reading");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw Error(path.string(), 0, {}, "read failed");
  return std::move(buffer).str();
}

void writeFileAtomically(const std::filesystem::path& path, const std::string& contents) {
  const std::filesystem::path temp = path.string() + ".part";
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error(path.string(), 0, {}, "cannot open for writing");
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.flush();
    if (!out) {
      out.close();
      std::filesystem::remove(temp);
      throw Error(path.string(), 0, {}, "write failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::filesystem::remove(temp);
    throw Error(path.string(), 0, {}, "cannot replace the file: " + ec.message());
  }
}

}  // namespace mpeg4face
