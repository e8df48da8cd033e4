// SPDX-License-Identifier: GPL-3.0-or-later
// Facial Motion Cloning: which lip each point of a surface belongs to, from the lip contours
// of the feature points in the cylindrical projection, so that the upper lip moves with the
// source's upper lip only and the lower with the lower (the lip rule, docs/clone.md).
#include <algorithm>

#include "clone/clone_internal.hpp"

namespace mpeg4face::clone {
namespace {

// Crossing-number test.
bool insidePolygon(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& p) {
  bool inside = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Eigen::Vector2d& a = poly[i];
    const Eigen::Vector2d& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

// A contour's projected points sorted along the mouth (by u, so that a face's left / right
// labels do not matter).
std::vector<Eigen::Vector2d> sortedContour(const FaceModel& model, const FaceFrame& frame,
                                           std::span<const std::string_view> ids) {
  std::vector<Eigen::Vector2d> points;
  for (std::string_view id : ids) points.push_back(projectedPoint(model, frame, id));
  std::sort(points.begin(), points.end(),
            [](const auto& a, const auto& b) { return a.x() < b.x(); });
  return points;
}

// The lip contour along the mouth, then the closing points back the other way.
std::vector<Eigen::Vector2d> lipPolygon(std::vector<Eigen::Vector2d> contour,
                                        std::vector<Eigen::Vector2d> back) {
  std::reverse(back.begin(), back.end());
  contour.insert(contour.end(), back.begin(), back.end());
  return contour;
}

// v of a contour sorted by u, linear between its points, held beyond its ends.
double contourHeight(const std::vector<Eigen::Vector2d>& contour, double u) {
  if (u <= contour.front().x()) return contour.front().y();
  for (std::size_t i = 1; i < contour.size(); ++i) {
    const Eigen::Vector2d &a = contour[i - 1], &b = contour[i];
    if (u <= b.x())
      return b.x() > a.x() ? a.y() + (u - a.x()) / (b.x() - a.x()) * (b.y() - a.y()) : b.y();
  }
  return contour.back().y();
}

}  // namespace

// Upper and lower lip vertices coincide on a closed mouth, so a vertex is classified at a
// point nudged a tenth of the way towards the mean centroid of its triangles: that side of
// the contour is the lip it belongs to. A point in the mouth slit (an open mouth's, or one
// nudged into it) belongs to the nearer inner contour, unless most of its neighbours say
// otherwise. The lip feature points are the lip
// the standard says, the corners neither (lipFeaturePoints): a corner's triangles belong
// to the lip of their other corners.
std::vector<LipRegion> classifyLips(const FaceModel& model, const FaceFrame& frame,
                                    const Projected& p, const Points2& centroid,
                                    const Surface& surface) {
  const auto upperContour = sortedContour(model, frame, upperLipContour());
  const auto lowerContour = sortedContour(model, frame, lowerLipContour());
  const auto upper = lipPolygon(upperContour, sortedContour(model, frame, noseSides()));
  const auto lower = lipPolygon(lowerContour, sortedContour(model, frame, chinSides()));
  const auto slit = lipPolygon(upperContour, lowerContour);
  // The box around the three polygons: most of a head is outside it.
  Eigen::Vector2d lo = upper.front(), hi = lo;
  for (const auto* polygon : {&upper, &lower}) {
    for (const Eigen::Vector2d& v : *polygon) {
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
  }
  const Eigen::Index n = p.uv.rows();
  std::vector<LipRegion> lips(static_cast<std::size_t>(n), LipRegion::Outside);
  std::vector<bool> inSlit(static_cast<std::size_t>(n), false);
  for (Eigen::Index r = 0; r < n; ++r) {
    const Eigen::Vector2d q = p.uv.row(r) + 0.1 * (centroid.row(r) - p.uv.row(r));
    if ((q.array() < lo.array()).any() || (q.array() > hi.array()).any()) continue;
    LipRegion& lip = lips[static_cast<std::size_t>(r)];
    if (insidePolygon(upper, q)) {
      lip = LipRegion::Upper;
    } else if (insidePolygon(lower, q)) {
      lip = LipRegion::Lower;
    } else if (insidePolygon(slit, q)) {
      const double middle =
          0.5 * (contourHeight(upperContour, q.x()) + contourHeight(lowerContour, q.x()));
      lip = q.y() >= middle ? LipRegion::Upper : LipRegion::Lower;
      inSlit[static_cast<std::size_t>(r)] = true;
    }
  }
  for (const auto& [id, lip] : lipFeaturePoints()) {
    const auto it = model.featurePoints.find(std::string(id));
    if (it == model.featurePoints.end() || it->second.mesh < 0) continue;
    const int first = surface.firstRow[static_cast<std::size_t>(it->second.mesh)];
    if (first < 0) continue;
    const auto row = static_cast<std::size_t>(first + it->second.vertex);
    lips[row] = lip;
    inSlit[row] = false;
  }
  // Behind the lips (a mouth bag seen through the slit) the height says little: a vertex of
  // the lower lip's inner side may project above the middle. There the surface decides: a
  // slit vertex takes the lip most of its neighbours belong to, until none changes.
  std::vector<std::vector<int>> neighbours(static_cast<std::size_t>(n));
  for (std::size_t t = 0; t + 2 < p.triangles.size(); t += 3) {
    for (std::size_t k = 0; k < 3; ++k) {
      const int a = p.triangles[t + k];
      if (!inSlit[static_cast<std::size_t>(a)]) continue;
      for (std::size_t j = 1; j < 3; ++j) {
        neighbours[static_cast<std::size_t>(a)].push_back(p.triangles[t + (k + j) % 3]);
      }
    }
  }
  for (bool changed = true; changed;) {  // converges: each change adds agreeing neighbours
    changed = false;
    for (Eigen::Index r = 0; r < n; ++r) {
      if (!inSlit[static_cast<std::size_t>(r)]) continue;
      int upperVotes = 0, lowerVotes = 0;
      for (int v : neighbours[static_cast<std::size_t>(r)]) {
        upperVotes += lips[static_cast<std::size_t>(v)] == LipRegion::Upper;
        lowerVotes += lips[static_cast<std::size_t>(v)] == LipRegion::Lower;
      }
      LipRegion& lip = lips[static_cast<std::size_t>(r)];
      const LipRegion vote = upperVotes > lowerVotes   ? LipRegion::Upper
                             : lowerVotes > upperVotes ? LipRegion::Lower
                                                       : lip;
      changed = changed || vote != lip;
      lip = vote;
    }
  }
  return lips;
}

}  // namespace mpeg4face::clone
