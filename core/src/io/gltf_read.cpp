// SPDX-License-Identifier: GPL-3.0-or-later
// glTF 2.0 -> FaceModel through tinygltf (Debian's shared libtinygltf; the implementation is
// in the .so, so TINYGLTF_IMPLEMENTATION must not be defined here): the file-system
// callbacks, the GLB checks and the entry points. The Reader (io/gltf_reader.hpp,
// gltf_read_*.cpp) turns the tinygltf::Model into a FaceModel.
#include <tiny_gltf.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <system_error>
#include <utility>
#include <vector>

#include "io/gltf_internal.hpp"
#include "io/gltf_reader.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/gltf.hpp"

namespace mpeg4face {
namespace {

using gltf_reader::str;

// glTF needs no deep nesting; the limit keeps hostile input from exhausting the stack in
// tinygltf's recursive conversion of extras.
constexpr int kMaxJsonDepth = 100;

// --- tinygltf glue --------------------------------------------------------------------

// External files may only come from baseDir or below it; with no baseDir, from nowhere.
struct FsContext {
  std::filesystem::path baseDir;
  std::string refused;  // an existing file that was not allowed, for the message

  bool allowed(const std::string& file) const {
    if (baseDir.empty()) return false;
    std::error_code ec;
    const auto base = std::filesystem::weakly_canonical(std::filesystem::absolute(baseDir), ec);
    if (ec) return false;
    const auto path = std::filesystem::weakly_canonical(std::filesystem::absolute(file), ec);
    if (ec) return false;
    const std::filesystem::path rel = path.lexically_relative(base);
    return !rel.empty() && *rel.begin() != ".." && rel != ".";
  }
};

bool fileExists(const std::string& path, void* user) {
  try {
    auto* ctx = static_cast<FsContext*>(user);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return false;
    if (ctx->allowed(path)) return true;
    ctx->refused = path;
    return false;
  } catch (...) {
    return false;  // must not throw through tinygltf
  }
}

std::string expandFilePath(const std::string& path, void*) { return path; }

bool readWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                   void* user) {
  try {
    const auto* ctx = static_cast<const FsContext*>(user);
    if (!ctx->allowed(path)) {
      if (err) *err += "outside the folder of the glTF file: " + path;
      return false;
    }
    const std::string bytes = readFile(path);
    out->assign(bytes.begin(), bytes.end());
    return true;
  } catch (const std::exception& e) {
    if (err) *err += e.what();
    return false;
  }
}

bool writeWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&,
                    void*) {
  if (err) *err += "mpeg4face does not let tinygltf write files";
  return false;
}

// Images are not part of the face model: skip decoding them.
bool skipImage(tinygltf::Image*, const int, std::string*, std::string*, int, int,
               const unsigned char*, int, void*) {
  return true;
}

uint32_t readU32(std::string_view bytes, size_t offset) {
  uint32_t value = 0;
  std::memcpy(&value, bytes.data() + offset, 4);
  return value;
}

// Checks the GLB container and returns the part tinygltf may read. tinygltf 2.7 lets a BIN
// chunk extend 8 bytes past the declared length (it forgets the chunk header), so the
// chunk layout is checked here before tinygltf sees it.
std::string_view checkGlb(std::string_view bytes, const std::string& fileName) {
  auto fail = [&](const std::string& field, const std::string& message) {
    throw Error(fileName, 0, field, message);
  };
  if (bytes.size() < 12) {
    fail("GLB header", "truncated: " + str(bytes.size()) + " bytes, the header alone needs 12");
  }
  const uint32_t version = readU32(bytes, 4);
  if (version != 2) fail("GLB header", "GLB version " + str(version) + " (only 2 is supported)");
  const uint64_t length = readU32(bytes, 8);
  if (length > bytes.size()) {
    fail("GLB header",
         "truncated: the header says " + str(length) + " bytes, the file has " + str(bytes.size()));
  }
  if (length < 20) fail("GLB header", "no JSON chunk");
  const uint64_t jsonLength = readU32(bytes, 12);
  if (readU32(bytes, 16) != 0x4E4F534A) fail("GLB chunk 0", "the first chunk is not JSON");
  const uint64_t jsonEnd = 20 + jsonLength;
  if (jsonEnd > length) {
    fail("GLB chunk 0", "truncated: the JSON chunk of " + str(jsonLength) +
                            " bytes runs past the end of the file (" + str(length) + " bytes)");
  }
  if (jsonEnd + 8 <= length) {
    const uint64_t binLength = readU32(bytes, jsonEnd);
    if (jsonEnd + 8 + binLength > length) {
      fail("GLB chunk 1", "truncated: the chunk of " + str(binLength) +
                              " bytes runs past the end of the file (" + str(length) + " bytes)");
    }
  }
  return bytes.substr(0, length);
}

// Nesting depth of JSON text, strings skipped.
int jsonDepth(std::string_view json) {
  int depth = 0;
  int deepest = 0;
  bool inString = false;
  for (size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (inString) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        inString = false;
      }
    } else if (c == '"') {
      inString = true;
    } else if (c == '{' || c == '[') {
      deepest = std::max(deepest, ++depth);
    } else if (c == '}' || c == ']') {
      --depth;
    }
  }
  return deepest;
}

std::string trimmed(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  for (char& c : s) {
    if (c == '\n') c = ';';
  }
  return s;
}

