// SPDX-License-Identifier: GPL-3.0-or-later
// MPEG-4 faces with their Face Animation Tables: the shape-key naming grammar, tables from
// shape keys, VRML and glTF files, animating a face with a FAP stream, Facial Motion Cloning
// and FAP Interpolation Tables. MpegFace and FitTable wrap the core structs (their contents
// are read through properties that copy); models go in and out as FaceModel mirrors.
#include <pybind11/functional.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>

#include "bindings.hpp"
#include "mpeg4face/clone/clone.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/fat/generate.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/fat/tables.hpp"
#include "mpeg4face/fit/fit.hpp"
#include "mpeg4face/fit/json.hpp"
#include "mpeg4face/fit/presets.hpp"
#include "mpeg4face/io/fat_gltf.hpp"
#include "mpeg4face/io/vrml.hpp"

namespace mpeg4face::python {
namespace {

using namespace pybind11::literals;
using Path = std::filesystem::path;
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

py::array_t<double> pointsToNumpy(const Points3& p) {
  py::array_t<double> out({static_cast<py::ssize_t>(p.rows()), py::ssize_t{3}});
  std::copy(p.data(), p.data() + p.size(), out.mutable_data());  // both row-major
  return out;
}

py::list stringList(const std::vector<std::string>& items) {
  py::list out;
  for (const std::string& s : items) out.append(toPy(s));
  return out;
}

// One table's outline, for reports: which FAP, which meshes and how many vertices.
py::dict tableSummary(const FaceDefTables& t) {
  py::dict d;
  d["fap"] = t.fapID;
  d["select"] = t.fapID <= 2 ? t.highLevelSelect : 0;
  py::list meshes;
  for (const FaceDefMesh& m : t.faceDefMesh) {
    meshes.append(py::dict("mesh"_a = m.mesh, "vertices"_a = m.coordIndex.size(),
                           "interval_borders"_a = m.intervalBorders));
  }
  d["meshes"] = meshes;
  py::list transforms;
  for (const FaceDefTransform& x : t.faceDefTransform) transforms.append(x.transform);
  d["transforms"] = transforms;
  return d;
}

// A shape as Python sees it: per mesh that moves, its vertices and their displacements (what
// Blender writes a shape key from), and the Transforms (empty: the neutral's).
py::dict shapeToPy(FaceShape&& shape) {
  py::list meshes;
  for (const MeshDisplacement& d : shape.meshes) {
    meshes.append(py::dict("mesh"_a = d.mesh, "vertices"_a = indicesFromCore(d.vertices),
                           "displacement"_a = pointsToNumpy(d.displacement)));
  }
  py::list transforms;
  for (Transform& t : shape.transforms) transforms.append(py::cast(fromCore(std::move(t))));
  return py::dict("name"_a = toPy(shape.name), "fap"_a = shape.fapID,
                  "select"_a = shape.fapID <= 2 ? shape.highLevelSelect : 0,
                  "amplitude"_a = shape.amplitude, "meshes"_a = meshes,
                  "transforms"_a = transforms);
}

// The source of a clone: a FaceModel with shape keys in the grammar, or an MpegFace.
std::pair<FaceModel, std::vector<FaceShape>> cloneSource(py::handle source) {
  if (py::isinstance<MpegFace>(source)) {
    const MpegFace& face = source.cast<const MpegFace&>();
    return {face.faceSceneGraph, shapesFromFaceDefTables(face, measureFapu(face.faceSceneGraph))};
  }
  const FaceModel model = toCore(asFaceModel(source, "clone_face"));
  return {neutralFaceModel(model), shapesFromShapeKeys(model).copies};
}

void bindNames(py::module_& m) {
  m.def(
      "parse_shape_key_name",
      [](const std::string& name) -> py::object {
        const std::optional<ShapeKeyName> key = parseShapeKeyName(name);
        if (!key) return py::none();
        return py::dict("fap"_a = key->fapID, "select"_a = key->highLevelSelect,
                        "amplitude"_a = key->amplitude, "label"_a = toPy(key->label));
      },
      "name"_a,
      "A shape-key name in the grammar (fap<N>[_<label>]@<value>, viseme<N>[_<label>], "
      "expression<N>[_<label>][@<intensity>]; docs/fat.md) as a dict of fap (1 viseme, 2 "
      "expression), select, amplitude and label; None for a name that is not ours; "
      "mpeg4face.Error, with the grammar, for one that starts so but is malformed.");
  m.def(
      "format_shape_key_name",
      [](int fap, int amplitude, int select, const std::string& label) {
        return formatShapeKeyName({fap, select, amplitude, label});
      },
      "fap"_a, "amplitude"_a = 63, "select"_a = 0, "label"_a = "",
      "The grammar's name of a FAP (3..68) at an amplitude, a viseme (fap 1, select 1..14) or "
      "an expression (fap 2, select 1..6, amplitude its intensity).");
}

void bindMpegFace(py::module_& m) {
  py::class_<MpegFace> cls(m, "MpegFace",
                           "An animatable MPEG-4 face: its neutral scene graph (with feature "
                           "points) and the FaceDefTables that animate it, and possibly a FAP "
                           "Interpolation Table.");
  cls.def_property_readonly(
      "scene_graph", [](const MpegFace& f) { return fromCore(FaceModel(f.faceSceneGraph)); },
      "The neutral face as a FaceModel (a copy).");
  cls.def_property_readonly(
      "tables",
      [](const MpegFace& f) {
        py::list out;
        for (const FaceDefTables& t : f.faceDefTables) out.append(tableSummary(t));
        return out;
      },
      "One dict per FaceDefTables: fap, select (viseme / expression), meshes (mesh, vertices, "
      "interval_borders) and transforms.");
  cls.def_property(
      "fit", [](const MpegFace& f) { return f.fit; },
      [](MpegFace& f, std::optional<FitTable> t) { f.fit = std::move(t); },
      "The Face node's FAP Interpolation Table, or None.");
  cls.def(
      "validate", [](const MpegFace& f) { validateMpegFace(f); },
      "Raises mpeg4face.Error naming the first broken table.");
  cls.def("__repr__", [](const MpegFace& f) {
    return "<MpegFace " + std::to_string(f.faceSceneGraph.meshes.size()) + " meshes, " +
           std::to_string(f.faceDefTables.size()) + " tables>";
  });

  m.def(
      "generate_face",
      [](py::handle model, double threshold, std::optional<double> absoluteThreshold) {
        const FaceModel core = toCore(asFaceModel(model, "generate_face"));
        ShapeKeyFace generated;
        {
          py::gil_scoped_release release;
          generated = faceFromShapeKeys(core, {threshold, absoluteThreshold});
        }
        return py::dict("face"_a = std::move(generated.face), "copies"_a = generated.copies,
                        "warnings"_a = stringList(generated.warnings),
                        "ignored"_a = stringList(generated.ignored));
      },
      "model"_a, "threshold"_a = 0.01, "absolute_threshold"_a = py::none(),
      "FaceDefTables from a model's morph targets named in the shape-key grammar "
      "(parse_shape_key_name); the basis is the model's own positions. Returns a dict: face "
      "(MpegFace), copies (how many shapes were used), warnings, ignored (morph target names "
      "not in the grammar). threshold: FAPU a vertex must move to be in a table.");
  m.def("read_vrml", &readVrml, "path"_a,
        "Reads an MPEG-4 face (or a plain VRML97 scene) from a .wrl file.",
        py::call_guard<py::gil_scoped_release>());
  m.def("write_vrml", &writeVrml, "face"_a, "path"_a,
        "Writes the face, its tables and FIT as VRML97 (docs/vrml.md).",
        py::call_guard<py::gil_scoped_release>());
  m.def(
      "write_face_gltf",
      [](const MpegFace& face, const Path& path, const std::vector<FapStream>& streams) {
        py::gil_scoped_release release;
        writeFatGltf(face, measureFapu(face.faceSceneGraph), streams, path);
      },
      "face"_a, "path"_a, "streams"_a = std::vector<FapStream>{},
      "Writes the face as glTF with one morph target per table interval and the tables in "
      "extras, each stream baked as an animation (docs/fat-gltf.md).");
}

// The tables compiled for the face's own FAPU, and the face's Transforms as flat arrays.
struct PyFatEvaluator {
  std::shared_ptr<const MpegFace> face;
  FatEvaluator evaluator;
  FatState state;
  std::vector<Transform> neutral;  // the neutral state's, for object_coordinates
  std::vector<Points3f> placed;    // object_coordinates' buffers, reused
  std::vector<Eigen::Affine3d> placements;

