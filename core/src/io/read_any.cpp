// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/io/read_any.hpp"

#include <algorithm>
#include <cctype>

#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/gltf.hpp"
#include "mpeg4face/io/obj.hpp"
#include "mpeg4face/io/vrml.hpp"
#include "mpeg4face/io/wfm.hpp"

namespace mpeg4face {
namespace {

std::string lowerCaseExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

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
