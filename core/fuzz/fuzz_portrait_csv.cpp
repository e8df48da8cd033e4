// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target for the talking portrait's CSV readers (mesh2d/portrait.hpp): the input is
// the feature points (fp,x,y), a line "--", then their tracks (frame,fp,x,y). mpeg4face::Error
// is the expected outcome for malformed input; what reads is meshed and moved.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "mpeg4face/error.hpp"
#include "mpeg4face/mesh2d/portrait.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace mpeg4face;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const size_t split = text.find("\n--\n");
  try {
    const PortraitFeaturePoints points =
        parsePortraitFeaturePoints(text.substr(0, split), "fp.csv");
    if (points.positions.rows() != static_cast<Eigen::Index>(points.ids.size())) std::abort();
    if (split == std::string_view::npos) return 0;
    const std::vector<Mesh2dNodes> tracks =
        parsePortraitTracks(text.substr(split + 4), points, "tracks.csv");
    for (const Mesh2dNodes& frame : tracks) {
      if (frame.rows() != points.positions.rows() || !frame.allFinite()) std::abort();
    }
    if (tracks.size() <= 64 && points.ids.size() <= 64) {
      const Mesh2dSequence s = portraitMesh2d(256, 256, points, tracks);
      if (s.frames.size() != tracks.size()) std::abort();
    }
  } catch (const Error&) {
    return 0;
  }
  return 0;
}
