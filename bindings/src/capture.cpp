// SPDX-License-Identifier: GPL-3.0-or-later
// Face captures: Live Link Face CSV, ARKit weights to FAP streams and back (io/livelink.hpp,
// arkit/capture.hpp).
#include "mpeg4face/arkit/capture.hpp"

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <memory>

#include "bindings.hpp"
#include "mpeg4face/io/livelink.hpp"

namespace mpeg4face::python {
namespace {

using namespace pybind11::literals;
using Path = std::filesystem::path;

// A prepared face, or one prepared from a FaceModel for this call.
std::shared_ptr<const ArkitCaptureFace> captureFace(py::handle face, const char* function) {
  if (py::isinstance<ArkitCaptureFace>(face)) {
    return face.cast<std::shared_ptr<ArkitCaptureFace>>();
  }
  const FaceModel head = toCore(asFaceModel(face, function));
  py::gil_scoped_release release;
  return std::make_shared<const ArkitCaptureFace>(prepareArkitCaptureFace(head));
}

}  // namespace

void bindCapture(py::module_& m) {
  m.def(
      "livelink_channel_names",
      [] {
        py::list out;
        for (std::string_view name : liveLinkChannelNames()) out.append(toPy(name));
        return out;
      },
      "The 61 channels of a Live Link Face CSV in its order: the 52 ARKit weights, then "
      "HeadYaw, HeadPitch, HeadRoll and each eye's yaw, pitch, roll.");

  py::class_<LiveLinkCapture> capture(
      m, "LiveLinkCapture",
      "A face capture as Live Link Face records it: per frame a time (seconds) and 61 channel "
      "values (52 ARKit weights in 0..1, 9 angles in radians).");
  capture.def(py::init<>());
  capture.def_readwrite("channels", &LiveLinkCapture::channels, "The 61 channel names.");
  capture.def_property(
      "times",
      [](const LiveLinkCapture& c) {
        return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(
            c.times.data(), static_cast<Eigen::Index>(c.times.size())));
      },
      [](LiveLinkCapture& c, const Eigen::VectorXd& t) { c.times.assign(t.begin(), t.end()); },
      "(N,) seconds since the timecode's midnight.");
  capture.def_readwrite("values", &LiveLinkCapture::values, "(N, 61) channel values.");
  capture.def_readwrite("frame_rate", &LiveLinkCapture::frameRate,
                        "The timecode's frame rate (found from the timecodes, 60 when in doubt).");
  capture.def_readonly("clamped_weights", &LiveLinkCapture::clampedWeights,
                       "How many weights outside 0..1 were clamped.");
  capture.def_readonly("warnings", &LiveLinkCapture::warnings);
  capture.def("__len__", &LiveLinkCapture::frameCount);
  capture.def("__repr__", [](const LiveLinkCapture& c) {
    return "<LiveLinkCapture " + std::to_string(c.frameCount()) + " frames at " +
           std::to_string(c.frameRate) + " fps>";
  });
  m.def("read_livelink_csv", &readLiveLinkCsv, "path"_a,
        "Reads a Live Link Face CSV; mpeg4face.Error names the line and column of bad input; "
        "weights outside 0..1 are clamped (counted in clamped_weights, one warning).",
        py::call_guard<py::gil_scoped_release>());
  m.def(
      "write_livelink_csv",
      [](const LiveLinkCapture& c, const Path& path) { writeLiveLinkCsv(path, c); }, "capture"_a,
      "path"_a, "Writes the capture in Live Link Face's layout, atomically.",
      py::call_guard<py::gil_scoped_release>());

