// SPDX-License-Identifier: GPL-3.0-or-later
// glTF reader: accessor decoding. tinygltf only parses the JSON and loads the buffers; it
// does not check accessors against their buffers. Every accessor is therefore read here
// with explicit bounds and type checks, and problems are reported as mpeg4face::Error
// naming the JSON path that is at fault.
#include <algorithm>
#include <cstring>

#include "io/gltf_reader.hpp"

namespace mpeg4face::gltf_reader {

namespace {

std::string typeName(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT2:
      return "MAT2";
    case TINYGLTF_TYPE_MAT3:
      return "MAT3";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "type " + std::to_string(type);
  }
}

std::string componentTypeName(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_INT:
      return "INT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return "FLOAT";
    default:
      return "component type " + std::to_string(componentType);
  }
}

int componentSize(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;  // INT and DOUBLE are not glTF 2.0 accessor types
  }
}

// Little-endian component at p (glTF is little-endian; so is every platform we build on).
template <typename T>
T load(const unsigned char* p) {
  T value;
  std::memcpy(&value, p, sizeof value);
  return value;
}

double readComponent(const unsigned char* p, int componentType, bool normalized) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return load<float>(p);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      const double v = load<uint8_t>(p);
      return normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const double v = load<int8_t>(p);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      const double v = load<uint16_t>(p);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      const double v = load<int16_t>(p);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return load<uint32_t>(p);
    default:
      return 0;
  }
}

// a * b + c without overflow; false when it does not fit.
bool mulAdd(uint64_t a, uint64_t b, uint64_t c, uint64_t& out) {
  uint64_t product = 0;
  return !__builtin_mul_overflow(a, b, &product) && !__builtin_add_overflow(product, c, &out);
}

}  // namespace

Reader::Reader(const tinygltf::Model& gltf, const std::string& fileName)
    : gltf_(gltf), fileName_(fileName) {
  for (const tinygltf::Buffer& b : gltf_.buffers) valueBudget_ += 4 * b.data.size();
  valueBudget_ += kMaxSyntheticValues;
}

// The bytes of buffer view `index`, checked against its buffer.
std::pair<const unsigned char*, uint64_t> Reader::viewBytes(int index, const std::string& field,
                                                            const std::string& what) const {
  if (index < 0 || static_cast<size_t>(index) >= gltf_.bufferViews.size()) {
    fail(field,
         what + " refers to buffer view " + std::to_string(index) + ", which does not exist");
  }
  const tinygltf::BufferView& view = gltf_.bufferViews[index];
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= gltf_.buffers.size()) {
    fail(field, what + ": buffer view " + std::to_string(index) + " refers to buffer " +
                    std::to_string(view.buffer) + ", which does not exist");
  }
  const std::vector<unsigned char>& data = gltf_.buffers[view.buffer].data;
  if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset) {
    fail(field, what + ": buffer view " + std::to_string(index) + " (bytes " +
                    str(view.byteOffset) + ".." + str(view.byteOffset + view.byteLength) +
                    ") runs past the end of buffer " + std::to_string(view.buffer) + " (" +
                    str(data.size()) + " bytes)");
  }
  return {data.data() + view.byteOffset, view.byteLength};
}

void Reader::spend(uint64_t values, const std::string& field) {
  if (values > valueBudget_) {
    fail(field, "the file decodes far more data than its buffers hold (" + str(values) +
                    " more values); refusing it");
  }
  valueBudget_ -= values;
}

