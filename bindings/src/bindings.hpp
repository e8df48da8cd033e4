// SPDX-License-Identifier: GPL-3.0-or-later
// Shared declarations of the pybind11 module mpeg4face._core.
//
// The model classes seen from Python (IndexedFaceSet, Transform, FaceModel, ...) are not the
// core structs themselves but "mirror" objects: their numeric fields are numpy arrays and
// their lists of objects are plain Python lists and dicts, all owned by the Python object.
// A getter hands out the stored array or list itself, so `mesh.coord[0] += 1`,
// `model.meshes.append(mesh)` and `model.meshes[0].name = "x"` change the model, and no
// Python reference can ever dangle (as it would with references into a std::vector that
// later reallocates). Each call into the core converts the mirror to a mpeg4face::FaceModel
// (toCore) and each result back (fromCore).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // in every file, so that each converts std types the same way

#include <cstdint>
#include <string>
#include <string_view>

#include "mpeg4face/io/wfm.hpp"
#include "mpeg4face/model/face_model.hpp"

namespace mpeg4face::python {

namespace py = pybind11;

// Registration, one function per source file.
void bindError(py::module_& m);
void bindSpec(py::module_& m);
void bindModel(py::module_& m);
void bindIo(py::module_& m);
void bindFapu(py::module_& m);
void bindStream(py::module_& m);
void bindFace(py::module_& m);
void bindCheck(py::module_& m);
void bindArkit(py::module_& m);
void bindCapture(py::module_& m);
void bindNormals(py::module_& m);
void bindMesh2d(py::module_& m);

// UTF-8 to str; invalid bytes (from a file's text) become U+FFFD instead of raising.
py::str toPy(std::string_view text);

// --- Checked numpy fields -------------------------------------------------------------------
// Each returns a new C-contiguous array of the stated dtype and shape, copied from any array
// or sequence of numbers, or raises ValueError (wrong shape) / TypeError (not numbers) naming
// `field`. None and empty sequences give an empty array.
py::array_t<double> emptyRows(py::ssize_t cols);  // shape (0, cols)
py::array_t<double> emptyVector();                // shape (0,)
py::array_t<int32_t> emptyIndices();              // shape (0,), int32
py::array_t<double> fixedVector(std::initializer_list<double> values);
py::array_t<double> checkedRows(py::handle value, const std::string& field, py::ssize_t cols);
py::array_t<double> checkedVector(py::handle value, const std::string& field);
py::array_t<double> checkedFixed(py::handle value, const std::string& field, py::ssize_t size);
py::array_t<int32_t> checkedIndices(py::handle value, const std::string& field);
// A Python int that fits a C++ int (numpy integers accepted).
int checkedInt(py::handle value, const std::string& field);
// A new list of Python ints.
py::list checkedIntList(py::handle value, const std::string& field);
// A new list holding the same objects (not copies), each an instance of T.
template <typename T>
py::list checkedObjectList(py::handle value, const std::string& field, const char* typeName);
// A stored index array as the core's vector (ValueError unless 1-D).
std::vector<int> indicesToCore(py::handle value, const std::string& field);
// A new dict of str -> FeaturePointBinding (the same binding objects).
py::dict checkedFeaturePoints(py::handle value, const std::string& field);
// "int" for 3, "str" for "x": for messages.
std::string typeName(py::handle value);

// --- Mirror types ---------------------------------------------------------------------------
struct PyMorphTarget {
  std::string name;
  py::array_t<double> displacements = emptyRows(3);
};

struct PyMesh {
  std::string name;
  py::array_t<double> coord = emptyRows(3);
  py::array_t<int32_t> coordIndex = emptyIndices();
  py::array_t<double> normal = emptyRows(3);
  py::array_t<double> texCoord = emptyRows(2);
  py::array_t<int32_t> texCoordIndex = emptyIndices();
  py::list morphTargets;  // of MorphTarget
  py::array_t<double> weights = emptyVector();
  py::array_t<int32_t> sourceIndex = emptyIndices();
};

struct PyTransform {
  std::string name;
  py::array_t<double> translation = fixedVector({0.0, 0.0, 0.0});
  py::array_t<double> rotation = fixedVector({0.0, 0.0, 0.0, 1.0});  // x, y, z, w
  py::array_t<double> scale = fixedVector({1.0, 1.0, 1.0});
  py::array_t<double> center = fixedVector({0.0, 0.0, 0.0});
  py::list children;  // of int
  py::list meshes;    // of int
};

struct PyFeaturePointBinding {
  int mesh = -1;
  int vertex = -1;
  py::array_t<double> position = fixedVector({0.0, 0.0, 0.0});
};

struct PyMorphWeightChannel {
  int mesh = 0;
  MorphWeightChannel::Interpolation interpolation = MorphWeightChannel::Interpolation::Linear;
  py::array_t<double> times = emptyVector();
  py::array_t<double> weights = emptyVector();
};

struct PyTransformChannel {
  int transform = 0;
  TransformChannel::Path path = TransformChannel::Path::Rotation;
  MorphWeightChannel::Interpolation interpolation = MorphWeightChannel::Interpolation::Linear;
  py::array_t<double> times = emptyVector();
  py::array_t<double> values = emptyVector();
};

struct PyMorphWeightAnimation {
  std::string name;
  py::list channels;           // of MorphWeightChannel
  py::list transformChannels;  // of TransformChannel
};

struct PyFaceModel {
  py::list meshes;         // of IndexedFaceSet
  py::list transforms;     // of Transform
  py::list roots;          // of int
  py::dict featurePoints;  // str -> FeaturePointBinding
  py::list animations;     // of MorphWeightAnimation
};

struct PyCandideUnit {
  std::string name;
  int fap = 0;
  std::string fapu;
  py::array_t<int32_t> vertices = emptyIndices();
  py::array_t<double> displacements = emptyRows(3);
};

struct PyCandideModel {
  py::object model;         // FaceModel
  py::list animationUnits;  // of CandideUnit
  py::list shapeUnits;      // of CandideUnit
};

// The FaceModel behind `model`, or TypeError naming `function`.
const PyFaceModel& asFaceModel(py::handle model, const char* function);

// --- Conversions ----------------------------------------------------------------------------
// How much of the meshes toCore copies: names only (scene-graph queries), names and vertex
// positions (feature-point positions), or everything.
enum class Depth { Structure, Geometry, Full };

FaceModel toCore(const PyFaceModel& model, Depth depth = Depth::Full);
IndexedFaceSet toCore(const PyMesh& mesh, const std::string& where, Depth depth = Depth::Full);
Transform toCore(const PyTransform& transform, const std::string& where);
CandideModel toCore(const PyCandideModel& candide);

PyFaceModel fromCore(FaceModel&& model);
PyTransform fromCore(Transform&& transform);
py::array_t<int32_t> indicesFromCore(const std::vector<int>& v);
PyFeaturePointBinding fromCore(const FeaturePointBinding& binding);
PyCandideModel fromCore(CandideModel&& candide);

// --- Template definitions -------------------------------------------------------------------
template <typename T>
py::list checkedObjectList(py::handle value, const std::string& field, const char* typeName_) {
  py::list out;
  if (value.is_none()) return out;
  if (py::isinstance<py::str>(value) || py::isinstance<py::bytes>(value) ||
      !py::isinstance<py::iterable>(value)) {
    throw py::type_error(field + ": expected a sequence of " + typeName_ + ", got " +
                         typeName(value));
  }
  size_t i = 0;
  for (py::handle item : py::iter(value)) {
    if (!py::isinstance<T>(item)) {
      throw py::type_error(field + "[" + std::to_string(i) + "]: expected " + typeName_ + ", got " +
                           typeName(item));
    }
    out.append(item);
    ++i;
  }
  return out;
}

}  // namespace mpeg4face::python
