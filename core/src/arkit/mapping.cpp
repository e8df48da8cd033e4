// SPDX-License-Identifier: GPL-3.0-or-later
// ARKit shapes -> FAPs, measured on the head: one small non-negative least-squares problem
// per FAP and sign over the feature points' motion; eyeball turns fitted as rotations.
// docs/arkit.md.
#include <Eigen/Dense>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>

#include "arkit/arkit_internal.hpp"
#include "mpeg4face/arkit/shapes.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

// How much more the FAP's own motion along its direction counts than any other motion: the
// amplitude is to be met (within a few percent), the rest kept small.
constexpr double kTargetWeight = 10;
// A key must reach this share of its motion along the FAP's direction ...
constexpr double kMinReached = 0.85;
// ... and move no other feature point more than this (relative to its own motion) ...
constexpr double kMaxOtherMotion = 1.25;
// ... and move its feature point by at least this fraction of ES0 (smaller is noise).
constexpr double kMinMotionEs0 = 0.01;
// A step past the first saturated shape is taken only while its other motion stays within
// this factor of the first step's, or below kCleanResidual (the key grows with its
// next-cleanest shapes, not with all of them).
constexpr double kMaxStepResidual = 1.5;
constexpr double kCleanResidual = 0.5;
// What a shape's weight of 1 costs in the least squares, as motion of a point in ES0.
constexpr double kWeightCost = 0.01;
// An eyeLook shape turns the eye when its motion of the eyeball is a rotation about the eye's
// Transform centre within this share of the motion.
constexpr double kMaxRotationFitError = 0.25;

// The side a FAP acts on, from the l / r / lm / rm part of its standard name.
FaceSide fapSide(const FapInfo& info) {
  std::stringstream parts{std::string(info.name)};
  for (std::string part; std::getline(parts, part, '_');) {
    if (part == "l" || part == "lm") return FaceSide::Left;
    if (part == "r" || part == "rm") return FaceSide::Right;
  }
  return FaceSide::Centre;
}

// The jaw FAPs carry the lower lip, chin, mouth corners and tongue along (the lip FAPs act on
// top of the jaw's), and the jaw turns rather than slides: for them those points are free,
// and so is the chin's motion across the FAP's direction (a jaw opening also draws the chin
// back) but for a little weight that keeps it from growing for nothing.
bool followsJaw(std::string_view point) {
  static const std::set<std::string_view> kPoints{"2.3",  "2.4", "2.5", "2.8", "2.9",
                                                  "2.10", "8.2", "8.3", "8.4", "8.7",
                                                  "8.8",  "6.1", "6.2", "6.3", "6.4"};
  return kPoints.contains(point);
}
constexpr double kJawAcrossWeight = 0;
// depress_chin (18) raises the chin boss 2.10, and the rest of the chin's soft tissue (its
// bottom 2.1) and the lower lip ride on it (the mentalis pushes the lip up; ARKit's
// mouthShrugLower does both): those points are free in that FAP's problem, the lip FAPs act
// on top. Held still, they took a cocktail of some sixteen shapes whose motion between the
// feature points folded a cloned nostril and stretched the mouth corners.
constexpr int kDepressChin = 18;
bool followsChin(std::string_view point) {
  static const std::set<std::string_view> kPoints{"2.1", "2.3", "2.8", "2.9", "8.2", "8.7", "8.8"};
  return kPoints.contains(point);
}
// The points FAP `fap`'s problem leaves free: they move along with it.
bool carriedAlong(int fap, std::string_view point) {
  if (arkit::isJawFap(fap)) return followsJaw(point);
  return fap == kDepressChin && followsChin(point);
}
bool ridesJaw(std::string_view point) {
  return point == "2.3" || point == "2.10" || point == "8.2";
}

struct LinearFap {
  const FapInfo* info;
  Eigen::Vector3d direction;
  double unit;  // model units per FAP unit
  int point;    // index into the motion's points
};

// Rows of one point's motion in a basis whose first vector is `u`.
Eigen::Matrix3d basisWithFirst(const Eigen::Vector3d& u) {
  Eigen::Matrix3d q;
  q.col(0) = u;
  q.col(1) = u.unitOrthogonal();
  q.col(2) = u.cross(q.col(1));
  return q;
}

