// SPDX-License-Identifier: GPL-3.0-or-later
// Names the glTF reader and writer agree on (see docs/file-formats.md).
#pragma once

namespace mpeg4face::gltf_names {

// Written by writeGltf next to the split vertices: each glTF vertex's IndexedFaceSet vertex,
// as SCALAR FLOAT (glTF does not allow UNSIGNED_INT vertex attributes). The reader also takes
// UNSIGNED_BYTE / UNSIGNED_SHORT / UNSIGNED_INT.
inline constexpr const char* kVertexAttribute = "_MPEG4FACE_VERTEX";
// Our key under extras (scene: feature points and FaceDefTables; helper nodes: meshInstance,
// center).
inline constexpr const char* kExtrasKey = "mpeg4face";

}  // namespace mpeg4face::gltf_names
