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

std::string copyField(const FaceShape& copy) { return "copy '" + copy.name + "'"; }

void checkCopy(const FaceModel& neutral, const FaceShape& copy) {
  const auto fail = [&](const std::string& field, const std::string& why) {
    throw Error({}, 0, copyField(copy) + " " + field, why);
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
  checkFaceShape(neutral, copy);
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
using Group = std::vector<const FaceShape*>;

// The copy's displacement of mesh m; nullptr if it moves none of its vertices.
const MeshDisplacement* displacementOf(const FaceShape& copy, int m) {
  const auto it = std::ranges::lower_bound(copy.meshes, m, {}, &MeshDisplacement::mesh);
  return it != copy.meshes.end() && it->mesh == m ? &*it : nullptr;
}

void addMeshes(const FaceModel& neutral, const Group& group, double scale, double threshold,
               FaceDefTables& table) {
  // Borders: the amplitudes and 0; the copy at border b, or nullptr for the neutral at 0.
  std::vector<int> borders;
  std::vector<const FaceShape*> at;
  for (const FaceShape* c : group) {
    if (c->amplitude > 0 && (borders.empty() || borders.back() < 0)) {
      borders.push_back(0);
      at.push_back(nullptr);
    }
    borders.push_back(c->amplitude);
    at.push_back(c);
  }
  if (borders.back() < 0) {
    borders.push_back(0);
    at.push_back(nullptr);
  }
  const std::size_t n = borders.size() - 1;
  const double threshold2 = threshold * threshold;
  for (std::size_t m = 0; m < neutral.meshes.size(); ++m) {
    const int mesh = static_cast<int>(m);
    std::vector<int> affected;
    for (const FaceShape* c : group) {
      const MeshDisplacement* d = displacementOf(*c, mesh);
      if (d == nullptr) continue;
      for (std::size_t k = 0; k < d->vertices.size(); ++k) {
        if (d->displacement.row(static_cast<Eigen::Index>(k)).squaredNorm() > threshold2) {
          affected.push_back(d->vertices[k]);
        }
      }
    }
    if (affected.empty()) continue;
    std::ranges::sort(affected);
    affected.erase(std::unique(affected.begin(), affected.end()), affected.end());
    // Each border's displacement of the affected vertices (0 where its copy lists none).
    std::vector<Points3> moved;
    for (const FaceShape* c : at) {
      Points3& p = moved.emplace_back(Points3::Zero(static_cast<Eigen::Index>(affected.size()), 3));
      const MeshDisplacement* d = c ? displacementOf(*c, mesh) : nullptr;
      if (d == nullptr) continue;
      auto i = affected.begin();
      for (std::size_t k = 0; k < d->vertices.size(); ++k) {
        i = std::lower_bound(i, affected.end(), d->vertices[k]);
        if (i == affected.end()) break;
        if (*i == d->vertices[k]) {
          p.row(i - affected.begin()) = d->displacement.row(static_cast<Eigen::Index>(k));
        }
      }
    }
    FaceDefMesh& out = table.faceDefMesh.emplace_back();
    out.mesh = mesh;
    out.intervalBorders = borders;
    out.coordIndex = affected;
    out.displacements.resize(static_cast<Eigen::Index>(affected.size() * n), 3);
    for (std::size_t j = 0; j < n; ++j) {
      const Points3& lo = moved[j];
      const Points3& hi = moved[j + 1];
      // Positive side and one interval: motion per FAP unit from lower to upper border;
      // negative side: per unit of |FAP| outwards, from upper to lower (the paper's rule 4).
      const double width = (double(borders[j + 1]) - double(borders[j])) * scale;
      const double factor = (borders[j] >= 0 || n == 1 ? 1.0 : -1.0) / width;
      for (std::size_t i = 0; i < affected.size(); ++i) {
        const auto r = static_cast<Eigen::Index>(i);
        out.displacements.row(static_cast<Eigen::Index>(i * n + j)) =
            factor * (hi.row(r) - lo.row(r));
      }
    }
  }
}

void addTransforms(const FaceModel& neutral, const Group& group, double scale, double threshold,
                   double size, FaceDefTables& table, std::vector<std::string>& warnings) {
  // A FaceDefTransform is linear in the FAP: the copy of largest |amplitude| defines it.
  const FaceShape* ref = *std::ranges::max_element(
      group, [](auto* a, auto* b) { return std::abs(a->amplitude) < std::abs(b->amplitude); });
  const double refValue = ref->amplitude * scale;
  for (std::size_t t = 0; t < neutral.transforms.size(); ++t) {
    const Transform& t0 = neutral.transforms[t];
    const Transform& t1 = shapeTransforms(neutral, *ref)[t];
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
    for (const FaceShape* c : group) {
      if (c == ref) continue;
      Transform predicted = t0;
      for (std::size_t k = first; k < table.faceDefTransform.size(); ++k) {
        applyFaceDefTransform(table.faceDefTransform[k], c->amplitude * scale, predicted);
      }
      const Transform& actual = shapeTransforms(neutral, *c)[t];
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
                                      std::span<const FaceShape> copies,
                                      const GeneratorOptions& options) {
  neutral.validate();
  std::map<std::pair<int, int>, Group> groups;
  for (const FaceShape& copy : copies) {
    checkCopy(neutral, copy);
    groups[{copy.fapID, copy.fapID <= 2 ? copy.highLevelSelect : 0}].push_back(&copy);
  }
  const double size = headSize(neutral);
  GeneratedTables result;
  for (auto& [key, group] : groups) {
    std::ranges::stable_sort(group, {}, &FaceShape::amplitude);
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
