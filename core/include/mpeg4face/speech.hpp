// SPDX-License-Identifier: GPL-3.0-or-later
// Text to a talking head: phones and their timing from a synthesiser (flite), visemes with
// transitions, and bookmarks in the text to expressions.
//
//   speech/speech.hpp  speak: text -> FapStream (and audio)
#pragma once

#include "mpeg4face/speech/speech.hpp"  // IWYU pragma: export
