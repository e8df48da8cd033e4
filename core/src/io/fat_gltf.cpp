// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/io/fat_gltf.hpp"

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "io/gltf_internal.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/io/gltf.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

constexpr int kExpressionCount = 7;

std::string str(size_t n) { return std::to_string(n); }

[[noreturn]] void fail(const std::string& field, const std::string& message) {
  throw Error({}, 0, field, message);
}

std::string tableField(size_t t) { return "faceDefTables[" + str(t) + "]"; }

// The first morph target of each FaceDefMesh in fatMorphModel's output, [table][faceDefMesh]:
// after the mesh's own targets, tables in order, a table's FaceDefMesh in order.
std::vector<std::vector<int>> firstTargets(const MpegFace& face) {
  std::vector<int> next;
  for (const IndexedFaceSet& mesh : face.faceSceneGraph.meshes) {
    next.push_back(static_cast<int>(mesh.morphTargets.size()));
  }
  std::vector<std::vector<int>> first;
  for (const FaceDefTables& table : face.faceDefTables) {
    first.emplace_back();
    for (const FaceDefMesh& def : table.faceDefMesh) {
      first.back().push_back(next[def.mesh]);
      next[def.mesh] += def.intervalCount();
    }
  }
  return first;
}

tinygltf::Value numbers(std::initializer_list<double> values) {
  tinygltf::Value::Array out;
  for (double v : values) out.emplace_back(v);
  return tinygltf::Value(std::move(out));
}

tinygltf::Value integers(const std::vector<int>& values) {
  tinygltf::Value::Array out;
  for (int v : values) out.emplace_back(v);
  return tinygltf::Value(std::move(out));
}

// scenes[0].extras.mpeg4face beside the feature points: the FAPU and the tables.
tinygltf::Value::Object fatExtras(const MpegFace& face, const FapuMeasurement& fapu) {
  const FaceModel& model = face.faceSceneGraph;
  tinygltf::Value::Object distances;
  for (const auto& [name, distance] : fapu.distances()) {
    if (distance->measured) distances[std::string(name)] = tinygltf::Value(distance->value);
  }
  const std::vector<std::vector<int>> first = firstTargets(face);
  tinygltf::Value::Array tables;
  for (size_t t = 0; t < face.faceDefTables.size(); ++t) {
    const FaceDefTables& table = face.faceDefTables[t];
    tinygltf::Value::Array meshes;
    for (size_t m = 0; m < table.faceDefMesh.size(); ++m) {
      const FaceDefMesh& def = table.faceDefMesh[m];
      std::vector<int> targets(static_cast<size_t>(def.intervalCount()));
      for (size_t k = 0; k < targets.size(); ++k) targets[k] = first[t][m] + static_cast<int>(k);
      tinygltf::Value::Object entry{{"mesh", tinygltf::Value(def.mesh)},
                                    {"meshName", tinygltf::Value(model.meshes[def.mesh].name)},
                                    {"intervalBorders", integers(def.intervalBorders)},
                                    {"targets", integers(targets)}};
      // tinygltf writes empty arrays and objects as null: leave them out.
      if (!def.coordIndex.empty()) entry["coordIndex"] = integers(def.coordIndex);
      meshes.emplace_back(std::move(entry));
    }
    tinygltf::Value::Array transforms;
    for (const FaceDefTransform& def : table.faceDefTransform) {
      const Eigen::Vector4d& r = def.rotationDef;
      const Eigen::Vector3d& s = def.scaleDef;
      const Eigen::Vector3d& d = def.translationDef;
      transforms.emplace_back(tinygltf::Value::Object{
          {"node", tinygltf::Value(def.transform)},  // writeGltf writes Transform i as node i
          {"nodeName", tinygltf::Value(model.transforms[def.transform].name)},
          {"fieldId", tinygltf::Value(static_cast<int>(def.fieldId))},
          {"rotationDef", numbers({r[0], r[1], r[2], r[3]})},
          {"scaleDef", numbers({s[0], s[1], s[2]})},
          {"translationDef", numbers({d[0], d[1], d[2]})}});
    }
    tinygltf::Value::Object entry{{"fapID", tinygltf::Value(table.fapID)},
                                  {"highLevelSelect", tinygltf::Value(table.highLevelSelect)}};
    if (!meshes.empty()) entry["faceDefMesh"] = tinygltf::Value(std::move(meshes));
    if (!transforms.empty()) entry["faceDefTransform"] = tinygltf::Value(std::move(transforms));
    tables.emplace_back(std::move(entry));
  }
  tinygltf::Value::Object extras{{"faceDefTables", tinygltf::Value(std::move(tables))}};
  if (!distances.empty()) extras["fapu"] = tinygltf::Value(std::move(distances));
  return extras;
}

