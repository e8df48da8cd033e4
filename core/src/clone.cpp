// SPDX-License-Identifier: GPL-3.0-or-later
// Facial Motion Cloning (Pandzic 2003): checks, the vertex mapping applied to every copy,
// and the target's tables. docs/clone.md.
#include "mpeg4face/clone.hpp"

#include "clone_internal.hpp"
#include "mpeg4face/clone_rigid.hpp"
#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

void requireFeaturePointsAndFapu(const FaceModel& source, const FaceModel& target) {
  std::string problems;
  for (const auto& [face, model] : {std::pair{"source", &source}, std::pair{"target", &target}}) {
    const auto missing = missingCloneFeaturePoints(*model);
    if (!missing.empty()) {
      problems += std::string(problems.empty() ? "" : "; ") + "the " + face +
                  " face lacks feature points " + joined(missing);
    }
  }
  if (!problems.empty()) throw Error({}, 0, "featurePoints", "cloning needs them: " + problems);
  for (const auto& [face, model] : {std::pair{"source", &source}, std::pair{"target", &target}}) {
    const FapuMeasurement fapu = measureFapu(*model);
    for (const auto& d : fapu.distances()) {
      if (!d.distance->measured) {
        problems += std::string(problems.empty() ? "" : "; ") + "the " + face + " face's " +
                    std::string(d.name) + " (" + d.distance->method + ")";
      }
    }
  }
  if (!problems.empty()) throw Error({}, 0, "FAPU", "cloning needs every FAPU: " + problems);
}

void requireSameTopology(const FaceModel& neutral, const DeformedCopy& copy) {
  const std::string label = "copy '" + copy.name + "'";
  const auto fail = [&](const std::string& where, const std::string& what) {
    throw Error({}, 0, label + where, label + where + " " + what);
  };
  if (copy.model.meshes.size() != neutral.meshes.size()) {
    fail("", "has " + std::to_string(copy.model.meshes.size()) + " meshes, the source neutral " +
                 std::to_string(neutral.meshes.size()));
  }
  for (std::size_t m = 0; m < neutral.meshes.size(); ++m) {
    const IndexedFaceSet& a = neutral.meshes[m];
    const IndexedFaceSet& b = copy.model.meshes[m];
    const std::string where = " mesh '" + a.name + "'";
    if (a.vertexCount() != b.vertexCount()) {
      fail(where, "has " + std::to_string(b.vertexCount()) + " vertices, the source neutral's " +
                      std::to_string(a.vertexCount()));
    }
    if (a.coordIndex != b.coordIndex) fail(where, "has other faces than the source neutral's");
    if (!b.coord.allFinite()) fail(where, "has a coordinate that is not a finite number");
  }
  if (copy.model.transforms.size() != neutral.transforms.size()) {
    fail("", "has " + std::to_string(copy.model.transforms.size()) +
                 " Transforms, the source neutral " + std::to_string(neutral.transforms.size()));
  }
}

std::vector<Eigen::Matrix3d> linearParts(const FaceModel& model, bool inverse) {
  std::vector<Eigen::Matrix3d> out;
  for (const Eigen::Affine3d& w : model.meshWorldMatrices()) {
    out.push_back(inverse ? Eigen::Matrix3d(w.linear().inverse()) : Eigen::Matrix3d(w.linear()));
  }
  return out;
}

}  // namespace

