// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the feature-point CSV reader, against small fixed models that cover
// each way a vertex number resolves: one mesh, several meshes with OBJ vertex numbers
// (sourceIndex), several meshes counted one after the other. mpeg4face::Error is the
// expected outcome for broken input; anything else is a bug.
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <utility>
#include <vector>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/feature_point_csv.hpp"

namespace {

mpeg4face::IndexedFaceSet triangle(const char* name, std::vector<int> sourceIndex) {
  mpeg4face::IndexedFaceSet mesh;
  mesh.name = name;
  mesh.coord.resize(3, 3);
  mesh.coord << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  mesh.coordIndex = {0, 1, 2, -1};
  mesh.sourceIndex = std::move(sourceIndex);
  return mesh;
}

struct Models {
  mpeg4face::FaceModel single, bySource, counted;
  Models() {
    single.addMeshWithTransform(triangle("face", {}));
    bySource.addMeshWithTransform(triangle("a", {0, 1, 2}));
    bySource.addMeshWithTransform(triangle("b", {2, 3, 4}));
    counted.addMeshWithTransform(triangle("a", {}));
    counted.addMeshWithTransform(triangle("b", {}));
  }
};

// The bindings go into the model itself and out again (a copy of the model per input cost
// more than the parse).
void parseAndCheck(std::string_view text, mpeg4face::FaceModel& model) {
  try {
    model.featurePoints = mpeg4face::parseFeaturePointCsv(text, "fuzz.csv", model).featurePoints;
  } catch (const mpeg4face::Error&) {
    return;
  }
  // Every binding the reader returns must be in range; an Error here escapes and aborts.
  model.validate();
  model.featurePoints.clear();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static Models models;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  parseAndCheck(text, models.single);
  parseAndCheck(text, models.bySource);
  parseAndCheck(text, models.counted);
  return 0;
}