// Reads accessor `index` (referenced at JSON path `field`) as doubles, count * components,
// after checking its type, its component type and that every element lies in its buffer.
std::vector<double> Reader::readAccessor(int index, const std::string& field,
                                         const AccessorSpec& spec,
                                         std::optional<uint64_t> expectedCount) {
  if (index < 0 || static_cast<size_t>(index) >= gltf_.accessors.size()) {
    fail(field, "accessor " + std::to_string(index) + " does not exist (the file has " +
                    str(gltf_.accessors.size()) + ")");
  }
  const tinygltf::Accessor& a = gltf_.accessors[index];
  const std::string what = "accessor " + std::to_string(index);
  if (a.type != spec.type) {
    fail(field, what + " has type " + typeName(a.type) + ", expected " + typeName(spec.type));
  }
  const int ct = a.componentType;
  const bool isFloat = ct == TINYGLTF_COMPONENT_TYPE_FLOAT;
  const bool smallInt =
      ct == TINYGLTF_COMPONENT_TYPE_BYTE || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
      ct == TINYGLTF_COMPONENT_TYPE_SHORT || ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
  const bool unsignedInt = ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                           ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
                           ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  const bool ok = (isFloat && spec.floats) || (smallInt && a.normalized && spec.normalizedInts) ||
                  (unsignedInt && !a.normalized && spec.unsignedInts);
  if (!ok) {
    fail(field, what + " has component type " + (a.normalized ? "normalized " : "") +
                    componentTypeName(ct) + ", which is not allowed here");
  }
  if (expectedCount && a.count != *expectedCount) {
    fail(field, what + " has " + str(a.count) + " elements, expected " + str(*expectedCount));
  }
  const uint64_t components = static_cast<uint64_t>(tinygltf::GetNumComponentsInType(a.type));
  const uint64_t size = static_cast<uint64_t>(componentSize(ct));
  const uint64_t elementSize = components * size;
  uint64_t valueCount = 0;
  if (!mulAdd(a.count, components, 0, valueCount)) fail(field, what + " count is too large");

  std::vector<double> values;
  if (a.bufferView != -1) {  // tinygltf's "absent"; other negative values are errors
    const auto [bytes, length] = viewBytes(a.bufferView, field, what);
    const uint64_t viewStride = gltf_.bufferViews[a.bufferView].byteStride;
    const uint64_t stride = viewStride != 0 ? viewStride : elementSize;
    if (stride < elementSize) {
      fail(field, what + ": byteStride " + str(stride) + " is smaller than one element (" +
                      str(elementSize) + " bytes)");
    }
    // The last element ends at byteOffset + (count - 1) * stride + elementSize.
    uint64_t end = 0;
    if (a.count > 0 &&
        (a.byteOffset > length || !mulAdd(a.count - 1, stride, a.byteOffset + elementSize, end) ||
         end > length)) {
      fail(field, what + " (" + str(a.count) + " x " + typeName(a.type) + " " +
                      componentTypeName(ct) + " from byte " + str(a.byteOffset) +
                      ") runs past the end of buffer view " + std::to_string(a.bufferView) + " (" +
                      str(length) + " bytes)");
    }
    spend(valueCount, field);
    values.resize(valueCount);
    for (uint64_t i = 0; i < a.count; ++i) {
      const unsigned char* element = bytes + a.byteOffset + i * stride;
      for (uint64_t c = 0; c < components; ++c) {
        values[i * components + c] = readComponent(element + c * size, ct, a.normalized);
      }
    }
  } else {
    if (valueCount > kMaxSyntheticValues) {
      fail(field, what + " has no buffer view and " + str(a.count) + " elements; at most " +
                      str(kMaxSyntheticValues / components) + " are accepted");
    }
    spend(valueCount, field);
    values.assign(valueCount, 0.0);  // the spec's initial value without a buffer view
  }
  if (a.sparse.isSparse) readSparse(a, what, field, components, elementSize, values);
  return values;
}

void Reader::readSparse(const tinygltf::Accessor& a, const std::string& what,
                        const std::string& field, uint64_t components, uint64_t elementSize,
                        std::vector<double>& values) const {
  const auto& sparse = a.sparse;
  if (sparse.count < 1 || static_cast<uint64_t>(sparse.count) > a.count) {
    fail(field, what + ": sparse count " + std::to_string(sparse.count) +
                    " must be between 1 and the accessor count " + str(a.count));
  }
  const uint64_t n = static_cast<uint64_t>(sparse.count);
  const int indexType = sparse.indices.componentType;
  if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
      indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
    fail(field, what + ": sparse indices have component type " + componentTypeName(indexType) +
                    ", expected an unsigned integer type");
  }
  if (sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0) {
    fail(field, what + ": negative sparse byteOffset");
  }
  const uint64_t indexSize = static_cast<uint64_t>(componentSize(indexType));
  const auto [indexBytes, indexLength] =
      viewBytes(sparse.indices.bufferView, field, what + " sparse indices");
  const auto [valueBytes, valueLength] =
      viewBytes(sparse.values.bufferView, field, what + " sparse values");
  uint64_t indexEnd = 0;
  uint64_t valueEnd = 0;
  if (!mulAdd(n, indexSize, static_cast<uint64_t>(sparse.indices.byteOffset), indexEnd) ||
      indexEnd > indexLength) {
    fail(field, what + ": sparse indices run past the end of buffer view " +
                    std::to_string(sparse.indices.bufferView));
  }
  if (!mulAdd(n, elementSize, static_cast<uint64_t>(sparse.values.byteOffset), valueEnd) ||
      valueEnd > valueLength) {
    fail(field, what + ": sparse values run past the end of buffer view " +
                    std::to_string(sparse.values.bufferView));
  }
  const uint64_t size = elementSize / components;
  for (uint64_t k = 0; k < n; ++k) {
    const auto target = static_cast<uint64_t>(
        readComponent(indexBytes + sparse.indices.byteOffset + k * indexSize, indexType, false));
    if (target >= a.count) {
      fail(field, what + ": sparse index " + str(target) + " is out of range (count " +
                      str(a.count) + ")");
    }
    const unsigned char* element = valueBytes + sparse.values.byteOffset + k * elementSize;
    for (uint64_t c = 0; c < components; ++c) {
      values[target * components + c] =
          readComponent(element + c * size, a.componentType, a.normalized);
    }
  }
}

// The accessor index of `attributes[name]`, or -1.
int Reader::attribute(const std::map<std::string, int>& attributes, const std::string& name) {
  auto it = attributes.find(name);
  return it == attributes.end() ? -1 : it->second;
}

uint64_t Reader::accessorCount(int index) const {
  return index >= 0 && static_cast<size_t>(index) < gltf_.accessors.size()
             ? gltf_.accessors[index].count
             : 0;
}

}  // namespace mpeg4face::gltf_reader
