// SPDX-License-Identifier: GPL-3.0-or-later
// The talking portrait: feature points moved in FAPU in the image plane.
#include "mpeg4face/mesh2d_portrait.hpp"

#include <charconv>
#include <cmath>
#include <optional>

#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

std::optional<Eigen::Vector2d> pointOf(const PortraitFeaturePoints& p, std::string_view id) {
  for (size_t i = 0; i < p.ids.size(); ++i) {
    if (p.ids[i] == id) return p.positions.row(static_cast<Eigen::Index>(i)).transpose();
  }
  return std::nullopt;
}

Eigen::Vector2d need(const PortraitFeaturePoints& p, std::string_view id, const char* unit) {
  const std::optional<Eigen::Vector2d> v = pointOf(p, id);
  if (!v) {
    throw Error({}, 0, std::string(id),
                std::string("feature point needed for the FAPU ") + unit + " is not in the CSV");
  }
  return *v;
}

}  // namespace

PortraitFeaturePoints parsePortraitFeaturePoints(std::string_view text, const std::string& source) {
  PortraitFeaturePoints out;
  std::vector<Eigen::Vector2d> points;
  int line = 0;
  for (size_t start = 0; start <= text.size();) {
    const size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view row = trim(text.substr(start, end - start));
    start = end + 1;
    ++line;
    if (row.empty() || row.front() == '#') continue;
    std::vector<std::string_view> fields;
    for (size_t s = 0;;) {
      const size_t comma = row.find(',', s);
      fields.push_back(trim(row.substr(s, comma == std::string_view::npos ? row.npos : comma - s)));
      if (comma == std::string_view::npos) break;
      s = comma + 1;
    }
    if (fields.size() == 3 && fields[0] == "fp" && fields[1] == "x" && fields[2] == "y") continue;
    if (fields.size() != 3) throw Error(source, line, "row", "expected fp,x,y");
    if (!findFeaturePoint(fields[0])) {
      throw Error(source, line, "fp", "'" + std::string(fields[0]) + "' is not a feature point");
    }
    double xy[2];
    for (int k = 0; k < 2; ++k) {
      const std::string_view f = fields[static_cast<size_t>(k) + 1];
      const auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), xy[k]);
      if (ec != std::errc() || ptr != f.data() + f.size() || !std::isfinite(xy[k])) {
        throw Error(source, line, k == 0 ? "x" : "y", "'" + std::string(f) + "' is not a number");
      }
    }
    for (const std::string& id : out.ids) {
      if (id == fields[0]) throw Error(source, line, "fp", id + " is given twice");
    }
    out.ids.emplace_back(fields[0]);
    points.emplace_back(xy[0], xy[1]);
  }
  if (out.ids.empty()) throw Error(source, 0, "fp", "no feature points");
  out.positions.resize(static_cast<Eigen::Index>(points.size()), 2);
  for (size_t i = 0; i < points.size(); ++i) {
    out.positions.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  }
  return out;
}

PortraitFapu portraitFapu(const PortraitFeaturePoints& p) {
  PortraitFapu u;
  const Eigen::Vector2d left = need(p, "3.5", "ES"), right = need(p, "3.6", "ES");
  u.es = (left - right).norm() / kFapuDivisor;
  const Eigen::Vector2d nose = need(p, "9.15", "ENS");
  u.ens = std::abs(nose.y() - (left.y() + right.y()) / 2) / kFapuDivisor;
  u.mns = std::abs(need(p, "2.2", "MNS").y() - nose.y()) / kFapuDivisor;
  if (pointOf(p, "8.3") && pointOf(p, "8.4")) {
    u.mw = (need(p, "8.3", "MW") - need(p, "8.4", "MW")).norm() / kFapuDivisor;
  } else {
    u.mw = (need(p, "2.4", "MW") - need(p, "2.5", "MW")).norm() / kFapuDivisor;
  }
  if (pointOf(p, "3.1") && pointOf(p, "3.3")) {
    u.irisd = std::abs(need(p, "3.3", "IRISD").y() - need(p, "3.1", "IRISD").y()) / kFapuDivisor;
  }
  if (u.irisd <= 0) u.irisd = u.es / 3;  // the iris is about a third of the eye separation
  for (const double v : {u.es, u.ens, u.mns, u.mw}) {
    if (!(v > 0)) throw Error({}, 0, "fapu", "a FAPU measures 0: feature points coincide");
  }
  return u;
}

