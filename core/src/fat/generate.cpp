// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/fat/generate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <utility>

#include "fat/support.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

std::string copyField(const DeformedCopy& copy) { return "copy '" + copy.name + "'"; }

void checkCopy(const FaceModel& neutral, const DeformedCopy& copy) {
  const std::string where = copyField(copy);
  const auto fail = [&](const std::string& field, const std::string& why) {
    throw Error({}, 0, field.empty() ? where : where + " " + field, why);
  };
  if (copy.fapID < 1 || copy.fapID > kFapCount) {
    fail("fapID", std::to_string(copy.fapID) + " is not a FAP (1..68)");
  }
  if (copy.fapID == 1 && (copy.highLevelSelect < 1 || copy.highLevelSelect > 14)) {
    fail("highLevelSelect", "viseme " + std::to_string(copy.highLevelSelect) + " is not 1..14");
  }
  if (copy.fapID == 2 && (copy.highLevelSelect < 1 || copy.highLevelSelect > 6)) {
    fail("highLevelSelect", "expression " + std::to_string(copy.highLevelSelect) + " is not 1..6");
  }
  if (copy.amplitude == 0) fail("amplitude", "is 0: the neutral face needs no copy");
  if (copy.fapID <= 2 && (copy.amplitude < 1 || copy.amplitude > 63)) {
    fail("amplitude", std::to_string(copy.amplitude) + " is not an amount 1..63");
  }
  const FaceModel& m = copy.model;
  if (m.meshes.size() != neutral.meshes.size()) {
    fail("", "has " + std::to_string(m.meshes.size()) + " meshes, the neutral model " +
                 std::to_string(neutral.meshes.size()));
  }
  for (std::size_t i = 0; i < m.meshes.size(); ++i) {
    const IndexedFaceSet& a = m.meshes[i];
    const IndexedFaceSet& b = neutral.meshes[i];
    const std::string mesh = "mesh '" + b.name + "'";
    if (a.vertexCount() != b.vertexCount()) {
      fail(mesh, "has " + std::to_string(a.vertexCount()) + " vertices, the neutral model " +
                     std::to_string(b.vertexCount()));
    }
    if (a.coordIndex != b.coordIndex) fail(mesh, "has other faces than the neutral model");
    if (!a.coord.allFinite()) fail(mesh, "has a vertex position that is not finite");
  }
  if (m.transforms.size() != neutral.transforms.size()) {
    fail("", "has " + std::to_string(m.transforms.size()) + " transforms, the neutral model " +
                 std::to_string(neutral.transforms.size()));
  }
  for (std::size_t i = 0; i < m.transforms.size(); ++i) {
    const Transform& a = m.transforms[i];
    const Transform& b = neutral.transforms[i];
    const std::string t = "transform '" + b.name + "'";
    if (a.children != b.children || a.meshes != b.meshes) {
      fail(t, "has other children or meshes than in the neutral model");
    }
    if (a.center != b.center) {
      fail(t, "center moved: only translation, rotation and scale can be animated");
    }
    if (!a.translation.allFinite() || !a.scale.allFinite() || !a.rotation.coeffs().allFinite()) {
      fail(t, "has a value that is not finite");
    }
  }
}

// The unit `threshold` is counted in (GeneratorOptions).
double thresholdUnit(const FapuMeasurement& fapu, int fapID, const std::string& field) {
  if (fapID >= 3) {
    const FapuKind kind = fapInfo(fapID).fapu;
    if (kind != FapuKind::AU && fapu.unit(kind) > 0) return fapu.unit(kind);
  }
  for (FapuKind kind :
       {FapuKind::ES, FapuKind::ENS, FapuKind::MNS, FapuKind::MW, FapuKind::IRISD}) {
    if (fapu.unit(kind) > 0) return fapu.unit(kind);
  }
  throw Error({}, 0, field,
              "no FAPU is measured to count the threshold in (bind feature points, or give an "
              "absolute threshold)");
}