  py::class_<ArkitCaptureFace, std::shared_ptr<ArkitCaptureFace>> face(
      m, "ArkitCaptureFace",
      "A face prepared for arkit_capture_to_faps and faps_to_arkit (docs/arkit.md, "
      "Captures): its face area, the ARKit shapes' and the FAPs' motion there.");
  face.def_property_readonly("has_shape", [](const ArkitCaptureFace& f) {
    return std::vector<bool>(f.hasShape.begin(), f.hasShape.end());
  });
  face.def_property_readonly(
      "area",
      [](const ArkitCaptureFace& f) {
        py::array_t<int32_t> out({static_cast<py::ssize_t>(f.area.size()), py::ssize_t{2}});
        for (std::size_t i = 0; i < f.area.size(); ++i) {
          out.mutable_at(static_cast<py::ssize_t>(i), 0) = f.area[i].first;
          out.mutable_at(static_cast<py::ssize_t>(i), 1) = f.area[i].second;
        }
        return out;
      },
      "(V, 2) mesh and vertex of each face-area vertex.");
  face.def_readonly("shape_motion", &ArkitCaptureFace::shapeMotion,
                    "(3V, 52) each ARKit shape's model-space motion over the area.");
  face.def_readonly("fap_motion", &ArkitCaptureFace::fapMotion,
                    "(3V, C) each FAP side's motion per FAPU over the area.");
  face.def_readonly("column_fap", &ArkitCaptureFace::columnFap);
  face.def_readonly("column_sign", &ArkitCaptureFace::columnSign);
  face.def_readonly("column_reach", &ArkitCaptureFace::columnReach,
                    "How far each column's FAP value stays linear (inf: without end).");
  face.def_readonly("from_tables", &ArkitCaptureFace::fromTables,
                    "True if the FAP columns come from the face's FAP keys.");
  face.def_readonly("warnings", &ArkitCaptureFace::warnings);
  m.def(
      "prepare_arkit_capture_face",
      [](py::handle head) {
        return std::const_pointer_cast<ArkitCaptureFace>(
            captureFace(head, "prepare_arkit_capture_face"));
      },
      "head"_a,
      "Prepares a head with ARKit shapes (and FAP keys) once for many captures or streams.");
  m.def(
      "arkit_capture_to_faps",
      [](const LiveLinkCapture& c, py::handle head, double fps) {
        const auto prepared = captureFace(head, "arkit_capture_to_faps");
        py::gil_scoped_release release;
        return arkitCaptureToFaps(c, *prepared, {fps, {}});
      },
      "capture"_a, "head"_a, "fps"_a = 25.0,
      "ARKit weights -> a FAP stream at fps: per frame the FAP values whose motion best fits "
      "the weights' motion of the head's face area; 23-26 and 48-50 from the angles.");
  m.def(
      "faps_to_arkit",
      [](const FapStream& stream, py::handle head) {
        const auto prepared = captureFace(head, "faps_to_arkit");
        py::gil_scoped_release release;
        return fapsToArkit(stream, *prepared);
      },
      "stream"_a, "head"_a,
      "A FAP stream -> ARKit weights in 0..1 (bounded least squares per frame) and angles, as "
      "a LiveLinkCapture.");
  m.def(
      "capture_fidelity",
      [](const LiveLinkCapture& c, py::handle head, const FapStream& stream) {
        const auto prepared = captureFace(head, "capture_fidelity");
        CaptureFidelity f;
        {
          py::gil_scoped_release release;
          f = measureCaptureFidelity(c, *prepared, stream);
        }
        py::list spikes;
        for (const auto& [mesh, vertex] : f.spikes) spikes.append(py::make_tuple(mesh, vertex));
        return py::dict("frames"_a = f.frames, "error_mean"_a = f.errorMean,
                        "error_p95"_a = f.errorP95, "bump_p99"_a = f.bumpP99,
                        "reference_bump_p99"_a = f.referenceBumpP99,
                        "point_bump_p99"_a = f.pointBumpP99,
                        "reference_point_bump_p99"_a = f.referencePointBumpP99,
                        "bump_max"_a = f.bumpMax, "reference_bump_max"_a = f.referenceBumpMax,
                        "spikes"_a = spikes);
      },
      "capture"_a, "head"_a, "stream"_a,
      "How `stream` (made from `capture`) plays through the head's tables against the capture "
      "through its ARKit shapes, relative to each frame's peak motion (docs/arkit.md, "
      "Fidelity): error mean / p95, bump p99 (all, near feature points) and max for both, "
      "and the spike vertices as (mesh, vertex).");
}

}  // namespace mpeg4face::python
