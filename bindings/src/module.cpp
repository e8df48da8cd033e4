// SPDX-License-Identifier: GPL-3.0-or-later
// The pybind11 module mpeg4face._core: module entry point and mpeg4face.Error.
#include <pybind11/eval.h>

#include <exception>

#include "bindings.hpp"
#include "mpeg4face/error.hpp"

#ifndef MPEG4FACE_VERSION
#error "MPEG4FACE_VERSION must be defined by the build"
#endif

namespace mpeg4face::python {
namespace {

// mpeg4face.Error, defined in Python so that its instances carry the attributes and users
// can raise it themselves with the same keywords.
constexpr const char* kErrorClass = R"PY(
class Error(ValueError):
    """An error of the mpeg4face library (a ValueError).

    Attributes name where the problem is, each None when it does not apply:
    file (str): the file at fault; line (int): its 1-based line (text formats);
    field (str): the field or element at fault (glTF field, mesh name, ...);
    reason (str): the message without the "file:line: field:" prefix.
    """

    def __init__(self, message="", file=None, line=None, field=None, reason=None):
        super().__init__(message)
        self.file = file
        self.line = line
        self.field = field
        self.reason = message if reason is None else reason
)PY";

// The class object, owned for the life of the process: the translator may run until
// interpreter shutdown, and a static py::object would be released after it.
PyObject* errorClass = nullptr;

py::object orNone(const std::string& text) {
  return text.empty() ? py::object(py::none()) : py::object(toPy(text));
}

void translateError(std::exception_ptr p) {
  try {
    if (p) std::rethrow_exception(p);
  } catch (const Error& e) {
    const py::object cls = py::reinterpret_borrow<py::object>(errorClass);
    const py::object instance = cls(
        toPy(e.what()), py::arg("file") = orNone(e.file()),
        py::arg("line") = e.line() > 0 ? py::object(py::int_(e.line())) : py::object(py::none()),
        py::arg("field") = orNone(e.field()), py::arg("reason") = toPy(e.reason()));
    PyErr_SetObject(errorClass, instance.ptr());
  }
}

}  // namespace

void bindError(py::module_& m) {
  py::dict scope;
  scope["__name__"] = "mpeg4face";
  py::exec(kErrorClass, scope);
  const py::object cls = scope["Error"];
  errorClass = cls.inc_ref().ptr();
  m.attr("Error") = cls;
  py::register_exception_translator(&translateError);
}

}  // namespace mpeg4face::python

PYBIND11_MODULE(_core, m) {
  namespace python = mpeg4face::python;
  m.doc() =
      "mpeg4face._core: the C++ core of the MPEG-4 Face Animation toolkit (tables, face "
      "model, file formats, FAPU). Import the package mpeg4face instead.";
  m.attr("__version__") = MPEG4FACE_VERSION;
  python::bindError(m);
  python::bindSpec(m);
  python::bindModel(m);
  python::bindIo(m);
  python::bindFapu(m);
  python::bindStream(m);
  python::bindFace(m);
  python::bindCheck(m);
  python::bindArkit(m);
  python::bindCapture(m);
  python::bindNormals(m);
  python::bindMesh2d(m);
}
