// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/model/fapu.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

using Positions = std::map<std::string, Eigen::Vector3d, std::less<>>;

Positions boundPositions(const FaceModel& model) {
  Positions out;
  const std::vector<Eigen::Affine3d> world = model.meshWorldMatrices();
  for (const auto& [id, fp] : model.featurePoints) {
    if (fp.mesh < 0) {
      out[id] = fp.position;
    } else if (fp.mesh < static_cast<int>(model.meshes.size()) && fp.vertex >= 0 &&
               fp.vertex < model.meshes[fp.mesh].vertexCount()) {
      out[id] = world[fp.mesh] * Eigen::Vector3d(model.meshes[fp.mesh].coord.row(fp.vertex));
    }
  }
  return out;
}

const Eigen::Vector3d* find(const Positions& p, std::string_view id) {
  auto it = p.find(id);
  return it == p.end() ? nullptr : &it->second;
}

// A pupil centre: the pupil point itself, else the midpoint of the two eye corners.
struct Pupil {
  Eigen::Vector3d position;
  std::vector<std::string> points;
};
std::optional<Pupil> pupil(const Positions& p, const char* centre, const char* cornerA,
                           const char* cornerB) {
  if (const auto* c = find(p, centre)) return Pupil{*c, {centre}};
  const auto* a = find(p, cornerA);
  const auto* b = find(p, cornerB);
  if (a && b) return Pupil{(*a + *b) / 2.0, {cornerA, cornerB}};
  return std::nullopt;
}

void setDistance(FapuDistance& d, double value, std::vector<std::string> points,
                 std::string method) {
  d.pointsUsed = std::move(points);
  if (value > 0.0 && std::isfinite(value)) {
    d.measured = true;
    d.value = value;
    d.method = std::move(method);
  } else {
    d.method = method + " is not positive (is the face Y-up with its left at +X?)";
  }
}

void append(std::vector<std::string>& to, const std::vector<std::string>& from) {
  to.insert(to.end(), from.begin(), from.end());
}

std::string pupilMethod(const Pupil& p) {
  return p.points.size() == 1 ? p.points[0] : "(" + p.points[0] + "+" + p.points[1] + ")/2";
}

// A term of a Table 6 constraint: `OP P.c` or `OP (P.c+Q.c)/2`.
struct ConstraintTerm {
  char op;
  std::vector<std::string> points;
  std::string text;  // the expression as written, for messages
};

std::vector<ConstraintTerm> parseConstraint(std::string_view spec, std::string_view fp) {
  std::vector<ConstraintTerm> terms;
  std::istringstream in{std::string(spec)};
  std::string token;
  while (in >> token) {
    ConstraintTerm t;
    t.op = token[0];
    t.text = token.substr(1);
    std::string expr = t.text;
    if (expr.size() > 4 && expr.front() == '(' && expr.ends_with(")/2")) {
      expr = expr.substr(1, expr.size() - 4);
      const auto plus = expr.find('+');
      if (plus == std::string::npos) throw Error("bad constraint for " + std::string(fp));
      t.points = {expr.substr(0, plus), expr.substr(plus + 1)};
    } else {
      t.points = {expr};
    }
    for (std::string& p : t.points) {
      // "2.2.x" -> "2.2": the axis is the constraint's own.
      const auto dot = p.rfind('.');
      if (dot == std::string::npos) throw Error("bad constraint for " + std::string(fp));
      p.resize(dot);
    }
    if (t.op != '=' && t.op != '<' && t.op != '>') {
      throw Error("bad constraint operator for " + std::string(fp));
    }
    terms.push_back(std::move(t));
  }
  return terms;
}

std::string percent(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f%%", v * 100.0);
  return buf;
}

}  // namespace

double FapuMeasurement::unit(FapuKind kind) const {
  const FapuDistance* d = nullptr;
  switch (kind) {
    case FapuKind::AU:
      return kAngleUnitRadians;
    case FapuKind::ES:
      d = &ES0;
      break;
    case FapuKind::IRISD:
      d = &IRISD0;
      break;
    case FapuKind::ENS:
      d = &ENS0;
      break;
    case FapuKind::MNS:
      d = &MNS0;
      break;
    case FapuKind::MW:
      d = &MW0;
      break;
    case FapuKind::None:
      return 0.0;
  }
  return d->measured ? d->value / kFapuDivisor : 0.0;
}

std::array<FapuMeasurement::NamedDistance, 5> FapuMeasurement::distances() const {
  return {{{"ES0", &ES0}, {"IRISD0", &IRISD0}, {"ENS0", &ENS0}, {"MNS0", &MNS0}, {"MW0", &MW0}}};
}

std::vector<std::string> FapuMeasurement::missing() const {
  std::vector<std::string> out;
  for (auto [name, d] : distances()) {
    if (!d->measured) out.emplace_back(name);
  }
  return out;
}

