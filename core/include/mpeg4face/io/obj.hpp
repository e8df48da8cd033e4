// SPDX-License-Identifier: GPL-3.0-or-later
// Wavefront OBJ reading and writing.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face {

// Wavefront OBJ: v, vt, vn, f (with any of the v/vt/vn forms, negative indices), g and o.
// Each group becomes its own mesh (faces of repeated groups are merged), holding only the
// vertices its faces use, with IndexedFaceSet::sourceIndex set to their 0-based OBJ vertex
// numbers. Faces before any g/o go to a mesh named after the file. Faces are in VRML form
// (-1 after each); a mesh keeps UVs (texCoord + texCoordIndex) only if all its corners have a
// vt, and normals only if each vertex has exactly one vn. Other statements (s, usemtl, l, ...)
// are ignored. Throws mpeg4face::Error with the line for bad numbers, a face with fewer than
// 3 corners, an index 0 or out of range, and for a file without faces.
FaceModel readObj(const std::filesystem::path& path);
// The same from text already in memory; `fileName` is used in messages and to name the
// default mesh.
FaceModel parseObj(std::string_view text, const std::string& fileName);

// The OBJ text of `model`: per mesh an `o` line with its name, its vertices in model space
// (after meshWorldMatrices) as `v` lines (shortest text that reads back to the same double),
// and its faces as 1-based `f` lines numbered across the file. UVs, normals, morph targets
// and animations are not written. Throws mpeg4face::Error for a model that fails validate()
// or a position that is not finite.
std::string objText(const FaceModel& model);
// objText written atomically (see writeFileAtomically).
void writeObj(const FaceModel& model, const std::filesystem::path& path);

}  // namespace mpeg4face