double headSize(const FaceModel& model) {
  const std::vector<Eigen::Affine3d> world = model.meshWorldMatrices();
  Eigen::AlignedBox3d box;
  for (std::size_t m = 0; m < model.meshes.size(); ++m) {
    const Points3& c = model.meshes[m].coord;
    for (Eigen::Index v = 0; v < c.rows(); ++v) box.extend(world[m] * c.row(v).transpose());
  }
  return box.isEmpty() ? 0.0 : box.diagonal().norm();
}

// The copies of one FAP (or viseme / expression), by increasing amplitude.
using Group = std::vector<const DeformedCopy*>;

void addMeshes(const FaceModel& neutral, const Group& group, double scale, double threshold,
               FaceDefTables& table) {
  // Borders: the amplitudes and 0; position at border b: the copy there, or neutral at 0.
  std::vector<int> borders;
  std::vector<const FaceModel*> at;
  for (const DeformedCopy* c : group) {
    if (c->amplitude > 0 && (borders.empty() || borders.back() < 0)) {
      borders.push_back(0);
      at.push_back(&neutral);
    }
    borders.push_back(c->amplitude);
    at.push_back(&c->model);
  }
  if (borders.back() < 0) {
    borders.push_back(0);
    at.push_back(&neutral);
  }
  const std::size_t n = borders.size() - 1;
  const double threshold2 = threshold * threshold;
  for (std::size_t m = 0; m < neutral.meshes.size(); ++m) {
    const Points3& p0 = neutral.meshes[m].coord;
    const auto rows = static_cast<std::size_t>(p0.rows());
    std::vector<bool> moved(rows, false);
    for (const DeformedCopy* c : group) {
      const double* a = c->model.meshes[m].coord.data();
      const double* b = p0.data();
      for (std::size_t v = 0; v < rows; ++v, a += 3, b += 3) {
        const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
        if (dx * dx + dy * dy + dz * dz > threshold2) moved[v] = true;
      }
    }
    std::vector<int> affected;
    for (std::size_t v = 0; v < rows; ++v) {
      if (moved[v]) affected.push_back(static_cast<int>(v));
    }
    if (affected.empty()) continue;
    FaceDefMesh& out = table.faceDefMesh.emplace_back();
    out.mesh = static_cast<int>(m);
    out.intervalBorders = borders;
    out.coordIndex = affected;
    out.displacements.resize(static_cast<Eigen::Index>(affected.size() * n), 3);
    for (std::size_t j = 0; j < n; ++j) {
      const Points3& lo = at[j]->meshes[m].coord;
      const Points3& hi = at[j + 1]->meshes[m].coord;
      // Positive side and one interval: motion per FAP unit from lower to upper border;
      // negative side: per unit of |FAP| outwards, from upper to lower (the paper's rule 4).
      const double width = (double(borders[j + 1]) - double(borders[j])) * scale;
      const double factor = (borders[j] >= 0 || n == 1 ? 1.0 : -1.0) / width;
      for (std::size_t i = 0; i < affected.size(); ++i) {
        const int v = affected[i];
        out.displacements.row(static_cast<Eigen::Index>(i * n + j)) =
            factor * (hi.row(v) - lo.row(v));
      }
    }
  }
}