// Where a tinygltf failure is: it gives only a message, but it fills the model's arrays in
// file order, so the element being parsed when it stopped is the next one.
std::pair<int, std::string> locateTinygltfError(const std::string& err, const tinygltf::Model& g) {
  auto has = [&](const char* s) { return err.find(s) != std::string::npos; };
  if (has("Chunk") || has("glTF binary") || has("glTF Binary")) return {0, "GLB"};
  if (has("parse_error") || has("parse error") || has("JSON string too short") ||
      has("not a JSON object")) {
    int line = 0;
    if (auto at = err.find("at line "); at != std::string::npos) {
      line = std::atoi(err.c_str() + at + 8);
    }
    return {line, "JSON"};
  }
  if (has("\"asset\"")) return {0, "asset"};
  if (has("primitive indices accessor") || has("invalid bufferView")) {
    for (size_t m = 0; m < g.meshes.size(); ++m) {
      for (size_t p = 0; p < g.meshes[m].primitives.size(); ++p) {
        const int i = g.meshes[m].primitives[p].indices;
        if (i < 0) continue;
        if (static_cast<size_t>(i) >= g.accessors.size() || g.accessors[i].bufferView < 0 ||
            static_cast<size_t>(g.accessors[i].bufferView) >= g.bufferViews.size()) {
          return {0, "meshes[" + str(m) + "].primitives[" + str(p) + "].indices"};
        }
      }
    }
    return {0, "meshes"};
  }
  if (has("File ") || has("'uri'") || has("Buffer") || has("byteLength") || has("BIN")) {
    return {0, "buffers[" + str(g.buffers.size()) + "]"};
  }
  if (has("byteStride") || has("BufferView"))
    return {0, "bufferViews[" + str(g.bufferViews.size()) + "]"};
  if (has("ccessor") || has("componentType") || has("`type`")) {
    return {0, "accessors[" + str(g.accessors.size()) + "]"};
  }
  if (has("nimation")) return {0, "animations[" + str(g.animations.size()) + "]"};
  if (has("image")) return {0, "images[" + str(g.images.size()) + "]"};
  return {0, {}};
}

}  // namespace

gltf_internal::ReadResult gltf_internal::parseGltf(std::string_view bytes,
                                                   const std::string& fileName,
                                                   const std::filesystem::path& baseDir) {
  if (bytes.empty()) throw Error(fileName, 0, {}, "empty file");
  if (bytes.size() > std::numeric_limits<uint32_t>::max()) {
    throw Error(fileName, 0, {}, "larger than 4 GiB, which tinygltf cannot read");
  }
  const bool binary = bytes.starts_with("glTF");
  std::string_view json = bytes;
  if (binary) {
    bytes = checkGlb(bytes, fileName);
    json = bytes.substr(20, readU32(bytes, 12));
  } else {
    size_t first = json.starts_with("\xEF\xBB\xBF") ? 3 : 0;  // a UTF-8 byte order mark
    while (first < json.size() && std::isspace(static_cast<unsigned char>(json[first]))) ++first;
    if (first == json.size() || json[first] != '{') {
      throw Error(fileName, 0, {},
                  "not glTF: neither the GLB magic 'glTF' nor a JSON object at the start");
    }
  }
  if (jsonDepth(json) > kMaxJsonDepth) {
    throw Error(fileName, 0, "JSON",
                "nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  }

  FsContext fs{baseDir, {}};
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({&fileExists, &expandFilePath, &readWholeFile, &writeWholeFile, &fs});
  loader.SetImageLoader(&skipImage, nullptr);
  tinygltf::Model gltf;
  std::string err;
  std::string warn;
  bool ok = false;
  try {
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    const auto size = static_cast<unsigned int>(bytes.size());
    ok = binary
             ? loader.LoadBinaryFromMemory(&gltf, &err, &warn, data, size, baseDir.string())
             : loader.LoadASCIIFromString(&gltf, &err, &warn, bytes.data(), size, baseDir.string());
  } catch (const std::exception& e) {  // tinygltf has a few .at() on hostile input
    ok = false;
    err += e.what();
  }
  // Harmless: tinygltf reads the file fine; some exporters do not pad the JSON chunk.
  if (ok && trimmed(err) == "JSON Chunk end does not aligned to a 4-byte boundary.") err.clear();
  // tinygltf reports some problems in `err` but still succeeds (and then silently drops the
  // element, which would shift every JSON path we report): treat them as errors too.
  if (!ok || !err.empty()) {
    if (err.empty()) err = "tinygltf could not read the file";
    std::string message = trimmed(err);
    if (!fs.refused.empty()) {
      message += " (" + fs.refused + " exists, but only files in the glTF file's folder are read)";
    } else if (baseDir.empty() && message.find("File not found") != std::string::npos) {
      message += " (no base folder was given, so no external file can be read)";
    }
    if (!warn.empty()) message += " (tinygltf warnings: " + trimmed(warn) + ")";
    const auto [line, field] = locateTinygltfError(err, gltf);
    throw Error(fileName, line, field, message);
  }
  return gltf_reader::Reader(gltf, fileName).read();
}

FaceModel parseGltf(std::string_view bytes, const std::string& fileName,
                    const std::filesystem::path& baseDir) {
  return gltf_internal::parseGltf(bytes, fileName, baseDir).model;
}

gltf_internal::ReadResult gltf_internal::readGltf(const std::filesystem::path& path) {
  const std::string bytes = readFile(path);
  std::filesystem::path baseDir = path.parent_path();
  if (baseDir.empty()) baseDir = ".";
  return parseGltf(bytes, path.string(), baseDir);
}

FaceModel readGltf(const std::filesystem::path& path) {
  return gltf_internal::readGltf(path).model;
}

}  // namespace mpeg4face
