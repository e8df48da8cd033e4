// SPDX-License-Identifier: GPL-3.0-or-later
// Facial Motion Cloning (Pandzic 2003): checks, the vertex mapping applied to every copy,
// and the target's tables. docs/clone.md.
#include "mpeg4face/clone/clone.hpp"

#include <algorithm>

#include "clone/clone_internal.hpp"
#include "mpeg4face/clone/rigid.hpp"
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

std::vector<Eigen::Matrix3d> linearParts(const FaceModel& model, bool inverse) {
  std::vector<Eigen::Matrix3d> out;
  for (const Eigen::Affine3d& w : model.meshWorldMatrices()) {
    out.push_back(inverse ? Eigen::Matrix3d(w.linear().inverse()) : Eigen::Matrix3d(w.linear()));
  }
  return out;
}

}  // namespace

CloneResult cloneDeformedCopies(const FaceModel& sourceNeutral,
                                std::span<const FaceShape> sourceCopies,
                                const FaceModel& targetNeutral, const CloneOptions& options) {
  requireFeaturePointsAndFapu(sourceNeutral, targetNeutral);
  for (const FaceShape& copy : sourceCopies) checkFaceShape(sourceNeutral, copy);

  CloneResult result;
  result.targetNeutral = targetNeutral;
  // Eyes, teeth and tongue move as rigid parts (clone/rigid.hpp), the head by its Transform;
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
  // This copy's target motion (mesh-local) and which rows move, reused from copy to copy.
  const std::size_t targetRows = targetSurface.owner.size();
  Points3 moved(static_cast<Eigen::Index>(targetRows), 3);
  std::vector<bool> moves(targetRows);
  std::vector<int> movedInMesh(result.targetNeutral.meshes.size());
  result.copies.reserve(sourceCopies.size());
  for (std::size_t c = 0; c < sourceCopies.size(); ++c) {
    if (options.progress) {
      options.progress(
          "copies", 0.5 + 0.5 * static_cast<double>(c) / static_cast<double>(sourceCopies.size()));
    }
    const FaceShape& from = sourceCopies[c];
    // Normalised source motion of every surface vertex, in model space (0 where the copy
    // lists none; rigid meshes are not on the surface).
    motion.setZero();
    for (const MeshDisplacement& d : from.meshes) {
      const int first = sourceSurface.firstRow[static_cast<std::size_t>(d.mesh)];
      if (first < 0) continue;
      for (std::size_t k = 0; k < d.vertices.size(); ++k) {
        const Eigen::Index r = first + d.vertices[k];
        const Eigen::Vector3d local = d.displacement.row(static_cast<Eigen::Index>(k)).transpose();
        motion.row(r) = (toModel[static_cast<std::size_t>(d.mesh)] * local)
                            .cwiseQuotient(map.sourceFactors.row(r).transpose())
                            .transpose();
      }
    }
    FaceShape& to = result.copies.emplace_back();
    to.name = from.name;
    to.fapID = from.fapID;
    to.highLevelSelect = from.highLevelSelect;
    to.amplitude = from.amplitude;
    to.transforms = result.targetNeutral.transforms;
    if (options.rigidParts) {
      cloneRigidMotion(rigid, sourceNeutral, sourceFapu, from, result.targetNeutral, targetFapu,
                       to.transforms);
    }
    std::fill(movedInMesh.begin(), movedInMesh.end(), 0);
    for (std::size_t t = 0; t < targetRows; ++t) {
      Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
      for (int i = map.rowStart[t]; i < map.rowStart[t + 1]; ++i) {
        sum += map.weight[static_cast<std::size_t>(i)] *
               motion.row(map.source[static_cast<std::size_t>(i)]);
      }
      moves[t] = !sum.isZero(0);
      if (!moves[t]) continue;
      const int m = targetSurface.owner[t].first;
      const Eigen::Vector3d modelMotion = sum.transpose().cwiseProduct(
          map.targetFactors.row(static_cast<Eigen::Index>(t)).transpose());
      moved.row(static_cast<Eigen::Index>(t)) =
          (toLocal[static_cast<std::size_t>(m)] * modelMotion).transpose();
      ++movedInMesh[static_cast<std::size_t>(m)];
    }
    // Rows are grouped by mesh, vertices ascending (gatherSurface).
    for (std::size_t m = 0; m < movedInMesh.size(); ++m) {
      if (movedInMesh[m] == 0) continue;
      MeshDisplacement& d = to.meshes.emplace_back();
      d.mesh = static_cast<int>(m);
      d.vertices.reserve(static_cast<std::size_t>(movedInMesh[m]));
      d.displacement.resize(movedInMesh[m], 3);
      const int first = targetSurface.firstRow[m];
      const int count = result.targetNeutral.meshes[m].vertexCount();
      for (int v = 0; v < count; ++v) {
        if (!moves[static_cast<std::size_t>(first + v)]) continue;
        d.displacement.row(static_cast<Eigen::Index>(d.vertices.size())) = moved.row(first + v);
        d.vertices.push_back(v);
      }
    }
  }
  if (options.relaxation) {
    std::vector<int> surfaceMeshes;
    for (std::size_t m = 0; m < targetSurface.firstRow.size(); ++m) {
      if (targetSurface.firstRow[m] >= 0) surfaceMeshes.push_back(static_cast<int>(m));
    }
    clone::relaxClonedShapes(result.targetNeutral, surfaceMeshes, *options.relaxation,
                             result.copies);
  }
  if (options.progress) options.progress("copies", 1.0);
  return result;
}

ClonedFace cloneFace(const FaceModel& sourceNeutral, std::span<const FaceShape> sourceCopies,
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
