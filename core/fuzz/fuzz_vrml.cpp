// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the VRML97 reader. mpeg4face::Error is the expected outcome for broken
// input; any other exception, a crash or a sanitizer report is a bug. A face the reader
// accepted must validate, be writable, and read back with the same structure: the same
// meshes (name, coordIndex) in the same order, the same transform tree, tables that refer to
// the same meshes and transforms, and the same feature points.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/vrml.hpp"

namespace {

using namespace mpeg4face;

bool sameTree(const FaceModel& a, const FaceModel& b) {
  if (a.meshes.size() != b.meshes.size() || a.transforms.size() != b.transforms.size() ||
      a.roots != b.roots) {
    return false;
  }
  for (std::size_t m = 0; m < a.meshes.size(); ++m) {
    if (a.meshes[m].coordIndex != b.meshes[m].coordIndex || a.meshes[m].name != b.meshes[m].name)
      return false;
  }
  for (std::size_t t = 0; t < a.transforms.size(); ++t) {
    if (a.transforms[t].name != b.transforms[t].name ||
        a.transforms[t].children != b.transforms[t].children ||
        a.transforms[t].meshes != b.transforms[t].meshes) {
      return false;
    }
  }
  return true;
}

bool sameTables(const std::vector<FaceDefTables>& a, const std::vector<FaceDefTables>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].fapID != b[i].fapID || a[i].highLevelSelect != b[i].highLevelSelect ||
        a[i].faceDefMesh.size() != b[i].faceDefMesh.size() ||
        a[i].faceDefTransform.size() != b[i].faceDefTransform.size()) {
      return false;
    }
    for (std::size_t j = 0; j < a[i].faceDefMesh.size(); ++j) {
      const FaceDefMesh& x = a[i].faceDefMesh[j];
      const FaceDefMesh& y = b[i].faceDefMesh[j];
      if (x.mesh != y.mesh || x.intervalBorders != y.intervalBorders ||
          x.coordIndex != y.coordIndex || x.displacements != y.displacements) {
        return false;
      }
    }
    for (std::size_t j = 0; j < a[i].faceDefTransform.size(); ++j) {
      const FaceDefTransform& x = a[i].faceDefTransform[j];
      const FaceDefTransform& y = b[i].faceDefTransform[j];
      if (x.transform != y.transform || x.fieldId != y.fieldId) return false;
    }
  }
  return true;
}

bool sameFeaturePoints(const FaceModel& a, const FaceModel& b) {
  if (a.featurePoints.size() != b.featurePoints.size()) return false;
  for (const auto& [id, x] : a.featurePoints) {
    const auto it = b.featurePoints.find(id);
    if (it == b.featurePoints.end()) return false;
    const FeaturePointBinding& y = it->second;
    if (x.mesh != y.mesh || x.vertex != y.vertex || (x.mesh < 0 && x.position != y.position))
      return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  MpegFace face;
  try {
    face = parseVrml(text, "fuzz.wrl");
  } catch (const Error&) {
    return 0;
  }
  // From here on an Error escapes and aborts: the reader let through something it should not.
  face.faceSceneGraph.validate();
  const MpegFace again = parseVrml(vrmlText(face), "again.wrl");
  if (!sameTree(face.faceSceneGraph, again.faceSceneGraph) ||
      !sameTables(face.faceDefTables, again.faceDefTables) ||
      !sameFeaturePoints(face.faceSceneGraph, again.faceSceneGraph)) {
    std::abort();
  }
  return 0;
}