CloneResult cloneDeformedCopies(const FaceModel& sourceNeutral,
                                std::span<const DeformedCopy> sourceCopies,
                                const FaceModel& targetNeutral, const CloneOptions& options) {
  requireFeaturePointsAndFapu(sourceNeutral, targetNeutral);
  for (const DeformedCopy& copy : sourceCopies) requireSameTopology(sourceNeutral, copy);

  CloneResult result;
  result.targetNeutral = targetNeutral;
  // Eyes, teeth and tongue move as rigid parts (clone_rigid.hpp), the head by its Transform;
  // every other mesh is part of the one surface whose vertex motion is mapped.
  RigidPartMap rigid;
  if (options.rigidParts) {
    rigid = matchRigidParts(sourceNeutral, sourceCopies, result.targetNeutral);
    result.warnings = rigid.warnings;
  }
  const FapuMeasurement sourceFapu = measureFapu(sourceNeutral);
  const FapuMeasurement targetFapu = measureFapu(result.targetNeutral);
  const clone::Surface sourceSurface = clone::gatherSurface(sourceNeutral, rigid.sourceRigidMeshes);
  const clone::Surface targetSurface =
      clone::gatherSurface(result.targetNeutral, rigid.targetRigidMeshes);
  const clone::Mapping map = clone::buildMapping(sourceNeutral, sourceSurface, result.targetNeutral,
                                                 targetSurface, options);

  const auto toModel = linearParts(sourceNeutral, false);
  const auto toLocal = linearParts(result.targetNeutral, true);
  Points3 motion(sourceSurface.positions.rows(), 3);
  for (std::size_t c = 0; c < sourceCopies.size(); ++c) {
    if (options.progress) {
      options.progress(
          "copies", 0.5 + 0.5 * static_cast<double>(c) / static_cast<double>(sourceCopies.size()));
    }
    const DeformedCopy& from = sourceCopies[c];
    // Normalised source motion of every surface vertex, in model space.
    for (Eigen::Index r = 0; r < motion.rows(); ++r) {
      const auto [m, v] = sourceSurface.owner[static_cast<std::size_t>(r)];
      const Eigen::Vector3d local = (from.model.meshes[static_cast<std::size_t>(m)].coord.row(v) -
                                     sourceNeutral.meshes[static_cast<std::size_t>(m)].coord.row(v))
                                        .transpose();
      motion.row(r) = (toModel[static_cast<std::size_t>(m)] * local)
                          .cwiseQuotient(map.sourceFactors.row(r).transpose())
                          .transpose();
    }
    DeformedCopy& to = result.copies.emplace_back();
    to.name = from.name;
    to.fapID = from.fapID;
    to.highLevelSelect = from.highLevelSelect;
    to.amplitude = from.amplitude;
    to.model = result.targetNeutral;
    if (options.rigidParts)
      cloneRigidMotion(rigid, sourceNeutral, sourceFapu, from, targetFapu, to.model);
    for (std::size_t t = 0; t + 1 < map.rowStart.size(); ++t) {
      Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
      for (int i = map.rowStart[t]; i < map.rowStart[t + 1]; ++i) {
        sum += map.weight[static_cast<std::size_t>(i)] *
               motion.row(map.source[static_cast<std::size_t>(i)]);
      }
      if (sum.isZero(0)) continue;
      const auto [m, v] = targetSurface.owner[t];
      const Eigen::Vector3d modelMotion = sum.transpose().cwiseProduct(
          map.targetFactors.row(static_cast<Eigen::Index>(t)).transpose());
      to.model.meshes[static_cast<std::size_t>(m)].coord.row(v) +=
          (toLocal[static_cast<std::size_t>(m)] * modelMotion).transpose();
    }
  }
  if (options.progress) options.progress("copies", 1.0);
  return result;
}

ClonedFace cloneFace(const FaceModel& sourceNeutral, std::span<const DeformedCopy> sourceCopies,
                     const FaceModel& targetNeutral, const CloneOptions& options) {
  CloneResult cloned = cloneDeformedCopies(sourceNeutral, sourceCopies, targetNeutral, options);
  const GeneratedTables tables =
      generateFaceDefTables(cloned.targetNeutral, measureFapu(cloned.targetNeutral), cloned.copies);
  ClonedFace out;
  out.face = {std::move(cloned.targetNeutral), tables.faceDefTables};
  out.copies = std::move(cloned.copies);
  out.warnings = std::move(cloned.warnings);
  out.warnings.insert(out.warnings.end(), tables.warnings.begin(), tables.warnings.end());
  return out;
}

}  // namespace mpeg4face
