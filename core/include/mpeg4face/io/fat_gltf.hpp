// SPDX-License-Identifier: GPL-3.0-or-later
// An MPEG-4 face with its Face Animation Tables as glTF 2.0: one morph target per FaceDefMesh
// interval, the tables' structure in the scene's extras, and FAP streams baked into glTF
// animations (morph weights and Transform channels). Target names, the extras schema, the
// baking rules and their limits are in docs/fat-gltf.md.
#pragma once

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "mpeg4face/fat/tables.hpp"
#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/model/fapu.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face {

// The name of the morph target of interval [lower, upper] of a table:
//   FAP 3..68  "fap<fapID>_<FAP name>[<lower>,<upper>]"   fap6_stretch_l_cornerlip[0,500]
//   FAP 1      "viseme<highLevelSelect>[<lower>,<upper>]"  viseme3[0,63]
//   FAP 2      "expression<highLevelSelect>[_<name>][<lower>,<upper>]"  expression1_joy[0,63]
// fatMorphModel appends "#2", "#3", ... to a name its mesh already has.
std::string fatTargetName(int fapID, int highLevelSelect, int lower, int upper);

// validateMpegFace (fat/evaluate.hpp), and throws mpeg4face::Error (field
// "faceDefTables[2].fapID") unless the face measures the FAPU of every FAP with a table.
void checkMpegFace(const MpegFace& face, const FapuMeasurement& fapu);

// The neutral scene graph with one morph target per FaceDefMesh interval appended to the
// targets of its mesh (tables in order, a table's FaceDefMesh in order, intervals in order):
// displacement = D_k * fapScale(fapu, fapID) for the vertices in coordIndex, zero elsewhere.
// So with weights intervalWeights(intervalBorders, value) (value: the FAP value, or the
// viseme / expression amount of fat/tables.hpp for FAP 1 / 2) the mesh is neutral + sum(weight *
// target), exactly the tables' piecewise-linear rule. Default weights of the new targets
// are 0. Checks the face first (checkMpegFace).
FaceModel fatMorphModel(const MpegFace& face, const FapuMeasurement& fapu);

// Bakes a FAP stream into an animation of fatMorphModel(face, fapu), named after the stream.
// Each frame is a key at frameTime (its number / frameRate: skipped numbers leave gaps) with
// the state resolveFapStream gives after it (values held, unsent left/right partners
// mirrored, nothing before a FAP is first sent); tables are driven by tableInput. Throws
// mpeg4face::Error for frame numbers that do not increase.
// - One morph-weight channel (LINEAR) per mesh with FAT targets: the weights of its FAT
//   targets per frame; its other targets keep their default weights.
// - One Transform channel (LINEAR; rotations are slerped) per animated field of a Transform
//   driven by FaceDefTransforms: per frame the neutral Transform with every FaceDefTransform
//   on it applied by applyFaceDefTransform in increasing fapID order.
// Low-level and high-level tables are applied independently and add up (see docs).
MorphWeightAnimation bakeFapStream(const MpegFace& face, const FapuMeasurement& fapu,
                                   const FapStream& stream);

// Writes fatMorphModel(face, fapu) with one baked animation per stream as .gltf or .glb
// (see writeGltf), plus the FAPU and the tables under scenes[0].extras.mpeg4face.
void writeFatGltf(const MpegFace& face, const FapuMeasurement& fapu,
                  std::span<const FapStream> streams, const std::filesystem::path& path);

// A face read back from writeFatGltf's output.
struct FatGltf {
  // faceSceneGraph: the file's model without the FAT morph targets (and their default
  // weights) and without animations (the baked streams are outputs of the tables; readGltf
  // gives them). Displacements are the targets divided by the FAP scale, as read from the
  // file's 32-bit floats.
  MpegFace face;
  FapuMeasurement fapu;  // the distances the targets were scaled with ("method": from glTF)
};
// Throws mpeg4face::Error naming the JSON path (e.g.
// "scenes[0].extras.mpeg4face.faceDefTables[1].faceDefMesh[0].targets") when the extras are
// missing or inconsistent with the file.
FatGltf readFatGltf(const std::filesystem::path& path);
// readFatGltf for any glTF file: std::nullopt when it holds no tables (no
// extras.mpeg4face.faceDefTables: a plain head, whose shape keys are its face); tables that
// do not read still throw.
std::optional<FatGltf> readFatGltfIfAny(const std::filesystem::path& path);
// From bytes in memory, as parseGltf.
FatGltf parseFatGltf(std::string_view bytes, const std::string& fileName,
                     const std::filesystem::path& baseDir = {});

}  // namespace mpeg4face