bool holdsTables(const gltf_internal::ReadResult& file) {
  return file.extras.IsObject() && file.extras.Has("faceDefTables");
}

// Reads the extras written by fatExtras, checking every value it uses.
class ExtrasReader {
 public:
  ExtrasReader(gltf_internal::ReadResult& file, const std::string& fileName)
      : file_(file), fileName_(fileName) {}

  FatGltf read() {
    const std::string base =
        file_.extrasField.empty() ? "scenes[0].extras.mpeg4face" : file_.extrasField;
    const tinygltf::Value& ours = file_.extras;
    if (!holdsTables(file_)) {
      fail(base + ".faceDefTables",
           "the file has no Face Animation Tables (it was not written by writeFatGltf)");
    }
    FatGltf out;
    readFapu(ours, base, out.fapu);
    MpegFace& face = out.face;
    FaceModel& model = file_.model;
    std::vector<std::vector<bool>> used(model.meshes.size());  // FAT targets per mesh
    for (size_t m = 0; m < model.meshes.size(); ++m) {
      used[m].assign(model.meshes[m].morphTargets.size(), false);
    }
    const tinygltf::Value& tables = array(ours.Get("faceDefTables"), base + ".faceDefTables");
    for (size_t t = 0; t < tables.ArrayLen(); ++t) {
      const std::string tp = base + "." + tableField(t);
      const tinygltf::Value& entry = object(tables.Get(static_cast<int>(t)), tp);
      FaceDefTables table;
      table.fapID = integer(entry, "fapID", tp);
      if (table.fapID < 1 || table.fapID > kFapCount) {
        fail(tp + ".fapID", "FAP " + std::to_string(table.fapID) + " does not exist");
      }
      table.highLevelSelect = integer(entry, "highLevelSelect", tp);
      const double scale = fapScale(out.fapu, table.fapID);
      if (entry.Has("faceDefMesh")) {
        const tinygltf::Value& meshes = array(entry.Get("faceDefMesh"), tp + ".faceDefMesh");
        for (size_t m = 0; m < meshes.ArrayLen(); ++m) {
          const std::string mp = tp + ".faceDefMesh[" + str(m) + "]";
          table.faceDefMesh.push_back(
              readFaceDefMesh(object(meshes.Get(static_cast<int>(m)), mp), mp, scale, used));
        }
      }
      if (entry.Has("faceDefTransform")) {
        const tinygltf::Value& defs =
            array(entry.Get("faceDefTransform"), tp + ".faceDefTransform");
        for (size_t d = 0; d < defs.ArrayLen(); ++d) {
          const std::string dp = tp + ".faceDefTransform[" + str(d) + "]";
          table.faceDefTransform.push_back(
              readFaceDefTransform(object(defs.Get(static_cast<int>(d)), dp), dp));
        }
      }
      face.faceDefTables.push_back(std::move(table));
    }
    // The FAT targets and the baked animations are outputs of the tables.
    for (size_t m = 0; m < model.meshes.size(); ++m) {
      IndexedFaceSet& mesh = model.meshes[m];
      std::vector<MorphTarget> kept;
      std::vector<double> weights;
      for (size_t k = 0; k < mesh.morphTargets.size(); ++k) {
        if (used[m][k]) continue;
        kept.push_back(std::move(mesh.morphTargets[k]));
        if (!mesh.weights.empty()) weights.push_back(mesh.weights[k]);
      }
      mesh.morphTargets = std::move(kept);
      mesh.weights = std::move(weights);
    }
    model.animations.clear();
    face.faceSceneGraph = std::move(model);
    try {
      checkMpegFace(face, out.fapu);
    } catch (const Error& e) {
      fail(e.field().starts_with("faceDefTables") ? base + "." + e.field() : e.field(), e.reason());
    }
    return out;
  }

 private:
  [[noreturn]] void fail(const std::string& field, const std::string& message) const {
    throw Error(fileName_, 0, field, message);
  }

