// SPDX-License-Identifier: GPL-3.0-or-later
// Face Animation Tables: the FaceDefTables, FaceDefMesh and FaceDefTransform nodes and the
// MpegFace they belong to; tables generated from a head's shapes and evaluated for a FAP frame;
// whether a face looks right when it moves.
//
//   fat/tables.hpp        the nodes, MpegFace, the rule (intervalWeights, borderWeights)
//   fat/evaluate.hpp      FatEvaluator: a FAP frame -> meshes and Transforms (float, 16-bit)
//   fat/generate.hpp      generateFaceDefTables: the neutral and its shapes -> tables
//   fat/names.hpp         the shape-key grammar (which FAP, viseme or expression a key shows)
//   fat/motion_check.hpp  the motion check: tears, folds, lips and lids crossing, per frame
#pragma once

#include "mpeg4face/fat/evaluate.hpp"      // IWYU pragma: export
#include "mpeg4face/fat/generate.hpp"      // IWYU pragma: export
#include "mpeg4face/fat/motion_check.hpp"  // IWYU pragma: export
#include "mpeg4face/fat/names.hpp"         // IWYU pragma: export
#include "mpeg4face/fat/tables.hpp"        // IWYU pragma: export
