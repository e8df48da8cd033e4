// SPDX-License-Identifier: GPL-3.0-or-later
// File helpers shared by every reader and writer. Readers throw mpeg4face::Error naming the
// file and the line (text formats) or the field (glTF) at fault; writers go through
// writeFileAtomically so a failed write leaves nothing half-written.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "mpeg4face/face_model.hpp"
#include "mpeg4face/fap_stream.hpp"

namespace mpeg4face {

// Any supported model by extension: .gltf, .glb, .obj, .wfm, .wrl (the faceSceneGraph).
FaceModel readModel(const std::filesystem::path& path);

// A FAP stream by extension: .fap (readFapFile) or .fba (readFbaFile).
FapStream readFapStream(const std::filesystem::path& path);

// Writes `contents` via a temporary file in the same folder and a rename.
void writeFileAtomically(const std::filesystem::path& path, const std::string& contents);
// Reads a whole file, throwing Error("cannot open") naming the path.
std::string readFile(const std::filesystem::path& path);

}  // namespace mpeg4face
