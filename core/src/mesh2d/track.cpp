// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh tracking with OpenCV's pyramidal Lucas-Kanade optical flow.
#include "mpeg4face/mesh2d/track.hpp"

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <opencv2/videoio.hpp>

#include "mpeg4face/error.hpp"
#include "mpeg4face/mesh2d/render.hpp"

namespace mpeg4face {
namespace {

cv::Mat grayOf(const Image& image) {
  const cv::Mat mat(image.height, image.width, CV_8UC3, const_cast<uint8_t*>(image.pixels.data()));
  cv::Mat gray;
  cv::cvtColor(mat, gray, cv::COLOR_BGR2GRAY);
  return gray;
}

Image imageOf(const cv::Mat& bgr) {
  Image image(bgr.cols, bgr.rows, 3);
  for (int y = 0; y < bgr.rows; ++y) std::memcpy(image.row(y), bgr.ptr(y), size_t(bgr.cols) * 3);
  return image;
}

// Triangles whose orientation flipped or collapsed (fold-overs), as flags per node.
std::vector<bool> foldedNodes(const Mesh2dNodes& p, const Mesh2dTriangles& t) {
  std::vector<bool> folded(static_cast<size_t>(p.rows()), false);
  for (Eigen::Index i = 0; i < t.rows(); ++i) {
    const Eigen::Vector2d a = p.row(t(i, 0)), b = p.row(t(i, 1)), c = p.row(t(i, 2));
    const Eigen::Vector2d u = b - a, v = c - a;
    if (u.x() * v.y() - u.y() * v.x() <= 1e-6) {
      for (int k = 0; k < 3; ++k) folded[static_cast<size_t>(t(i, k))] = true;
    }
  }
  return folded;
}

}  // namespace

std::vector<Image> readFrames(const std::filesystem::path& path, size_t limit) {
  std::vector<Image> frames;
  if (std::filesystem::is_directory(path)) {
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(path)) {
      if (entry.is_regular_file()) files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    files.resize(std::min(files.size(), limit));
    for (const auto& file : files) frames.push_back(readImage(file));
    if (frames.empty()) throw Error(path.string(), 0, "frames", "the folder has no images");
    return frames;
  }
  if (!std::filesystem::is_regular_file(path))
    throw Error(path.string(), 0, "video", "no such file");
  cv::VideoCapture video(path.string());
  if (!video.isOpened()) throw Error(path.string(), 0, "video", "does not open as a video");
  for (cv::Mat frame; frames.size() < limit && video.read(frame);) {
    if (frame.type() != CV_8UC3) cv::cvtColor(frame, frame, cv::COLOR_GRAY2BGR);
    frames.push_back(imageOf(frame));
  }
  if (frames.empty()) throw Error(path.string(), 0, "video", "has no frames");
  return frames;
}

Mesh2dSequence trackMesh2d(const std::vector<Image>& frames, const Mesh2dSequence& mesh,
                           const Mesh2dTrackOptions& options) {
  if (frames.empty()) throw Error({}, 0, "frames", "no frames to track");
  Mesh2dSequence out = mesh;
  out.frames.resize(1);
  validateMesh2d(out);
  if (out.triangles.rows() == 0) out.triangles = meshTriangles(out);
  for (size_t f = 0; f < frames.size(); ++f) {
    if (frames[f].width != mesh.width || frames[f].height != mesh.height) {
      throw Error({}, 0, "frames[" + std::to_string(f) + "]",
                  "is " + std::to_string(frames[f].width) + "x" + std::to_string(frames[f].height) +
                      ", the mesh's image " + std::to_string(mesh.width) + "x" +
                      std::to_string(mesh.height));
    }
  }
  const Mesh2dNodes intra = out.frames[0];  // a copy: frames grows
  const auto count = static_cast<size_t>(intra.rows());
  std::vector<std::vector<int>> neighbours(count);
  for (Eigen::Index t = 0; t < out.triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      for (int j = 1; j < 3; ++j) {
        neighbours[static_cast<size_t>(out.triangles(t, k))].push_back(
            out.triangles(t, (k + j) % 3));
      }
    }
  }
  const cv::Mat reference = grayOf(frames[0]);
  std::vector<cv::Point2f> start(count), guess(count);
  for (size_t n = 0; n < count; ++n) {
    start[n] = cv::Point2f(static_cast<float>(intra(n, 0)), static_cast<float>(intra(n, 1)));
  }
  guess = start;
  std::vector<cv::Mat> referencePyramid;
  const cv::Size window(options.window, options.window);
  cv::buildOpticalFlowPyramid(reference, referencePyramid, window, options.levels);
  for (size_t f = 1; f < frames.size(); ++f) {
    std::vector<uchar> status;
    std::vector<float> error;
    std::vector<cv::Mat> pyramid;
    cv::buildOpticalFlowPyramid(grayOf(frames[f]), pyramid, window, options.levels);
    cv::calcOpticalFlowPyrLK(
        referencePyramid, pyramid, start, guess, status, error, window, options.levels,
        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01),
        cv::OPTFLOW_USE_INITIAL_FLOW);
    const Mesh2dNodes& previous = out.frames.back();
    Mesh2dNodes next(intra.rows(), 2);
    std::vector<bool> lost(count);
    for (size_t n = 0; n < count; ++n) {
      lost[n] = !status[n] || !std::isfinite(guess[n].x) || !std::isfinite(guess[n].y);
      next(n, 0) = lost[n] ? previous(n, 0) : guess[n].x;
      next(n, 1) = lost[n] ? previous(n, 1) : guess[n].y;
    }
    // Lost nodes and folded triangles: the neighbours' mean motion, a few rounds; then what
    // still folds keeps its previous position (the previous plane has no fold-overs).
    for (int round = 0; round < 8; ++round) {
      std::vector<bool> fix = foldedNodes(next, out.triangles);
      bool any = false;
      for (size_t n = 0; n < count; ++n) {
        fix[n] = fix[n] || lost[n];
        any = any || fix[n];
      }
      if (!any) break;
      const Mesh2dNodes motion = next - previous;
      for (size_t n = 0; n < count; ++n) {
        if (!fix[n] || neighbours[n].empty()) continue;
        Eigen::RowVector2d mean = Eigen::RowVector2d::Zero();
        for (int m : neighbours[n]) mean += motion.row(m);
        next.row(static_cast<Eigen::Index>(n)) = previous.row(static_cast<Eigen::Index>(n)) +
                                                 mean / static_cast<double>(neighbours[n].size());
      }
      std::fill(lost.begin(), lost.end(), false);
    }
    for (int round = 0; round < 64; ++round) {
      const std::vector<bool> folded = foldedNodes(next, out.triangles);
      if (std::none_of(folded.begin(), folded.end(), [](bool b) { return b; })) break;
      for (size_t n = 0; n < count; ++n) {
        if (folded[n])
          next.row(static_cast<Eigen::Index>(n)) = previous.row(static_cast<Eigen::Index>(n));
      }
    }
    for (size_t n = 0; n < count; ++n) {
      guess[n] = cv::Point2f(static_cast<float>(next(n, 0)), static_cast<float>(next(n, 1)));
    }
    out.frames.push_back(std::move(next));
    if (options.progress) options.progress(f, frames.size());
  }
  return out;
}

}  // namespace mpeg4face