void mapLinearFap(const LinearFap& fap, int sign, const ArkitPointMotion& motion,
                  const std::vector<int>& columns, double es0, ArkitMapping& out) {
  const double minMotion = kMinMotionEs0 * es0;
  const auto points = static_cast<Eigen::Index>(motion.points.size());
  const auto n = static_cast<Eigen::Index>(columns.size());
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(3 * points, n);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(3 * points);
  Eigen::VectorXd rowWeight = Eigen::VectorXd::Ones(3 * points);
  const Eigen::Vector3d target = sign * fap.direction;
  const Eigen::Matrix3d basis = basisWithFirst(target);
  for (Eigen::Index p = 0; p < points; ++p) {
    Eigen::Matrix<double, 3, Eigen::Dynamic> rows(3, n);
    for (Eigen::Index c = 0; c < n; ++c)
      rows.col(c) = motion.motion.block<3, 1>(3 * p, columns[static_cast<std::size_t>(c)]);
    const std::string& id = motion.points[static_cast<std::size_t>(p)];
    const bool jaw = arkit::isJawFap(fap.info->number);
    if (p == fap.point || (jaw && ridesJaw(id))) {
      // Along the direction: the motion asked for; across: none (for the jaw, little).
      A.middleRows<3>(3 * p) = basis.transpose() * rows;
      b(3 * p) = 1;
      if (p == fap.point) rowWeight(3 * p) = kTargetWeight;
      if (jaw) rowWeight.segment<2>(3 * p + 1).setConstant(kJawAcrossWeight);
    } else if (carriedAlong(fap.info->number, id)) {
      rowWeight.segment<3>(3 * p).setZero();
    } else {
      A.middleRows<3>(3 * p) = rows;
    }
  }
  // The weights themselves cost a little (a weight of 1 as much as moving a point by
  // kWeightCost ES0), which makes the answer unique when shapes overlap.
  Eigen::MatrixXd weighted(3 * points + n, n);
  weighted << rowWeight.asDiagonal() * A, Eigen::MatrixXd::Identity(n, n) * (kWeightCost * es0);
  Eigen::VectorXd wb(3 * points + n);
  wb << rowWeight.asDiagonal() * b, Eigen::VectorXd::Zero(n);
  const Eigen::VectorXd counts = (rowWeight.array() > 0).cast<double>();
  // How good weights `w` are for motion `along` of the FAP's point: the other motion (every
  // row that counts, unweighted, relative to `along`) and the point that moves most.
  struct Quality {
    double residual = 0, worst = 0;
    std::string worstPoint;
  };
  const auto quality = [&](const Eigen::VectorXd& w, double along) {
    Eigen::VectorXd others = counts.asDiagonal() * (A * w - along * b);
    others(3 * fap.point) = 0;
    Quality q{others.norm() / along, 0, ""};
    for (Eigen::Index p = 0; p < points; ++p) {
      if (others.segment<3>(3 * p).norm() > q.worst * along) {
        q.worst = others.segment<3>(3 * p).norm() / along;
        q.worstPoint = motion.points[static_cast<std::size_t>(p)];
      }
    }
    return q;
  };
  const std::string& point = motion.points[static_cast<std::size_t>(fap.point)];
  const std::string toward =
      std::string(sign > 0 ? "" : "against ") + std::string(fap.info->positiveMotion);
  // The amplitude: the combination per unit of motion (NNLS) taken as far as every weight
  // allows (<= 1); when a shape reaches 1 it stays there and the others, solved again for
  // more motion, carry on, as long as each step is clean (a small shape that saturates
  // early, like mouthLowerDown for the chin, hands over to a larger one, like jawOpen).
  Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
  double firstReached = 0, firstResidual = 0;
  char text[160] = "";
  for (Eigen::Index step = 0; step < n; ++step) {
    for (Eigen::Index c = 0; c < n; ++c) {
      if (w(c) >= 1) weighted.col(c).setZero();
    }
    const Eigen::VectorXd w1 = nonNegativeLeastSquares(weighted, wb);
    if (w1.maxCoeff() <= 0) {
      if (step == 0) {
        std::snprintf(text, sizeof text, "no ARKit shape of the head moves %s %s", point.c_str(),
                      toward.c_str());
      }
      break;
    }
    const double reached = (A.row(3 * fap.point) * w1).value();
    const Quality q = quality(w1, reached);
    if (step == 0) {
      firstReached = reached;
      firstResidual = q.residual;
    }
    if (reached < kMinReached || q.worst > kMaxOtherMotion) {
      if (step > 0) break;
      if (reached < kMinReached) {
        std::snprintf(text, sizeof text,
                      "the shapes move %s %s only %.0f%% as asked without moving the other "
                      "feature points more",
                      point.c_str(), toward.c_str(), 100 * reached);
      } else {
        std::snprintf(text, sizeof text,
                      "the shapes that move %s %s move %s %.1f times as much (at most %.2f)",
                      point.c_str(), toward.c_str(), q.worstPoint.c_str(), q.worst,
                      kMaxOtherMotion);
      }
      break;
    }
    if (step > 0 && q.residual > std::max(kMaxStepResidual * firstResidual, kCleanResidual)) break;
    double room = std::numeric_limits<double>::infinity();
    for (Eigen::Index c = 0; c < n; ++c) {
      if (w1(c) > 0) room = std::min(room, (1 - w(c)) / w1(c));
    }
    w += room * w1;
    for (Eigen::Index c = 0; c < n; ++c) {
      if (w(c) > 1 - 1e-9) w(c) = 1;
    }
  }
  if (text[0] != 0) {
    out.missed.push_back({fap.info->number, sign, text});
    return;
  }
  const double along = (A.row(3 * fap.point) * w).value();
  // floor: every weight stays <= 1 (the margin keeps an exact value from rounding down).
  const int value = static_cast<int>(std::floor(along / fap.unit + 1e-9));
  if (value * fap.unit < minMotion) {
    std::snprintf(text, sizeof text,
                  "the shapes move %s %s by %.3g model units at most (less than %.0f%% of ES0)",
                  point.c_str(), toward.c_str(), along, 100 * kMinMotionEs0);
    out.missed.push_back({fap.info->number, sign, text});
    return;
  }
  ArkitFapKey key;
  key.fap = fap.info->number;
  key.amplitude = sign * value;
  w *= value * fap.unit / along;  // the point moves by the amplitude exactly
  for (Eigen::Index c = 0; c < n; ++c) {
    if (w(c) > 1e-4) key.weights.emplace_back(columns[static_cast<std::size_t>(c)], w(c));
  }
  std::sort(key.weights.begin(), key.weights.end(),
            [](const auto& x, const auto& y) { return x.second > y.second; });
  const Quality q = quality(w, value * fap.unit);
  key.reached = firstReached;
  key.residual = q.residual;
  key.worstPoint = q.worstPoint;
  key.worstMotion = q.worst;
  out.keys.push_back(std::move(key));
}