  // Sets `state` to the face after frame `index` of the stream, resolved as a decoder does.
  void evaluateAt(const FapStream& stream, std::size_t index) {
    if (index >= stream.frames.size()) {
      throw py::index_error("frame index " + std::to_string(index) + " outside the stream's " +
                            std::to_string(stream.frames.size()) + " frames");
    }
    FapState resolved;
    for (std::size_t i = 0; i <= index; ++i) applyFrame(resolved, stream.frames[i]);
    evaluator.evaluate(resolved, state);
  }
};

py::dict stateToPython(const FatState& state) {
  py::list coord;
  for (const Points3& p : state.coord) coord.append(pointsToNumpy(p));
  const auto n = static_cast<py::ssize_t>(state.transforms.size());
  py::array_t<double> translation({n, py::ssize_t{3}}), rotation({n, py::ssize_t{4}}),
      scale({n, py::ssize_t{3}});
  for (py::ssize_t i = 0; i < n; ++i) {
    const Transform& t = state.transforms[static_cast<std::size_t>(i)];
    for (int j = 0; j < 3; ++j) {
      translation.mutable_at(i, j) = t.translation[j];
      scale.mutable_at(i, j) = t.scale[j];
    }
    const Eigen::Quaterniond& q = t.rotation;
    rotation.mutable_at(i, 0) = q.x(), rotation.mutable_at(i, 1) = q.y();
    rotation.mutable_at(i, 2) = q.z(), rotation.mutable_at(i, 3) = q.w();
  }
  return py::dict("coord"_a = coord, "translation"_a = translation, "rotation"_a = rotation,
                  "scale"_a = scale);
}

void bindEvaluator(py::module_& m) {
  py::class_<PyFatEvaluator> cls(
      m, "FatEvaluator",
      "A face's tables compiled once (for the FAPU measured on its feature points) to animate "
      "it with FAP frames.");
  cls.def(
      py::init([](const MpegFace& face, const std::string& storage) {
        if (storage != "float" && storage != "int16") {
          throw py::value_error("storage: '" + storage + "' is not 'float' or 'int16'");
        }
        auto shared = std::make_shared<const MpegFace>(face);
        FatEvaluator evaluator(*shared, measureFapu(shared->faceSceneGraph),
                               storage == "int16" ? FatStorage::Int16 : FatStorage::Float);
        FatState state = evaluator.neutralState();
        std::vector<Transform> neutral = state.transforms;
        return PyFatEvaluator{
            std::move(shared), std::move(evaluator), std::move(state), std::move(neutral), {}, {}};
      }),
      "face"_a, "storage"_a = "float",
      "storage: 'float' (the default: about 7 significant digits) or 'int16' (half the "
      "memory read per frame, for playback; a motion is off by at most 1/32768 of its "
      "table's largest per interval, docs/fat.md).");
  cls.def(
      "evaluate",
      [](PyFatEvaluator& self, const FapStream& stream, std::size_t index) {
        self.evaluateAt(stream, index);
        return stateToPython(self.state);
      },
      "stream"_a, "index"_a,
      "The face after frame `index` of the stream (0-based, values held and mirrored as a "
      "decoder does): a dict of coord (a list of (N, 3) arrays, one per mesh, mesh-local), and "
      "translation (T, 3), rotation (T, 4) quaternions x, y, z, w, and scale (T, 3) of every "
      "Transform.");
  cls.def(
      "object_coordinates",
      [](PyFatEvaluator& self, const FapStream& stream, std::size_t index,
         const std::vector<std::vector<int>>& chains, const std::optional<DoubleArray>& axes) {
        Eigen::Matrix3d turn = Eigen::Matrix3d::Identity();
        if (axes) {
          if (axes->ndim() != 2 || axes->shape(0) != 3 || axes->shape(1) != 3) {
            throw Error({}, 0, "axes", "expected (3, 3)");
          }
          turn = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(axes->data());
        }
        self.evaluateAt(stream, index);
        objectCoordinates(self.state, self.neutral, chains, turn, self.placed, self.placements);
        py::list coord, placed;
        const auto n = static_cast<py::ssize_t>(chains.size());
        py::array_t<double> placement({n, py::ssize_t{4}, py::ssize_t{4}});
        for (py::ssize_t i = 0; i < n; ++i) {
          const auto k = static_cast<std::size_t>(i);
          coord.append(pointsToNumpy(self.state.coord[k]));
          const Points3f& p = self.placed[k];
          py::array_t<float> out(std::vector<py::ssize_t>{p.rows(), 3});
          std::copy(p.data(), p.data() + p.size(), out.mutable_data());
          placed.append(std::move(out));
          const Eigen::Matrix4d& matrix = self.placements[k].matrix();
          for (int r = 0; r < 4; ++r) {
            for (int c = 0; c < 4; ++c) placement.mutable_at(i, r, c) = matrix(r, c);
          }
        }
        return py::dict("coord"_a = coord, "placed"_a = placed, "placement"_a = placement);
      },
      "stream"_a, "index"_a, "chains"_a, "axes"_a = py::none(),
      "The face after frame `index` (as evaluate()) seen by objects that stay where they are: "
      "object i shows mesh i, under the Transforms chains[i] (indices, outermost first). A "
      "dict of coord (mesh i's evaluated (N, 3) mesh-local coordinates, as evaluate()), "
      "placed (float32 (N, 3): coord where the evaluated Transforms along the chain put it, "
      "taken back through the inverse of the neutral Transforms' product, then turned by "
      "`axes` (3, 3), say Y-up to Z-up) and placement ((O, 4, 4): the matrix doing that, "
      "whose upper-left 3x3 turns normals).");
  cls.def(
      "neutral",
      [](const PyFatEvaluator& self) { return stateToPython(self.evaluator.neutralState()); },
      "The neutral face, shaped as evaluate()'s result.");
  cls.def(
      "priority_frames",
      [](const PyFatEvaluator& self, const FapStream& stream) {
        const std::vector<FapState> states = resolveFapStream(stream);
        py::array_t<bool> out(static_cast<py::ssize_t>(states.size()));
        for (std::size_t i = 0; i < states.size(); ++i) {
          out.mutable_at(static_cast<py::ssize_t>(i)) = self.evaluator.priorityApplies(states[i]);
        }
        return out;
      },
      "stream"_a,
      "Per frame of the stream (resolved as evaluate() does), whether a low-level FAP present "
      "overrides a viseme or expression on a vertex or Transform field both move: there the "
      "result is not the sum of the tables' motions (which shape keys show).");
  m.def(
      "border_weights",
      [](const std::vector<int>& borders,
         const py::array_t<double, py::array::c_style | py::array::forcecast>& values) {
        checkIntervalBorders(borders);
        const py::ssize_t n = values.size();
        py::array_t<double> out({n, static_cast<py::ssize_t>(borders.size())});
        const double* in = values.data();
        std::vector<double> w;
        for (py::ssize_t i = 0; i < n; ++i) {
          borderWeights(borders, in[i], w);
          for (std::size_t b = 0; b < w.size(); ++b) out.mutable_at(i, py::ssize_t(b)) = w[b];
        }
        return out;
      },
      "borders"_a, "values"_a,
      "The FAT rule as weights of the motions at the interval borders, (len(values), "
      "len(borders)): what shape keys at those amplitudes are set to (borderWeights).");
}

void bindClone(py::module_& m) {
  m.def(
      "clone_feature_points",
      [] {
        py::list out;
        for (std::string_view id : cloneFeaturePoints()) out.append(toPy(id));
        return out;
      },
      "The feature points cloning needs (docs/clone.md), in table order.");
  py::class_<CloneRelaxation>(
      m, "CloneRelaxation",
      "How clone_face relaxes the cloned motion over the target (docs/clone.md, \"Relaxing "
      "the cloned motion\"); the defaults are those of `mpeg4face animate`.")
      .def(py::init([](int fapPasses, int fringePasses, double fringeBelow,
                       int attachedNeighbours, int attachedPasses) {
             return CloneRelaxation{fapPasses, fringePasses, fringeBelow, attachedNeighbours,
                                    attachedPasses};
           }),
           py::kw_only(), "fap_passes"_a = CloneRelaxation{}.fapPasses,
           "fringe_passes"_a = CloneRelaxation{}.fringePasses,
           "fringe_below"_a = CloneRelaxation{}.fringeBelow,
           "attached_neighbours"_a = CloneRelaxation{}.attachedNeighbours,
           "attached_passes"_a = CloneRelaxation{}.attachedPasses)
      .def_readwrite("fap_passes", &CloneRelaxation::fapPasses)
      .def_readwrite("fringe_passes", &CloneRelaxation::fringePasses)
      .def_readwrite("fringe_below", &CloneRelaxation::fringeBelow)
      .def_readwrite("attached_neighbours", &CloneRelaxation::attachedNeighbours)
      .def_readwrite("attached_passes", &CloneRelaxation::attachedPasses);
  m.def(
      "clone_face",
      [](py::handle source, py::handle target, double filterSupport, bool adaptiveFilter,
         bool rigidParts, std::optional<CloneRelaxation> relaxation,
         std::function<void(std::string, double)> progress) {
        auto [sourceNeutral, copies] = cloneSource(source);
        const FaceModel targetNeutral = toCore(asFaceModel(target, "clone_face"));
        CloneOptions options;
        options.filterSupport = filterSupport;
        options.adaptiveFilter = adaptiveFilter;
        options.rigidParts = rigidParts;
        options.relaxation = relaxation;
        if (progress) {
          options.progress = [&progress](std::string_view stage, double fraction) {
            py::gil_scoped_acquire acquire;
            progress(std::string(stage), fraction);
          };
        }
        ClonedFace result;
        {
          py::gil_scoped_release release;
          result = cloneFace(sourceNeutral, copies, targetNeutral, options);
        }
        py::list cloned;
        for (FaceShape& copy : result.copies) cloned.append(shapeToPy(std::move(copy)));
        return py::dict("face"_a = std::move(result.face), "copies"_a = cloned,
                        "warnings"_a = stringList(result.warnings));
      },
      "source"_a, "target"_a, "filter_support"_a = 0.02, "adaptive_filter"_a = true,
      "rigid_parts"_a = true, "relaxation"_a = py::none(), "progress"_a = py::none(),
      "Facial Motion Cloning (Pandzic 2003; docs/clone.md): every FAP, viseme and expression "
      "shape of `source` (a FaceModel with shape keys in the grammar, or an MpegFace) onto the "
      "neutral FaceModel `target`; both need the clone_feature_points(). Returns a dict: face "
      "(the target as an MpegFace with its tables), copies (one dict per shape: name, fap, "
      "select, amplitude, meshes: one dict per target mesh that moves, with mesh, vertices "
      "(ascending) and displacement (len(vertices), 3), and transforms: the target's Transforms "
      "with the rigid parts' motion) and warnings. A CloneRelaxation relaxes the cloned "
      "motion over the target (none: as the mapping carries it). "
      "progress(stage, fraction) is called as it goes.");
}

void bindFit(py::module_& m) {
  py::class_<FitTable> cls(m, "FitTable",
                           "A FAP Interpolation Table (Tao et al.): FAP sets as nodes, links "
                           "with rational polynomials (docs/fit.md).");
  cls.def_property_readonly("nodes", [](const FitTable& t) { return t.nodes; });
  cls.def_property_readonly("link_count", [](const FitTable& t) { return t.links.size(); });
  cls.def("problems", &fitProblems, "What is wrong with the table, in words (empty if valid).");
  cls.def(
      "interpolate",
      [](const FitTable& t, FapStream stream) {
        interpolateFitStream(t, stream);
        return stream;
      },
      "stream"_a, "A copy of the stream with the FAPs the table derives filled in.");
  cls.def("to_json", [](const FitTable& t) { return fitTableToJson(t); });
  cls.def("__eq__", [](const FitTable& a, const FitTable& b) { return a == b; });
  m.def("read_fit_json", &readFitJson, "path"_a, "A table from its JSON form.");
  m.def("fit_table_from_json", &fitTableFromJson, "text"_a, "source"_a = "FIT JSON");
  m.def("fit_preset", &fitPreset, "name"_a,
        "A preset table: left-right, inner-outer-lip, eyebrow or expression.");
}

}  // namespace

void bindFace(py::module_& m) {
  bindNames(m);
  bindFit(m);
  bindMpegFace(m);
  bindEvaluator(m);
  bindClone(m);
}

}  // namespace mpeg4face::python
