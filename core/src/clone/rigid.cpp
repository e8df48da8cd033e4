// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/clone/rigid.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <set>

#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

using Kind = RigidPart::Kind;

// The parts found from feature points; the Head part is handled apart (it holds them all).
struct PartSpec {
  Kind kind;
  std::array<std::string_view, 4> points;  // unused slots empty
  FapuKind unit;                           // scales the part's translation
};
constexpr std::array<PartSpec, 5> kParts{{
    {Kind::LeftEye, {"3.5"}, FapuKind::ES},
    {Kind::RightEye, {"3.6"}, FapuKind::ES},
    {Kind::UpperTeeth, {"9.8", "9.10"}, FapuKind::MNS},
    {Kind::LowerTeeth, {"9.9", "9.11"}, FapuKind::MNS},
    {Kind::Tongue, {"6.1", "6.2", "6.3", "6.4"}, FapuKind::MNS},
}};
constexpr int kPartCount = static_cast<int>(kParts.size());
constexpr FapuKind kHeadUnit = FapuKind::ES;

bool isPartPoint(const PartSpec& spec, const std::string& id) {
  return std::find(spec.points.begin(), spec.points.end(), id) != spec.points.end();
}

std::string pointList(const PartSpec& spec) {
  std::string out;
  for (std::string_view p : spec.points) {
    if (p.empty()) continue;
    out += (out.empty() ? "" : ", ") + std::string(p);
  }
  return out;
}

// Tolerances relative to the model's size: what counts as motion in a copy, and how far a
// rotation centre may be from the part's centre (fraction of the part's size).
constexpr double kMotionTolerance = 1e-6;
constexpr double kCentreTolerance = 0.01;
// Vertex positions closer than this fraction of the part's feature-point meshes' size
// (bounding-box diagonal) are shared.
constexpr double kConnectTolerance = 0.001;

// A mesh in model space, for the connected-mesh test and part centres.
struct MeshGeometry {
  Points3 points;
  Eigen::AlignedBox3d box;
};

// The Transform tree of a model as walked by FaceModel::meshWorldMatrices (depth first from
// the roots, a mesh belonging to its first holder, a transform walked once).
struct Scene {
  std::vector<int> parent, depth;
  std::vector<int> holder;                      // per mesh, -1 if no transform holds it
  std::vector<Eigen::Affine3d> world;           // per transform, its own local matrix included
  std::vector<std::vector<int>> subtreeMeshes;  // per transform
  std::vector<MeshGeometry> geometry;
  std::vector<std::vector<std::string>> featurePoints;  // per mesh, the ids bound to it

  Eigen::Affine3d parentWorld(int t) const {
    return parent[t] >= 0 ? world[parent[t]] : Eigen::Affine3d::Identity();
  }
  // Where the Transform's centre is in model space (it stays there when rotation changes).
  Eigen::Vector3d pivot(const FaceModel& model, int t) const {
    const Transform& x = model.transforms[t];
    return parentWorld(t) * (x.translation + x.center);
  }
};

// The tree alone (what a copy's motion needs), or with the meshes in model space and their
// feature points (what identifying the parts needs).
enum class SceneContent { Transforms, TransformsAndMeshes };