void addTransforms(const FaceModel& neutral, const Group& group, double scale, double threshold,
                   double size, FaceDefTables& table, std::vector<std::string>& warnings) {
  // A FaceDefTransform is linear in the FAP: the copy of largest |amplitude| defines it.
  const DeformedCopy* ref = *std::ranges::max_element(
      group, [](auto* a, auto* b) { return std::abs(a->amplitude) < std::abs(b->amplitude); });
  const double refValue = ref->amplitude * scale;
  for (std::size_t t = 0; t < neutral.transforms.size(); ++t) {
    const Transform& t0 = neutral.transforms[t];
    const Transform& t1 = ref->model.transforms[t];
    const std::size_t first = table.faceDefTransform.size();
    const Eigen::AngleAxisd turn(t0.rotation.inverse() * t1.rotation);
    if (std::abs(turn.angle()) * size > threshold) {
      FaceDefTransform& d = table.faceDefTransform.emplace_back();
      d.transform = static_cast<int>(t);
      d.fieldId = FaceDefTransform::Field::Rotation;
      d.rotationDef << turn.axis(), turn.angle() / refValue;
    }
    if ((t1.scale - t0.scale).norm() * size > threshold) {
      FaceDefTransform& d = table.faceDefTransform.emplace_back();
      d.transform = static_cast<int>(t);
      d.fieldId = FaceDefTransform::Field::Scale;
      d.scaleDef = (t1.scale - t0.scale) / refValue;
    }
    if ((t1.translation - t0.translation).norm() > threshold) {
      FaceDefTransform& d = table.faceDefTransform.emplace_back();
      d.transform = static_cast<int>(t);
      d.fieldId = FaceDefTransform::Field::Translation;
      d.translationDef = (t1.translation - t0.translation) / refValue;
    }
    // Every other copy must be what the definitions predict at its amplitude.
    for (const DeformedCopy* c : group) {
      if (c == ref) continue;
      Transform predicted = t0;
      for (std::size_t k = first; k < table.faceDefTransform.size(); ++k) {
        applyFaceDefTransform(table.faceDefTransform[k], c->amplitude * scale, predicted);
      }
      const Transform& actual = c->model.transforms[t];
      const double off = std::max(
          {std::abs(Eigen::AngleAxisd(predicted.rotation.inverse() * actual.rotation).angle()) *
               size,
           (predicted.scale - actual.scale).norm() * size,
           (predicted.translation - actual.translation).norm()});
      if (off > threshold) {
        warnings.push_back(
            copyField(*c) + ": transform '" + t0.name + "' is not where " + copyField(*ref) +
            " puts it at this amplitude (off by " + std::to_string(off) +
            " model units); a FaceDefTransform is linear, the tables follow " + copyField(*ref));
      }
    }
  }
}

}  // namespace

GeneratedTables generateFaceDefTables(const FaceModel& neutral, const FapuMeasurement& fapu,
                                      std::span<const DeformedCopy> copies,
                                      const GeneratorOptions& options) {
  neutral.validate();
  std::map<std::pair<int, int>, Group> groups;
  for (const DeformedCopy& copy : copies) {
    checkCopy(neutral, copy);
    groups[{copy.fapID, copy.fapID <= 2 ? copy.highLevelSelect : 0}].push_back(&copy);
  }
  const double size = headSize(neutral);
  GeneratedTables result;
  for (auto& [key, group] : groups) {
    std::ranges::stable_sort(group, {}, &DeformedCopy::amplitude);
    for (std::size_t i = 1; i < group.size(); ++i) {
      if (group[i]->amplitude == group[i - 1]->amplitude) {
        throw Error({}, 0, copyField(*group[i]),
                    "shows " + fat::fapLabel(key.first, key.second) + " at " +
                        std::to_string(group[i]->amplitude) + " as " + copyField(*group[i - 1]) +
                        " does");
      }
    }
    const std::string field = copyField(*group.front());
    const double scale = fat::requireFapScale(fapu, key.first, field);
    const double threshold = options.absoluteThreshold
                                 ? *options.absoluteThreshold
                                 : options.threshold * thresholdUnit(fapu, key.first, field);
    FaceDefTables table;
    table.fapID = key.first;
    table.highLevelSelect = key.first <= 2 ? key.second : 1;
    addMeshes(neutral, group, scale, threshold, table);
    addTransforms(neutral, group, scale, threshold, size, table, result.warnings);
    if (table.faceDefMesh.empty() && table.faceDefTransform.empty()) {
      result.warnings.push_back(field + ": " + fat::fapLabel(key.first, key.second) +
                                " changes nothing by more than the threshold (" +
                                std::to_string(threshold) + " model units); no table");
      continue;
    }
    result.faceDefTables.push_back(std::move(table));
  }
  return result;
}

}  // namespace mpeg4face
