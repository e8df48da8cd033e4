// SPDX-License-Identifier: GPL-3.0-or-later
// File reading and writing. The GIL is released while the core reads, parses and writes.
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <utility>

#include "bindings.hpp"
#include "mpeg4face/io/feature_point_csv.hpp"
#include "mpeg4face/io/gltf.hpp"
#include "mpeg4face/io/obj.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "mpeg4face/io/wfm.hpp"

namespace mpeg4face::python {
namespace {

using namespace pybind11::literals;
using Path = std::filesystem::path;

// Runs `read(path)` without the GIL and returns its FaceModel as a Python FaceModel.
template <typename Read>
py::object readFaceModel(Read read, const Path& path) {
  FaceModel model;
  {
    py::gil_scoped_release release;
    model = read(path);
  }
  return py::cast(fromCore(std::move(model)));
}

void bindCandide(py::module_& m) {
  py::class_<PyCandideUnit> unit(m, "CandideUnit",
                                 "A CANDIDE animation or shape unit: a sparse displacement of "
                                 "some vertices at unit value 1.");
  unit.def(py::init([](std::string name, py::handle fap, std::string fapu, py::object vertices,
                       py::object displacements) {
             PyCandideUnit u;
             u.name = std::move(name);
             u.fap = checkedInt(fap, "CandideUnit.fap");
             u.fapu = std::move(fapu);
             if (!vertices.is_none()) u.vertices = checkedIndices(vertices, "CandideUnit.vertices");
             if (!displacements.is_none()) {
               u.displacements = checkedRows(displacements, "CandideUnit.displacements", 3);
             }
             return u;
           }),
           "name"_a = "", "fap"_a = 0, "fapu"_a = "", "vertices"_a = py::none(),
           "displacements"_a = py::none());
  unit.def_property(
      "name", [](const PyCandideUnit& u) { return toPy(u.name); },
      [](PyCandideUnit& u, std::string v) { u.name = std::move(v); },
      "The unit's comment line, e.g. \"FAP 3 open_jaw\" or \"Head height\".");
  unit.def_readwrite("fap", &PyCandideUnit::fap, "FAP number for MPEG-4 units, else 0.");
  unit.def_property(
      "fapu", [](const PyCandideUnit& u) { return toPy(u.fapu); },
      [](PyCandideUnit& u, std::string v) { u.fapu = std::move(v); },
      "FAPU name (\"MNS\", \"ES\", ...) for MPEG-4 units, else \"\".");
  unit.def_property(
      "vertices", [](const PyCandideUnit& u) { return u.vertices; },
      [](PyCandideUnit& u, py::handle v) {
        u.vertices = checkedIndices(v, "CandideUnit.vertices");
      },
      "1-D int32 array: the vertices the unit moves.");
  unit.def_property(
      "displacements", [](const PyCandideUnit& u) { return u.displacements; },
      [](PyCandideUnit& u, py::handle v) {
        u.displacements = checkedRows(v, "CandideUnit.displacements", 3);
      },
      "(len(vertices), 3) float64 displacements, one row per entry of vertices.");
  unit.def("__repr__", [](const PyCandideUnit& u) {
    return "<CandideUnit '" + std::string(toPy(u.name)) +
           "': " + std::to_string(u.vertices.shape(0)) + " vertices>";
  });

  py::class_<PyCandideModel> model(m, "CandideModel",
                                   "A CANDIDE .wfm file: its mesh (in a FaceModel) plus "
                                   "animation and shape units.");
  model.def(py::init([](py::object faceModel, py::object animationUnits, py::object shapeUnits) {
              PyCandideModel c;
              c.model = faceModel.is_none() ? py::cast(PyFaceModel()) : faceModel;
              asFaceModel(c.model, "CandideModel.model");
              c.animationUnits = checkedObjectList<PyCandideUnit>(
                  animationUnits, "CandideModel.animation_units", "CandideUnit");
              c.shapeUnits = checkedObjectList<PyCandideUnit>(
                  shapeUnits, "CandideModel.shape_units", "CandideUnit");
              return c;
            }),
            "model"_a = py::none(), "animation_units"_a = py::none(), "shape_units"_a = py::none());
  model.def_property(
      "model", [](const PyCandideModel& c) { return c.model; },
      [](PyCandideModel& c, py::object v) {
        asFaceModel(v, "CandideModel.model");
        c.model = std::move(v);
      },
      "FaceModel with one triangle mesh named \"candide3\".");
  model.def_property(
      "animation_units", [](const PyCandideModel& c) { return c.animationUnits; },
      [](PyCandideModel& c, py::handle v) {
        c.animationUnits =
            checkedObjectList<PyCandideUnit>(v, "CandideModel.animation_units", "CandideUnit");
      },
      "list of CandideUnit: the animation units (MPEG-4 FAP units among them).");
  model.def_property(
      "shape_units", [](const PyCandideModel& c) { return c.shapeUnits; },
      [](PyCandideModel& c, py::handle v) {
        c.shapeUnits =
            checkedObjectList<PyCandideUnit>(v, "CandideModel.shape_units", "CandideUnit");
      },
      "list of CandideUnit: the shape units.");
  model.def("__repr__", [](const PyCandideModel& c) {
    return "<CandideModel: " + std::to_string(c.animationUnits.size()) + " animation units, " +
           std::to_string(c.shapeUnits.size()) + " shape units>";
  });
}

void bindReadersAndWriters(py::module_& m) {
  m.def(
      "read_model",
      [](const Path& path) {
        return readFaceModel([](const Path& p) { return readModel(p); }, path);
      },
      "path"_a,
      "Reads any supported model by extension (.gltf, .glb, .obj, .wfm); raises "
      "mpeg4face.Error naming the file and line or field at fault.");
  m.def(
      "read_gltf",
      [](const Path& path) {
        return readFaceModel([](const Path& p) { return readGltf(p); }, path);
      },
      "path"_a,
      "Reads glTF 2.0 (.gltf or .glb): node hierarchy, meshes, morph targets with names, "
      "default weights, morph-weight animations and the feature points stored by write_gltf.");
  m.def(
      "write_gltf",
      [](py::handle model, const Path& path) {
        const FaceModel core = toCore(asFaceModel(model, "write_gltf"));
        py::gil_scoped_release release;
        writeGltf(core, path);
      },
      "model"_a, "path"_a,
      "Writes .gltf (embedded buffer) or .glb by the extension, atomically. Raises "
      "mpeg4face.Error for a model that FaceModel.validate() rejects or that glTF cannot hold "
      "(e.g. an animation channel with the wrong number of weights).");
  m.def(
      "read_obj",
      [](const Path& path) {
        return readFaceModel([](const Path& p) { return readObj(p); }, path);
      },
      "path"_a,
      "Reads Wavefront OBJ; each group becomes its own mesh with source_index set to the OBJ "
      "vertex numbers.");
  m.def(
      "read_wfm",
      [](const Path& path) {
        CandideModel candide;
        {
          py::gil_scoped_release release;
          candide = readWfm(path);
        }
        return py::cast(fromCore(std::move(candide)));
      },
      "path"_a, "Reads a CANDIDE .wfm file as a CandideModel.");
  m.def(
      "candide_to_face_model",
      [](const PyCandideModel& candide) {
        const CandideModel core = toCore(candide);
        FaceModel model;
        {
          py::gil_scoped_release release;
          model = candideToFaceModel(core);
        }
        return py::cast(fromCore(std::move(model)));
      },
      "candide"_a,
      "The CANDIDE model as a FaceModel whose mesh carries every animation unit as a morph "
      "target named after the unit (dense displacements at unit value 1).");
  m.def(
      "name_candide_fap_units",
      [](py::handle model, const PyCandideModel& candide) {
        FaceModel core = toCore(asFaceModel(model, "name_candide_fap_units"));
        const CandideModel source = toCore(candide);
        {
          py::gil_scoped_release release;
          nameCandideFapUnits(core, source);
        }
        return py::cast(fromCore(std::move(core)));
      },
      "model"_a, "candide"_a,
      "candide_to_face_model's model (with its feature points bound) with CANDIDE's MPEG-4 "
      "animation units renamed and scaled into the shape-key grammar (fap<N>_<name>@1000, and "
      "@-1000 for a bidirectional FAP; docs/fat.md), as fat generate reads a .wfm. Returns a "
      "new FaceModel.");
  m.def(
      "read_feature_point_csv",
      [](const Path& path, py::handle model) {
        const FaceModel core = toCore(asFaceModel(model, "read_feature_point_csv"));
        FeaturePointCsv csv;
        {
          py::gil_scoped_release release;
          csv = readFeaturePointCsv(path, core);
        }
        py::dict points;
        for (const auto& [id, binding] : csv.featurePoints) {
          points[toPy(id)] = py::cast(fromCore(binding));
        }
        py::list warnings;
        for (const std::string& warning : csv.warnings) warnings.append(toPy(warning));
        return py::make_tuple(points, warnings);
      },
      "path"_a, "model"_a,
      "Reads feature-point bindings for `model` from CSV (rows `fp,vertex`, `fp,mesh,vertex` "
      "or `fp,x,y,z`, or named columns). Returns (dict id -> FeaturePointBinding, list of "
      "warning strings); the model is not changed (use model.feature_points.update(...)).");
}

}  // namespace

void bindIo(py::module_& m) {
  bindCandide(m);
  bindReadersAndWriters(m);
}

}  // namespace mpeg4face::python
