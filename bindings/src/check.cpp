// SPDX-License-Identifier: GPL-3.0-or-later
// The motion check (fat/motion_check.hpp): a head's shape keys, or a face's tables, and FAP
// streams played on them, measured against the neutral. The result is plain dicts and lists
// with the same keys as `mpeg4face check --json`. And one of its measures on its own: the
// bumps and spikes of a displacement field over a mesh (model/surface_bump.hpp).
#include <pybind11/eigen.h>
#include <pybind11/functional.h>

#include <functional>
#include <vector>

#include "bindings.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/motion_check.hpp"
#include "mpeg4face/fat/tables.hpp"
#include "mpeg4face/model/surface_bump.hpp"

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
        "flipped_triangles"_a = m.flippedTriangles, "contact_folds"_a = m.contactFolds,
        "new_intersections"_a = pairs,
        "touching_self_intersections"_a = m.touchingIntersections,
        "own_shape_faults"_a = m.ownShapeFaults,
        "spike_vertices"_a = py::array_t<int32_t>(static_cast<py::ssize_t>(m.spikeVertices.size()),
                                                  m.spikeVertices.data()),
        "bump_p99_of_peak"_a = m.bumpP99, "bump_ratio_max"_a = m.bumpRatioMax));
  }
  py::dict d("name"_a = p.name, "stream"_a = p.stream, "frame"_a = p.frame,
             "edge_ratio_max"_a = p.edgeRatioMax, "edge_ratio_p99"_a = p.edgeRatioP99,
             "normal_flips"_a = p.normalFlips, "contact_folds"_a = p.contactFolds,
             "new_self_intersections"_a = p.newIntersections,
             "touching_self_intersections"_a = p.touchingIntersections, "spikes"_a = p.spikes,
             "own_shape_faults"_a = p.ownShapeFaults,
             "bump_p99_of_peak"_a = p.bumpP99, "bump_ratio_max"_a = p.bumpRatioMax,
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
                  "notes"_a = c.notes, "own_shapes"_a = c.ownShapes);
}

}  // namespace

