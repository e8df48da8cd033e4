// SPDX-License-Identifier: GPL-3.0-or-later
// The talking portrait: feature points moved in FAPU in the image plane, or along tracks.
#include "mpeg4face/mesh2d/portrait.hpp"

#include <algorithm>
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

// Calls row(line, fields) for each row of a CSV: fields trimmed, blank lines and # comments
// skipped.
template <typename Row>
void forEachCsvRow(std::string_view text, Row&& row) {
  int line = 0;
  std::vector<std::string_view> fields;
  for (size_t start = 0; start <= text.size();) {
    const size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view r = trim(text.substr(start, end - start));
    start = end + 1;
    ++line;
    if (r.empty() || r.front() == '#') continue;
    fields.clear();
    for (size_t s = 0;;) {
      const size_t comma = r.find(',', s);
      fields.push_back(trim(r.substr(s, comma == std::string_view::npos ? r.npos : comma - s)));
      if (comma == std::string_view::npos) break;
      s = comma + 1;
    }
    row(line, fields);
  }
}

double numberField(std::string_view f, const std::string& source, int line, const char* field) {
  double v = 0;
  const auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
  if (ec != std::errc() || ptr != f.data() + f.size() || !std::isfinite(v)) {
    throw Error(source, line, field, "'" + std::string(f) + "' is not a number");
  }
  return v;
}

}  // namespace

PortraitFeaturePoints parsePortraitFeaturePoints(std::string_view text, const std::string& source) {
  PortraitFeaturePoints out;
  std::vector<Eigen::Vector2d> points;
  forEachCsvRow(text, [&](int line, const std::vector<std::string_view>& fields) {
    if (fields.size() == 3 && fields[0] == "fp" && fields[1] == "x" && fields[2] == "y") return;
    if (fields.size() != 3) throw Error(source, line, "row", "expected fp,x,y");
    if (!findFeaturePoint(fields[0])) {
      throw Error(source, line, "fp", "'" + std::string(fields[0]) + "' is not a feature point");
    }
    const double x = numberField(fields[1], source, line, "x");
    const double y = numberField(fields[2], source, line, "y");
    for (const std::string& id : out.ids) {
      if (id == fields[0]) throw Error(source, line, "fp", id + " is given twice");
    }
    out.ids.emplace_back(fields[0]);
    points.emplace_back(x, y);
  });
  if (out.ids.empty()) throw Error(source, 0, "fp", "no feature points");
  out.positions.resize(static_cast<Eigen::Index>(points.size()), 2);
  for (size_t i = 0; i < points.size(); ++i) {
    out.positions.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  }
  return out;
}