  const tinygltf::Value& object(const tinygltf::Value& v, const std::string& field) const {
    if (!v.IsObject()) fail(field, "must be an object");
    return v;
  }
  const tinygltf::Value& array(const tinygltf::Value& v, const std::string& field) const {
    if (!v.IsArray()) fail(field, "must be an array");
    return v;
  }
  int integer(const tinygltf::Value& parent, const char* key, const std::string& field) const {
    if (!parent.Has(key) || !parent.Get(key).IsInt()) {
      fail(field + "." + key, "expected an integer");
    }
    return parent.Get(key).Get<int>();
  }
  std::vector<int> integers(const tinygltf::Value& parent, const char* key,
                            const std::string& field) const {
    const tinygltf::Value& values = array(parent.Get(key), field + "." + key);
    std::vector<int> out;
    for (size_t i = 0; i < values.ArrayLen(); ++i) {
      const tinygltf::Value& v = values.Get(static_cast<int>(i));
      if (!v.IsInt()) fail(field + "." + key + "[" + str(i) + "]", "expected an integer");
      out.push_back(v.Get<int>());
    }
    return out;
  }
  // `N` numbers at parent[key], or `fallback` when the key is absent.
  template <int N>
  Eigen::Vector<double, N> vector(const tinygltf::Value& parent, const char* key,
                                  const std::string& field,
                                  const Eigen::Vector<double, N>& fallback) const {
    if (!parent.Has(key)) return fallback;
    const tinygltf::Value& values = parent.Get(key);
    if (!values.IsArray() || values.ArrayLen() != N) {
      fail(field + "." + key, "expected " + std::to_string(N) + " numbers");
    }
    Eigen::Vector<double, N> out;
    for (int i = 0; i < N; ++i) {
      if (!values.Get(i).IsNumber()) fail(field + "." + key, "expected numbers");
      out[i] = values.Get(i).GetNumberAsDouble();
    }
    if (!out.allFinite()) fail(field + "." + key, "has a non-finite number");
    return out;
  }

  void readFapu(const tinygltf::Value& ours, const std::string& base, FapuMeasurement& fapu) const {
    // In the order of FapuMeasurement::distances(), which names them.
    const std::array<FapuDistance*, 5> slots{&fapu.ES0, &fapu.IRISD0, &fapu.ENS0, &fapu.MNS0,
                                             &fapu.MW0};
    const auto named = fapu.distances();
    const tinygltf::Value* distances = nullptr;
    if (ours.Has("fapu")) distances = &object(ours.Get("fapu"), base + ".fapu");
    for (size_t i = 0; i < slots.size(); ++i) {
      const std::string key(named[i].name);
      if (distances == nullptr || !distances->Has(key)) {
        slots[i]->method = "not in the glTF file";
        continue;
      }
      const tinygltf::Value& v = distances->Get(key);
      if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()) || !(v.GetNumberAsDouble() > 0)) {
        fail(base + ".fapu." + key, "expected a positive distance in model units");
      }
      *slots[i] = {true, v.GetNumberAsDouble(), {}, "from the glTF file"};
    }
  }

  FaceDefMesh readFaceDefMesh(const tinygltf::Value& entry, const std::string& mp, double scale,
                              std::vector<std::vector<bool>>& used) const {
    const FaceModel& model = file_.model;
    FaceDefMesh def;
    def.mesh = integer(entry, "mesh", mp);
    if (def.mesh < 0 || static_cast<size_t>(def.mesh) >= model.meshes.size()) {
      fail(mp + ".mesh", "mesh " + std::to_string(def.mesh) + " does not exist");
    }
    const IndexedFaceSet& mesh = model.meshes[def.mesh];
    def.intervalBorders = integers(entry, "intervalBorders", mp);
    try {
      checkIntervalBorders(def.intervalBorders);
    } catch (const Error& e) {
      fail(mp + ".intervalBorders", e.reason());
    }
    if (entry.Has("coordIndex")) def.coordIndex = integers(entry, "coordIndex", mp);
    for (size_t i = 0; i < def.coordIndex.size(); ++i) {
      if (def.coordIndex[i] < 0 || def.coordIndex[i] >= mesh.vertexCount()) {
        fail(mp + ".coordIndex[" + str(i) + "]",
             "vertex " + std::to_string(def.coordIndex[i]) + " is not in mesh '" + mesh.name + "'");
      }
    }
    const std::vector<int> targets = integers(entry, "targets", mp);
    const int intervals = def.intervalCount();
    if (static_cast<int>(targets.size()) != intervals) {
      fail(mp + ".targets", "has " + str(targets.size()) + " morph targets for " +
                                std::to_string(intervals) + " intervals");
    }
    for (size_t k = 0; k < targets.size(); ++k) {
      if (targets[k] < 0 || targets[k] >= static_cast<int>(mesh.morphTargets.size()) ||
          used[def.mesh][targets[k]]) {
        fail(mp + ".targets[" + str(k) + "]",
             "morph target " + std::to_string(targets[k]) + " of mesh '" + mesh.name +
                 "' does not exist or belongs to another interval");
      }
      used[def.mesh][targets[k]] = true;
    }
    if (!(scale > 0)) return def;  // checkMpegFace names the missing FAPU
    def.displacements.resize(static_cast<Eigen::Index>(def.coordIndex.size()) * intervals, 3);
    for (size_t i = 0; i < def.coordIndex.size(); ++i) {
      for (int k = 0; k < intervals; ++k) {
        def.displacements.row(static_cast<Eigen::Index>(i) * intervals + k) =
            mesh.morphTargets[targets[k]].displacements.row(def.coordIndex[i]) / scale;
      }
    }
    return def;
  }

  FaceDefTransform readFaceDefTransform(const tinygltf::Value& entry, const std::string& dp) const {
    FaceDefTransform def;
    const int node = integer(entry, "node", dp);
    if (node < 0 || static_cast<size_t>(node) >= file_.transformOfNode.size() ||
        file_.transformOfNode[node] < 0) {
      fail(dp + ".node", "node " + std::to_string(node) + " is not a Transform of the file");
    }
    def.transform = file_.transformOfNode[node];
    const int field = integer(entry, "fieldId", dp);
    if (field < 1 || field > 3) {
      fail(dp + ".fieldId", "expected 1 (rotation), 2 (scale) or 3 (translation)");
    }
    def.fieldId = static_cast<FaceDefTransform::Field>(field);
    def.rotationDef = vector<4>(entry, "rotationDef", dp, def.rotationDef);
    def.scaleDef = vector<3>(entry, "scaleDef", dp, def.scaleDef);
    def.translationDef = vector<3>(entry, "translationDef", dp, def.translationDef);
    return def;
  }

  gltf_internal::ReadResult& file_;
  const std::string& fileName_;
};

}  // namespace