void bindCheck(py::module_& m) {
  m.def(
      "check_motion",
      [](py::handle face, const std::vector<FapStream>& streams, double maxEdgeRatio,
         double flipDegrees, int maxFlips, int maxIntersections, int maxSpikes, double spikeRatio,
         double spikeOfPeak, double maxLipCorner, double minLowerLip, double lipRegion,
         double lidRegion, bool ownShapes,
         std::function<void(std::size_t, std::size_t)> progress) {
        MotionLimits limits;
        limits.edgeRatioP99 = maxEdgeRatio;
        limits.flipDegrees = flipDegrees;
        limits.normalFlips = maxFlips;
        limits.newIntersections = maxIntersections;
        limits.spikeVertices = maxSpikes;
        limits.bumpOfLocalMotion = spikeRatio;
        limits.bumpOfPeak = spikeOfPeak;
        limits.lipCornerOutside = maxLipCorner;
        limits.lowerLipShare = minLowerLip;
        limits.lipRegion = lipRegion;
        limits.lidRegion = lidRegion;
        limits.ownShapes = ownShapes;
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
      "flip_degrees"_a = 120.0, "max_flips"_a = 0, "max_intersections"_a = 0, "max_spikes"_a = 0,
      "spike_ratio"_a = 0.75, "spike_of_peak"_a = 0.05, "max_lip_corner"_a = 0.02,
      "min_lower_lip"_a = 0.5, "lip_region"_a = 0.25, "lid_region"_a = 0.2,
      "own_shapes"_a = true, "progress"_a = py::none(),
      "The motion check (docs/motion-check.md) of a FaceModel with shape keys in the grammar "
      "(each key, and the streams through the tables made from them) or of an MpegFace (each "
      "table at its outermost borders, and the streams through its tables). Limits as "
      "`mpeg4face check` takes them (max_lip_corner in MW0, min_lower_lip and spike_of_peak "
      "fractions; own_shapes=False is --no-own-shapes). Returns a dict with the keys of "
      "`mpeg4face check --json`: passed, keys and frames (one dict per pose: name, stream, "
      "frame, edge_ratio_max, edge_ratio_p99, normal_flips, contact_folds, "
      "new_self_intersections, touching_self_intersections, spikes, own_shape_faults, "
      "bump_p99_of_peak, bump_ratio_max, lip_corner_outside_mw0, inner_lip_gap_mns0, failures, "
      "meshes: per mesh moved its offending_vertices (int32 array), flipped_triangles, "
      "new_intersections, spike_vertices (int32 array)), streams, neutral_self_intersections, "
      "neutral_lip_gap_mns0, lower_lip_share, failures, notes, own_shapes. progress(done, "
      "total) is called after each pose.");

  m.def(
      "surface_bump",
      [](const PyMesh& mesh, py::handle displacements, double spikeRatio, double spikeOfPeak) {
        IndexedFaceSet core = toCore(mesh, "mesh", Depth::Geometry);
        core.coordIndex = indicesToCore(mesh.coordIndex, "mesh.coord_index");
        const py::array_t<double> d = checkedRows(displacements, "displacements", 3);
        const Eigen::Map<const Points3> field(d.data(), d.shape(0), 3);
        SurfaceBump bump;
        SurfaceSpikes spikes;
        {
          py::gil_scoped_release release;
          bump = surfaceBump(weldedRings(core), field);
          spikes = surfaceSpikes(bump, spikeOfPeak, spikeRatio);
        }
        return py::dict(
            "bump"_a = bump.bump,
            "local_motion"_a = bump.localMotion, "peak"_a = bump.peak,
            "bump_p99_of_peak"_a = spikes.bumpP99,
            "bump_ratio_max"_a = spikes.localRatioMax,
            "spikes"_a = py::array_t<int32_t>(static_cast<py::ssize_t>(spikes.vertices.size()),
                                              spikes.vertices.data()));
      },
      "mesh"_a, "displacements"_a, py::kw_only(), "spike_ratio"_a = 0.75,
      "spike_of_peak"_a = 0.05,
      "The bumps of a displacement field (N, 3) over an IndexedFaceSet's triangles, as the "
      "motion check measures them (docs/motion-check.md): per vertex its bump |d_i - the mean "
      "d_j of its one-ring| (vertices at the same position welded; NaN for a vertex on no "
      "triangle) and its local_motion max(|d_i|, |d_j| over the ring), both (N,) float64; "
      "peak, the largest |d_i| on a triangle; bump_p99_of_peak over the vertices moving at "
      "least 2% of the peak; bump_ratio_max, the largest bump / local_motion where bump > "
      "spike_of_peak * peak; spikes (int32, ascending), the vertices where bump > spike_of_peak "
      "* peak and bump > spike_ratio * local_motion.");

  m.def(
      "relax_displacement",
      [](const PyMesh& mesh, py::handle displacements, int passes, py::handle where) {
        IndexedFaceSet core = toCore(mesh, "mesh", Depth::Geometry);
        core.coordIndex = indicesToCore(mesh.coordIndex, "mesh.coord_index");
        const py::array_t<double> d = checkedRows(displacements, "displacements", 3);
        Points3 field = Eigen::Map<const Points3>(d.data(), d.shape(0), 3);
        std::vector<bool> mask;
        if (!where.is_none()) {
          const auto w =
              py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(where);
          if (!w || w.ndim() != 1) throw Error({}, 0, "where", "expected a (N,) bool array");
          mask.assign(w.data(), w.data() + w.shape(0));
        }
        {
          py::gil_scoped_release release;
          relaxDisplacement(weldedRings(core), field, passes, mask);
        }
        return field;
      },
      "mesh"_a, "displacements"_a, "passes"_a, py::kw_only(), "where"_a = py::none(),
      "A displacement field (N, 3) over an IndexedFaceSet's triangles smoothed `passes` times: "
      "each vertex moved halfway to the mean of its one-ring's (vertices at the same position "
      "welded), but a vertex on no triangle or one the (N,) bool array `where` leaves out. "
      "Returns the new (N, 3) float64 array; cloning's relaxation does the same "
      "(CloneRelaxation, docs/clone.md).");
}

}  // namespace mpeg4face::python
