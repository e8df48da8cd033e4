// SPDX-License-Identifier: GPL-3.0-or-later
// Apple ARKit's 52 blendshapes as a source of MPEG-4 motion: FAP keys made from a head's ARKit
// shapes, and face captures turned into FAP streams and back.
//
//   arkit/shapes.hpp   ARKit shapes on a head -> the FAP keys they make
//   arkit/capture.hpp  ARKit weights (a capture) -> FAP streams, and back
#pragma once

#include "mpeg4face/arkit/capture.hpp"  // IWYU pragma: export
#include "mpeg4face/arkit/shapes.hpp"   // IWYU pragma: export
