// SPDX-License-Identifier: GPL-3.0-or-later
// How long `landmarks` and `animate` take on a 50,000-vertex head, on one core (nothing in
// them runs threads): the MakeHuman sample (samples/build.sh makes it) without its feature
// points, subdivided twice and decimated back to about 50,000 vertices, its points found
// from the ICT sample; then the ICT sample's shapes cloned onto it and the demo's sentence
// checked through its tables. Medians of several runs, and the ratio to the 4,352-vertex
// head as it is, measured in the same process.
//   bench_landmarks [SAMPLES_DIR]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <vector>

#include "mpeg4face/clone/clone.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/motion_check.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "mpeg4face/model/landmarks.hpp"
#include "mpeg4face/model/mesh_resample.hpp"

namespace {

using namespace mpeg4face;

double medianSeconds(int runs, const std::function<void()>& work) {
  std::vector<double> s;
  for (int i = 0; i < runs; ++i) {
    const auto start = std::chrono::steady_clock::now();
    work();
    s.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::nth_element(s.begin(), s.begin() + runs / 2, s.end());
  return s[static_cast<std::size_t>(runs / 2)];
}

int vertexCount(const FaceModel& m) {
  int n = 0;
  for (const IndexedFaceSet& mesh : m.meshes) n += mesh.vertexCount();
  return n;
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path dir = argc > 1 ? argv[1] : MPEG4FACE_SAMPLES;
  try {
    const FaceModel ict = readModel(dir / "ict_head.glb");
    FaceModel small = neutralFaceModel(readModel(dir / "makehuman_head.glb"));
    small.featurePoints.clear();
    FaceModel large = subdivideFaceModel(small, 2);
    large = decimateFaceModel(large, 50000.0 / vertexCount(large));
    const ShapeKeyCopies source = shapesFromShapeKeys(ict);
    const FaceModel sourceNeutral = neutralFaceModel(ict);
    const std::vector<FapStream> sentence{readFapStream(dir / "streams" / "hello.fap")};
    std::printf("template: ICT sample, %d vertices; %zu shapes to clone\n", vertexCount(ict),
                source.copies.size());
    double base[2] = {0, 0};
    for (const FaceModel* head : {&small, &large}) {
      LandmarkResult found;
      const double find = medianSeconds(3, [&] { found = findFeaturePoints(*head, ict); });
      FaceModel target = *head;
      for (const auto& [id, p] : found.points) target.featurePoints[id] = p.binding;
      ClonedFace cloned;
      CloneOptions options;  // as animate clones: relaxed
      options.relaxation = CloneRelaxation{};
      const double clone = medianSeconds(
          3, [&] { cloned = cloneFace(sourceNeutral, source.copies, target, options); });
      const double check = medianSeconds(3, [&] { checkMotion(cloned.face, sentence); });
      const double animate = find + clone + check;
      if (head == &small) {
        base[0] = find;
        base[1] = animate;
      }
      std::printf("MakeHuman head, %d vertices: landmarks %.2f s (%.1fx), animate %.2f s "
                  "(%.1fx: points, clone %.2f s, check of the 190-frame sentence %.2f s), "
                  "medians of 3\n",
                  vertexCount(*head), find, find / base[0], animate, animate / base[1], clone,
                  check);
    }
  } catch (const Error& e) {
    std::fprintf(stderr, "bench_landmarks: %s (run samples/build.sh first)\n", e.what());
    return 1;
  }
}
