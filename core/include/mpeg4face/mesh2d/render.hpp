// SPDX-License-Identifier: GPL-3.0-or-later
// Rendering a 2D mesh sequence: image files through OpenCV, every plane's warped texture
// (mesh2d/warp.hpp) to PNG frames or, through ffmpeg, to an MP4 with optional audio.
#pragma once

#include <filesystem>
#include <functional>

#include "mpeg4face/mesh2d/mesh2d.hpp"
#include "mpeg4face/mesh2d/warp.hpp"

namespace mpeg4face {

// Any image OpenCV reads, as 3-channel BGR. Throws mpeg4face::Error naming the file if it does
// not exist or does not load as an image.
Image readImage(const std::filesystem::path& path);
// By extension (.png, .jpg, ...), written atomically.
void writeImage(const std::filesystem::path& path, const Image& image);

// The texture warped to plane `frame` of `sequence` (the texture lies on frame 0), pixels
// outside the mesh the texture's own. The texture must be the sequence's width x height.
Image renderMesh2dFrame(const Image& texture, const Mesh2dSequence& sequence, size_t frame);

struct Mesh2dVideoOptions {
  double fps = 25;
  std::filesystem::path audio;  // muxed in when not empty (any format ffmpeg reads)
  // Called after each frame with (frame, count), e.g. for progress.
  std::function<void(size_t, size_t)> progress;
};

// Renders every plane: to `out`.mp4 with ffmpeg (H.264, yuv420p; odd sizes padded by a
// pixel), otherwise into the folder `out` as frame_00000.png ... Both appear only when complete.
// Throws mpeg4face::Error naming the file on failure (ffmpeg missing or failing included).
void renderMesh2d(const Image& texture, const Mesh2dSequence& sequence,
                  const std::filesystem::path& out, const Mesh2dVideoOptions& options = {});

}  // namespace mpeg4face
