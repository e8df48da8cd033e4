// SPDX-License-Identifier: GPL-3.0-or-later
// The ARKit -> FAP mapping's speed on a synthetic 26,000-vertex head with all 52 ARKit
// shapes (dense morph targets, as glTF stores them): findArkitShapes + mapArkitToFaps, and
// for information the whole arkitFapKeys (keys, tables, visemes, expressions). The head is
// tests/cpp/arkit_test_head.hpp's with 26,000 vertices; each shape moves the feature points
// near a point of the face in a direction of its own and, more weakly, every vertex (so the
// NNLS problems are full ones). Median wall-clock time of several runs.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "arkit_test_head.hpp"
#include "mpeg4face/arkit/shapes.hpp"
#include "mpeg4face/model/fapu.hpp"

using namespace mpeg4face;

namespace {

constexpr int kVertices = 26000;

double medianMs(int runs, const std::function<void()>& work) {
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    work();
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::nth_element(ms.begin(), ms.begin() + static_cast<std::ptrdiff_t>(ms.size() / 2), ms.end());
  return ms[ms.size() / 2];
}

FaceModel benchHead() {
  const int points = static_cast<int>(test::arkitTestPoints().size());
  FaceModel head = test::arkitTestHead(kVertices - points);
  IndexedFaceSet& skin = head.meshes[0];
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (std::string_view name : arkitShapeNames()) {
    // A smooth bump of motion about a random point of the face, in a random direction.
    const Eigen::RowVector3d centre = skin.coord.row(random() % static_cast<unsigned>(points));
    const Eigen::RowVector3d direction =
        Eigen::RowVector3d(unit(random), unit(random), unit(random)).normalized() * 0.005;
    MorphTarget target{std::string(name), Points3(skin.vertexCount(), 3)};
    for (int v = 0; v < skin.vertexCount(); ++v) {
      const double d = (skin.coord.row(v) - centre).norm();
      target.displacements.row(v) = direction * std::exp(-d * d / (2 * 0.02 * 0.02));
    }
    skin.morphTargets.push_back(std::move(target));
  }
  return head;
}

}  // namespace

int main() {
  const FaceModel head = benchHead();
  const FapuMeasurement fapu = measureFapu(head);
  std::size_t keys = 0;
  const double mapping = medianMs(9, [&] {
    const ArkitShapes shapes = findArkitShapes(head);
    keys = mapArkitToFaps(head, shapes, fapu).keys.size();
  });
  std::printf(
      "arkit mapping (findArkitShapes + mapArkitToFaps), %d vertices, %zu shapes: "
      "median %.1f ms of 9 runs (target <= 200 ms), %zu FAP keys\n",
      head.meshes[0].vertexCount(), arkitShapeNames().size(), mapping, keys);
  const double whole = medianMs(3, [&] { keys = arkitFapKeys(head).mapping.keys.size(); });
  std::printf("arkitFapKeys (keys, tables, 14 visemes, 6 expressions): median %.0f ms of 3 runs\n",
              whole);
  return 0;
}
