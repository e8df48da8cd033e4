// SPDX-License-Identifier: GPL-3.0-or-later
// FAPU measurement and the feature-point location constraints.
#include "mpeg4face/model/fapu.hpp"

#include <algorithm>
#include <cctype>
#include <utility>

#include "bindings.hpp"

namespace mpeg4face::python {
namespace {

using namespace pybind11::literals;

FapuKind fapuKind(std::string name) {
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  if (name.size() > 1 && name.back() == '0') name.pop_back();  // "ES0" -> "ES"
  for (FapuKind kind :
       {FapuKind::IRISD, FapuKind::ES, FapuKind::ENS, FapuKind::MNS, FapuKind::MW, FapuKind::AU}) {
    if (fapuName(kind) == name) return kind;
  }
  throw py::value_error("unknown FAPU '" + name +
                        "' (expected IRISD, ES, ENS, MNS, MW or AU, or IRISD0, ES0, ...)");
}

void bindDistance(py::module_& m) {
  py::class_<FapuDistance> cls(m, "FapuDistance",
                               "One neutral-face distance (ES0, IRISD0, ENS0, MNS0 or MW0) in "
                               "model units.");
  cls.def(py::init([](bool measured, double value, std::vector<std::string> pointsUsed,
                      std::string method) {
            return FapuDistance{measured, value, std::move(pointsUsed), std::move(method)};
          }),
          "measured"_a = false, "value"_a = 0.0, "points_used"_a = std::vector<std::string>{},
          "method"_a = "");
  cls.def_readwrite("measured", &FapuDistance::measured,
                    "True if the feature points needed were bound.");
  cls.def_readwrite("value", &FapuDistance::value,
                    "The distance in model units (the unit itself is value / 1024).");
  cls.def_property(
      "points_used",
      [](const FapuDistance& d) {
        py::list out;
        for (const std::string& id : d.pointsUsed) out.append(toPy(id));
        return py::tuple(out);
      },
      [](FapuDistance& d, std::vector<std::string> v) { d.pointsUsed = std::move(v); },
      "tuple of the feature point ids the value came from.");
  cls.def_property(
      "method", [](const FapuDistance& d) { return toPy(d.method); },
      [](FapuDistance& d, std::string v) { d.method = std::move(v); },
      "How the value was measured, in words, e.g. \"|3.5 - 3.6|\".");
  cls.def("__repr__", [](const FapuDistance& d) -> std::string {
    if (!d.measured) return "<FapuDistance unmeasured>";
    return "<FapuDistance " + std::string(py::repr(py::float_(d.value))) + " from " +
           std::string(toPy(d.method)) + ">";
  });
}

void bindMeasurement(py::module_& m) {
  py::class_<FapuMeasurement> cls(m, "FapuMeasurement",
                                  "The five neutral-face distances that define the FAPU.");
  cls.def(py::init<>());
  cls.def_readwrite("es0", &FapuMeasurement::ES0, "Eye separation (FapuDistance).");
  cls.def_readwrite("irisd0", &FapuMeasurement::IRISD0, "Iris diameter (FapuDistance).");
  cls.def_readwrite("ens0", &FapuMeasurement::ENS0, "Eye-nose separation (FapuDistance).");
  cls.def_readwrite("mns0", &FapuMeasurement::MNS0, "Mouth-nose separation (FapuDistance).");
  cls.def_readwrite("mw0", &FapuMeasurement::MW0, "Mouth width (FapuDistance).");
  cls.def(
      "unit", [](const FapuMeasurement& f, std::string fapu) { return f.unit(fapuKind(fapu)); },
      "fapu"_a,
      "The unit in model units: value / 1024 for \"IRISD\", \"ES\", \"ENS\", \"MNS\", \"MW\" "
      "(\"ES0\" etc. accepted too), 1e-5 for \"AU\", 0.0 if unmeasured. Raises ValueError for "
      "another name.");
  cls.def(
      "missing",
      [](const FapuMeasurement& f) {
        py::list out;
        for (const std::string& name : f.missing()) out.append(toPy(name));
        return out;
      },
      "Names of the distances not measured, e.g. [\"ENS0\"].");
  cls.def("__repr__", [](const FapuMeasurement& f) {
    std::string out = "<FapuMeasurement";
    for (auto [name, d] : f.distances()) {
      out += " " + std::string(name) + "=" +
             (d->measured ? std::string(py::repr(py::float_(d->value))) : "?");
    }
    return out + ">";
  });

  m.def(
      "measure_fapu",
      [](py::handle model) {
        const FaceModel core = toCore(asFaceModel(model, "measure_fapu"));
        py::gil_scoped_release release;
        return measureFapu(core);
      },
      "model"_a,
      "Measures ES0, IRISD0, ENS0, MNS0 and MW0 from the model's bound feature points "
      "(pupils 3.5/3.6 or eye corners, eyelids 3.1-3.4, nose 9.15, mouth 2.2, lip corners "
      "8.3/8.4 or 2.4/2.5).");
}

void bindConstraints(py::module_& m) {
  py::class_<ConstraintWarning> cls(m, "ConstraintWarning",
                                    "A feature point that breaks a recommended location "
                                    "constraint (read-only).");
  cls.def_property_readonly(
      "feature_point", [](const ConstraintWarning& w) { return toPy(w.featurePoint); },
      "Feature point id, e.g. \"2.1\".");
  cls.def_readonly("axis", &ConstraintWarning::axis, "\"x\", \"y\" or \"z\".");
  cls.def_property_readonly(
      "message", [](const ConstraintWarning& w) { return toPy(w.message); },
      "What is wrong, e.g. \"2.1.x differs from 7.1.x by 4.2% of ES0\".");
  cls.def_readonly("advisory", &ConstraintWarning::advisory,
                   "True if the paper allows an alternative location (advice, not an error).");
  cls.def("__repr__", [](const ConstraintWarning& w) {
    return "<ConstraintWarning " + std::string(toPy(w.message)) + ">";
  });

  m.def(
      "check_location_constraints",
      [](py::handle model, const FapuMeasurement& fapu, double tolerance) {
        const FaceModel core = toCore(asFaceModel(model, "check_location_constraints"));
        py::gil_scoped_release release;
        return checkLocationConstraints(core, fapu, tolerance);
      },
      "model"_a, "fapu"_a, "tolerance"_a = 0.02,
      "Checks every recommended feature-point location constraint whose points are all bound; "
      "returns a list of ConstraintWarning. Equalities may be off by `tolerance` times the "
      "scale (ES0 if measured, else the bounding-box diagonal); inequalities must hold by at "
      "least that much.");
}

}  // namespace

void bindFapu(py::module_& m) {
  bindDistance(m);
  bindMeasurement(m);
  bindConstraints(m);
}

}  // namespace mpeg4face::python