Scene makeScene(const FaceModel& model, SceneContent content) {
  const int nt = static_cast<int>(model.transforms.size());
  const int nm = static_cast<int>(model.meshes.size());
  Scene s;
  s.parent.assign(nt, -1);
  s.depth.assign(nt, 0);
  s.holder.assign(nm, -1);
  s.world.assign(nt, Eigen::Affine3d::Identity());
  s.subtreeMeshes.assign(nt, {});
  std::vector<bool> visited(nt, false);
  std::function<void(int, int, const Eigen::Affine3d&)> walk = [&](int t, int up,
                                                                   const Eigen::Affine3d& m) {
    if (t < 0 || t >= nt || visited[t]) return;
    visited[t] = true;
    s.parent[t] = up;
    s.depth[t] = up >= 0 ? s.depth[up] + 1 : 0;
    s.world[t] = m * model.transforms[t].localMatrix();
    for (int mesh : model.transforms[t].meshes) {
      if (mesh >= 0 && mesh < nm && s.holder[mesh] < 0) s.holder[mesh] = t;
    }
    for (int child : model.transforms[t].children) walk(child, t, s.world[t]);
  };
  for (int root : model.roots) walk(root, -1, Eigen::Affine3d::Identity());
  for (int mesh = 0; mesh < nm; ++mesh) {
    for (int t = s.holder[mesh]; t >= 0; t = s.parent[t]) s.subtreeMeshes[t].push_back(mesh);
  }
  if (content == SceneContent::Transforms) return s;
  const std::vector<Eigen::Affine3d> meshWorld = model.meshWorldMatrices();
  s.geometry.resize(nm);
  for (int mesh = 0; mesh < nm; ++mesh) {
    MeshGeometry& g = s.geometry[mesh];
    const IndexedFaceSet& set = model.meshes[mesh];
    g.points.resize(set.vertexCount(), 3);
    for (int v = 0; v < set.vertexCount(); ++v) {
      g.points.row(v) = (meshWorld[mesh] * set.coord.row(v).transpose()).transpose();
      g.box.extend(g.points.row(v).transpose());
    }
  }
  s.featurePoints.assign(nm, {});
  for (const auto& [id, fp] : model.featurePoints) {
    if (fp.mesh >= 0 && fp.mesh < nm && fp.vertex >= 0 &&
        fp.vertex < model.meshes[fp.mesh].vertexCount()) {
      s.featurePoints[fp.mesh].push_back(id);
    }
  }
  return s;
}

// Two meshes are connected when they share a vertex position (within `tol`): pieces of one
// object meet along common vertices; a mesh that merely lies close (eyelashes by the
// eyeball, a joint helper inside the tongue) is not part of it.
bool connected(const MeshGeometry& a, const MeshGeometry& b, double tol) {
  if (a.box.isEmpty() || b.box.isEmpty() || a.box.exteriorDistance(b.box) > tol) return false;
  Eigen::AlignedBox3d overlap = a.box.intersection(b.box);
  overlap.min().array() -= tol;
  overlap.max().array() += tol;
  std::vector<Eigen::Vector3d> near;
  for (Eigen::Index w = 0; w < b.points.rows(); ++w) {
    if (overlap.contains(b.points.row(w).transpose())) near.push_back(b.points.row(w).transpose());
  }
  const double tol2 = tol * tol;
  for (Eigen::Index v = 0; v < a.points.rows(); ++v) {
    const Eigen::Vector3d p = a.points.row(v).transpose();
    if (!overlap.contains(p)) continue;
    for (const Eigen::Vector3d& q : near) {
      if ((p - q).squaredNorm() <= tol2) return true;
    }
  }
  return false;
}

Eigen::AlignedBox3d boxOf(const Scene& s, const std::vector<int>& meshes) {
  Eigen::AlignedBox3d box;
  for (int mesh : meshes) box.extend(s.geometry[mesh].box);
  return box;
}

double sizeOf(const Scene& s, const std::vector<int>& meshes) {
  const Eigen::AlignedBox3d box = boxOf(s, meshes);
  return box.isEmpty() ? 0.0 : box.diagonal().norm();
}

