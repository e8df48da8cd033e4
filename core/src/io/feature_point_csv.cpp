// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/io/feature_point_csv.hpp"

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>

#include "io/text_reader.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

// One CSV record and the line it starts on (a quoted field may continue on later lines).
struct Record {
  int line = 0;
  std::vector<std::string> fields;
};

// A column as messages name it: by its header name, else by its position.
std::string columnName(const std::vector<std::string>& names, std::size_t column) {
  return column < names.size() && !names[column].empty() ? names[column]
                                                         : "column " + std::to_string(column + 1);
}

std::string lowerCase(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// RFC 4180 records: fields separated by ',', a field in double quotes may hold ',', '""' for
// a quote and line breaks. Spaces around unquoted fields are trimmed; blank lines and lines
// starting with '#' are skipped.
class CsvReader {
 public:
  CsvReader(std::string_view text, const std::string& fileName) : reader_(text, fileName) {}

  const std::string& fileName() const { return reader_.fileName(); }
  // Header names, for messages about later records.
  void setColumnNames(std::vector<std::string> names) { names_ = std::move(names); }

  bool next(Record& record) {
    std::string_view line;
    do {
      if (!reader_.next(line)) return false;
    } while (text::trim(line).empty() || text::trim(line).front() == '#');
    record.line = reader_.lineNumber();
    record.fields.clear();
    std::string field;
    std::size_t i = 0;
    while (true) {
      // One field starting at line[i].
      field.clear();
      while (i < line.size() && text::isSpace(line[i])) ++i;
      if (i < line.size() && line[i] == '"') {
        ++i;
        while (true) {
          const std::size_t quote = line.find('"', i);
          if (quote == std::string_view::npos) {
            field.append(line.substr(i));
            field += '\n';
            if (!reader_.next(line)) {
              throw Error(fileName(), record.line, columnName(names_, record.fields.size()),
                          "quoted field not closed (it starts on this line)");
            }
            i = 0;
            continue;
          }
          field.append(line.substr(i, quote - i));
          i = quote + 1;
          if (i < line.size() && line[i] == '"') {
            field += '"';
            ++i;
            continue;
          }
          break;
        }
        while (i < line.size() && text::isSpace(line[i])) ++i;
        if (i < line.size() && line[i] != ',') {
          // Most likely an earlier quote was never closed and this one closes it by accident.
          const bool spanned = reader_.lineNumber() != record.line;
          reader_.fail(columnName(names_, record.fields.size()),
                       "',' expected after the closing quote, found " +
                           text::quote(line.substr(i, 1)) +
                           (spanned ? " (is the quote opened on line " +
                                          std::to_string(record.line) + " not closed?)"
                                    : std::string()));
        }
      } else {
        const std::size_t comma = std::min(line.find(',', i), line.size());
        field.assign(text::trim(line.substr(i, comma - i)));
        i = comma;
      }
      record.fields.push_back(field);
      if (i >= line.size()) return true;
      ++i;  // past the ','
    }
  }

 private:
  text::LineReader reader_;
  std::vector<std::string> names_;
};

// Which field holds what; kNone when the file has no such column.
struct Columns {
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::size_t fp = kNone, mesh = kNone, vertex = kNone, x = kNone, y = kNone, z = kNone;
  std::vector<std::string> names;  // for messages
};

Columns columnsFromHeader(const Record& header, const std::string& fileName) {
  Columns c;
  const auto take = [](std::size_t& slot, std::size_t i) {
    if (slot == Columns::kNone) slot = i;  // a repeated name: the first column counts
  };
  for (std::size_t i = 0; i < header.fields.size(); ++i) {
    const std::string name = lowerCase(header.fields[i]);
    if (name == "fp" || name == "mpeg4_fp" || name == "feature_point") {
      take(c.fp, i);
    } else if (name == "vertex" || (name.size() > 7 && name.ends_with("_vertex"))) {
      take(c.vertex, i);
    } else if (name == "mesh") {
      take(c.mesh, i);
    } else if (name == "x") {
      take(c.x, i);
    } else if (name == "y") {
      take(c.y, i);
    } else if (name == "z") {
      take(c.z, i);
    }
  }
  if (c.fp == Columns::kNone) {
    throw Error(fileName, header.line, {},
                "no feature point column (fp, mpeg4_fp or feature_point) in the header");
  }
  const bool xyz = c.x != Columns::kNone && c.y != Columns::kNone && c.z != Columns::kNone;
  if (c.vertex == Columns::kNone && !xyz) {
    throw Error(fileName, header.line, {}, "no vertex column (vertex, *_vertex) nor x, y, z");
  }
  c.names = header.fields;
  return c;
}

// Without a header the number of fields says what they are.
Columns columnsFromWidth(const Record& record, const std::string& fileName) {
  Columns c;
  c.fp = 0;
  switch (record.fields.size()) {
    case 2:
      c.vertex = 1;
      c.names = {"fp", "vertex"};
      break;
    case 3:
      c.mesh = 1;
      c.vertex = 2;
      c.names = {"fp", "mesh", "vertex"};
      break;
    case 4:
      c.x = 1;
      c.y = 2;
      c.z = 3;
      c.names = {"fp", "x", "y", "z"};
      break;
    default:
      throw Error(fileName, record.line, {},
                  "2 to 4 columns expected (fp,vertex / fp,mesh,vertex / fp,x,y,z), found " +
                      std::to_string(record.fields.size()));
  }
  return c;
}

// Resolves vertex numbers to (mesh, vertex) as io/feature_point_csv.hpp describes.
class VertexResolver {
 public:
  explicit VertexResolver(const FaceModel& model) : model_(model) {}

  // Binds `vertex` of `mesh`, or without a mesh as io/feature_point_csv.hpp describes. Returns
  // what is wrong, or "" with `binding` set.
  std::string resolve(std::optional<int> mesh, int vertex, FeaturePointBinding& binding) {
    if (mesh) return bind(*mesh, vertex, binding);
    const int meshCount = static_cast<int>(model_.meshes.size());
    if (meshCount == 0) return "the model has no mesh to bind vertices to";
    // A file's vertex numbers count vertices no face uses, which the reader drops: even one
    // mesh is looked up through sourceIndex.
    const bool bySource =
        std::any_of(model_.meshes.begin(), model_.meshes.end(),
                    [](const IndexedFaceSet& m) { return !m.sourceIndex.empty(); });
    if (bySource) {
      if (source_.empty()) {
        // A file vertex shared by several meshes binds to the first of them.
        for (int m = 0; m < meshCount; ++m) {
          const std::vector<int>& index = model_.meshes[m].sourceIndex;
          for (std::size_t i = 0; i < index.size(); ++i) {
            source_.try_emplace(index[i], m, static_cast<int>(i));
          }
        }
      }
      const auto it = source_.find(vertex);
      if (it == source_.end()) {
        return "no mesh holds vertex " + std::to_string(vertex) + " of the model's file";
      }
      binding.mesh = it->second.first;
      binding.vertex = it->second.second;
      return {};
    }
    if (meshCount == 1) return bind(0, vertex, binding);
    int first = 0;  // the meshes' vertices counted one after the other
    for (int m = 0; m < meshCount; ++m) {
      const int count = model_.meshes[m].vertexCount();
      if (vertex >= first && vertex - first < count) return bind(m, vertex - first, binding);
      first += count;
    }
    return "vertex " + std::to_string(vertex) + " out of range (the meshes have " +
           std::to_string(first) + " vertices in all)";
  }

 private:
  std::string bind(int mesh, int vertex, FeaturePointBinding& binding) const {
    const IndexedFaceSet& m = model_.meshes[mesh];
    if (vertex < 0 || vertex >= m.vertexCount()) {
      return "vertex " + std::to_string(vertex) + " out of range (mesh '" + m.name + "' has " +
             std::to_string(m.vertexCount()) + " vertices)";
    }
    binding.mesh = mesh;
    binding.vertex = vertex;
    return {};
  }

  const FaceModel& model_;
  std::unordered_map<int, std::pair<int, int>> source_;
};

}  // namespace

