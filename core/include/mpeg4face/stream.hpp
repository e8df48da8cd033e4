// SPDX-License-Identifier: GPL-3.0-or-later
// FAP streams: frames of Face Animation Parameters as they are sent, and the state a decoder
// holds after each.
//
//   stream/fap_stream.hpp  FapStream, FapFrame, FapState; resolving a stream frame by frame
#pragma once

#include "mpeg4face/stream/fap_stream.hpp"  // IWYU pragma: export
