// SPDX-License-Identifier: GPL-3.0-or-later
#include "model/landmark_rules.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <tuple>

#include "percentile.hpp"

namespace mpeg4face::landmark_fit {
namespace {

constexpr double kNone = std::numeric_limits<double>::infinity();

// The triangles of `s` with a corner within `reach` of `centre`.
std::vector<int> trianglesNear(const Surface& s, const Vector3d& centre, double reach) {
  std::vector<int> out;
  for (int t = 0; t < s.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if ((s.corner(t, k) - centre).norm() < reach) {
        out.push_back(t);
        break;
      }
    }
  }
  return out;
}

// The distance along the ray o + t d (d of unit length) to its first hit on the triangles
// `ids` of `s`, kNone if it meets none (Moeller and Trumbore 1997).
double firstHit(const Surface& s, const std::vector<int>& ids, const Vector3d& o,
                const Vector3d& d) {
  double nearest = kNone;
  for (const int t : ids) {
    const Vector3d a = s.corner(t, 0), e1 = s.corner(t, 1) - a, e2 = s.corner(t, 2) - a;
    const Vector3d p = d.cross(e2);
    const double det = e1.dot(p);
    if (std::abs(det) < 1e-300) continue;
    const Vector3d from = o - a, q = from.cross(e1);
    const double u = from.dot(p) / det, v = d.dot(q) / det, at = e2.dot(q) / det;
    if (u >= 0 && v >= 0 && u + v <= 1 && at > 0) nearest = std::min(nearest, at);
  }
  return nearest;
}

// An eye and the skin around it seen from the front: which of them a ray along -front
// meets first. The eye's opening is where it is the eye.
class FrontView {
 public:
  FrontView(const Surface& skin, const Surface& eye, const Vector3d& pupil,
            const Vector3d& front, double es0)
      : skin_(skin), eye_(eye), front_(front), reach_(0.6 * es0),
        skinNear_(trianglesNear(skin, pupil, reach_)),
        eyeNear_(trianglesNear(eye, pupil, reach_)) {}

  bool eyeSeen(const Vector3d& at) const {
    const Vector3d o = at + reach_ * front_;
    const double onEye = firstHit(eye_, eyeNear_, o, -front_);
    return onEye < kNone && onEye < firstHit(skin_, skinNear_, o, -front_);
  }
  // The skin's point seen at `at` (its line along front), if the skin is seen first there.
  std::optional<Vector3d> skinSeen(const Vector3d& at) const {
    const Vector3d o = at + reach_ * front_;
    const double onSkin = firstHit(skin_, skinNear_, o, -front_);
    if (onSkin == kNone || onSkin >= firstHit(eye_, eyeNear_, o, -front_)) return std::nullopt;
    return o - onSkin * front_;
  }
  // The skin vertex seen from the front nearest `at` across the line of sight: a point on
  // the opening's edge binds to the vertex in front, not to one the lid hides (on a coarse
  // mesh the margin's triangles run back into the socket, 7% of ES0 deep). -1: none within
  // `within`.
  int nearestSeenVertex(const Vector3d& at, double within) const {
    int best = -1;
    double nearest = within;
    for (Eigen::Index v = 0; v < skin_.points.rows(); ++v) {
      const Vector3d q = skin_.points.row(v);
      const Vector3d across = (q - at) - (q - at).dot(front_) * front_;
      if (across.norm() >= nearest || (q - at).norm() > 2 * within) continue;
      const auto seen = skinSeen(q);
      if (seen && (*seen - q).norm() < 0.1 * within) {
        nearest = across.norm();
        best = static_cast<int>(v);
      }
    }
    return best;
  }

