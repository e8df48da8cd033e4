// SPDX-License-Identifier: GPL-3.0-or-later
// Internal: what the ARKit mapping and the keys made from it share (docs/arkit.md). Not
// installed.
#pragma once

namespace mpeg4face::arkit {

// The jaw FAPs (open, thrust, shift): their keys carry the lower lip, chin, mouth corners
// and tongue along, and a head may move its lower teeth with them as a Transform.
inline bool isJawFap(int fap) { return fap == 3 || fap == 14 || fap == 15; }

}  // namespace mpeg4face::arkit
