// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh tracking (Tekalp & Ostermann 2000, section 3.2.2): the nodes of an intra plane followed
// through a video or an image sequence by pyramidal Lucas-Kanade optical flow (OpenCV), the
// mesh kept free of fold-overs.
#pragma once

#include <filesystem>
#include <functional>
#include <limits>
#include <vector>

#include "mpeg4face/mesh2d/mesh2d.hpp"
#include "mpeg4face/mesh2d/warp.hpp"

namespace mpeg4face {

// The frames of a video file (anything OpenCV's VideoCapture reads), or of a folder of images
// in name order; the first `limit` only. Throws mpeg4face::Error naming the file that does
// not load.
std::vector<Image> readFrames(const std::filesystem::path& path,
                              size_t limit = std::numeric_limits<size_t>::max());

struct Mesh2dTrackOptions {
  int window = 21;                               // Lucas-Kanade window, pixels
  int levels = 3;                                // pyramid levels above the image
  std::function<void(size_t, size_t)> progress;  // (frame, count)
};

// Tracks `mesh`'s intra plane (on frames[0]) through `frames`: one plane per frame. Each frame
// is matched against frame 0 (no drift), starting from the previous plane. Nodes the flow
// loses, and nodes of triangles that would fold over, take their neighbours' mean motion; what
// still folds keeps its previous position. The result's triangles are set.
Mesh2dSequence trackMesh2d(const std::vector<Image>& frames, const Mesh2dSequence& mesh,
                           const Mesh2dTrackOptions& options = {});

}  // namespace mpeg4face