std::vector<Mesh2dNodes> parsePortraitTracks(std::string_view text,
                                             const PortraitFeaturePoints& points,
                                             const std::string& source) {
  std::vector<Mesh2dNodes> frames;
  std::vector<bool> given;
  const auto count = static_cast<Eigen::Index>(points.ids.size());
  auto checkComplete = [&](int line) {
    for (size_t i = 0; i < given.size(); ++i) {
      if (!given[i]) {
        throw Error(source, line, "fp",
                    "frame " + std::to_string(frames.size() - 1) + " lacks " + points.ids[i]);
      }
    }
  };
  forEachCsvRow(text, [&](int line, const std::vector<std::string_view>& fields) {
    if (fields.size() == 4 && fields[0] == "frame" && fields[1] == "fp") return;
    if (fields.size() != 4) throw Error(source, line, "row", "expected frame,fp,x,y");
    const double frame = numberField(fields[0], source, line, "frame");
    if (frame != static_cast<double>(frames.size()) &&
        (frames.empty() || frame != static_cast<double>(frames.size() - 1))) {
      throw Error(source, line, "frame",
                  "frames must be 0, 1, 2, ... in order; expected " +
                      std::to_string(frames.size()) + ", not " + std::string(fields[0]));
    }
    if (frame == static_cast<double>(frames.size())) {
      if (!frames.empty()) checkComplete(line);
      if (frames.size() >= (size_t{1} << 20)) throw Error(source, line, "frame", "too many frames");
      frames.emplace_back(Mesh2dNodes::Zero(count, 2));
      given.assign(points.ids.size(), false);
    }
    const auto it = std::find(points.ids.begin(), points.ids.end(), fields[1]);
    if (it == points.ids.end()) {
      throw Error(source, line, "fp",
                  "'" + std::string(fields[1]) + "' is not one of the portrait's feature points");
    }
    const auto i = static_cast<size_t>(it - points.ids.begin());
    if (given[i]) throw Error(source, line, "fp", points.ids[i] + " is given twice in a frame");
    given[i] = true;
    frames.back()(static_cast<Eigen::Index>(i), 0) = numberField(fields[2], source, line, "x");
    frames.back()(static_cast<Eigen::Index>(i), 1) = numberField(fields[3], source, line, "y");
  });
  if (frames.empty()) throw Error(source, 0, "frame", "no frames");
  checkComplete(0);
  return frames;
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

namespace {

// The portrait's mesh: the image frame, the feature points, an even grid clear of them. A
// point closer than ES0 / 12 to an earlier one (a closed mouth's inner lip points) is no
// node: triangles between the two would fold as they part. anchors[k] is the point at node
// boundary + k.
struct PortraitMesh {
  Mesh2dSequence sequence;
  std::vector<int> anchors;
  double es0 = 0;
};

PortraitMesh portraitIntra(int width, int height, const PortraitFeaturePoints& points, double es0,
                           const PortraitOptions& options) {
  PortraitMesh out;
  out.es0 = es0;
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
    bool clear = true;
    for (size_t j = static_cast<size_t>(boundary); j < nodes.size() && clear; ++j) {
      clear = (nodes[j] - p).norm() >= minGap;
    }
    if (!clear) continue;
    nodes.push_back(p);
    out.anchors.push_back(i);
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
  Mesh2dSequence& s = out.sequence;
  s.width = width;
  s.height = height;
  s.type = Mesh2dType::Delaunay;
  s.boundary = boundary;
  Mesh2dNodes intra(static_cast<Eigen::Index>(nodes.size()), 2);
  for (size_t i = 0; i < nodes.size(); ++i)
    intra.row(static_cast<Eigen::Index>(i)) = nodes[i].transpose();
  s.frames.push_back(intra);
  s.triangles = meshTriangles(s, "the portrait mesh");
  return out;
}

// Appends the plane where the feature points have moved by `moved` (one row per point) and
// the other interior nodes by a Gaussian-weighted share of the anchors' motion; the frame
// stays.
void addPortraitPlane(PortraitMesh& mesh, const Mesh2dNodes& moved) {
  Mesh2dSequence& s = mesh.sequence;
  const Mesh2dNodes& intra = s.frames[0];
  const int boundary = s.boundary;
  const auto anchorCount = static_cast<int>(mesh.anchors.size());
  const double sigma = mesh.es0 / 4;
  Mesh2dNodes plane = intra;
  for (int k = 0; k < anchorCount; ++k) plane.row(boundary + k) += moved.row(mesh.anchors[k]);
  for (Eigen::Index n = boundary + anchorCount; n < intra.rows(); ++n) {
    Eigen::RowVector2d sum = Eigen::RowVector2d::Zero();
    double weights = 1;  // the node's own stillness
    for (int k = 0; k < anchorCount; ++k) {
      const double r2 = (intra.row(n) - intra.row(boundary + k)).squaredNorm();
      const double wgt = 4 * std::exp(-r2 / (2 * sigma * sigma));
      sum += wgt * moved.row(mesh.anchors[k]);
      weights += wgt;
    }
    plane.row(n) += sum / weights;
  }
  s.frames.push_back(std::move(plane));
}

}  // namespace

Mesh2dSequence portraitMesh2d(int width, int height, const PortraitFeaturePoints& points,
                              const FapStream& stream, const PortraitOptions& options) {
  const PortraitFapu fapu = portraitFapu(points);
  const double es0 = fapu.es * kFapuDivisor;
  PortraitMesh mesh = portraitIntra(width, height, points, es0, options);
  const auto featureCount = static_cast<int>(points.ids.size());
  // Which FAPs move which feature point in the image plane, and how far per FAP unit.
  struct Mover {
    int fap, point;  // the point's row in `points`
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
        movers.push_back({f.number, i, direction * unit});
      }
    }
  }
  const std::vector<FapState> states = resolveFapStream(stream);
  for (size_t f = 1; f < states.size(); ++f) {
    Mesh2dNodes moved = Mesh2dNodes::Zero(featureCount, 2);
    for (const Mover& m : movers) {
      if (states[f].has(m.fap)) {
        moved.row(m.point) += states[f].value(m.fap) * m.perUnit.transpose();
      }
    }
    addPortraitPlane(mesh, moved);
  }
  return mesh.sequence;
}

Mesh2dSequence portraitMesh2d(int width, int height, const PortraitFeaturePoints& points,
                              const std::vector<Mesh2dNodes>& tracks,
                              const PortraitOptions& options) {
  // Only ES0 is needed (the mesh's spacing near the points and the motion's spread).
  const double es0 = (need(points, "3.5", "ES") - need(points, "3.6", "ES")).norm();
  if (!(es0 > 0)) throw Error({}, 0, "fapu", "ES measures 0: 3.5 and 3.6 coincide");
  PortraitMesh mesh = portraitIntra(width, height, points, es0, options);
  for (size_t f = 1; f < tracks.size(); ++f) {
    if (tracks[f].rows() != points.positions.rows()) {
      throw Error({}, 0, "frame " + std::to_string(f), "not one position per feature point");
    }
    addPortraitPlane(mesh, tracks[f] - points.positions);
  }
  return mesh.sequence;
}

}  // namespace mpeg4face
