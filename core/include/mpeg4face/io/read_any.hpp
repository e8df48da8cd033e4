// SPDX-License-Identifier: GPL-3.0-or-later
// Reading a face model or a FAP stream in any supported format, chosen by the file's
// extension: the one place that knows every reader (the CLI and Python open files here).
#pragma once

#include <filesystem>

#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face {

// Any supported model by extension: .gltf, .glb, .obj, .wfm, .wrl (the faceSceneGraph).
FaceModel readModel(const std::filesystem::path& path);

// A FAP stream by extension: .fap (readFapFile) or .fba (readFbaFile).
FapStream readFapStream(const std::filesystem::path& path);

}  // namespace mpeg4face
