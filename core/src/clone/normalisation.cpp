// SPDX-License-Identifier: GPL-3.0-or-later
// The normalised facial space and the cylindrical projection into the 2D alignment space of
// Facial Motion Cloning (Pandzic 2003, "Normalizing the face", "Aligning source and target
// face"). Choices and formulas in docs/clone.md.
#include <cmath>
#include <numbers>

#include "clone/clone_internal.hpp"
#include "mpeg4face/error.hpp"

namespace mpeg4face::clone {
namespace {

// The mouth's angular width seen from the projection axis, the same for every face.
constexpr double kMouthAngle = std::numbers::pi / 3;

Eigen::Vector3d requirePoint(const FaceModel& model, std::string_view id) {
  const auto p = model.featurePointPosition(std::string(id));
  if (!p) throw Error({}, 0, std::string(id), "feature point " + std::string(id) + " is not bound");
  return *p;
}

}  // namespace

Eigen::Vector3d motionFactors(std::string_view id, const FapuMeasurement& fapu) {
  const double es = fapu.ES0.value, irisd = fapu.IRISD0.value, ens = fapu.ENS0.value,
               mns = fapu.MNS0.value, mw = fapu.MW0.value;
  const std::string_view group = id.substr(0, id.find('.'));
  if (group == "2" || group == "8") return {mw, mns, mns};  // jaw, chin, lips
  if (group == "3") return {es, irisd, es};                 // eyes and lids
  if (group == "9") return {ens, ens, ens};                 // nose
  return {es, ens, es};                                     // brows, cheeks, ears, forehead
}

FaceFrame faceFrame(const FaceModel& model, const FapuMeasurement& fapu) {
  FaceFrame f;
  f.centre = requirePoint(model, "9.15");
  f.positionScale = {fapu.ES0.value, fapu.ENS0.value, fapu.ES0.value};
  const auto normalised = [&](std::string_view id) -> Eigen::Vector3d {
    return (requirePoint(model, id) - f.centre).cwiseQuotient(f.positionScale);
  };
  const Eigen::Vector3d left = normalised("8.3"), right = normalised("8.4");
  const double halfWidth = 0.5 * Eigen::Vector2d(left.x() - right.x(), left.z() - right.z()).norm();
  if (!(halfWidth > 0)) throw Error({}, 0, "8.3", "the mouth corners 8.3 and 8.4 coincide");
  f.axisX = 0.5 * (left.x() + right.x());
  f.axisZ = 0.5 * (left.z() + right.z()) - halfWidth / std::tan(kMouthAngle / 2);
  f.radius = halfWidth / std::sin(kMouthAngle / 2);
  const Eigen::Vector3d nose = normalised("9.3");
  f.angle0 = std::atan2(nose.x() - f.axisX, nose.z() - f.axisZ);
  return f;
}

Eigen::Vector2d project(const FaceFrame& frame, const Eigen::Vector3d& p, double* depth) {
  const Eigen::Vector3d q = (p - frame.centre).cwiseQuotient(frame.positionScale);
  const double dx = q.x() - frame.axisX, dz = q.z() - frame.axisZ;
  double angle = std::atan2(dx, dz) - frame.angle0;
  if (angle > std::numbers::pi) angle -= 2 * std::numbers::pi;
  if (angle <= -std::numbers::pi) angle += 2 * std::numbers::pi;
  if (depth) *depth = -std::hypot(dx, dz);
  return {frame.radius * angle, q.y()};
}

Eigen::Vector3d unproject(const FaceFrame& frame, const Eigen::Vector2d& uv, double depth) {
  const double angle = uv.x() / frame.radius;
  return {-depth * std::sin(angle), uv.y(), -depth * std::cos(angle)};
}

}  // namespace mpeg4face::clone