std::string fatTargetName(int fapID, int highLevelSelect, int lower, int upper) {
  std::string name;
  if (fapID == 1) {
    name = "viseme" + std::to_string(highLevelSelect);
  } else if (fapID == 2) {
    name = "expression" + std::to_string(highLevelSelect);
    if (highLevelSelect >= 0 && highLevelSelect < kExpressionCount) {
      name += "_" + std::string(expressionTable()[static_cast<size_t>(highLevelSelect)].name);
    }
  } else {
    name = "fap" + std::to_string(fapID) + "_" + std::string(fapInfo(fapID).name);
  }
  return name + "[" + std::to_string(lower) + "," + std::to_string(upper) + "]";
}

void checkMpegFace(const MpegFace& face, const FapuMeasurement& fapu) {
  validateMpegFace(face);
  for (size_t t = 0; t < face.faceDefTables.size(); ++t) {
    const int fap = face.faceDefTables[t].fapID;
    if (fapScale(fapu, fap) > 0) continue;
    const std::string unit(fapuName(fapInfo(fap).fapu));
    std::string why;
    for (const auto& [name, distance] : fapu.distances()) {
      if (name == unit + "0") why = distance->method;
    }
    fail(tableField(t) + ".fapID", "FAP " + std::to_string(fap) + " (" +
                                       std::string(fapInfo(fap).name) + ") moves in " + unit +
                                       " units, but the face's " + unit + "0 is not measured" +
                                       (why.empty() ? "" : ": " + why));
  }
}

