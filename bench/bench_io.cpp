// SPDX-License-Identifier: GPL-3.0-or-later
// How long the readers and writers take on the real MakeHuman mesh (19,158 vertices,
// 139 groups): the median of several runs, and the rate in vertices per second.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <vector>

#include "mpeg4face/io/gltf.hpp"
#include "mpeg4face/io/obj.hpp"

namespace {

double medianMilliseconds(int runs, const std::function<void()>& work) {
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    const auto start = std::chrono::steady_clock::now();
    work();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                     .count());
  }
  std::nth_element(ms.begin(), ms.begin() + runs / 2, ms.end());
  return ms[runs / 2];
}

void report(const char* what, double ms, long vertices) {
  std::printf("%-28s %9.2f ms  %7.2f M vertices/s\n", what, ms,
              static_cast<double>(vertices) / ms / 1e3);
}

}  // namespace

int main() {
  constexpr int kRuns = 9;
  const std::filesystem::path obj = MPEG4FACE_TEST_DATA "/makehuman/base.obj";
  const std::filesystem::path glb = std::filesystem::temp_directory_path() / "mpeg4face_bench.glb";

  mpeg4face::FaceModel model = mpeg4face::readObj(obj);
  long vertices = 0;
  for (const auto& mesh : model.meshes) vertices += mesh.vertexCount();
  std::printf("MakeHuman base.obj: %zu meshes, %ld vertices; median of %d runs\n",
              model.meshes.size(), vertices, kRuns);

  report("readObj", medianMilliseconds(kRuns, [&] { model = mpeg4face::readObj(obj); }), vertices);
  report("writeGltf (.glb)", medianMilliseconds(kRuns, [&] { mpeg4face::writeGltf(model, glb); }),
         vertices);
  report("readGltf (.glb)", medianMilliseconds(kRuns, [&] { model = mpeg4face::readGltf(glb); }),
         vertices);
  std::filesystem::remove(glb);
}
