// SPDX-License-Identifier: GPL-3.0-or-later
// glTF 2.0 reading and writing with tinygltf.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face {

// glTF 2.0, .gltf (JSON + embedded or external buffers) and .glb.
//
// Reads the node hierarchy (every node becomes a Transform; TRS, or a matrix decomposed into
// TRS, where shear or projection is an Error), meshes (the triangles of every primitive
// merged into one IndexedFaceSet named after the mesh or "mesh<N>"; strips and fans become
// triangles; points and lines add their vertices but no faces), POSITION / NORMAL /
// TEXCOORD_0, morph target POSITION deltas (sparse accessors too) named by
// mesh.extras.targetNames (else "target<N>"), mesh.weights, animations of morph weights and
// of node translation / rotation / scale (TransformChannel), and the project's own data
// under scenes[s].extras.mpeg4face:
//   {"featurePoints": {"2.1": {"mesh": "<mesh name>", "vertex": 10},
//                      "9.3": {"position": [x, y, z]}}}
// (with "meshIndex" too when the name does not identify the mesh). The roots are the nodes of
// the default scene, else of scene 0, else every parentless node. UVs are flipped (v' = 1 - v)
// because glTF puts the texture origin at the top left, VRML and OBJ at the bottom left.
// The glTF mesh instanced by several nodes stays one IndexedFaceSet that several transforms
// hold. Every accessor is checked against its buffer; any problem throws Error(file, line,
// field, message) with the JSON path as field (e.g. "meshes[0].primitives[1].indices") and
// tinygltf's own messages in the message. External buffers are read only from the file's
// folder or below.
FaceModel readGltf(const std::filesystem::path& path);
// From bytes in memory (.glb when they start with the "glTF" magic, else JSON); external
// buffer URIs resolve against `baseDir` (none allowed when it is empty).
FaceModel parseGltf(std::string_view bytes, const std::string& fileName,
                    const std::filesystem::path& baseDir = {});
// Writes .gltf (buffer embedded as a base64 data: URI) or .glb (BIN chunk) by the extension
// (anything else is an Error), atomically. Polygons are fan-triangulated; a mesh without
// faces is written as points. Where texCoordIndex gives a vertex several UVs (seams), the
// vertex is split into one glTF vertex per (vertex, UV) pair, with the original number kept
// in the `_MPEG4FACE_VERTEX` attribute (SCALAR FLOAT; glTF forbids UNSIGNED_INT attributes)
// so that readGltf welds them back into the same vertices, faces and texCoordIndex layout.
// glTF has no centre: a Transform with one becomes a node T + C, R, S whose only child, a
// helper node translated by -C, holds its meshes and children (so rotating or scaling the
// node, by an animation or in a modeller, stays about the centre; its translation channels
// get + C). A Transform holding several meshes gets one child node per mesh. Helper nodes
// are marked in their extras so readGltf folds them back. Normals are normalized (glTF requires
// unit length). Animation channels of a mesh no transform holds cannot be written (glTF animates
// nodes): Error.
void writeGltf(const FaceModel& model, const std::filesystem::path& path);

}  // namespace mpeg4face