// The eyeball's centre: the least-squares sphere through the vertices (|p|^2 = 2 c.p + k),
// the bounding-box centre when the vertices do not span a volume or the sphere's centre
// falls outside the box. The pupil centre 3.5 / 3.6 lies on the surface, not at the centre
// the eye turns about.
Eigen::Vector3d eyeCentre(const Scene& s, const std::vector<int>& meshes) {
  const Eigen::AlignedBox3d box = boxOf(s, meshes);
  Eigen::Index n = 0;
  for (int mesh : meshes) n += s.geometry[mesh].points.rows();
  if (box.isEmpty()) return Eigen::Vector3d::Zero();
  if (n < 4) return box.center();
  const Eigen::Vector3d mid = box.center();
  Eigen::MatrixXd a(n, 4);
  Eigen::VectorXd rhs(n);
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  Eigen::Index row = 0;
  for (int mesh : meshes) {
    const Points3& pts = s.geometry[mesh].points;
    for (Eigen::Index v = 0; v < pts.rows(); ++v, ++row) {
      const Eigen::Vector3d x = pts.row(v).transpose() - mid;
      a.row(row) << 2 * x.transpose(), 1.0;
      rhs(row) = x.squaredNorm();
      scatter += x * x.transpose();
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> spread(scatter);
  if (spread.eigenvalues()(0) <= 1e-6 * spread.eigenvalues()(2)) return mid;
  const Eigen::Vector4d fit = a.colPivHouseholderQr().solve(rhs);
  const Eigen::Vector3d centre = mid + fit.head<3>();
  return centre.allFinite() && box.contains(centre) ? centre : mid;
}

// The meshes of each part in one face, found from its feature points and grown over
// connected meshes.
struct Identified {
  std::array<std::vector<int>, kPartCount> meshes;  // sorted; empty if not found
  std::array<std::string, kPartCount> why;          // why a part is not found
  std::vector<int> faceMeshes;                      // meshes holding any feature point
  std::vector<int> partOf;                          // per mesh: part index, -1
};

Identified identify(const FaceModel& model, const Scene& s) {
  const int nm = static_cast<int>(model.meshes.size());
  Identified out;
  out.partOf.assign(nm, -1);
  for (int mesh = 0; mesh < nm; ++mesh) {
    if (!s.featurePoints[mesh].empty() && s.holder[mesh] >= 0) out.faceMeshes.push_back(mesh);
  }
  // Seeds: a mesh holding a feature point of the part and none of anything else (a mesh
  // that also holds skin or another part's points is not a rigid part, e.g. CANDIDE's).
  std::array<double, kPartCount> tolerance{};
  for (int p = 0; p < kPartCount; ++p) {
    const PartSpec& spec = kParts[p];
    bool bound = false;
    std::vector<int> seeds;
    for (std::string_view id : spec.points) {
      if (id.empty()) continue;
      const auto it = model.featurePoints.find(std::string(id));
      if (it == model.featurePoints.end()) continue;
      const int mesh = it->second.mesh;
      if (mesh < 0 || mesh >= nm || s.holder[mesh] < 0) continue;
      bound = true;
      const auto& ids = s.featurePoints[mesh];
      const auto other = std::find_if(ids.begin(), ids.end(),
                                      [&](const std::string& x) { return !isPartPoint(spec, x); });
      if (other != ids.end()) {
        out.why[p] = "mesh '" + model.meshes[mesh].name + "' holding " + std::string(id) +
                     " also holds " + *other + ", so it is not a separate mesh";
        seeds.clear();
        break;
      }
      if (std::find(seeds.begin(), seeds.end(), mesh) == seeds.end()) seeds.push_back(mesh);
    }
    if (!bound) out.why[p] = "none of " + pointList(spec) + " is bound to a vertex of a mesh";
    for (int mesh : seeds) out.partOf[mesh] = p;
    out.meshes[p] = seeds;
    tolerance[p] = kConnectTolerance * sizeOf(s, seeds);
  }
  // Grow every part at once, a ring of connected meshes per round, over meshes that hold no
  // feature point. A mesh two parts reach in the same round (clenched teeth) joins neither.
  std::array<std::vector<int>, kPartCount> frontier = out.meshes;
  std::vector<bool> contested(nm, false);
  for (bool grew = true; grew;) {
    grew = false;
    std::vector<std::vector<int>> claims(nm);
    for (int mesh = 0; mesh < nm; ++mesh) {
      if (out.partOf[mesh] >= 0 || contested[mesh] || !s.featurePoints[mesh].empty() ||
          s.holder[mesh] < 0) {
        continue;
      }
      for (int p = 0; p < kPartCount; ++p) {
        for (int from : frontier[p]) {
          if (connected(s.geometry[from], s.geometry[mesh], tolerance[p])) {
            claims[mesh].push_back(p);
            break;
          }
        }
      }
    }
    for (auto& f : frontier) f.clear();
    for (int mesh = 0; mesh < nm; ++mesh) {
      if (claims[mesh].size() > 1) contested[mesh] = true;
      if (claims[mesh].size() != 1) continue;
      const int p = claims[mesh].front();
      out.partOf[mesh] = p;
      out.meshes[p].push_back(mesh);
      frontier[p].push_back(mesh);
      grew = true;
    }
  }
  for (auto& meshes : out.meshes) std::sort(meshes.begin(), meshes.end());
  return out;
}

// A mesh that belongs to something other than part p: another part's, or one holding a
// feature point that is not p's (the skin).
bool foreignTo(const Scene& s, const Identified& id, int p, int mesh) {
  if (id.partOf[mesh] >= 0 && id.partOf[mesh] != p) return true;
  const auto& ids = s.featurePoints[mesh];
  return std::any_of(ids.begin(), ids.end(),
                     [&](const std::string& x) { return !isPartPoint(kParts[p], x); });
}

// The lowest Transform over all `meshes`; -1 if some mesh has no holder or there is none.
int lowestCommon(const Scene& s, const std::vector<int>& meshes) {
  int common = -1;
  for (size_t i = 0; i < meshes.size(); ++i) {
    int t = s.holder[meshes[i]];
    if (t < 0) return -1;
    if (i == 0) {
      common = t;
      continue;
    }
    while (s.depth[t] > s.depth[common]) t = s.parent[t];
    while (s.depth[common] > s.depth[t]) common = s.parent[common];
    while (t != common && t >= 0) {
      t = s.parent[t];
      common = s.parent[common];
    }
    if (common < 0) return -1;
  }
  return common;
}

// Whether Transform t holds a mesh foreign to part p (p = -1: the Head, nothing is).
bool holdsForeign(const Scene& s, const Identified& id, int p, int t) {
  if (p < 0) return false;
  const auto& meshes = s.subtreeMeshes[t];
  return std::any_of(meshes.begin(), meshes.end(),
                     [&](int mesh) { return foreignTo(s, id, p, mesh); });
}

std::vector<bool> movingTransforms(const FaceModel& neutral, std::span<const FaceShape> copies,
                                   const Scene& s) {
  const size_t nt = neutral.transforms.size();
  Eigen::AlignedBox3d box;
  for (const MeshGeometry& g : s.geometry) box.extend(g.box);
  const double size = box.isEmpty() ? 1.0 : std::max(box.diagonal().norm(), 1e-12);
  std::vector<bool> moves(nt, false);
  for (const FaceShape& copy : copies) {
    if (copy.transforms.empty()) continue;  // moves no Transform
    if (copy.transforms.size() != nt) {
      throw Error(copy.name, 0, "transforms",
                  "the copy has " + std::to_string(copy.transforms.size()) +
                      " Transforms, the source neutral " + std::to_string(nt));
    }
    for (size_t t = 0; t < nt; ++t) {
      const Transform& a = neutral.transforms[t];
      const Transform& b = copy.transforms[t];
      if ((a.translation - b.translation).norm() > kMotionTolerance * size ||
          a.rotation.angularDistance(b.rotation) > kMotionTolerance ||
          (a.scale - b.scale).cwiseAbs().maxCoeff() >
              kMotionTolerance * a.scale.cwiseAbs().maxCoeff()) {
        moves[t] = true;
      }
    }
  }
  return moves;
}

// Moves the rotation centre of Transform t to the model-space point `centre` without moving
// anything: T' = T + (C - C') - R S (C - C').
void installCentre(FaceModel& model, const Scene& s, int t, const Eigen::Vector3d& centre) {
  Transform& x = model.transforms[t];
  const Eigen::Vector3d local = s.world[t].inverse() * centre;
  const Eigen::Vector3d shift = x.center - local;
  x.translation += shift - x.rotation * x.scale.cwiseProduct(shift);
  x.center = local;
}

std::string transformName(const FaceModel& model, int t) {
  return "Transform '" + model.transforms[t].name + "'";
}

}  // namespace

std::string_view rigidPartName(Kind kind) {
  switch (kind) {
    case Kind::LeftEye:
      return "left eye";
    case Kind::RightEye:
      return "right eye";
    case Kind::UpperTeeth:
      return "upper teeth";
    case Kind::LowerTeeth:
      return "lower teeth";
    case Kind::Tongue:
      return "tongue";
    case Kind::Head:
      return "head";
  }
  return "part";
}

RigidPartMap matchRigidParts(const FaceModel& sourceNeutral,
                             std::span<const FaceShape> sourceCopies, FaceModel& target) {
  RigidPartMap map;
  const Scene source = makeScene(sourceNeutral, SceneContent::TransformsAndMeshes);
  const std::vector<bool> moves = movingTransforms(sourceNeutral, sourceCopies, source);
  Scene goal = makeScene(target, SceneContent::TransformsAndMeshes);
  const Identified sourceParts = identify(sourceNeutral, source);
  const Identified targetParts = identify(target, goal);
  for (int p = 0; p < kPartCount; ++p) {
    map.sourceRigidMeshes.insert(map.sourceRigidMeshes.end(), sourceParts.meshes[p].begin(),
                                 sourceParts.meshes[p].end());
    map.targetRigidMeshes.insert(map.targetRigidMeshes.end(), targetParts.meshes[p].begin(),
                                 targetParts.meshes[p].end());
  }
  std::sort(map.sourceRigidMeshes.begin(), map.sourceRigidMeshes.end());
  std::sort(map.targetRigidMeshes.begin(), map.targetRigidMeshes.end());

  std::set<int> claimed, claimedTarget;  // Transforms given to a part
  // Parts in order, the head (p = kPartCount) last.
  for (int p = 0; p <= kPartCount; ++p) {
    const bool head = p == kPartCount;
    const int spec = head ? -1 : p;
    RigidPart part;
    part.kind = head ? Kind::Head : kParts[p].kind;
    const std::string name(rigidPartName(part.kind));
    part.sourceMeshes = head ? sourceParts.faceMeshes : sourceParts.meshes[p];
    part.targetMeshes = head ? targetParts.faceMeshes : targetParts.meshes[p];
    if (part.sourceMeshes.empty()) continue;  // a moving Transform is reported below
    // Source: the lowest Transform over the meshes that moves, below anything foreign.
    for (int t = lowestCommon(source, part.sourceMeshes);
         t >= 0 && !holdsForeign(source, sourceParts, spec, t); t = source.parent[t]) {
      if (moves[t]) {
        part.sourceTransform = t;
        break;
      }
    }
    if (part.sourceTransform < 0) continue;  // the part does not move
    claimed.insert(part.sourceTransform);
    const std::string skipped = "the " + name + " moves in the source (" +
                                transformName(sourceNeutral, part.sourceTransform) +
                                ") but its motion is skipped: ";
    if (part.targetMeshes.empty()) {
      map.warnings.push_back(
          skipped + "the target " +
          (head ? std::string("has no feature points on its meshes") : targetParts.why[p]));
      continue;
    }
    // The centre the motion is taken about.
    Eigen::Vector3d sourceCentre, targetCentre;
    if (head) {
      const auto neck = [](const FaceModel& m) {
        auto c = m.featurePointPosition("7.2");
        return c ? c : m.featurePointPosition("7.1");
      };
      const auto t = neck(target);
      if (!t) {
        map.warnings.push_back(skipped + "the target binds neither 7.2 (neck base) nor 7.1");
        continue;
      }
      targetCentre = *t;
      sourceCentre =
          neck(sourceNeutral).value_or(source.pivot(sourceNeutral, part.sourceTransform));
    } else if (part.kind == Kind::LeftEye || part.kind == Kind::RightEye) {
      sourceCentre = eyeCentre(source, part.sourceMeshes);
      targetCentre = eyeCentre(goal, part.targetMeshes);
    } else {
      sourceCentre = boxOf(source, part.sourceMeshes).center();
      targetCentre = boxOf(goal, part.targetMeshes).center();
    }
    const bool rotates = head || part.kind == Kind::LeftEye || part.kind == Kind::RightEye;
    // The source's own pivot when it is the right one, so that a pure rotation stays one.
    if (rotates) {
      const Eigen::Vector3d pivot = source.pivot(sourceNeutral, part.sourceTransform);
      if ((pivot - sourceCentre).norm() <= kCentreTolerance * sizeOf(source, part.sourceMeshes)) {
        sourceCentre = pivot;
      }
    }
    // Target: the lowest Transform over the meshes, if it holds nothing foreign; else a new
    // Transform of their own under their common holder.
    int t = lowestCommon(goal, part.targetMeshes);
    if (t < 0 || holdsForeign(goal, targetParts, spec, t)) {
      std::vector<int> holders;
      for (int mesh : part.targetMeshes) holders.push_back(goal.holder[mesh]);
      const bool oneHolder =
          std::all_of(holders.begin(), holders.end(), [&](int h) { return h == holders[0]; });
      const bool allHeld =
          std::none_of(holders.begin(), holders.end(), [](int h) { return h < 0; });
      Transform inserted;
      inserted.name = "fmc_" + name;
      std::replace(inserted.name.begin(), inserted.name.end(), ' ', '_');
      const int index = static_cast<int>(target.transforms.size());
      if (!head && oneHolder && holders[0] >= 0) {
        Transform& h = target.transforms[holders[0]];
        inserted.meshes = part.targetMeshes;
        std::erase_if(h.meshes, [&](int mesh) {
          return std::binary_search(part.targetMeshes.begin(), part.targetMeshes.end(), mesh);
        });
        h.children.push_back(index);
      } else if (head && allHeld) {
        inserted.children = target.roots;
        target.roots = {index};
      } else {
        map.warnings.push_back(skipped + "the target's " + name +
                               " meshes have no Transform in common");
        continue;
      }
      target.transforms.push_back(std::move(inserted));
      goal = makeScene(target, SceneContent::TransformsAndMeshes);
      t = index;
    }
    if (claimedTarget.count(t) != 0) {
      map.warnings.push_back(skipped + "the target's " + transformName(target, t) +
                             " already moves another part");
      continue;
    }
    claimedTarget.insert(t);
    if (rotates && (goal.pivot(target, t) - targetCentre).norm() >
                       kCentreTolerance * sizeOf(goal, part.targetMeshes)) {
      installCentre(target, goal, t, targetCentre);
      goal = makeScene(target, SceneContent::TransformsAndMeshes);
    }
    if (rotates) targetCentre = goal.pivot(target, t);
    part.targetTransform = t;
    part.sourceCentre = sourceCentre;
    part.targetCentre = targetCentre;
    const double sourceSize = sizeOf(source, part.sourceMeshes);
    part.sizeRatio = sourceSize > 0 ? sizeOf(goal, part.targetMeshes) / sourceSize : 1.0;
    map.parts.push_back(std::move(part));
  }
  for (int t = 0; t < static_cast<int>(moves.size()); ++t) {
    if (moves[t] && claimed.count(t) == 0) {
      map.warnings.push_back(transformName(sourceNeutral, t) +
                             " moves in the source copies but holds no eye, teeth, tongue or "
                             "head identified from feature points: its motion is skipped");
    }
  }
  return map;
}

void cloneRigidMotion(const RigidPartMap& map, const FaceModel& sourceNeutral,
                      const FapuMeasurement& sourceFapu, const FaceShape& sourceCopy,
                      const FaceModel& targetNeutral, const FapuMeasurement& targetFapu,
                      std::vector<Transform>& transforms) {
  if (map.parts.empty()) return;
  const Scene source = makeScene(sourceNeutral, SceneContent::Transforms);
  const Scene goal = makeScene(targetNeutral, SceneContent::Transforms);
  const int ns = static_cast<int>(sourceNeutral.transforms.size());
  const int nt = static_cast<int>(std::min(transforms.size(), targetNeutral.transforms.size()));
  const std::vector<Transform>& sourceTransforms = shapeTransforms(sourceNeutral, sourceCopy);
  if (static_cast<int>(sourceTransforms.size()) != ns) {
    throw Error(sourceCopy.name, 0, "transforms",
                "the copy's Transform tree differs from the source neutral's");
  }
  for (const RigidPart& part : map.parts) {
    const int st = part.sourceTransform, tt = part.targetTransform;
    if (st < 0 || st >= ns || tt < 0 || tt >= nt) {
      throw Error(sourceCopy.name, 0, std::string(rigidPartName(part.kind)),
                  "the part's Transform is not in the source neutral or the target copy");
    }
    // The source part's motion in model space, its parent held still: D = P L1 L0^-1 P^-1.
    const Transform& s0 = sourceNeutral.transforms[st];
    const Transform& s1 = sourceTransforms[st];
    const Eigen::Affine3d up = source.parentWorld(st);
    const Eigen::Affine3d motion =
        up * s1.localMatrix() * s0.localMatrix().inverse() * up.inverse();
    const Eigen::Vector3d displacement = motion * part.sourceCentre - part.sourceCentre;
    // The rotation change R0^-1 R1 turned to model-space axes, then to the target's.
    const Eigen::Matrix3d sourceAxes = up.rotation() * s0.rotation.toRotationMatrix();
    const Eigen::Matrix3d turn =
        sourceAxes * (s0.rotation.inverse() * s1.rotation) * sourceAxes.transpose();
    Transform& t = transforms[tt];
    const Eigen::Affine3d targetUp = goal.parentWorld(tt);
    const Eigen::Matrix3d targetAxes = targetUp.rotation() * t.rotation.toRotationMatrix();
    const Eigen::Vector3d local = goal.world[tt].inverse() * part.targetCentre;

    const FapuKind unit = part.kind == Kind::Head
                              ? kHeadUnit
                              : std::find_if(kParts.begin(), kParts.end(), [&](const PartSpec& x) {
                                  return x.kind == part.kind;
                                })->unit;
    const double su = sourceFapu.unit(unit), tu = targetFapu.unit(unit);
    const double ratio = su > 0 && tu > 0 ? tu / su : part.sizeRatio;

    t.rotation =
        (t.rotation * Eigen::Quaterniond(targetAxes.transpose() * turn * targetAxes)).normalized();
    for (int k = 0; k < 3; ++k) {
      if (s0.scale(k) != 0) t.scale(k) *= s1.scale(k) / s0.scale(k);
    }
    // The target centre moves by ratio * displacement: P (T + C + R S (u - C)) = c + r d.
    t.translation = targetUp.inverse() * (part.targetCentre + ratio * displacement) - t.center -
                    t.rotation * t.scale.cwiseProduct(local - t.center);
  }
}

}  // namespace mpeg4face