FaceModel fatMorphModel(const MpegFace& face, const FapuMeasurement& fapu) {
  checkMpegFace(face, fapu);
  FaceModel model = face.faceSceneGraph;
  for (const FaceDefTables& table : face.faceDefTables) {
    const double scale = fapScale(fapu, table.fapID);
    for (const FaceDefMesh& def : table.faceDefMesh) {
      IndexedFaceSet& mesh = model.meshes[def.mesh];
      const int intervals = def.intervalCount();
      for (int k = 0; k < intervals; ++k) {
        MorphTarget target;
        target.name = fatTargetName(table.fapID, table.highLevelSelect, def.intervalBorders[k],
                                    def.intervalBorders[k + 1]);
        auto taken = [&](const std::string& name) {
          return std::ranges::any_of(mesh.morphTargets,
                                     [&](const MorphTarget& m) { return m.name == name; });
        };
        if (taken(target.name)) {
          int n = 2;
          while (taken(target.name + "#" + std::to_string(n))) ++n;
          target.name += "#" + std::to_string(n);
        }
        target.displacements = Points3::Zero(mesh.vertexCount(), 3);
        for (size_t i = 0; i < def.coordIndex.size(); ++i) {
          target.displacements.row(def.coordIndex[i]) =
              scale * def.displacements.row(static_cast<Eigen::Index>(i) * intervals + k);
        }
        mesh.morphTargets.push_back(std::move(target));
        if (!mesh.weights.empty()) mesh.weights.push_back(0.0);
      }
    }
  }
  return model;
}

