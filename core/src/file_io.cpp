// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/file_io.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>
#include <system_error>

#include "mpeg4face/error.hpp"
#include "mpeg4face/fap_file.hpp"
#include "mpeg4face/fba_codec.hpp"
#include "mpeg4face/gltf.hpp"
#include "mpeg4face/obj.hpp"
#include "mpeg4face/vrml.hpp"
#include "mpeg4face/wfm.hpp"

namespace mpeg4face {
namespace {

std::string lowerCaseExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// A folder opens as an empty stream and has no extension: name the real problem instead.
void rejectFolder(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw Error(path.string(), 0, {}, "is a folder, not a file");
  }
}

}  // namespace

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

FaceModel readModel(const std::filesystem::path& path) {
  rejectFolder(path);
  const std::string ext = lowerCaseExtension(path);
  if (ext == ".gltf" || ext == ".glb") return readGltf(path);
  if (ext == ".obj") return readObj(path);
  if (ext == ".wfm") return candideToFaceModel(readWfm(path));
  if (ext == ".wrl") return readVrml(path).faceSceneGraph;
  throw Error(path.string(), 0, {},
              "unknown model format '" + ext + "' (expected .gltf, .glb, .obj, .wfm or .wrl)");
}

FapStream readFapStream(const std::filesystem::path& path) {
  const std::string ext = lowerCaseExtension(path);
  if (ext == ".fap") return readFapFile(path);
  if (ext == ".fba") return readFbaFile(path);
  throw Error(path.string(), 0, {}, "expected a .fap or .fba file");
}

}  // namespace mpeg4face
