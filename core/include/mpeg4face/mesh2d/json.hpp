// SPDX-License-Identifier: GPL-3.0-or-later
// A 2D mesh sequence as JSON (docs/mesh2d.md): {"width", "height", "mesh": "uniform" |
// "delaunay", "boundary": N_b (delaunay), "uniform": {"nodes_x", "nodes_y", "x0", "y0", "dx",
// "dy", "topology"} (uniform), "triangles": [[i, j, k], ...] (optional on input), "frames":
// [[[x, y], ...], ...]}, pixels, y down, frame 0 the intra plane.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "mpeg4face/mesh2d/mesh2d.hpp"

namespace mpeg4face {

// Parses and validates (validateMesh2d) a sequence. Throws mpeg4face::Error naming `source`
// and the field ("frames[2][7][1]") at fault, or the line and column of a JSON syntax error.
// Triangles, when given, are kept as they are (checked in range); when absent they are
// left empty (meshTriangles derives them).
Mesh2dSequence parseMesh2dJson(std::string_view text, const std::string& source = {});
Mesh2dSequence readMesh2dJson(const std::filesystem::path& path);

// The sequence as JSON text (triangles included when it has them), coordinates with up to
// 6 significant decimals.
std::string mesh2dJson(const Mesh2dSequence& sequence);
void writeMesh2dJson(const std::filesystem::path& path, const Mesh2dSequence& sequence);

}  // namespace mpeg4face