// The Transform that holds mesh `mesh` alone, no child Transform, and no mesh that a feature
// point outside the eyes (group 3) binds: the eyeball as a part of its own; else nullopt.
std::optional<int> eyeTransform(const FaceModel& head, int mesh) {
  for (std::size_t t = 0; t < head.transforms.size(); ++t) {
    const std::vector<int>& meshes = head.transforms[t].meshes;
    if (std::find(meshes.begin(), meshes.end(), mesh) == meshes.end()) continue;
    if (meshes.size() != 1 || !head.transforms[t].children.empty()) return std::nullopt;
    for (const auto& [id, binding] : head.featurePoints) {
      if (!id.starts_with("3.") && binding.mesh >= 0 &&
          std::find(meshes.begin(), meshes.end(), binding.mesh) != meshes.end()) {
        return std::nullopt;
      }
    }
    return static_cast<int>(t);
  }
  return std::nullopt;
}

// The eyeLook shape that turns an eye each way, with the angle ARKit's eyeLook at weight 1
// stands for when the shape does not turn the eyeball itself (it moves the lids only, as
// ICT-FaceKit's do): Apple's own eye angles against its eyeLook weights in a Live Link Face
// capture give about 0.6 rad looking in, out or down and 0.44 rad looking up (docs/arkit.md).
struct EyeLook {
  int fap;
  int sign;
  std::string_view shape;
  double angle;  // radians
};
constexpr std::array<EyeLook, 8> kEyeLooks{{
    {23, 1, "eyeLookOutLeft", 0.6},  // yaw_l_eyeball: the left eye looks left (out)
    {23, -1, "eyeLookInLeft", 0.6},
    {24, 1, "eyeLookInRight", 0.6},  // yaw_r_eyeball: the right eye looks left (in)
    {24, -1, "eyeLookOutRight", 0.6},
    {25, 1, "eyeLookDownLeft", 0.6},  // pitch_l_eyeball: down
    {25, -1, "eyeLookUpLeft", 0.44},
    {26, 1, "eyeLookDownRight", 0.6},
    {26, -1, "eyeLookUpRight", 0.44},
}};

