// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for FAT validation and evaluation: the bytes build a small MpegFace (any
// indices, borders, counts and values, NaN among them) and a frame. validateMpegFace and
// FatEvaluator must refuse what the evaluator cannot run with mpeg4face::Error; whatever
// they accept must evaluate without a crash, a sanitizer report or another exception.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/evaluate.hpp"

namespace {

class Bytes {
 public:
  Bytes(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  uint8_t u8() { return pos_ < size_ ? data_[pos_++] : 0; }
  int small(int lo, int hi) { return lo + u8() % (hi - lo + 1); }
  int i16() { return static_cast<int16_t>(static_cast<uint16_t>(u8() | u8() << 8)); }
  double value() {
    const uint8_t kind = u8();
    if (kind == 255) return std::numeric_limits<double>::quiet_NaN();
    if (kind == 254) return 1e300;
    return i16() / 64.0;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace mpeg4face;
  Bytes in(data, size);
  MpegFace face;
  const int meshes = in.small(1, 2);
  for (int m = 0; m < meshes; ++m) {
    IndexedFaceSet mesh;
    mesh.name = "m" + std::to_string(m);
    mesh.coord = Points3::Zero(in.small(0, 12), 3);
    face.faceSceneGraph.addMeshWithTransform(mesh);
  }
  const int tables = in.small(0, 6);
  for (int t = 0; t < tables; ++t) {
    FaceDefTables& table = face.faceDefTables.emplace_back();
    table.fapID = in.small(-1, 70);
    table.highLevelSelect = in.small(-1, 16);
    for (int k = in.small(0, 2); k > 0; --k) {
      FaceDefMesh& m = table.faceDefMesh.emplace_back();
      m.mesh = in.small(-1, 2);
      for (int b = in.small(0, 5); b > 0; --b)
        m.intervalBorders.push_back(in.i16() * (in.u8() % 4 == 0 ? 65536 : 1));
      for (int c = in.small(0, 8); c > 0; --c) m.coordIndex.push_back(in.small(-1, 13));
      m.displacements.resize(in.small(0, 40), 3);
      for (Eigen::Index r = 0; r < m.displacements.rows(); ++r) {
        for (int c = 0; c < 3; ++c) m.displacements(r, c) = in.value();
      }
    }
    for (int k = in.small(0, 2); k > 0; --k) {
      FaceDefTransform& d = table.faceDefTransform.emplace_back();
      d.transform = in.small(-1, 2);
      d.fieldId = static_cast<FaceDefTransform::Field>(in.small(0, 4));
      d.rotationDef = {in.value(), in.value(), in.value(), in.value()};
      d.scaleDef = {in.value(), in.value(), in.value()};
      d.translationDef = {in.value(), in.value(), in.value()};
    }
  }
  FapuMeasurement fapu;
  for (auto [name, distance] : fapu.distances()) {
    auto* d = const_cast<FapuDistance*>(distance);
    if (in.u8() % 4 != 0) *d = {true, 1024.0 * (1 + in.u8()), {}, "fuzz"};
  }
  try {
    validateMpegFace(face);
  } catch (const Error&) {
    return 0;
  }
  try {
    const FatEvaluator eval(face, fapu, in.u8() % 2 ? FatStorage::Int16 : FatStorage::Float);
    FatState state = eval.neutralState();
    for (int f = in.small(1, 3); f > 0; --f) {
      FapFrame frame;
      for (int fap = 1; fap <= kFapCount; ++fap) {
        if (in.u8() % 2) frame.set(fap, in.i16() * (in.u8() % 8 == 0 ? 65536 : 1));
      }
      frame.viseme = {in.small(-1, 15), in.small(-1, 15), in.small(-1, 64), false};
      frame.expression = {
          in.small(-1, 7), in.small(-1, 64), in.small(-1, 7), in.small(-1, 64), false, false};
      try {
        eval.evaluate(frame, state);
      } catch (const Error&) {
        // frame fields out of range: a clear error, and the state stays usable
      }
    }
  } catch (const Error&) {
    // an unmeasured FAPU, a motion out of float range
  }
  return 0;
}
