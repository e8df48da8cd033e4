// SPDX-License-Identifier: GPL-3.0-or-later
// The error of a decoded FAP stream where it shows: the motion of a face's feature points,
// animated by the original and by the decoded stream through the face's tables, in % of ES0
// (docs/rate-distortion.md, "Motion error at the feature points").
#pragma once

#include <string>

#include "mpeg4face/fat/tables.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face {

struct FeaturePointMotionError {
  int points = 0;  // feature points bound to a mesh vertex (free ones never move)
  int frames = 0;
  double rmsPercentEs0 = 0;  // sqrt(mean over frames and points of |p - q|^2), % of ES0
  double maxPercentEs0 = 0;  // the largest |p - q|
  std::string worstPoint;    // where the largest is, e.g. "2.1"
  int worstFrame = -1;       // and in which frame (number)
};

// Animates `face` (its tables, FatEvaluator, the Transforms included) by the resolved states
// of `original` and of `decoded`, frame by frame, and compares the feature points' model-space
// positions. Throws mpeg4face::Error if the streams' frames differ (as compareFapStreams), if
// the face's ES0 cannot be measured or no feature point is bound to a vertex, and whatever
// FatEvaluator throws.
FeaturePointMotionError featurePointMotionError(const MpegFace& face, const FapStream& original,
                                                const FapStream& decoded);

}  // namespace mpeg4face