// The eyeball's motion under a shape as a rotation about its Transform's centre (Kabsch), in
// model space (axis * angle); nullopt if the shape does not move it, or not as a rotation.
std::optional<Eigen::Vector3d> fittedTurn(const FaceModel& head, const ArkitShape& shape, int mesh,
                                          const Eigen::Matrix3d& world) {
  const Transform* eye = nullptr;
  for (const Transform& t : head.transforms) {
    if (std::find(t.meshes.begin(), t.meshes.end(), mesh) != t.meshes.end()) eye = &t;
  }
  const Points3& coord = head.meshes[static_cast<std::size_t>(mesh)].coord;
  for (const ArkitTarget& t : shape.targets) {
    if (t.mesh != mesh) continue;
    const Points3& d = head.meshes[static_cast<std::size_t>(mesh)]
                           .morphTargets[static_cast<std::size_t>(t.target)]
                           .displacements;
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    for (Eigen::Index v = 0; v < coord.rows(); ++v) {
      const Eigen::Vector3d p = coord.row(v).transpose() - eye->center;
      h += p * (p + d.row(v).transpose()).transpose();
    }
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
    fix(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1 : 1;
    const Eigen::Matrix3d r = svd.matrixV() * fix * svd.matrixU().transpose();
    double fitError = 0, moved = 0;
    for (Eigen::Index v = 0; v < coord.rows(); ++v) {
      const Eigen::Vector3d p = coord.row(v).transpose() - eye->center;
      fitError += (r * p - p - d.row(v).transpose()).norm();
      moved += d.row(v).norm();
    }
    if (moved == 0 || fitError > kMaxRotationFitError * moved) return std::nullopt;
    const Eigen::AngleAxisd aa(r);
    return aa.angle() * (world * aa.axis()).normalized();
  }
  return std::nullopt;
}

// Eyeball turns 23..26 as rotations of the eyeball's own Transform (the eyeball: the mesh
// feature point 3.5 / 3.6 is on), with the eyeLook shape's motion of the lids: the angle the
// shape turns the eyeball by when it does (fitted), else the nominal angle of kEyeLooks.
void mapEyeball(const FaceModel& head, const ArkitShapes& shapes, bool left, ArkitMapping& out) {
  const std::string point = left ? "3.5" : "3.6";
  auto it = head.featurePoints.find(point);
  const int mesh = it == head.featurePoints.end() ? -1 : it->second.mesh;
  const std::optional<int> transform = mesh < 0 ? std::optional<int>() : eyeTransform(head, mesh);
  const int eye = transform.value_or(-1);
  for (const EyeLook& look : kEyeLooks) {
    if ((look.fap % 2 == 1) != left) continue;
    if (!transform) {
      out.missed.push_back({look.fap, look.sign,
                            "the eyeball (the mesh " + point +
                                " is on) is "
                                "not a mesh under its own Transform"});
      continue;
    }
    std::optional<int> shape;
    for (std::size_t i = 0; i < arkitKnownShapeNames().size(); ++i) {
      if (arkitKnownShapeNames()[i] == look.shape) shape = shapes.find({static_cast<int>(i)});
    }
    if (!shape) {
      out.missed.push_back({look.fap, look.sign, "the head has no " + std::string(look.shape)});
      continue;
    }
    const Eigen::Matrix3d world = head.meshWorldMatrices()[static_cast<std::size_t>(mesh)].linear();
    // yaw left: about +y (turns +z towards +x); pitch down: about +x (turns +z towards -y).
    const Eigen::Vector3d axis =
        look.fap <= 24 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitX();
    ArkitFapKey key;
    double angle = look.angle;
    if (const std::optional<Eigen::Vector3d> turn =
            fittedTurn(head, shapes.shapes[static_cast<std::size_t>(*shape)], mesh, world)) {
      angle = look.sign * turn->dot(axis);
      if (angle <= 0) {
        out.missed.push_back({look.fap, look.sign,
                              std::string(look.shape) + " turns the eyeball "
                                                        "the other way"});
        continue;
      }
      key.residual = (*turn - look.sign * angle * axis).norm() / angle;
    }
    const int value = static_cast<int>(std::lround(angle / kAngleUnitRadians));
    key.fap = look.fap;
    key.amplitude = look.sign * value;
    key.weights = {{*shape, 1.0}};
    key.transform = eye;
    const Eigen::Vector3d local = (world.inverse() * axis).normalized();
    key.rotation = head.transforms[static_cast<std::size_t>(eye)].rotation *
                   Eigen::AngleAxisd(look.sign * value * kAngleUnitRadians, local);
    out.keys.push_back(std::move(key));
  }
}

// Pupils 29 / 30: pupilDilate as the FAP, its amplitude the growth of the pupil's diameter
// (twice the largest outward motion about the pupil's centre, across the gaze) in IRISD.
void mapPupil(const FaceModel& head, const ArkitShapes& shapes, const FapuMeasurement& fapu,
              bool left, ArkitMapping& out) {
  const int fap = left ? 29 : 30;
  const std::string point = left ? "3.5" : "3.6";
  const std::optional<int> shape =
      shapes.find({left ? kArkitShapeCount + 2 : kArkitShapeCount + 3});
  const std::optional<Eigen::Vector3d> centre = head.featurePointPosition(point);
  const double unit = fapu.unit(FapuKind::IRISD);
  if (!shape || !centre || unit == 0) {
    out.missed.push_back({fap, 0,
                          !shape    ? "no pupilDilate shape (not one of ARKit's 52)"
                          : !centre ? "feature point " + point + " is not bound"
                                    : "IRISD0 is not measured"});
    return;
  }
  const std::vector<Eigen::Affine3d> world = head.meshWorldMatrices();
  double growth = 0;
  for (const ArkitTarget& t : shapes.shapes[static_cast<std::size_t>(*shape)].targets) {
    const IndexedFaceSet& mesh = head.meshes[static_cast<std::size_t>(t.mesh)];
    const Points3& d = mesh.morphTargets[static_cast<std::size_t>(t.target)].displacements;
    const Eigen::Affine3d& m = world[static_cast<std::size_t>(t.mesh)];
    for (Eigen::Index v = 0; v < d.rows(); ++v) {
      if (d.row(v).isZero()) continue;
      Eigen::Vector3d radial = m * Eigen::Vector3d(mesh.coord.row(v).transpose()) - *centre;
      radial.z() = 0;
      if (radial.norm() == 0) continue;
      growth = std::max(growth, (m.linear() * d.row(v).transpose()).dot(radial.normalized()));
    }
  }
  const int value = static_cast<int>(std::floor(2 * growth / unit));
  if (value < 1) {
    out.missed.push_back({fap, 0, "pupilDilate does not widen the pupil around " + point});
    return;
  }
  ArkitFapKey key;
  key.fap = fap;
  key.amplitude = value;
  key.weights = {{*shape, 1.0}};
  key.reached = 2 * growth / (value * unit);
  out.keys.push_back(std::move(key));
  out.missed.push_back({fap, -1, "no shape narrows the pupil"});
}

}  // namespace