FeaturePointCsv parseFeaturePointCsv(std::string_view text, const std::string& fileName,
                                     const FaceModel& model) {
  CsvReader csv(text, fileName);
  VertexResolver resolver(model);
  FeaturePointCsv result;
  std::unordered_map<std::string, int> firstLine;
  std::optional<Columns> header;
  bool firstRecord = true;
  Record record;
  while (csv.next(record)) {
    if (firstRecord) {
      firstRecord = false;
      // Feature point ids and vertex numbers are numbers; column names are not.
      double number = 0;
      if (!record.fields[0].empty() && !text::tryParseDouble(record.fields[0], number)) {
        header = columnsFromHeader(record, fileName);
        csv.setColumnNames(record.fields);
        continue;
      }
    }
    const Columns columns = header ? *header : columnsFromWidth(record, fileName);
    const auto field = [&](std::size_t column) -> std::string_view {
      return column < record.fields.size() ? std::string_view(record.fields[column]) : "";
    };
    const auto fail = [&](std::size_t column, const std::string& message) {
      return Error(fileName, record.line, columnName(columns.names, column), message);
    };

    const std::string id(field(columns.fp));
    if (id.empty()) throw fail(columns.fp, "feature point id missing");
    if (findFeaturePoint(id) == nullptr) {
      throw fail(columns.fp,
                 "unknown feature point " + text::quote(id) + " (not in the MPEG-4 table)");
    }

    FeaturePointBinding binding;
    if (!field(columns.vertex).empty()) {
      const int vertex = text::parseInt(field(columns.vertex), fileName, record.line,
                                        columnName(columns.names, columns.vertex));
      std::optional<int> mesh;
      if (!field(columns.mesh).empty()) {
        mesh = model.findMesh(text::toUtf8(field(columns.mesh)));
        if (!mesh) throw fail(columns.mesh, "unknown mesh " + text::quote(field(columns.mesh)));
      }
      const std::string problem = resolver.resolve(mesh, vertex, binding);
      if (!problem.empty()) throw fail(columns.vertex, problem);
    } else if (columns.x != Columns::kNone) {
      const std::size_t xyz[3] = {columns.x, columns.y, columns.z};
      for (int k = 0; k < 3; ++k) {
        binding.position[k] = text::parseDouble(field(xyz[k]), fileName, record.line,
                                                columnName(columns.names, xyz[k]));
      }
    } else {
      throw fail(columns.vertex, "vertex missing");
    }

    const auto [it, added] = firstLine.try_emplace(id, record.line);
    if (added) {
      result.featurePoints.emplace(id, binding);
    } else {
      result.warnings.push_back(fileName + ":" + std::to_string(record.line) + ": feature point " +
                                id + " is bound again (first on line " +
                                std::to_string(it->second) + "); the first binding is kept");
    }
  }
  if (firstLine.empty()) throw Error(fileName, 0, {}, "no feature point rows");
  return result;
}

FeaturePointCsv readFeaturePointCsv(const std::filesystem::path& path, const FaceModel& model) {
  return parseFeaturePointCsv(readFile(path), path.string(), model);
}

}  // namespace mpeg4face
