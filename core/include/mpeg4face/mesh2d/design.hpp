// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh design on an intra plane (Tekalp & Ostermann 2000, section 3.2.1): a uniform mesh over
// the image, or a content-based Delaunay mesh whose boundary follows the image's frame (or a
// mask's outline) and whose interior nodes sit on corner points, so more of them where the
// image has detail.
#pragma once

#include "mpeg4face/mesh2d/mesh2d.hpp"
#include "mpeg4face/mesh2d/warp.hpp"

namespace mpeg4face {

// A uniform mesh of cols x rows cells over the whole width x height image (cell sizes in half
// pixels, the last node at most half a pixel short of the far edge), one intra plane.
Mesh2dSequence designUniformMesh2d(int width, int height, int cols, int rows, int topology = 0);

// A Delaunay mesh of about `nodes` nodes (at least 8) on `image`: a tenth of them (at least 4)
// on the boundary, the rest on corner points (OpenCV's goodFeaturesToTrack), topped up with
// evenly spread points where corners are scarce. With a mask (non-zero inside; the image's
// size), the boundary is the outline of its largest region and the nodes lie inside it.
// Coordinates are on half pixels. Throws mpeg4face::Error if the mask is empty or too small.
Mesh2dSequence designDelaunayMesh2d(const Image& image, int nodes, const Image* mask = nullptr);

}  // namespace mpeg4face