Eigen::VectorXd nonNegativeLeastSquares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  const Eigen::Index n = A.cols();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  if (n == 0) return x;
  std::vector<bool> passive(static_cast<std::size_t>(n), false);
  const double tolerance = 10 * std::numeric_limits<double>::epsilon() *
                           A.cwiseAbs().colwise().sum().maxCoeff() *
                           static_cast<double>(std::max(A.rows(), n));
  // The unconstrained least-squares solution on the passive set, 0 elsewhere.
  const auto solvePassive = [&]() {
    std::vector<Eigen::Index> cols;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (passive[static_cast<std::size_t>(j)]) cols.push_back(j);
    }
    Eigen::MatrixXd sub(A.rows(), static_cast<Eigen::Index>(cols.size()));
    for (std::size_t k = 0; k < cols.size(); ++k)
      sub.col(static_cast<Eigen::Index>(k)) = A.col(cols[k]);
    const Eigen::VectorXd zp = sub.completeOrthogonalDecomposition().solve(b);
    Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
    for (std::size_t k = 0; k < cols.size(); ++k) z(cols[k]) = zp(static_cast<Eigen::Index>(k));
    return z;
  };
  for (int iteration = 0; iteration < 3 * n + 10; ++iteration) {
    const Eigen::VectorXd gradient = A.transpose() * (b - A * x);
    Eigen::Index next = -1;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (!passive[static_cast<std::size_t>(j)] && gradient(j) > tolerance &&
          (next < 0 || gradient(j) > gradient(next))) {
        next = j;
      }
    }
    if (next < 0) break;
    passive[static_cast<std::size_t>(next)] = true;
    for (int inner = 0; inner < 3 * n + 10; ++inner) {
      const Eigen::VectorXd z = solvePassive();
      double alpha = 1;
      for (Eigen::Index j = 0; j < n; ++j) {
        if (passive[static_cast<std::size_t>(j)] && z(j) <= 0)
          alpha = std::min(alpha, x(j) / (x(j) - z(j)));
      }
      x += alpha * (z - x);
      if (alpha == 1) break;
      for (Eigen::Index j = 0; j < n; ++j) {
        if (passive[static_cast<std::size_t>(j)] && x(j) <= tolerance) {
          passive[static_cast<std::size_t>(j)] = false;
          x(j) = 0;
        }
      }
    }
  }
  return x.cwiseMax(0.0);
}