 private:
  const Surface& skin_;
  const Surface& eye_;
  Vector3d front_;
  double reach_;
  std::vector<int> skinNear_, eyeNear_;
};

// Where a lid meets the eye, seen from the front: on the line along `up` through the lid
// point the fit placed, the first height, going from the pupil's towards the fit's and on,
// at which the skin is seen before the eye. The standard's IRISD0 is the distance between
// the lids (3.1 to 3.3), so their points sit at the opening's edge; the fit alone left the
// ICT head's lower lid 4% of ES0 below it, a quarter of IRISD0. nullopt where the eye is not
// seen at the pupil's height (a closed eye) or no lid within 0.4 ES0 of it.
std::optional<Vector3d> lidMargin(const FrontView& view, const Vector3d& pupil,
                                  const Vector3d& fitted, const Vector3d& up, double es0) {
  const Vector3d towards = up.dot(fitted - pupil) >= 0 ? up : Vector3d(-up);
  const Vector3d base = fitted - towards * towards.dot(fitted - pupil);
  if (!view.eyeSeen(base)) return std::nullopt;
  const double step = 0.005 * es0;
  for (double h = step; h <= 0.4 * es0; h += step) {
    std::optional<Vector3d> seen = view.skinSeen(base + h * towards);
    if (!seen) continue;
    double eyeAt = h - step, skinAt = h;  // bisected down to a thousandth of ES0
    while (skinAt - eyeAt > 0.001 * es0) {
      const double mid = (eyeAt + skinAt) / 2;
      if (const auto s = view.skinSeen(base + mid * towards)) {
        skinAt = mid;
        seen = s;
      } else {
        eyeAt = mid;
      }
    }
    return seen;
  }
  return std::nullopt;
}

// The eye's outer corner (3.7, 3.12): the far end of its opening seen from the front,
// `lateral` pointing away from the midline. The fit alone left it 5-8% of ES0 off on the
// sample heads: the template's eye is shaped differently. (The inner corner is left to the
// fit: both samples put it on the skin of the tear duct, past the opening.) nullopt where
// the eye is not seen at the pupil.
std::optional<Vector3d> outerEyeCorner(const FrontView& view, const Vector3d& pupil,
                                       const Vector3d& up, const Vector3d& lateral,
                                       double es0) {
  if (!view.eyeSeen(pupil)) return std::nullopt;
  const auto at = [&](double u, double v) {
    return Vector3d(pupil + es0 * (u * lateral + v * up));
  };
  // A grid of 1% of ES0 for the farthest cell seen, then its rows a fifth as far apart and
  // each walked out in steps of 0.2%.
  double farU = -1, farV = 0;
  for (double v = -0.2; v <= 0.2; v += 0.01) {
    for (double u = 0.45; u > farU; u -= 0.01) {
      if (view.eyeSeen(at(u, v))) {
        farU = u;
        farV = v;
        break;
      }
    }
  }
  if (farU < 0) return std::nullopt;
  std::optional<Vector3d> corner;
  double cornerU = -1;
  for (double v = farV - 0.01; v <= farV + 0.01; v += 0.002) {
    double u = farU - 0.02;
    if (!view.eyeSeen(at(u, v))) continue;
    while (u < farU + 0.02 && view.eyeSeen(at(u + 0.002, v))) u += 0.002;
    if (u <= cornerU) continue;
    if (const auto skin = view.skinSeen(at(u + 0.002, v))) {
      corner = skin;
      cornerU = u;
    }
  }
  return corner;
}

}  // namespace

// Vertex normals of a triangle set over `points`.
std::vector<Vector3d> normalsOf(const Points3& points, const std::vector<int>& triangles) {
  std::vector<Vector3d> n(static_cast<std::size_t>(points.rows()), Vector3d::Zero());
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
    const Vector3d a = points.row(triangles[t]), b = points.row(triangles[t + 1]),
                   c = points.row(triangles[t + 2]);
    const Vector3d f = (b - a).cross(c - a);
    for (std::size_t k = 0; k < 3; ++k) n[static_cast<std::size_t>(triangles[t + k])] += f;
  }
  for (Vector3d& v : n) v = v.norm() > 0 ? v.normalized() : Vector3d::Zero();
  return n;
}