MorphWeightAnimation bakeFapStream(const MpegFace& face, const FapuMeasurement& fapu,
                                   const FapStream& stream) {
  checkMpegFace(face, fapu);
  if (!std::isfinite(stream.frameRate) || !(stream.frameRate > 0)) {
    fail("frameRate", "FAP stream '" + stream.name + "' has frame rate " +
                          std::to_string(stream.frameRate) + "; expected a positive number");
  }
  if (stream.frames.empty()) fail("frames", "FAP stream '" + stream.name + "' has no frames");
  const FaceModel& model = face.faceSceneGraph;
  const std::vector<std::vector<int>> first = firstTargets(face);
  MorphWeightAnimation out;
  out.name = stream.name;

  // One weight channel per mesh with FAT targets, starting from the mesh's default weights.
  std::vector<int> channelOf(model.meshes.size(), -1);
  std::vector<std::vector<double>> defaults;  // per channel, one per target of the output
  for (size_t t = 0; t < face.faceDefTables.size(); ++t) {
    for (size_t m = 0; m < face.faceDefTables[t].faceDefMesh.size(); ++m) {
      const FaceDefMesh& def = face.faceDefTables[t].faceDefMesh[m];
      if (channelOf[def.mesh] < 0) {
        channelOf[def.mesh] = static_cast<int>(out.channels.size());
        out.channels.emplace_back().mesh = def.mesh;
        defaults.push_back(model.meshes[def.mesh].weights);
        defaults.back().resize(model.meshes[def.mesh].morphTargets.size(), 0.0);
      }
      // Targets are appended in this order, so the defaults grow with them.
      defaults[channelOf[def.mesh]].resize(static_cast<size_t>(first[t][m] + def.intervalCount()),
                                           0.0);
    }
  }

  // The FaceDefTransforms on each Transform, in increasing fapID order (table order for
  // equal fapIDs), and the fields they animate.
  struct Driven {
    int transform = -1;
    std::vector<std::pair<size_t, size_t>> defs;  // (table, faceDefTransform)
    std::array<int, 3> channel{-1, -1, -1};       // TransformChannel per Field - 1
  };
  std::vector<Driven> driven;
  std::vector<size_t> order(face.faceDefTables.size());
  for (size_t t = 0; t < order.size(); ++t) order[t] = t;
  std::ranges::stable_sort(order, {}, [&](size_t t) { return face.faceDefTables[t].fapID; });
  for (size_t t : order) {
    const std::vector<FaceDefTransform>& defs = face.faceDefTables[t].faceDefTransform;
    for (size_t d = 0; d < defs.size(); ++d) {
      auto it = std::ranges::find(driven, defs[d].transform, &Driven::transform);
      if (it == driven.end()) {
        driven.emplace_back().transform = defs[d].transform;
        it = driven.end() - 1;
      }
      it->defs.emplace_back(t, d);
      int& channel = it->channel[static_cast<size_t>(defs[d].fieldId) - 1];
      if (channel < 0) {
        channel = static_cast<int>(out.transformChannels.size());
        const auto path = defs[d].fieldId == FaceDefTransform::Field::Rotation
                              ? TransformChannel::Path::Rotation
                          : defs[d].fieldId == FaceDefTransform::Field::Scale
                              ? TransformChannel::Path::Scale
                              : TransformChannel::Path::Translation;
        TransformChannel& added = out.transformChannels.emplace_back();
        added.transform = defs[d].transform;
        added.path = path;
      }
    }
  }

  // What a decoder holds after each frame: values held, unsent left/right partners mirrored.
  const std::vector<FapState> states = resolveFapStream(stream);
  std::vector<double> inputs(face.faceDefTables.size());
  std::vector<double> weights;
  std::vector<double> interval;
  double previous = -1;
  for (size_t f = 0; f < stream.frames.size(); ++f) {
    const FapFrame& frame = states[f];
    const double time = frameTime(stream, stream.frames[f]);
    if (!(time > previous)) {
      fail("frames[" + str(f) + "].number", "FAP stream '" + stream.name + "': frame number " +
                                                std::to_string(stream.frames[f].number) +
                                                " is not after the previous one (or negative)");
    }
    previous = time;
    for (size_t t = 0; t < inputs.size(); ++t) {
      const FaceDefTables& table = face.faceDefTables[t];
      inputs[t] =
          frame.has(table.fapID) ? tableInput(table.fapID, table.highLevelSelect, frame) : 0;
    }

    for (size_t c = 0; c < out.channels.size(); ++c) {
      MorphWeightChannel& channel = out.channels[c];
      weights = defaults[c];
      for (size_t t = 0; t < face.faceDefTables.size(); ++t) {
        for (size_t m = 0; m < face.faceDefTables[t].faceDefMesh.size(); ++m) {
          const FaceDefMesh& def = face.faceDefTables[t].faceDefMesh[m];
          if (def.mesh != channel.mesh) continue;
          intervalWeights(def.intervalBorders, inputs[t], interval);
          std::ranges::copy(interval, weights.begin() + first[t][m]);
        }
      }
      channel.times.push_back(time);
      channel.weights.insert(channel.weights.end(), weights.begin(), weights.end());
    }

    for (const Driven& d : driven) {
      Transform transform = model.transforms[d.transform];
      for (auto [t, i] : d.defs) {
        const FaceDefTables& table = face.faceDefTables[t];
        applyFaceDefTransform(table.faceDefTransform[i], inputs[t] * fapScale(fapu, table.fapID),
                              transform);
      }
      for (int channelIndex : d.channel) {
        if (channelIndex < 0) continue;
        TransformChannel& channel = out.transformChannels[channelIndex];
        channel.times.push_back(time);
        std::vector<double>& v = channel.values;
        switch (channel.path) {
          case TransformChannel::Path::Rotation: {
            Eigen::Quaterniond q = transform.rotation.normalized();
            // Keep consecutive keys in one hemisphere so that slerp takes the short way.
            if (v.size() >= 4 &&
                q.coeffs().dot(Eigen::Map<const Eigen::Vector4d>(v.data() + v.size() - 4)) < 0) {
              q.coeffs() = -q.coeffs();
            }
            v.insert(v.end(), {q.x(), q.y(), q.z(), q.w()});
            break;
          }
          case TransformChannel::Path::Translation:
            v.insert(v.end(), transform.translation.begin(), transform.translation.end());
            break;
          case TransformChannel::Path::Scale:
            v.insert(v.end(), transform.scale.begin(), transform.scale.end());
            break;
        }
      }
    }
  }
  return out;
}

void writeFatGltf(const MpegFace& face, const FapuMeasurement& fapu,
                  std::span<const FapStream> streams, const std::filesystem::path& path) {
  FaceModel model = fatMorphModel(face, fapu);
  for (const FapStream& stream : streams) {
    model.animations.push_back(bakeFapStream(face, fapu, stream));
  }
  gltf_internal::writeGltf(model, path, fatExtras(face, fapu));
}

FatGltf parseFatGltf(std::string_view bytes, const std::string& fileName,
                     const std::filesystem::path& baseDir) {
  gltf_internal::ReadResult file = gltf_internal::parseGltf(bytes, fileName, baseDir);
  return ExtrasReader(file, fileName).read();
}

FatGltf readFatGltf(const std::filesystem::path& path) {
  gltf_internal::ReadResult file = gltf_internal::readGltf(path);
  return ExtrasReader(file, path.string()).read();
}

std::optional<FatGltf> readFatGltfIfAny(const std::filesystem::path& path) {
  gltf_internal::ReadResult file = gltf_internal::readGltf(path);
  if (!holdsTables(file)) return std::nullopt;
  return ExtrasReader(file, path.string()).read();
}

}  // namespace mpeg4face