ArkitMapping mapArkitToFaps(const FaceModel& head, const ArkitShapes& shapes,
                            const FapuMeasurement& fapu) {
  ArkitMapping out;
  std::vector<std::string> ids;
  std::vector<const FapInfo*> linear;
  for (const FapInfo& info : fapTable()) {
    const int f = info.number;
    if (f < 3) continue;
    if (f >= 23 && f <= 26) continue;  // mapEyeball
    if (f == 29 || f == 30) continue;  // mapPupil
    if (f == 27 || f == 28) {
      out.missed.push_back({f, 0, "no ARKit shape thrusts the eyeball"});
    } else if (f == 47) {
      out.missed.push_back({f, 0,
                            "no ARKit shape rolls the tongue (and its motion is a curl, "
                            "not a feature point's)"});
    } else if (info.fapu == FapuKind::AU) {
      out.missed.push_back({f, 0,
                            "a head rotation: a Transform, not a blendshape (Live Link's "
                            "HeadPitch / HeadYaw / HeadRoll)"});
    } else if (!arkit::fapDirection(info.positiveMotion) ||
               info.featurePoint.find(',') != std::string_view::npos) {
      out.missed.push_back({f, 0, "no linear direction at one feature point"});
    } else if (fapu.unit(info.fapu) == 0) {
      out.missed.push_back({f, 0, std::string(fapuName(info.fapu)) + "0 is not measured"});
    } else {
      linear.push_back(&info);
      if (std::find(ids.begin(), ids.end(), info.featurePoint) == ids.end()) {
        ids.emplace_back(info.featurePoint);
      }
    }
  }
  const ArkitPointMotion motion = arkitFeaturePointMotion(head, shapes, ids);
  for (const FapInfo* info : linear) {
    auto p = std::find(motion.points.begin(), motion.points.end(), info->featurePoint);
    if (p == motion.points.end()) {
      out.missed.push_back({info->number, 0,
                            "feature point " + std::string(info->featurePoint) +
                                " is not bound to a vertex of the head"});
      continue;
    }
    const LinearFap fap{info, *arkit::fapDirection(info->positiveMotion), fapu.unit(info->fapu),
                        static_cast<int>(p - motion.points.begin())};
    const FaceSide side = fapSide(*info);
    std::vector<int> columns;
    for (std::size_t s = 0; s < shapes.shapes.size(); ++s) {
      const ArkitShapeRef& ref = shapes.shapes[s].ref;
      const FaceSide shapeSide = arkitShapeSide(ref);
      if (isArkitEyeShape(ref.shape)) continue;
      if (side != FaceSide::Centre && shapeSide != FaceSide::Centre && shapeSide != side) continue;
      columns.push_back(static_cast<int>(s));
    }
    for (int sign : {1, -1}) {
      if (sign < 0 && !info->bidirectional) break;
      mapLinearFap(fap, sign, motion, columns, fapu.ES0.value, out);
    }
  }
  for (bool left : {true, false}) mapEyeball(head, shapes, left, out);
  for (bool left : {true, false}) mapPupil(head, shapes, fapu, left, out);
  const auto byFap = [](const auto& x, const auto& y) {
    return x.fap != y.fap ? x.fap < y.fap : x.amplitude > y.amplitude;
  };
  std::stable_sort(out.keys.begin(), out.keys.end(), byFap);
  std::stable_sort(out.missed.begin(), out.missed.end(), [](const auto& x, const auto& y) {
    return x.fap != y.fap ? x.fap < y.fap : x.sign > y.sign;
  });
  return out;
}

}  // namespace mpeg4face
