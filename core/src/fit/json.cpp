// SPDX-License-Identifier: GPL-3.0-or-later
// The FAP Interpolation Table as JSON, with nlohmann::json.
#include "mpeg4face/fit/json.hpp"

#include <cctype>
#include <nlohmann/json.hpp>

#include "io/json_reader.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"

namespace mpeg4face {
namespace {

using Json = nlohmann::ordered_json;
constexpr const char* kFormat = "mpeg4face-fit";

constexpr std::array<int, 4> kSelects{kVisemeSelect1, kVisemeSelect2, kExpressionSelect1,
                                      kExpressionSelect2};

Json termJson(const FitTerm& term) {
  Json j{{"coefficient", term.coefficient}, {"exponents", term.exponents}};
  if (term.impulseSelect != 0) {
    j["impulse"] = {{"select", fitVariableName(term.impulseSelect)}, {"value", term.impulseValue}};
  }
  return j;
}

// The FIT's own value: a term, with the JSON path of each of its values in errors.
struct Reader : JsonReader<Json> {
  FitTerm term(const Json& j, const std::string& path) const {
    FitTerm t;
    t.coefficient = number(j, path, "coefficient");
    const Json& exponents = array(j, path, "exponents");
    for (std::size_t i = 0; i < exponents.size(); ++i) {
      t.exponents.push_back(integer(exponents[i], elementPath(path + ".exponents", i)));
    }
    if (j.contains("impulse")) {
      const std::string at = path + ".impulse";
      const Json& select = member(j["impulse"], at, "select");
      if (!select.is_string()) fail(at + ".select", "expected a select's name");
      for (int s : kSelects) {
        if (fitVariableName(s) == select.get<std::string>()) t.impulseSelect = s;
      }
      if (t.impulseSelect == 0) {
        fail(at + ".select",
             "'" + select.get<std::string>() + "' is not viseme_select1/2 or expression_select1/2");
      }
      t.impulseValue = integer(j["impulse"], at, "value");
    }
    return t;
  }
};

// nlohmann's indented output puts every array element on a line of its own; FAP sets and
// exponent lists read better on one line each.
std::string withFlatInnerArrays(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const std::size_t close = text[i] == '[' ? text.find(']', i) : std::string::npos;
    if (close == std::string::npos || text.find_first_of("[{\"", i + 1) < close) {
      out += text[i];
      continue;
    }
    out += '[';
    bool space = false;
    for (std::size_t k = i + 1; k < close; ++k) {
      if (std::isspace(static_cast<unsigned char>(text[k]))) {
        space = true;
      } else {
        if (space && out.back() == ',') out += ' ';
        space = false;
        out += text[k];
      }
    }
    out += ']';
    i = close;
  }
  return out;
}

}  // namespace

std::string fitTableToJson(const FitTable& table) {
  Json j{{"format", kFormat}, {"version", 1}, {"nodes", table.nodes}, {"links", Json::array()}};
  for (const FitLink& link : table.links) {
    Json l{{"parent", link.parent}, {"child", link.child}, {"functions", Json::array()}};
    const auto& child = table.nodes.at(static_cast<std::size_t>(link.child));
    for (std::size_t i = 0; i < link.functions.size(); ++i) {
      Json f{{"fap", i < child.size() ? child[i] : 0},
             {"numerator", Json::array()},
             {"denominator", Json::array()}};
      for (const FitTerm& t : link.functions[i].numerator) f["numerator"].push_back(termJson(t));
      for (const FitTerm& t : link.functions[i].denominator)
        f["denominator"].push_back(termJson(t));
      l["functions"].push_back(std::move(f));
    }
    j["links"].push_back(std::move(l));
  }
  return withFlatInnerArrays(j.dump(2)) + "\n";
}

FitTable fitTableFromJson(const std::string& text, const std::string& source) {
  const Reader r{{source}};
  const Json j = parseJson<Json>(text, source);
  const Json& format = r.member(j, "(top)", "format");
  if (format != kFormat) r.fail("format", std::string("expected \"") + kFormat + "\"");
  if (r.integer(j, "(top)", "version") != 1) r.fail("version", "expected 1");
  FitTable table;
  const Json& nodes = r.array(j, "(top)", "nodes");
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    const std::string path = r.elementPath("nodes", n);
    if (!nodes[n].is_array()) r.fail(path, "expected an array of FAP numbers");
    auto& faps = table.nodes.emplace_back();
    for (std::size_t i = 0; i < nodes[n].size(); ++i) {
      faps.push_back(r.integer(nodes[n][i], r.elementPath(path, i)));
    }
  }
  const Json& links = r.array(j, "(top)", "links");
  for (std::size_t k = 0; k < links.size(); ++k) {
    const std::string path = r.elementPath("links", k);
    FitLink& link = table.links.emplace_back();
    link.parent = r.integer(links[k], path, "parent");
    link.child = r.integer(links[k], path, "child");
    if (link.child < 0 || link.child >= static_cast<int>(table.nodes.size())) {
      r.fail(path + ".child", "no node " + std::to_string(link.child));
    }
    const auto& child = table.nodes[static_cast<std::size_t>(link.child)];
    const Json& functions = r.array(links[k], path, "functions");
    for (std::size_t i = 0; i < functions.size(); ++i) {
      const std::string at = r.elementPath(path + ".functions", i);
      const int fap = r.integer(functions[i], at, "fap");
      if (i >= child.size() || child[i] != fap) {
        r.fail(at + ".fap", "FAP " + std::to_string(fap) + " is not the child node's FAP number " +
                                std::to_string(i));
      }
      FitFunction& f = link.functions.emplace_back();
      for (const auto& [key, terms] :
           {std::pair{"numerator", &f.numerator}, std::pair{"denominator", &f.denominator}}) {
        const Json& list = r.array(functions[i], at, key);
        for (std::size_t t = 0; t < list.size(); ++t) {
          terms->push_back(r.term(list[t], r.elementPath(at + "." + key, t)));
        }
      }
    }
  }
  validateFitTable(table, source);
  return table;
}

void writeFitJson(const FitTable& table, const std::filesystem::path& path) {
  writeFileAtomically(path, fitTableToJson(table));
}

FitTable readFitJson(const std::filesystem::path& path) {
  return fitTableFromJson(readFile(path), path.string());
}

}  // namespace mpeg4face
