// SPDX-License-Identifier: GPL-3.0-or-later
// Texture warping of the 2D mesh object (Tekalp & Ostermann 2000, section 3.1, eq. 2): each
// triangle of the current mesh object plane is filled from the same triangle of the intra
// plane by the affine map their nodes define, the texture resampled bilinearly. Pixel centres
// lie at integer coordinates, so a node on a pixel centre carries that texture pixel exactly.
#pragma once

#include <cstdint>
#include <vector>

#include "mpeg4face/mesh2d/mesh2d.hpp"

namespace mpeg4face {

// An 8-bit image, rows top to bottom, channels interleaved (OpenCV's order: BGR for colour).
struct Image {
  int width = 0;
  int height = 0;
  int channels = 3;
  std::vector<uint8_t> pixels;  // width * height * channels

  Image() = default;
  Image(int w, int h, int c) : width(w), height(h), channels(c), pixels(size_t(w) * h * c) {}
  uint8_t* row(int y) { return pixels.data() + size_t(y) * width * channels; }
  const uint8_t* row(int y) const { return pixels.data() + size_t(y) * width * channels; }
};

// Warps `texture` (which the intra plane `intra` lies on) onto `out` for the plane `current`:
// every pixel of `out` whose centre is in a triangle of `current` is resampled from the
// texture; the others are left as they are. `out` must have the texture's channel count.
void warpMesh2d(const Image& texture, const Mesh2dNodes& intra, const Mesh2dNodes& current,
                const Mesh2dTriangles& triangles, Image& out);

}  // namespace mpeg4face