FapuMeasurement measureFapu(const FaceModel& model) {
  const Positions p = boundPositions(model);
  FapuMeasurement m;
  // What each distance needs; replaced by how it was measured when it is.
  m.ES0.method = "needs 3.5 and 3.6, or the eye corners 3.7, 3.11, 3.8 and 3.12";
  m.IRISD0.method = "needs 3.1 and 3.3, or 3.2 and 3.4";
  m.ENS0.method =
      "needs 9.15 and a pupil (3.5 or 3.6) or an eye's corners (3.7 and 3.11, or "
      "3.8 and 3.12)";
  m.MNS0.method = "needs 9.15 and 2.2";
  m.MW0.method = "needs 8.3 and 8.4, or 2.4 and 2.5";

  const auto left = pupil(p, "3.5", "3.7", "3.11");
  const auto right = pupil(p, "3.6", "3.8", "3.12");
  if (left && right) {
    std::vector<std::string> points = left->points;
    append(points, right->points);
    setDistance(m.ES0, (left->position - right->position).norm(), std::move(points),
                "|" + pupilMethod(*left) + " - " + pupilMethod(*right) + "|");
  }

  {
    double sum = 0.0;
    int eyes = 0;
    std::vector<std::string> points;
    std::string method;
    for (auto [upper, lower] : {std::pair{"3.1", "3.3"}, {"3.2", "3.4"}}) {
      const auto* u = find(p, upper);
      const auto* l = find(p, lower);
      if (!u || !l) continue;
      sum += u->y() - l->y();
      ++eyes;
      points.insert(points.end(), {upper, lower});
      method += std::string(method.empty() ? "" : ", ") + upper + ".y - " + lower + ".y";
    }
    if (eyes > 0) {
      setDistance(m.IRISD0, sum / eyes, std::move(points),
                  eyes == 2 ? "mean of " + method : method);
    }
  }

  const auto* noseBottom = find(p, "9.15");
  if (noseBottom && (left || right)) {
    std::vector<std::string> points;
    double eyeLevel = 0.0;
    std::string method;
    if (left && right) {
      eyeLevel = (left->position.y() + right->position.y()) / 2.0;
      points = left->points;
      append(points, right->points);
      method = "mean y of " + pupilMethod(*left) + " and " + pupilMethod(*right);
    } else {
      const Pupil& one = left ? *left : *right;
      eyeLevel = one.position.y();
      points = one.points;
      method = "y of " + pupilMethod(one);
    }
    points.emplace_back("9.15");
    setDistance(m.ENS0, eyeLevel - noseBottom->y(), std::move(points), method + " - 9.15.y");
  }

  if (const auto* upperLip = find(p, "2.2"); noseBottom && upperLip) {
    setDistance(m.MNS0, noseBottom->y() - upperLip->y(), {"9.15", "2.2"}, "9.15.y - 2.2.y");
  }

  for (auto [a, b] : {std::pair{"8.3", "8.4"}, {"2.4", "2.5"}}) {
    const auto* pa = find(p, a);
    const auto* pb = find(p, b);
    if (pa && pb) {
      setDistance(m.MW0, (*pa - *pb).norm(), {a, b}, std::string("|") + a + " - " + b + "|");
      break;
    }
  }
  return m;
}

std::vector<ConstraintWarning> checkLocationConstraints(const FaceModel& model,
                                                        const FapuMeasurement& fapu,
                                                        double tolerance) {
  const Positions p = boundPositions(model);
  std::vector<ConstraintWarning> warnings;
  if (p.empty()) return warnings;

  double scale = fapu.ES0.value;
  std::string scaleName = "ES0";
  if (!fapu.ES0.measured) {
    Eigen::AlignedBox3d box;
    for (const auto& [id, pos] : p) box.extend(pos);
    scale = box.diagonal().norm();
    scaleName = "the feature points' extent";
  }
  if (!(scale > 0.0)) return warnings;

  for (const FeaturePointInfo& info : featurePointTable()) {
    const auto* self = find(p, info.id);
    if (!self) continue;
    const std::string id(info.id);
    for (auto [axis, spec] :
         {std::pair{0, info.constraintX}, {1, info.constraintY}, {2, info.constraintZ}}) {
      const char axisName = "xyz"[axis];
      for (const ConstraintTerm& term : parseConstraint(spec, info.id)) {
        double expected = 0.0;
        bool bound = true;
        for (const std::string& other : term.points) {
          const auto* q = find(p, other);
          if (!q) {
            bound = false;
            break;
          }
          expected += (*q)[axis];
        }
        if (!bound) continue;
        expected /= static_cast<double>(term.points.size());
        const double value = (*self)[axis];
        const double limit = tolerance * scale;
        const std::string lhs = id + "." + axisName;
        std::string message;
        if (term.op == '=' && std::abs(value - expected) > limit) {
          message = lhs + " differs from " + term.text + " by " +
                    percent(std::abs(value - expected) / scale) + " of " + scaleName;
        } else if (term.op == '<' && value > expected + limit) {
          message = lhs + " should be < " + term.text + " but exceeds it by " +
                    percent((value - expected) / scale) + " of " + scaleName;
        } else if (term.op == '>' && value < expected - limit) {
          message = lhs + " should be > " + term.text + " but falls short by " +
                    percent((expected - value) / scale) + " of " + scaleName;
        }
        if (message.empty()) continue;
        const bool advisory = !info.constraintNote.empty();
        if (advisory) message += " (Table 6: " + std::string(info.constraintNote) + ")";
        warnings.push_back({id, axisName, std::move(message), advisory});
      }
    }
  }
  return warnings;
}

}  // namespace mpeg4face
