// SPDX-License-Identifier: GPL-3.0-or-later
// A talking portrait: a still image animated by a FAP stream through the 2D mesh object
// (Tekalp & Ostermann 2000, section 3.5, "animating generic still texture images"). A
// Delaunay mesh over the image is anchored on the face's feature points; each frame moves
// the feature points in the image plane by their FAPs (value x FAPU along the FAP's positive
// motion, up/down/left/right ones), the other interior nodes by a Gaussian-weighted share of
// the nearby feature points' motion, the image frame not at all. Or the feature points follow
// given tracks (a 3D face's FaceDefTables evaluated and projected by a camera, say).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "mpeg4face/mesh2d/mesh2d.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

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
// mpeg4face::Error if a feature point lies outside the image. A point closer than ES0 / 12 to
// an earlier one (a closed mouth's inner lip) is not a node of its own (it would fold).
Mesh2dSequence portraitMesh2d(int width, int height, const PortraitFeaturePoints& points,
                              const FapStream& stream, const PortraitOptions& options = {});

// Feature points tracked through frames in the image: rows `frame,fp,x,y` (pixels, y down), an
// optional header row `frame,fp,x,y`, frames 0, 1, 2, ... in order, each giving every point of
// `points` once (no other). One plane per frame, rows in the order of `points`. Throws
// mpeg4face::Error naming `source`, the line and the field at fault.
std::vector<Mesh2dNodes> parsePortraitTracks(std::string_view text,
                                             const PortraitFeaturePoints& points,
                                             const std::string& source = {});

// As above, the feature points at `tracks[k]` in plane k (tracks[0] is taken as the neutral
// face, `points`, which the image shows). Of the FAPU only ES is needed (3.5 and 3.6).
Mesh2dSequence portraitMesh2d(int width, int height, const PortraitFeaturePoints& points,
                              const std::vector<Mesh2dNodes>& tracks,
                              const PortraitOptions& options = {});

}  // namespace mpeg4face
