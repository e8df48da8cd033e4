// SPDX-License-Identifier: GPL-3.0-or-later
// A talking portrait: a still image animated by a FAP stream through the 2D mesh object
// (Tekalp & Ostermann 2000, section 3.5, "animating generic still texture images"). A
// Delaunay mesh over the image is anchored on the face's feature points; each frame moves
// the feature points in the image plane by their FAPs (value x FAPU along the FAP's positive
// motion, up/down/left/right ones), the other interior nodes by a Gaussian-weighted share of
// the nearby feature points' motion, the image frame not at all.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "mpeg4face/fap_stream.hpp"
#include "mpeg4face/mesh2d.hpp"

namespace mpeg4face {

// Feature points in an image: rows `fp,x,y` (pixels, y down), an optional header row
// `fp,x,y`, blank lines and # comments allowed.
struct PortraitFeaturePoints {
  std::vector<std::string> ids;  // "2.1", ...
  Mesh2dNodes positions;         // one row per id
};
// Throws mpeg4face::Error naming `source`, the line and the field at fault (an unknown
// feature point, a number that is not one, a point given twice).
PortraitFeaturePoints parsePortraitFeaturePoints(std::string_view text,
                                                 const std::string& source = {});

// The FAPU measured in the image plane (pixels per FAPU; AU is not used).
struct PortraitFapu {
  double irisd = 0, es = 0, ens = 0, mns = 0, mw = 0;
};
// Throws mpeg4face::Error naming the feature point a unit needs and the CSV lacks.
PortraitFapu portraitFapu(const PortraitFeaturePoints& points);

struct PortraitOptions {
  int gridNodes = 150;  // evenly spread interior nodes besides the feature points
};

// One plane per frame of `stream`, frame 0 the neutral face (the intra plane; the stream's
// own frame 0 is taken as neutral) and frame k the stream's frame k after it. Throws
// mpeg4face::Error if a feature point lies outside the image or too close to another.
Mesh2dSequence portraitMesh2d(int width, int height, const PortraitFeaturePoints& points,
                              const FapStream& stream, const PortraitOptions& options = {});

}  // namespace mpeg4face
