// SPDX-License-Identifier: GPL-3.0-or-later
// Reading a JSON document (nlohmann::json) whose errors name the JSON path of the value at
// fault, "links[0].functions[1].fap", and for a syntax error its line and column: the FIT and
// 2D mesh formats share it.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <string_view>
#include <utility>

#include "mpeg4face/error.hpp"

namespace mpeg4face {

// Line and column of a byte offset, 1-based.
inline std::pair<int, int> lineColumn(std::string_view text, std::size_t byte) {
  byte = std::min(byte, text.size());
  int line = 1, column = 1;
  for (std::size_t i = 0; i < byte; ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return {line, column};
}

// Json: nlohmann::json or nlohmann::ordered_json.
template <class Json>
Json parseJson(std::string_view text, const std::string& source) {
  try {
    return Json::parse(text);
  } catch (const typename Json::parse_error& e) {
    // nlohmann's byte is one past the offending character.
    const auto [line, column] = lineColumn(text, e.byte > 0 ? e.byte - 1 : 0);
    throw Error(source, line, "JSON",
                "column " + std::to_string(column) + ": not valid JSON: " + e.what());
  } catch (const typename Json::exception& e) {  // out_of_range for 1e999
    throw Error(source, 0, "JSON", std::string("not valid JSON: ") + e.what());
  }
}

// The top-level object's path is "(top)"; a member's is its object's path, ".", its key.
template <class Json>
struct JsonReader {
  std::string source;

  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw Error(source, 0, path, what);
  }
  static std::string memberPath(const std::string& path, const char* key) {
    return path == "(top)" ? key : path + "." + key;
  }
  static std::string elementPath(const std::string& path, std::size_t i) {
    return path + "[" + std::to_string(i) + "]";
  }
  // A missing member is reported at its object.
  const Json& member(const Json& object, const std::string& path, const char* key) const {
    if (!object.is_object()) fail(path, "expected an object");
    const auto it = object.find(key);
    if (it == object.end()) fail(path, std::string("has no \"") + key + "\"");
    return *it;
  }
  const Json& array(const Json& value, const std::string& path) const {
    if (!value.is_array()) fail(path, "expected an array");
    return value;
  }
  const Json& array(const Json& object, const std::string& path, const char* key) const {
    return array(member(object, path, key), memberPath(path, key));
  }
  int integer(const Json& value, const std::string& path) const {
    if (!value.is_number_integer()) fail(path, "expected an integer");
    const auto v = value.template get<long long>();
    if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
      fail(path, "out of range");
    }
    return static_cast<int>(v);
  }
  int integer(const Json& object, const std::string& path, const char* key) const {
    return integer(member(object, path, key), memberPath(path, key));
  }
  double number(const Json& value, const std::string& path) const {
    if (!value.is_number()) fail(path, "expected a number");
    const double v = value.template get<double>();
    if (!std::isfinite(v)) fail(path, "expected a finite number");
    return v;
  }
  double number(const Json& object, const std::string& path, const char* key) const {
    return number(member(object, path, key), memberPath(path, key));
  }
};

}  // namespace mpeg4face