Mesh2dSequence portraitMesh2d(int width, int height, const PortraitFeaturePoints& points,
                              const FapStream& stream, const PortraitOptions& options) {
  const PortraitFapu fapu = portraitFapu(points);
  const double es0 = fapu.es * kFapuDivisor;
  const auto featureCount = static_cast<int>(points.ids.size());
  for (int i = 0; i < featureCount; ++i) {
    const double x = points.positions(i, 0), y = points.positions(i, 1);
    if (x <= 1 || y <= 1 || x >= width - 2 || y >= height - 2) {
      throw Error({}, 0, points.ids[static_cast<size_t>(i)], "lies outside the image");
    }
  }
  // Nodes: the image frame, the feature points, then a grid kept clear of them.
  std::vector<Eigen::Vector2d> nodes;
  const double w = width - 1, h = height - 1;
  const int perSide = 6;
  for (int i = 0; i < perSide; ++i) nodes.emplace_back(w * i / perSide, 0);
  for (int i = 0; i < perSide; ++i) nodes.emplace_back(w, h * i / perSide);
  for (int i = 0; i < perSide; ++i) nodes.emplace_back(w - w * i / perSide, h);
  for (int i = 0; i < perSide; ++i) nodes.emplace_back(0, h - h * i / perSide);
  const int boundary = static_cast<int>(nodes.size());
  const double minGap = es0 / 12;
  for (int i = 0; i < featureCount; ++i) {
    const Eigen::Vector2d p = points.positions.row(i).transpose();
    for (int j = boundary; j < static_cast<int>(nodes.size()); ++j) {
      if ((nodes[static_cast<size_t>(j)] - p).norm() < 0.5) {
        throw Error({}, 0, points.ids[static_cast<size_t>(i)],
                    "coincides with " + points.ids[static_cast<size_t>(j - boundary)]);
      }
    }
    nodes.push_back(p);
  }
  const double spacing =
      std::sqrt(static_cast<double>(width) * height / std::max(1, options.gridNodes));
  for (double y = spacing / 2; y < h - spacing / 4; y += spacing) {
    for (double x = spacing / 2; x < w - spacing / 4; x += spacing) {
      const Eigen::Vector2d p(x, y);
      bool clear = true;
      for (int i = boundary; i < static_cast<int>(nodes.size()) && clear; ++i) {
        clear = (nodes[static_cast<size_t>(i)] - p).norm() > std::max(minGap, spacing / 2);
      }
      if (clear) nodes.push_back(p);
    }
  }
  Mesh2dSequence s;
  s.width = width;
  s.height = height;
  s.type = Mesh2dType::Delaunay;
  s.boundary = boundary;
  Mesh2dNodes intra(static_cast<Eigen::Index>(nodes.size()), 2);
  for (size_t i = 0; i < nodes.size(); ++i)
    intra.row(static_cast<Eigen::Index>(i)) = nodes[i].transpose();
  s.frames.push_back(intra);
  s.triangles = meshTriangles(s, "the portrait mesh");
  // Which FAPs move which feature point in the image plane, and how far per FAP unit.
  struct Mover {
    int fap, node;
    Eigen::Vector2d perUnit;
  };
  std::vector<Mover> movers;
  for (const FapInfo& f : fapTable()) {
    Eigen::Vector2d direction;
    if (f.positiveMotion == "up")
      direction = {0, -1};
    else if (f.positiveMotion == "down")
      direction = {0, 1};
    else if (f.positiveMotion == "left")
      direction = {1, 0};  // the face's left: the image's right
    else if (f.positiveMotion == "right")
      direction = {-1, 0};
    else
      continue;
    double unit = 0;
    switch (f.fapu) {
      case FapuKind::IRISD:
        unit = fapu.irisd;
        break;
      case FapuKind::ES:
        unit = fapu.es;
        break;
      case FapuKind::ENS:
        unit = fapu.ens;
        break;
      case FapuKind::MNS:
        unit = fapu.mns;
        break;
      case FapuKind::MW:
        unit = fapu.mw;
        break;
      default:
        continue;
    }
    for (int i = 0; i < featureCount; ++i) {
      if (points.ids[static_cast<size_t>(i)] == f.featurePoint) {
        movers.push_back({f.number, boundary + i, direction * unit});
      }
    }
  }
  const double sigma = es0 / 4;
  const std::vector<FapState> states = resolveFapStream(stream);
  for (size_t f = 1; f < states.size(); ++f) {
    Mesh2dNodes plane = intra;
    Mesh2dNodes moved = Mesh2dNodes::Zero(intra.rows(), 2);
    for (const Mover& m : movers) {
      if (states[f].has(m.fap)) moved.row(m.node) += states[f].value(m.fap) * m.perUnit.transpose();
    }
    for (int i = boundary; i < boundary + featureCount; ++i) plane.row(i) += moved.row(i);
    for (Eigen::Index n = boundary + featureCount; n < intra.rows(); ++n) {
      Eigen::RowVector2d sum = Eigen::RowVector2d::Zero();
      double weights = 1;  // the node's own stillness
      for (int i = boundary; i < boundary + featureCount; ++i) {
        const double r2 = (intra.row(n) - intra.row(i)).squaredNorm();
        const double wgt = 4 * std::exp(-r2 / (2 * sigma * sigma));
        sum += wgt * moved.row(i);
        weights += wgt;
      }
      plane.row(n) += sum / weights;
    }
    s.frames.push_back(std::move(plane));
  }
  return s;
}

}  // namespace mpeg4face
