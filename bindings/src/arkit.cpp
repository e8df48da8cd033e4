// SPDX-License-Identifier: GPL-3.0-or-later
// ARKit blendshapes as a source of MPEG-4 motion (docs/arkit.md): the names, a head's ARKit
// shapes, the ARKit -> FAP mapping measured on it, and the head with FAP, viseme and
// expression keys. Results are plain dicts and lists.
#include <string>
#include <utility>

#include "bindings.hpp"
#include "mpeg4face/arkit/shapes.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face::python {
namespace {

using namespace pybind11::literals;

py::object halfName(FaceSide half) {
  if (half == FaceSide::Left) return py::str("left");
  if (half == FaceSide::Right) return py::str("right");
  return py::none();
}

py::dict shapeRef(const ArkitShapeRef& ref) {
  return py::dict(
      "shape"_a = std::string(arkitKnownShapeNames()[static_cast<std::size_t>(ref.shape)]),
      "index"_a = ref.shape, "half"_a = halfName(ref.half));
}

py::list shapeList(const ArkitShapes& shapes) {
  py::list out;
  for (const ArkitShape& s : shapes.shapes) {
    py::dict d = shapeRef(s.ref);
    d["name"] = toPy(s.name);
    py::list meshes;
    for (const ArkitTarget& t : s.targets) meshes.append(t.mesh);
    d["meshes"] = meshes;
    out.append(d);
  }
  return out;
}

py::list keyList(const ArkitMapping& mapping, const ArkitShapes& shapes) {
  py::list out;
  for (const ArkitFapKey& key : mapping.keys) {
    py::dict weights;
    for (const auto& [shape, weight] : key.weights) {
      weights[py::str(shapes.shapes[static_cast<std::size_t>(shape)].name)] = weight;
    }
    py::dict d("fap"_a = key.fap, "amplitude"_a = key.amplitude,
               "name"_a = formatShapeKeyName(
                   {key.fap, 0, key.amplitude, std::string(fapInfo(key.fap).name)}),
               "weights"_a = weights, "reached"_a = key.reached, "residual"_a = key.residual,
               "worst_point"_a = key.worstPoint, "worst_motion"_a = key.worstMotion);
    d["transform"] = key.transform >= 0 ? py::object(py::int_(key.transform)) : py::none();
    d["rotation"] = key.transform >= 0
                        ? py::object(py::make_tuple(key.rotation.x(), key.rotation.y(),
                                                    key.rotation.z(), key.rotation.w()))
                        : py::none();
    out.append(d);
  }
  return out;
}

py::list missedList(const ArkitMapping& mapping) {
  py::list out;
  for (const ArkitMissedFap& m : mapping.missed) {
    out.append(py::dict("fap"_a = m.fap, "sign"_a = m.sign, "reason"_a = toPy(m.reason)));
  }
  return out;
}

}  // namespace

void bindArkit(py::module_& m) {
  m.def(
      "arkit_shape_names",
      []() {
        py::list out;
        for (std::string_view n : arkitShapeNames()) out.append(py::str(std::string(n)));
        return out;
      },
      "Apple ARKit's 52 blendshape names in Live Link Face's column order, spelled as Apple "
      "does (eyeBlinkLeft, ...).");
  m.def(
      "arkit_shape_index",
      [](const std::string& name) -> py::object {
        const std::optional<ArkitShapeRef> ref = arkitShapeIndex(name);
        return ref ? py::object(shapeRef(*ref)) : py::none();
      },
      "name"_a,
      "The ARKit shape a morph-target name is (case and '_' ignored, 'blendShape1.' prefixes "
      "dropped, _L / _R for Left / Right): dict(shape=ARKit name, index, half='left' / "
      "'right' / None for a half of a whole shape such as browInnerUp_L), or None.");
  m.def(
      "find_arkit_shapes",
      [](py::handle head) {
        const FaceModel core = toCore(asFaceModel(head, "find_arkit_shapes"));
        return shapeList(findArkitShapes(core));
      },
      "head"_a,
      "The head's morph targets that are ARKit shapes: a list of dict(shape, index, half, "
      "name (the target's), meshes). Raises mpeg4face.Error listing the names looked for if "
      "there are none.");
  m.def(
      "map_arkit_to_faps",
      [](py::handle head) {
        const FaceModel core = toCore(asFaceModel(head, "map_arkit_to_faps"));
        ArkitShapes shapes;
        ArkitMapping mapping;
        {
          py::gil_scoped_release release;
          shapes = findArkitShapes(core);
          mapping = mapArkitToFaps(core, shapes, measureFapu(core));
        }
        return py::dict("keys"_a = keyList(mapping, shapes), "missed"_a = missedList(mapping));
      },
      "head"_a,
      "For each low-level FAP (and sign), the non-negative combination of the head's ARKit "
      "shapes that makes it (docs/arkit.md): dict(keys=[dict(fap, amplitude, name, weights "
      "{target name: weight}, reached, residual, worst_point, worst_motion, transform, rotation)], "
      "missed=[dict(fap, "
      "sign, reason)]).");
  m.def(
      "arkit_fap_keys",
      [](py::handle head, bool visemes, bool expressions) {
        FaceModel core = toCore(asFaceModel(head, "arkit_fap_keys"));
        ArkitKeys keys;
        {
          py::gil_scoped_release release;
          keys = arkitFapKeys(core, {visemes, expressions});
        }
        py::list warnings;
        for (const std::string& w : keys.warnings) warnings.append(toPy(w));
        py::list mapping = keyList(keys.mapping, keys.shapes);
        py::list missed = missedList(keys.mapping);
        return py::dict("head"_a = fromCore(std::move(keys.head)), "mapping"_a = mapping,
                        "missed"_a = missed, "warnings"_a = warnings);
      },
      "head"_a, "visemes"_a = true, "expressions"_a = true,
      "The head with FAP keys fap<N>_<name>@<amplitude> made from its ARKit shapes (eyeball "
      "turns as poses), and viseme and expression keys made from them with the FIT presets, "
      "each alone from the neutral face; keys already named so are replaced. Returns "
      "dict(head=FaceModel, mapping=[as map_arkit_to_faps' keys], missed=[...], warnings=[...]).");
}

}  // namespace mpeg4face::python
