// SPDX-License-Identifier: GPL-3.0-or-later
// Checked numpy fields and the conversions between the Python mirror objects and the core
// structs (see bindings.hpp).
#include <algorithm>
#include <climits>
#include <cstring>
#include <utility>

#include "bindings.hpp"

namespace mpeg4face::python {

template <int Cols>
using Rows = Eigen::Matrix<double, Eigen::Dynamic, Cols, Eigen::RowMajor>;
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using IntArray = py::array_t<int32_t, py::array::c_style | py::array::forcecast>;
static_assert(sizeof(int) == sizeof(int32_t), "the core's indices are 32-bit ints");

py::str toPy(std::string_view text) {
  PyObject* s = PyUnicode_DecodeUTF8(text.data(), static_cast<Py_ssize_t>(text.size()), "replace");
  if (s == nullptr) throw py::error_already_set();
  return py::reinterpret_steal<py::str>(s);
}

std::string typeName(py::handle value) { return Py_TYPE(value.ptr())->tp_name; }

const PyFaceModel& asFaceModel(py::handle model, const char* function) {
  if (!py::isinstance<PyFaceModel>(model)) {
    throw py::type_error(std::string(function) + ": expected FaceModel, got " + typeName(model));
  }
  return model.cast<const PyFaceModel&>();
}

namespace {

py::module_ numpy() { return py::module_::import("numpy"); }

std::string shapeText(const py::array& a) {
  std::string out = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) {
    if (i > 0) out += ", ";
    out += std::to_string(a.shape(i));
  }
  return out + (a.ndim() == 1 ? ",)" : ")");
}

py::array asArray(py::handle value, const std::string& field) {
  try {
    return numpy().attr("asarray")(value);
  } catch (py::error_already_set& e) {
    throw py::value_error(field + ": cannot make an array of it (" + e.what() + ")");
  }
}

// dtype kinds: f float, i signed, u unsigned.
void requireKind(const py::array& a, const char* kinds, const std::string& field,
                 const char* what) {
  if (std::strchr(kinds, a.dtype().kind()) == nullptr) {
    throw py::type_error(field + ": expected " + what + ", got an array of dtype " +
                         std::string(py::str(a.dtype())));
  }
}

template <typename T>
py::array_t<T> copyAs(const py::array& a) {
  return numpy().attr("array")(a, py::arg("dtype") = py::dtype::of<T>(), py::arg("order") = "C",
                               py::arg("copy") = true);
}

template <int Cols>
Rows<Cols> rowsToCore(py::handle value, const std::string& field) {
  const DoubleArray a = DoubleArray::ensure(value);
  if (!a) throw py::type_error(field + ": expected an array of numbers, got " + typeName(value));
  if (a.ndim() == 1 && a.size() == 0) return Rows<Cols>(0, Cols);
  if (a.ndim() != 2 || a.shape(1) != Cols) {
    throw py::value_error(field + ": expected an array of shape (N, " + std::to_string(Cols) +
                          "), got shape " + shapeText(a));
  }
  Rows<Cols> out(a.shape(0), Cols);
  std::copy_n(a.data(), a.size(), out.data());
  return out;
}

template <int Cols>
py::array_t<double> rowsFromCore(const Rows<Cols>& m) {
  py::array_t<double> out(std::vector<py::ssize_t>{m.rows(), Cols});
  std::copy_n(m.data(), m.size(), out.mutable_data());
  return out;
}

Eigen::VectorXd fixedToCore(py::handle value, const std::string& field, py::ssize_t size) {
  const DoubleArray a = DoubleArray::ensure(value);
  if (!a || a.ndim() != 1 || a.shape(0) != size) {
    throw py::value_error(field + ": expected an array of shape (" + std::to_string(size) + ",)");
  }
  Eigen::VectorXd out(size);
  std::copy_n(a.data(), size, out.data());
  return out;
}

py::array_t<double> fixedFromCore(const double* data, py::ssize_t size) {
  py::array_t<double> out(size);
  std::copy_n(data, size, out.mutable_data());
  return out;
}

std::vector<double> vectorToCore(py::handle value, const std::string& field) {
  const DoubleArray a = DoubleArray::ensure(value);
  if (!a || a.ndim() != 1) {
    throw py::value_error(field + ": expected a 1-D array of numbers, shape (N,)");
  }
  return {a.data(), a.data() + a.size()};
}

py::array_t<double> vectorFromCore(const std::vector<double>& v) {
  return fixedFromCore(v.data(), static_cast<py::ssize_t>(v.size()));
}

std::vector<int> intListToCore(const py::list& list, const std::string& field) {
  std::vector<int> out;
  out.reserve(list.size());
  size_t i = 0;
  for (py::handle item : list)
    out.push_back(checkedInt(item, field + "[" + std::to_string(i++) + "]"));
  return out;
}

py::list intListFromCore(const std::vector<int>& v) {
  py::list out;
  for (int x : v) out.append(x);
  return out;
}

template <typename T>
const T& itemAs(py::handle item, const std::string& field, const char* name) {
  if (!py::isinstance<T>(item)) {
    throw py::type_error(field + ": expected " + name + ", got " + typeName(item));
  }
  return item.cast<const T&>();
}

std::string indexed(const std::string& field, size_t i) {
  return field + "[" + std::to_string(i) + "]";
}

FeaturePointBinding toCore(const PyFeaturePointBinding& fp, const std::string& where) {
  FeaturePointBinding out;
  out.mesh = fp.mesh;
  out.vertex = fp.vertex;
  out.position = fixedToCore(fp.position, where + ".position", 3);
  return out;
}

MorphWeightChannel toCore(const PyMorphWeightChannel& channel, const std::string& where) {
  MorphWeightChannel out;
  out.mesh = channel.mesh;
  out.interpolation = channel.interpolation;
  out.times = vectorToCore(channel.times, where + ".times");
  out.weights = vectorToCore(channel.weights, where + ".weights");
  return out;
}

TransformChannel toCore(const PyTransformChannel& channel, const std::string& where) {
  TransformChannel out;
  out.transform = channel.transform;
  out.path = channel.path;
  out.interpolation = channel.interpolation;
  out.times = vectorToCore(channel.times, where + ".times");
  out.values = vectorToCore(channel.values, where + ".values");
  return out;
}

PyMesh fromCore(IndexedFaceSet&& mesh) {
  PyMesh out;
  out.name = std::move(mesh.name);
  out.coord = rowsFromCore<3>(mesh.coord);
  out.coordIndex = indicesFromCore(mesh.coordIndex);
  out.normal = rowsFromCore<3>(mesh.normal);
  out.texCoord = rowsFromCore<2>(mesh.texCoord);
  out.texCoordIndex = indicesFromCore(mesh.texCoordIndex);
  for (MorphTarget& target : mesh.morphTargets) {
    PyMorphTarget t;
    t.name = std::move(target.name);
    t.displacements = rowsFromCore<3>(target.displacements);
    out.morphTargets.append(py::cast(std::move(t)));
  }
  out.weights = vectorFromCore(mesh.weights);
  out.sourceIndex = indicesFromCore(mesh.sourceIndex);
  return out;
}

PyCandideUnit fromCore(CandideUnit&& unit) {
  PyCandideUnit out;
  out.name = std::move(unit.name);
  out.fap = unit.fap;
  out.fapu = std::move(unit.fapu);
  out.vertices = indicesFromCore(unit.vertices);
  out.displacements = rowsFromCore<3>(unit.displacements);
  return out;
}

CandideUnit toCore(const PyCandideUnit& unit, const std::string& where) {
  CandideUnit out;
  out.name = unit.name;
  out.fap = unit.fap;
  out.fapu = unit.fapu;
  out.vertices = indicesToCore(unit.vertices, where + ".vertices");
  out.displacements = rowsToCore<3>(unit.displacements, where + ".displacements");
  return out;
}

}  // namespace

