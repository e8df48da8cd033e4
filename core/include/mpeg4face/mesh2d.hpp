// SPDX-License-Identifier: GPL-3.0-or-later
// The MPEG-4 2D mesh object (Tekalp & Ostermann 2000, section 3): meshes over an image designed,
// tracked, coded, warped and rendered, and still portraits animated by FAP streams.
//
//   mesh2d/mesh2d.hpp    the mesh object planes and their geometry
//   mesh2d/design.hpp    uniform and content-based Delaunay meshes
//   mesh2d/track.hpp     node tracking by optical flow (OpenCV)
//   mesh2d/codec.hpp     intra and inter plane coding
//   mesh2d/warp.hpp      texture warping (eq. 2)
//   mesh2d/render.hpp    frames and video (OpenCV, ffmpeg)
//   mesh2d/json.hpp      a mesh sequence as JSON
//   mesh2d/portrait.hpp  a talking portrait from a still image
#pragma once

#include "mpeg4face/mesh2d/codec.hpp"     // IWYU pragma: export
#include "mpeg4face/mesh2d/design.hpp"    // IWYU pragma: export
#include "mpeg4face/mesh2d/json.hpp"      // IWYU pragma: export
#include "mpeg4face/mesh2d/mesh2d.hpp"    // IWYU pragma: export
#include "mpeg4face/mesh2d/portrait.hpp"  // IWYU pragma: export
#include "mpeg4face/mesh2d/render.hpp"    // IWYU pragma: export
#include "mpeg4face/mesh2d/track.hpp"     // IWYU pragma: export
#include "mpeg4face/mesh2d/warp.hpp"      // IWYU pragma: export
