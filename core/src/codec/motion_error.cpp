// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/codec/motion_error.hpp"

#include <cmath>
#include <vector>

#include "mpeg4face/codec/measure.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/model/fapu.hpp"

namespace mpeg4face {

FeaturePointMotionError featurePointMotionError(const MpegFace& face, const FapStream& original,
                                                const FapStream& decoded) {
  compareFapStreams(original, decoded);  // the same frames, or a clear error
  const FapuMeasurement fapu = measureFapu(face.faceSceneGraph);
  if (!fapu.ES0.measured) throw Error({}, 0, "ES0", "not measured: " + fapu.ES0.method);
  std::vector<std::pair<std::string, FeaturePointBinding>> points;
  for (const auto& [id, fp] : face.faceSceneGraph.featurePoints) {
    if (fp.mesh >= 0) points.emplace_back(id, fp);
  }
  if (points.empty()) throw Error({}, 0, "featurePoints", "none is bound to a mesh vertex");

  const FatEvaluator evaluator(face, fapu);
  FatState a = evaluator.neutralState(), b = evaluator.neutralState();
  FaceModel posed = face.faceSceneGraph;  // its transforms take each frame's animated ones
  const auto positions = [&](const FatState& state, std::vector<Eigen::Vector3d>& out) {
    posed.transforms = state.transforms;
    const std::vector<Eigen::Affine3d> world = posed.meshWorldMatrices();
    out.clear();
    for (const auto& [id, fp] : points) {
      out.push_back(
          world[static_cast<size_t>(fp.mesh)] *
          Eigen::Vector3d(state.coord[static_cast<size_t>(fp.mesh)].row(fp.vertex).transpose()));
    }
  };
  FeaturePointMotionError out;
  out.points = static_cast<int>(points.size());
  out.frames = static_cast<int>(original.frames.size());
  const double percent = 100.0 / fapu.ES0.value;
  FapState sa, sb;
  std::vector<Eigen::Vector3d> pa, pb;
  double sumSquares = 0;
  for (size_t k = 0; k < original.frames.size(); ++k) {
    applyFrame(sa, original.frames[k]);
    applyFrame(sb, decoded.frames[k]);
    evaluator.evaluate(sa, a);
    evaluator.evaluate(sb, b);
    positions(a, pa);
    positions(b, pb);
    for (size_t p = 0; p < points.size(); ++p) {
      const double d = (pa[p] - pb[p]).norm() * percent;
      sumSquares += d * d;
      if (d > out.maxPercentEs0) {
        out.maxPercentEs0 = d;
        out.worstPoint = points[p].first;
        out.worstFrame = original.frames[k].number;
      }
    }
  }
  if (out.frames > 0) {
    out.rmsPercentEs0 = std::sqrt(sumSquares / (double(out.frames) * double(points.size())));
  }
  return out;
}

}  // namespace mpeg4face
