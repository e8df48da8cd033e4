// SPDX-License-Identifier: GPL-3.0-or-later
// The glTF reader and writer with more of the project's own data under
// scenes[0].extras.mpeg4face than FaceModel holds, for formats built on the plain mapping
// (io/fat_gltf.cpp). Internal: tinygltf is a private dependency of the core.
#pragma once

#include <tiny_gltf.h>

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face::gltf_internal {

// writeGltf, with `extras` added to scenes[0].extras.mpeg4face beside featurePoints.
void writeGltf(const FaceModel& model, const std::filesystem::path& path,
               const tinygltf::Value::Object& extras);

struct ReadResult {
  FaceModel model;
  tinygltf::Value extras;            // scenes[s].extras.mpeg4face, a null Value when absent
  std::string extrasField;           // its JSON path, for messages
  std::vector<int> transformOfNode;  // the Transform of each glTF node, -1 for helper nodes
};
// parseGltf and readGltf, also handing back the extras and the node -> Transform mapping.
ReadResult parseGltf(std::string_view bytes, const std::string& fileName,
                     const std::filesystem::path& baseDir);
ReadResult readGltf(const std::filesystem::path& path);

}  // namespace mpeg4face::gltf_internal
