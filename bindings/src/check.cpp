// SPDX-License-Identifier: GPL-3.0-or-later
// The motion check (fat/motion_check.hpp): a head's shape keys, or a face's tables, and FAP
// streams played on them, measured against the neutral. The result is plain dicts and lists
// with the same keys as `mpeg4face check --json`.
#include <pybind11/functional.h>

#include <functional>
#include <vector>

#include "bindings.hpp"
#include "mpeg4face/fat/motion_check.hpp"
#include "mpeg4face/fat/tables.hpp"

namespace mpeg4face::python {
namespace {

using namespace pybind11::literals;

py::object optional(const std::optional<double>& v) {
  return v ? py::object(py::float_(*v)) : py::object(py::none());
}

py::dict poseDict(const PoseMotion& p) {
  py::list meshes;
  for (const MeshMotion& m : p.meshes) {
    py::list pairs;
    for (const auto& [a, b] : m.newIntersections) pairs.append(py::make_tuple(a, b));
    meshes.append(py::dict(
        "mesh"_a = m.mesh, "moved_edges"_a = m.movedEdges, "edge_ratio_max"_a = m.edgeRatioMax,
        "edge_ratio_p99"_a = m.edgeRatioP99,
        "offending_vertices"_a = py::array_t<int32_t>(
            static_cast<py::ssize_t>(m.offendingVertices.size()), m.offendingVertices.data()),
        "flipped_triangles"_a = m.flippedTriangles, "new_intersections"_a = pairs,
        "touching_self_intersections"_a = m.touchingIntersections));
  }
  py::dict d("name"_a = p.name, "stream"_a = p.stream, "frame"_a = p.frame,
             "edge_ratio_max"_a = p.edgeRatioMax, "edge_ratio_p99"_a = p.edgeRatioP99,
             "normal_flips"_a = p.normalFlips, "new_self_intersections"_a = p.newIntersections,
             "touching_self_intersections"_a = p.touchingIntersections,
             "lip_corner_outside_mw0"_a = optional(p.lipCornerOutside),
             "inner_lip_gap_mns0"_a = optional(p.innerLipGap), "failures"_a = p.failures);
  d["meshes"] = meshes;
  return d;
}

py::dict checkDict(const MotionCheck& c) {
  py::list keys, frames, streams;
  for (const PoseMotion& p : c.keys) keys.append(poseDict(p));
  for (const PoseMotion& p : c.frames) frames.append(poseDict(p));
  for (const StreamMotion& s : c.streams) {
    streams.append(py::dict("name"_a = s.name, "frames"_a = s.frames,
                            "inner_lip_gap_min_mns0"_a = s.innerLipGapMin,
                            "inner_lip_gap_max_mns0"_a = s.innerLipGapMax));
  }
  return py::dict("passed"_a = c.passed(), "keys"_a = keys, "frames"_a = frames,
                  "streams"_a = streams, "neutral_self_intersections"_a = c.neutralIntersections,
                  "neutral_lip_gap_mns0"_a = optional(c.neutralLipGap),
                  "lower_lip_share"_a = optional(c.lowerLipShare), "failures"_a = c.failures,
                  "notes"_a = c.notes);
}

}  // namespace

void bindCheck(py::module_& m) {
  m.def(
      "check_motion",
      [](py::handle face, const std::vector<FapStream>& streams, double maxEdgeRatio,
         double flipDegrees, int maxFlips, int maxIntersections, double maxLipCorner,
         double minLowerLip, double lipRegion, double lidRegion,
         std::function<void(std::size_t, std::size_t)> progress) {
        const MotionLimits limits{maxEdgeRatio, flipDegrees, maxFlips,     maxIntersections,
                                  lipRegion,    lidRegion,   maxLipCorner, minLowerLip};
        MotionProgress report;
        if (progress) {
          report = [&progress](std::size_t done, std::size_t total) {
            py::gil_scoped_acquire acquire;
            progress(done, total);
          };
        }
        MotionCheck result;
        if (py::isinstance<MpegFace>(face)) {
          const MpegFace& mpeg = face.cast<const MpegFace&>();
          py::gil_scoped_release release;
          result = checkMotion(mpeg, streams, limits, report);
        } else {
          const FaceModel head = toCore(asFaceModel(face, "check_motion"));
          py::gil_scoped_release release;
          result = checkMotion(head, streams, limits, report);
        }
        return checkDict(result);
      },
      "face"_a, "streams"_a = std::vector<FapStream>{}, py::kw_only(), "max_edge_ratio"_a = 2.0,
      "flip_degrees"_a = 120.0, "max_flips"_a = 0, "max_intersections"_a = 0,
      "max_lip_corner"_a = 0.02, "min_lower_lip"_a = 0.5, "lip_region"_a = 0.25,
      "lid_region"_a = 0.2, "progress"_a = py::none(),
      "The motion check (docs/motion-check.md) of a FaceModel with shape keys in the grammar "
      "(each key, and the streams through the tables made from them) or of an MpegFace (each "
      "table at its outermost borders, and the streams through its tables). Limits as "
      "`mpeg4face check` takes them (max_lip_corner in MW0, min_lower_lip a fraction). Returns "
      "a dict with the keys of `mpeg4face check --json`: passed, keys and frames (one dict per "
      "pose: name, stream, frame, edge_ratio_max, edge_ratio_p99, normal_flips, "
      "new_self_intersections, touching_self_intersections, lip_corner_outside_mw0, "
      "inner_lip_gap_mns0, failures, meshes: per mesh moved its offending_vertices (int32 "
      "array), flipped_triangles, new_intersections), streams, neutral_self_intersections, "
      "neutral_lip_gap_mns0, lower_lip_share, failures, notes. progress(done, total) is "
      "called after each pose.");
}

}  // namespace mpeg4face::python
