// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh design with OpenCV: corner points, a mask's outline.
#include "mpeg4face/mesh2d/design.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

cv::Mat grayOf(const Image& image) {
  const cv::Mat mat(image.height, image.width, image.channels == 1 ? CV_8UC1 : CV_8UC3,
                    const_cast<uint8_t*>(image.pixels.data()));
  if (image.channels == 1) return mat.clone();
  cv::Mat gray;
  cv::cvtColor(mat, gray, cv::COLOR_BGR2GRAY);
  return gray;
}

double halfPixel(double v) { return std::round(2 * v) / 2; }

// `count` points evenly along a closed polyline, starting at its first point.
std::vector<cv::Point2d> resample(const std::vector<cv::Point2d>& line, int count) {
  std::vector<double> at{0};
  for (size_t i = 0; i < line.size(); ++i) {
    at.push_back(at.back() + cv::norm(line[(i + 1) % line.size()] - line[i]));
  }
  std::vector<cv::Point2d> out;
  size_t k = 0;
  for (int i = 0; i < count; ++i) {
    const double s = at.back() * i / count;
    while (at[k + 1] < s) ++k;
    const double f = (s - at[k]) / std::max(1e-12, at[k + 1] - at[k]);
    out.push_back(line[k] + f * (line[(k + 1) % line.size()] - line[k]));
  }
  return out;
}

}  // namespace

Mesh2dSequence designUniformMesh2d(int width, int height, int cols, int rows, int topology) {
  if (width < 2 || height < 2) throw Error({}, 0, "image", "is smaller than 2x2 pixels");
  if (cols < 1 || rows < 1) throw Error({}, 0, "uniform", "needs at least 1x1 cells");
  Mesh2dSequence s;
  s.width = width;
  s.height = height;
  s.type = Mesh2dType::Uniform;
  const double dx = std::floor(2.0 * (width - 1) / cols) / 2;
  const double dy = std::floor(2.0 * (height - 1) / rows) / 2;
  if (dx <= 0 || dy <= 0) throw Error({}, 0, "uniform", "more cells than half pixels");
  s.uniform = {cols + 1, rows + 1, 0, 0, dx, dy, topology};
  s.frames.push_back(uniformMeshNodes(s.uniform));
  return s;
}

Mesh2dSequence designDelaunayMesh2d(const Image& image, int nodes, const Image* mask) {
  if (nodes < 8) throw Error({}, 0, "nodes", "a Delaunay mesh needs at least 8 nodes");
  const cv::Mat gray = grayOf(image);
  cv::Mat region(image.height, image.width, CV_8UC1, cv::Scalar(255));
  std::vector<cv::Point2d> outline;
  if (mask) {
    if (mask->width != image.width || mask->height != image.height) {
      throw Error({}, 0, "mask", "is not the image's size");
    }
    cv::Mat binary;
    cv::threshold(grayOf(*mask), binary, 127, 255, cv::THRESH_BINARY);
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(binary, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
    const auto largest = std::max_element(contours.begin(), contours.end(), [](auto& a, auto& b) {
      return cv::contourArea(a) < cv::contourArea(b);
    });
    if (largest == contours.end() || cv::contourArea(*largest) < 4 * nodes) {
      throw Error({}, 0, "mask", "has no region large enough for the mesh");
    }
    region.setTo(0);
    cv::drawContours(region, contours, static_cast<int>(largest - contours.begin()), 255,
                     cv::FILLED);
    for (const cv::Point& p : *largest) outline.emplace_back(p.x, p.y);
  } else {
    const double w = image.width - 1, h = image.height - 1;
    outline = {{0, 0}, {w, 0}, {w, h}, {0, h}};
  }
  const int boundary = std::max(4, nodes / 10);
  std::vector<cv::Point2d> points;
  if (mask) {
    points = resample(outline, boundary);
  } else {
    // Along each side from its corner, so the corners are nodes.
    const double perimeter = 2.0 * (image.width - 1 + image.height - 1);
    for (size_t side = 0; side < 4; ++side) {
      const cv::Point2d a = outline[side], b = outline[(side + 1) % 4];
      const int n =
          std::max(1, static_cast<int>(std::lround(boundary * cv::norm(b - a) / perimeter)));
      for (int i = 0; i < n; ++i) points.push_back(a + (b - a) * (static_cast<double>(i) / n));
    }
  }
  for (cv::Point2d& p : points) p = {halfPixel(p.x), halfPixel(p.y)};
  const auto boundaryCount = static_cast<int>(points.size());
  // The region is the boundary polygon itself (the resampled outline cuts the mask's corners).
  std::vector<cv::Point> polygon;
  for (const cv::Point2d& p : points) polygon.emplace_back(cvRound(p.x), cvRound(p.y));
  region.setTo(0);
  cv::fillPoly(region, std::vector<std::vector<cv::Point>>{polygon}, 255);
  // Interior: corners first, kept apart and off the boundary.
  const double area = cv::countNonZero(region);
  const double spacing = std::sqrt(area / nodes);
  cv::Mat inner;
  // Erosion takes the image's outside as inside: a frame of 0 first.
  cv::rectangle(region, cv::Rect(0, 0, image.width, image.height), 0);
  cv::erode(
      region, inner,
      cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(1, 1) * (2 * int(spacing / 2) + 1)));
  std::vector<cv::Point2f> corners;
  const int wanted = nodes - boundaryCount;
  cv::goodFeaturesToTrack(gray, corners, wanted, 0.01, spacing / 2, inner);
  std::vector<cv::Point2d> interior;
  auto farFromAll = [&](const cv::Point2d& p, double distance) {
    for (const cv::Point2d& q : interior) {
      if (cv::norm(p - q) < distance) return false;
    }
    return true;
  };
  for (const cv::Point2f& c : corners) {
    const cv::Point2d p(halfPixel(c.x), halfPixel(c.y));
    if (farFromAll(p, spacing / 2)) interior.push_back(p);
  }
  // Top up on a grid where corners are scarce.
  for (double scale = 1; static_cast<int>(interior.size()) < wanted && scale > 0.2; scale *= 0.8) {
    for (double y = spacing * scale / 2; y < image.height - 1; y += spacing * scale) {
      for (double x = spacing * scale / 2; x < image.width - 1; x += spacing * scale) {
        if (static_cast<int>(interior.size()) >= wanted) break;
        const cv::Point2d p(halfPixel(x), halfPixel(y));
        if (inner.at<uint8_t>(static_cast<int>(p.y), static_cast<int>(p.x)) &&
            farFromAll(p, spacing * scale * 0.9)) {
          interior.push_back(p);
        }
      }
    }
  }
  Mesh2dSequence s;
  s.width = image.width;
  s.height = image.height;
  s.type = Mesh2dType::Delaunay;
  s.boundary = boundaryCount;
  Mesh2dNodes& frame = s.frames.emplace_back(boundaryCount + static_cast<int>(interior.size()), 2);
  Eigen::Index row = 0;
  for (const auto* list : {&points, &interior}) {
    for (const cv::Point2d& p : *list) frame.row(row++) << p.x, p.y;
  }
  s.triangles = meshTriangles(s, "the designed mesh");
  return s;
}

}  // namespace mpeg4face