py::array_t<int32_t> indicesFromCore(const std::vector<int>& v) {
  py::array_t<int32_t> out(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}

PyTransform fromCore(Transform&& transform) {
  PyTransform out;
  out.name = std::move(transform.name);
  out.translation = fixedFromCore(transform.translation.data(), 3);
  out.rotation = fixedFromCore(transform.rotation.coeffs().data(), 4);  // x, y, z, w
  out.scale = fixedFromCore(transform.scale.data(), 3);
  out.center = fixedFromCore(transform.center.data(), 3);
  out.children = intListFromCore(transform.children);
  out.meshes = intListFromCore(transform.meshes);
  return out;
}

std::vector<int> indicesToCore(py::handle value, const std::string& field) {
  const IntArray a = IntArray::ensure(value);
  if (!a || a.ndim() != 1) {
    throw py::value_error(field + ": expected a 1-D array of integers, shape (N,)");
  }
  return {a.data(), a.data() + a.size()};
}

// --- Checked fields -------------------------------------------------------------------------

py::array_t<double> emptyRows(py::ssize_t cols) {
  return py::array_t<double>(std::vector<py::ssize_t>{0, cols});
}

py::array_t<double> emptyVector() { return py::array_t<double>(0); }

py::array_t<int32_t> emptyIndices() { return py::array_t<int32_t>(0); }

py::array_t<double> fixedVector(std::initializer_list<double> values) {
  return fixedFromCore(values.begin(), static_cast<py::ssize_t>(values.size()));
}

py::array_t<double> checkedRows(py::handle value, const std::string& field, py::ssize_t cols) {
  if (value.is_none()) return emptyRows(cols);
  const py::array a = asArray(value, field);
  if (a.ndim() == 1 && a.size() == 0) return emptyRows(cols);
  requireKind(a, "fiu", field, "numbers");
  if (a.ndim() != 2 || a.shape(1) != cols) {
    throw py::value_error(field + ": expected an array of shape (N, " + std::to_string(cols) +
                          "), got shape " + shapeText(a));
  }
  return copyAs<double>(a);
}

py::array_t<double> checkedVector(py::handle value, const std::string& field) {
  if (value.is_none()) return emptyVector();
  const py::array a = asArray(value, field);
  if (a.ndim() == 1 && a.size() == 0) return emptyVector();
  requireKind(a, "fiu", field, "numbers");
  if (a.ndim() != 1) {
    throw py::value_error(field + ": expected an array of shape (N,), got shape " + shapeText(a));
  }
  return copyAs<double>(a);
}

py::array_t<double> checkedFixed(py::handle value, const std::string& field, py::ssize_t size) {
  const std::string expected = "(" + std::to_string(size) + ",)";
  if (value.is_none()) {
    throw py::type_error(field + ": expected an array of shape " + expected + ", got None");
  }
  const py::array a = asArray(value, field);
  if (a.size() > 0) requireKind(a, "fiu", field, "numbers");
  if (a.ndim() != 1 || a.shape(0) != size) {
    throw py::value_error(field + ": expected an array of shape " + expected + ", got shape " +
                          shapeText(a));
  }
  return copyAs<double>(a);
}

py::array_t<int32_t> checkedIndices(py::handle value, const std::string& field) {
  if (value.is_none()) return emptyIndices();
  const py::array a = asArray(value, field);
  if (a.ndim() == 1 && a.size() == 0) return emptyIndices();
  requireKind(a, "iu", field, "integers");
  if (a.ndim() != 1) {
    throw py::value_error(field + ": expected an array of shape (N,), got shape " + shapeText(a));
  }
  if (a.size() > 0 && (py::object(a.attr("min")()) < py::int_(INT32_MIN) ||
                       py::object(a.attr("max")()) > py::int_(INT32_MAX))) {
    throw py::value_error(field + ": values must fit a 32-bit int");
  }
  return copyAs<int32_t>(a);
}

int checkedInt(py::handle value, const std::string& field) {
  const py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
  if (!index) {
    PyErr_Clear();
    throw py::type_error(field + ": expected an integer, got " + typeName(value));
  }
  int overflow = 0;
  const long long v = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
  if (overflow != 0 || v < INT_MIN || v > INT_MAX) {
    throw py::value_error(field + ": " + std::string(py::str(index)) + " does not fit an int");
  }
  return static_cast<int>(v);
}

py::list checkedIntList(py::handle value, const std::string& field) {
  py::list out;
  if (value.is_none()) return out;
  if (!py::isinstance<py::iterable>(value) || py::isinstance<py::str>(value)) {
    throw py::type_error(field + ": expected a sequence of integers, got " + typeName(value));
  }
  size_t i = 0;
  for (py::handle item : py::iter(value)) out.append(checkedInt(item, indexed(field, i++)));
  return out;
}

py::dict checkedFeaturePoints(py::handle value, const std::string& field) {
  py::dict out;
  if (value.is_none()) return out;
  if (!py::hasattr(value, "items")) {
    throw py::type_error(field + ": expected a dict of feature point id -> " +
                         "FeaturePointBinding, got " + typeName(value));
  }
  for (py::handle pair : py::iter(value.attr("items")())) {
    const py::tuple item = py::reinterpret_borrow<py::tuple>(pair);
    const py::handle key = item[0];
    const py::handle binding = item[1];
    if (!py::isinstance<py::str>(key)) {
      throw py::type_error(field + ": keys must be feature point ids (str) like '2.1', got " +
                           typeName(key));
    }
    if (!py::isinstance<PyFeaturePointBinding>(binding)) {
      throw py::type_error(field + "['" + std::string(py::str(key)) +
                           "']: expected FeaturePointBinding, got " + typeName(binding));
    }
    out[key] = binding;
  }
  return out;
}

// --- Conversions ----------------------------------------------------------------------------

IndexedFaceSet toCore(const PyMesh& mesh, const std::string& where, Depth depth) {
  IndexedFaceSet out;
  out.name = mesh.name;
  if (depth == Depth::Structure) return out;
  out.coord = rowsToCore<3>(mesh.coord, where + ".coord");
  if (depth == Depth::Geometry) return out;
  out.coordIndex = indicesToCore(mesh.coordIndex, where + ".coord_index");
  out.normal = rowsToCore<3>(mesh.normal, where + ".normal");
  out.texCoord = rowsToCore<2>(mesh.texCoord, where + ".tex_coord");
  out.texCoordIndex = indicesToCore(mesh.texCoordIndex, where + ".tex_coord_index");
  size_t i = 0;
  for (py::handle item : mesh.morphTargets) {
    const std::string field = indexed(where + ".morph_targets", i++);
    const auto& target = itemAs<PyMorphTarget>(item, field, "MorphTarget");
    out.morphTargets.push_back(
        {target.name, rowsToCore<3>(target.displacements, field + ".displacements")});
  }
  out.weights = vectorToCore(mesh.weights, where + ".weights");
  out.sourceIndex = indicesToCore(mesh.sourceIndex, where + ".source_index");
  return out;
}

Transform toCore(const PyTransform& transform, const std::string& where) {
  Transform out;
  out.name = transform.name;
  out.translation = fixedToCore(transform.translation, where + ".translation", 3);
  const Eigen::VectorXd q = fixedToCore(transform.rotation, where + ".rotation", 4);
  out.rotation = Eigen::Quaterniond(q[3], q[0], q[1], q[2]);  // Eigen's order is w, x, y, z
  out.scale = fixedToCore(transform.scale, where + ".scale", 3);
  out.center = fixedToCore(transform.center, where + ".center", 3);
  out.children = intListToCore(transform.children, where + ".children");
  out.meshes = intListToCore(transform.meshes, where + ".meshes");
  return out;
}

FaceModel toCore(const PyFaceModel& model, Depth depth) {
  FaceModel out;
  size_t i = 0;
  for (py::handle item : model.meshes) {
    const std::string field = indexed("FaceModel.meshes", i++);
    out.meshes.push_back(toCore(itemAs<PyMesh>(item, field, "IndexedFaceSet"), field, depth));
  }
  i = 0;
  for (py::handle item : model.transforms) {
    const std::string field = indexed("FaceModel.transforms", i++);
    out.transforms.push_back(toCore(itemAs<PyTransform>(item, field, "Transform"), field));
  }
  out.roots = intListToCore(model.roots, "FaceModel.roots");
  for (auto [key, value] : model.featurePoints) {
    if (!py::isinstance<py::str>(key)) {
      throw py::type_error("FaceModel.feature_points: keys must be str, got " + typeName(key));
    }
    const std::string id = py::cast<std::string>(key);
    const std::string field = "FaceModel.feature_points['" + id + "']";
    out.featurePoints.emplace(
        id, toCore(itemAs<PyFeaturePointBinding>(value, field, "FeaturePointBinding"), field));
  }
  if (depth != Depth::Full) return out;
  i = 0;
  for (py::handle item : model.animations) {
    const std::string field = indexed("FaceModel.animations", i++);
    const auto& animation = itemAs<PyMorphWeightAnimation>(item, field, "MorphWeightAnimation");
    MorphWeightAnimation a;
    a.name = animation.name;
    size_t c = 0;
    for (py::handle channel : animation.channels) {
      const std::string where = indexed(field + ".channels", c++);
      a.channels.push_back(
          toCore(itemAs<PyMorphWeightChannel>(channel, where, "MorphWeightChannel"), where));
    }
    c = 0;
    for (py::handle channel : animation.transformChannels) {
      const std::string where = indexed(field + ".transform_channels", c++);
      a.transformChannels.push_back(
          toCore(itemAs<PyTransformChannel>(channel, where, "TransformChannel"), where));
    }
    out.animations.push_back(std::move(a));
  }
  return out;
}

CandideModel toCore(const PyCandideModel& candide) {
  CandideModel out;
  out.model = toCore(itemAs<PyFaceModel>(candide.model, "CandideModel.model", "FaceModel"));
  size_t i = 0;
  for (py::handle item : candide.animationUnits) {
    const std::string field = indexed("CandideModel.animation_units", i++);
    out.animationUnits.push_back(toCore(itemAs<PyCandideUnit>(item, field, "CandideUnit"), field));
  }
  i = 0;
  for (py::handle item : candide.shapeUnits) {
    const std::string field = indexed("CandideModel.shape_units", i++);
    out.shapeUnits.push_back(toCore(itemAs<PyCandideUnit>(item, field, "CandideUnit"), field));
  }
  return out;
}

PyFaceModel fromCore(FaceModel&& model) {
  PyFaceModel out;
  for (IndexedFaceSet& mesh : model.meshes) out.meshes.append(py::cast(fromCore(std::move(mesh))));
  for (Transform& t : model.transforms) out.transforms.append(py::cast(fromCore(std::move(t))));
  out.roots = intListFromCore(model.roots);
  for (const auto& [id, binding] : model.featurePoints) {
    out.featurePoints[toPy(id)] = py::cast(fromCore(binding));
  }
  for (MorphWeightAnimation& animation : model.animations) {
    PyMorphWeightAnimation a;
    a.name = std::move(animation.name);
    for (const MorphWeightChannel& channel : animation.channels) {
      PyMorphWeightChannel c;
      c.mesh = channel.mesh;
      c.interpolation = channel.interpolation;
      c.times = vectorFromCore(channel.times);
      c.weights = vectorFromCore(channel.weights);
      a.channels.append(py::cast(std::move(c)));
    }
    for (const TransformChannel& channel : animation.transformChannels) {
      PyTransformChannel c;
      c.transform = channel.transform;
      c.path = channel.path;
      c.interpolation = channel.interpolation;
      c.times = vectorFromCore(channel.times);
      c.values = vectorFromCore(channel.values);
      a.transformChannels.append(py::cast(std::move(c)));
    }
    out.animations.append(py::cast(std::move(a)));
  }
  return out;
}

PyFeaturePointBinding fromCore(const FeaturePointBinding& binding) {
  PyFeaturePointBinding out;
  out.mesh = binding.mesh;
  out.vertex = binding.vertex;
  out.position = fixedFromCore(binding.position.data(), 3);
  return out;
}

PyCandideModel fromCore(CandideModel&& candide) {
  PyCandideModel out;
  out.model = py::cast(fromCore(std::move(candide.model)));
  for (CandideUnit& unit : candide.animationUnits) {
    out.animationUnits.append(py::cast(fromCore(std::move(unit))));
  }
  for (CandideUnit& unit : candide.shapeUnits) {
    out.shapeUnits.append(py::cast(fromCore(std::move(unit))));
  }
  return out;
}

}  // namespace mpeg4face::python
