// SPDX-License-Identifier: GPL-3.0-or-later
// File helpers shared by every reader and writer, the leaf of io: readers throw
// mpeg4face::Error naming the file and the line (text formats) or the field (glTF) at fault;
// writers go through writeFileAtomically so a failed write leaves nothing half-written.
// Reading any format by its extension is io/read_any.hpp.
#pragma once

#include <filesystem>
#include <string>

namespace mpeg4face {

// Writes `contents` via a temporary file in the same folder and a rename.
void writeFileAtomically(const std::filesystem::path& path, const std::string& contents);
// Reads a whole file, throwing Error("cannot open") naming the path.
std::string readFile(const std::filesystem::path& path);
// Throws Error naming the path when it is a folder: a folder opens as an empty stream and has
// no extension, so a reader would report the wrong problem.
void rejectFolder(const std::filesystem::path& path);

}  // namespace mpeg4face