// The midline points onto the head's symmetry plane, the nose tip as its most forward midline
// vertex, the subnasale as the deepest midline vertex between the nose tip and the upper lip
// (the rules both sample heads' points follow), the eyelids and the outer eye corners at the
// edge of the eye's opening.
void refineByRules(const FaceModel& templateHead, const Surface& face,
                   const std::vector<Surface>& parts, const Matrix3d& rotation, double es0,
                   LandmarkResult& result) {
  const auto placedAt = [&](const std::string& id) -> std::optional<Vector3d> {
    const auto p = result.points.find(id);
    if (p == result.points.end() || p->second.binding.mesh != face.mesh) return std::nullopt;
    return p->second.binding.position;
  };
  // Left/right pairs and midline points, by the template's x (MPEG-4 axes: x to the face's
  // left, the midline at the template's symmetry plane).
  std::vector<std::pair<std::string, Vector3d>> templatePoints;
  for (const auto& [id, b] : templateHead.featurePoints) {
    if (const auto p = templateHead.featurePointPosition(id); p && result.points.count(id))
      templatePoints.emplace_back(id, *p);
  }
  double midX = 0;
  int onMid = 0;
  for (const auto& [id, p] : templatePoints) {
    if (id == "9.3" || id == "2.1" || id == "8.1" || id == "9.15") {
      midX += p.x();
      ++onMid;
    }
  }
  midX = onMid ? midX / onMid : 0;
  const double templateEs0 = es0 / result.scale;
  Vector3d normal = Vector3d::Zero();
  std::vector<Vector3d> middles;
  std::vector<std::string> midline;
  for (const auto& [id, p] : templatePoints) {
    if (std::abs(p.x() - midX) < 0.005 * templateEs0) {
      midline.push_back(id);
      continue;
    }
    if (p.x() < midX) continue;
    for (const auto& [other, q] : templatePoints) {
      const Vector3d mirrored(2 * midX - q.x(), q.y(), q.z());
      if (other == id || (mirrored - p).norm() > 0.02 * templateEs0) continue;
      const auto a = placedAt(id), b = placedAt(other);
      if (!a || !b) continue;
      normal += *a - *b;
      middles.push_back((*a + *b) / 2);
    }
  }
  if (middles.size() < 4 || !(normal.norm() > 0)) return;
  normal.normalize();
  double offset = 0;
  for (const Vector3d& m : middles) offset += normal.dot(m);
  offset /= static_cast<double>(middles.size());
  // The plane refined on the surface itself: each face vertex near the points and the
  // surface point nearest its mirror image are a pair the plane's reflection should swap.
  {
    Vector3d centre = Vector3d::Zero();
    for (const Vector3d& m : middles) centre += m;
    centre /= static_cast<double>(middles.size());
    std::vector<Eigen::Index> near;
    for (Eigen::Index v = 0; v < face.points.rows(); ++v) {
      if ((face.points.row(v).transpose() - centre).norm() < 1.2 * es0) near.push_back(v);
    }
    const std::size_t step = std::max<std::size_t>(1, near.size() / 2000);
    for (int it = 0; it < 10; ++it) {
      Vector3d sum = Vector3d::Zero(), across = Vector3d::Zero();  // across: the midpoints
      int pairs = 0;
      for (std::size_t k = 0; k < near.size(); k += step) {
        const Vector3d p = face.points.row(near[k]);
        const double side = normal.dot(p) - offset;
        if (std::abs(side) < 0.05 * es0) continue;  // too near the plane to say which way
        const Vector3d image = p - 2 * side * normal;
        const ClosestPoint c = face.search->closest(image);
        if ((c.point - image).norm() > 0.05 * es0) continue;
        sum += side > 0 ? Vector3d(p - c.point) : Vector3d(c.point - p);
        across += (p + c.point) / 2;
        ++pairs;
      }
      if (pairs < 20 || !(sum.norm() > 0)) break;
      normal = sum.normalized();
      offset = normal.dot(across / pairs);  // with the new normal: far from the origin the
                                            // old one's offset is off by the turn times the
                                            // distance
    }
  }
  // Forward and up in the plane.
  Vector3d front = rotation * Vector3d::UnitZ();
  front = (front - front.dot(normal) * normal).normalized();
  Vector3d up = normal.cross(front).normalized();
  if ((rotation * Vector3d::UnitY()).dot(up) < 0) up = -up;
  // Half the mesh's median edge, so that a coarse mesh still has a vertex on the plane.
  std::vector<double> edgeLengths;
  for (int t = 0; t < face.triangleCount(); ++t) {
    edgeLengths.push_back((face.corner(t, 1) - face.corner(t, 0)).norm());
  }
  const double band = std::clamp(0.5 * percentile(edgeLengths, 0.5), 0.005 * es0, 0.03 * es0);
  // On the plane and facing out of it, not a wall of the plane such as the nasal septum.
  const std::vector<Vector3d> facing = normalsOf(face.points, face.triangles);
  const auto onPlane = [&](Eigen::Index v) {
    return std::abs(normal.dot(face.points.row(v).transpose()) - offset) < band &&
           std::abs(facing[static_cast<std::size_t>(v)].dot(normal)) < 0.5;
  };
  const auto set = [&](const std::string& id, Eigen::Index v, const std::string& rule) {
    PlacedFeaturePoint& p = result.points[id];
    p.binding.vertex = static_cast<int>(v);
    p.binding.position = face.points.row(v);
    p.rule = rule;
  };
  // The eyelids and the outer eye corners, at the edge of the eye's opening (the eye mesh
  // that holds the pupil).
  const auto onSkin = [&](const FrontView& view, const std::string& id, const Vector3d& at,
                          const std::string& rule) {
    const int seen = view.nearestSeenVertex(at, 0.1 * es0);
    set(id, seen >= 0 ? seen : nearestCorner(face.points, face.search->closest(at), at), rule);
  };
  for (const auto& [pupilId, upper, lower, corner] :
       {std::tuple{"3.5", "3.1", "3.3", "3.7"}, std::tuple{"3.6", "3.2", "3.4", "3.12"}}) {
    const auto pupil = result.points.find(pupilId);
    if (pupil == result.points.end()) continue;
    const auto eye = std::find_if(parts.begin(), parts.end(), [&](const Surface& s) {
      return s.mesh == pupil->second.binding.mesh;
    });
    if (eye == parts.end()) continue;
    const Vector3d centre = pupil->second.binding.position;
    const FrontView view(face, *eye, centre, front, es0);
    for (const char* lid : {upper, lower}) {
      if (const auto at = placedAt(lid)) {
        if (const auto margin = lidMargin(view, centre, *at, up, es0)) {
          onSkin(view, lid, *margin, "on the lid margin, seen from the front");
        }
      }
    }
    const Vector3d lateral = normal.dot(centre) > offset ? normal : Vector3d(-normal);
    if (placedAt(corner)) {
      if (const auto end = outerEyeCorner(view, centre, up, lateral, es0)) {
        onSkin(view, corner, *end, "outer end of the eye's opening, seen from the front");
      }
    }
  }
  // Midline points: the plane's vertex nearest where the fit put them.
  for (const std::string& id : midline) {
    const auto at = placedAt(id);
    if (!at) continue;
    Eigen::Index best = -1;
    double nearest = 0.15 * es0;
    for (Eigen::Index v = 0; v < face.points.rows(); ++v) {
      const double d = (face.points.row(v).transpose() - *at).norm();
      if (d < nearest && onPlane(v)) {
        nearest = d;
        best = v;
      }
    }
    if (best >= 0) set(id, best, "fit, on the symmetry plane");
  }
  // The nose tip: the most forward midline vertex near the fit's.
  if (const auto tip = placedAt("9.3")) {
    Eigen::Index best = -1;
    double ahead = -std::numeric_limits<double>::infinity();
    for (Eigen::Index v = 0; v < face.points.rows(); ++v) {
      const Vector3d q = face.points.row(v);
      if ((q - *tip).norm() > 0.4 * es0 || !onPlane(v) || front.dot(q) <= ahead) continue;
      ahead = front.dot(q);
      best = v;
    }
    if (best >= 0) set("9.3", best, "most forward midline vertex");
  }
  // The subnasale: the least forward vertex of the midline profile (the most forward
  // midline vertex at each height, of those facing forward: not the nose's inside) between
  // the nose tip and the upper lip.
  const auto tip = placedAt("9.3"), lip = placedAt("8.1"), sub = placedAt("9.15");
  if (tip && lip && sub) {
    const double bin = 0.025 * es0;
    std::map<long, Eigen::Index> profile;  // height bin -> most forward vertex
    for (Eigen::Index v = 0; v < face.points.rows(); ++v) {
      const Vector3d q = face.points.row(v);
      if (!onPlane(v) || up.dot(q) >= up.dot(*tip) || up.dot(q) <= up.dot(*lip) ||
          (q - *sub).norm() > 0.3 * es0 || facing[static_cast<std::size_t>(v)].dot(front) < 0)
        continue;
      const long key = std::lround(up.dot(q) / bin);
      const auto [at, added] = profile.emplace(key, v);
      if (!added && front.dot(q) > front.dot(face.points.row(at->second).transpose())) {
        at->second = v;
      }
    }
    Eigen::Index best = -1;
    double depth = std::numeric_limits<double>::infinity();
    for (const auto& [key, v] : profile) {
      const double d = front.dot(face.points.row(v).transpose());
      if (d < depth) {
        depth = d;
        best = v;
      }
    }
    if (best >= 0) set("9.15", best, "least forward midline vertex between 9.3 and 8.1");
  }
}

}  // namespace mpeg4face::landmark_fit
