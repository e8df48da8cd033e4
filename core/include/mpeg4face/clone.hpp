// SPDX-License-Identifier: GPL-3.0-or-later
// Facial Motion Cloning (Pandzic 2003): the shapes of a source face carried onto a neutral
// target face, vertex motion by the feature-point triangulation and the rigid parts as
// Transforms. The triangle interpolation is internal (src/clone/).
//
//   clone/clone.hpp  cloneDeformedCopies, cloneFace: the source's shapes -> the target's
//   clone/rigid.hpp  eyes, teeth, tongue and head motion as Transforms
#pragma once

#include "mpeg4face/clone/clone.hpp"  // IWYU pragma: export
#include "mpeg4face/clone/rigid.hpp"  // IWYU pragma: export
