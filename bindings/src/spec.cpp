// SPDX-License-Identifier: GPL-3.0-or-later
// The MPEG-4 face animation tables: FAPs, feature points, FAPU, FAP groups, visemes,
// expressions. Rows are read-only views of the core's static tables.
#include "mpeg4face/spec.hpp"

#include <span>

#include "bindings.hpp"

namespace mpeg4face::python {
namespace {

using namespace pybind11::literals;

constexpr auto kReference = py::return_value_policy::reference;

template <typename T>
py::list rows(std::span<const T> table) {
  py::list out;
  for (const T& row : table) out.append(py::cast(&row, kReference));
  return out;
}

py::object fapuOrNone(FapuKind kind) {
  if (kind == FapuKind::None) return py::none();
  return toPy(fapuName(kind));
}

// A read-only str property over a std::string_view member.
template <typename T>
void text(py::class_<T>& cls, const char* name, std::string_view T::*member, const char* doc) {
  cls.def_property_readonly(
      name, [member](const T& row) { return toPy(row.*member); }, doc);
}

void bindFaps(py::module_& m) {
  py::class_<FapInfo> cls(m, "FapInfo", "One row of the 68-FAP table (read-only).");
  cls.def_readonly("number", &FapInfo::number, "FAP number, 1..68.");
  text(cls, "name", &FapInfo::name, "Standard name, e.g. \"open_jaw\".");
  text(cls, "bifs_name", &FapInfo::bifsName,
       "BIFS FAP node field name (usually the same as name).");
  cls.def_property_readonly(
      "fapu", [](const FapInfo& f) { return fapuOrNone(f.fapu); },
      "Unit name (\"IRISD\", \"ES\", \"ENS\", \"MNS\", \"MW\" or \"AU\"); None for FAP 1 "
      "and 2.");
  cls.def_readonly("bidirectional", &FapInfo::bidirectional,
                   "True if the FAP moves both ways (B), False if unidirectional (U).");
  text(cls, "positive_motion", &FapInfo::positiveMotion,
       "Direction of positive values, e.g. \"down\" (\"\" for FAP 1, 2).");
  cls.def_readonly("group", &FapInfo::group, "FAP group, 1..10.");
  text(cls, "feature_point", &FapInfo::featurePoint,
       "Feature point(s) moved, e.g. \"2.1\" (\"\" for FAP 1, 2).");
  cls.def_readonly("quant_step", &FapInfo::quantStep, "Quantiser step size QP.");
  cls.def_readonly("intra_range", &FapInfo::intraRange, "Default I-frame range (+-).");
  cls.def_readonly("inter_range", &FapInfo::interRange, "Default P-frame range (+-).");
  cls.def("__repr__", [](const FapInfo& f) {
    return "<FapInfo " + std::to_string(f.number) + " " + std::string(f.name) + ">";
  });

  m.attr("FAP_COUNT") = kFapCount;
  m.def(
      "faps", [] { return rows(fapTable()); },
      "All 68 FAPs as a list of FapInfo; index i holds FAP i + 1.");
  m.def(
      "fap", [](int number) { return &fapInfo(number); }, "number"_a, kReference,
      "The FapInfo of FAP `number` (1..68); raises mpeg4face.Error otherwise.");
  m.def("fap_number", &fapNumber, "name"_a,
        "FAP number of a standard name or BIFS field name, or None if unknown. Standard names "
        "win: \"stretch_l_cornerlip\" gives 6 although it is also FAP 53's BIFS field name.");

  py::class_<FapGroupInfo> group(m, "FapGroupInfo", "One of the ten FAP groups (read-only).");
  group.def_readonly("number", &FapGroupInfo::number, "Group number, 1..10.");
  text(group, "name", &FapGroupInfo::name, "Group name.");
  group.def_readonly("first_fap", &FapGroupInfo::firstFap, "First FAP of the group.");
  group.def_readonly("last_fap", &FapGroupInfo::lastFap, "Last FAP of the group.");
  group.def("__repr__", [](const FapGroupInfo& g) {
    return "<FapGroupInfo " + std::to_string(g.number) + " " + std::string(g.name) + ">";
  });
  m.def(
      "fap_groups", [] { return rows(fapGroupTable()); }, "The ten FAP groups.");
}

void bindFeaturePoints(py::module_& m) {
  py::class_<FeaturePointInfo> cls(m, "FeaturePointInfo",
                                   "One MPEG-4 feature point with its recommended location "
                                   "constraints (read-only).");
  text(cls, "id", &FeaturePointInfo::id, "Id such as \"2.1\".");
  cls.def_readonly("group", &FeaturePointInfo::group, "Group, 2..11.");
  cls.def_readonly("index", &FeaturePointInfo::index, "Index within the group.");
  text(cls, "description", &FeaturePointInfo::description, "Description of the location.");
  text(cls, "constraint_x", &FeaturePointInfo::constraintX,
       "Location constraint on x: space-separated `OP EXPR` terms, e.g. \"=7.1.x\"; \"\" none.");
  text(cls, "constraint_y", &FeaturePointInfo::constraintY, "Location constraint on y.");
  text(cls, "constraint_z", &FeaturePointInfo::constraintZ, "Location constraint on z.");
  text(cls, "constraint_note", &FeaturePointInfo::constraintNote,
       "Alternative location the paper allows, or \"\".");
  cls.def_readonly("in_standard", &FeaturePointInfo::inStandard,
                   "False only for 7.2, which Pandzic's FMC adds.");
  cls.def("__repr__", [](const FeaturePointInfo& f) {
    return "<FeaturePointInfo " + std::string(f.id) + ": " + std::string(f.description) + ">";
  });

  m.attr("FEATURE_POINT_COUNT") = kFeaturePointCount;
  m.def(
      "feature_points", [] { return rows(featurePointTable()); },
      "All feature points (the 84 of the standard plus 7.2) in group/index order.");
  m.def(
      "feature_point",
      [](std::string_view id) -> py::object {
        const FeaturePointInfo* info = findFeaturePoint(id);
        if (info == nullptr) return py::none();
        return py::cast(info, kReference);
      },
      "id"_a, "The FeaturePointInfo of `id` (e.g. \"2.1\"), or None if unknown.");
}

void bindFapuTable(py::module_& m) {
  py::class_<FapuInfo> cls(m, "FapuInfo", "One Face Animation Parameter Unit (read-only).");
  text(cls, "name", &FapuInfo::name, "\"IRISD\", \"ES\", \"ENS\", \"MNS\", \"MW\" or \"AU\".");
  text(cls, "neutral_name", &FapuInfo::neutralName,
       "The neutral-face distance, e.g. \"ES0\" (\"\" for AU).");
  text(cls, "description", &FapuInfo::description, "What the distance is.");
  text(cls, "definition", &FapuInfo::definition, "E.g. \"ES = ES0 / 1024\".");
  cls.def("__repr__", [](const FapuInfo& f) { return "<FapuInfo " + std::string(f.name) + ">"; });

  m.attr("ANGLE_UNIT") = kAngleUnitRadians;
  m.attr("FAPU_DIVISOR") = kFapuDivisor;
  m.def(
      "fapu_table", [] { return rows(fapuTable()); }, "The six FAPU: IRISD, ES, ENS, MNS, MW, AU.");
}

void bindVisemesAndExpressions(py::module_& m) {
  py::class_<VisemeInfo> viseme(m, "VisemeInfo", "One value of FAP 1 (read-only).");
  viseme.def_readonly("number", &VisemeInfo::number, "Viseme number, 0..14.");
  text(viseme, "phonemes", &VisemeInfo::phonemes, "E.g. \"p, b, m\".");
  text(viseme, "example", &VisemeInfo::example, "E.g. \"put, bed, mill\".");
  viseme.def("__repr__", [](const VisemeInfo& v) {
    return "<VisemeInfo " + std::to_string(v.number) + ": " + std::string(v.phonemes) + ">";
  });
  m.def(
      "visemes", [] { return rows(visemeTable()); }, "The 15 visemes of FAP 1.");

  py::class_<ExpressionInfo> expression(m, "ExpressionInfo", "One value of FAP 2 (read-only).");
  expression.def_readonly("number", &ExpressionInfo::number, "Expression number, 0..6.");
  text(expression, "name", &ExpressionInfo::name, "E.g. \"joy\".");
  text(expression, "description", &ExpressionInfo::description, "Textual description.");
  expression.def("__repr__", [](const ExpressionInfo& e) {
    return "<ExpressionInfo " + std::to_string(e.number) + " " + std::string(e.name) + ">";
  });
  m.def(
      "expressions", [] { return rows(expressionTable()); }, "The 7 expressions of FAP 2.");
}

}  // namespace

void bindSpec(py::module_& m) {
  bindFaps(m);
  bindFeaturePoints(m);
  bindFapuTable(m);
  bindVisemesAndExpressions(m);
}

}  // namespace mpeg4face::python
