// SPDX-License-Identifier: GPL-3.0-or-later
// FAP Interpolation Tables: the graph that says how unsent FAPs follow sent ones, its BIFS node,
// a JSON form for editing, ready-made tables and tables learned from data.
//
//   fit/fit.hpp      Fit (the FIG and its functions) and interpolation of a frame
//   fit/node.hpp     the BIFS FIT node's fields
//   fit/json.hpp     the readable JSON form
//   fit/presets.hpp  ready-made tables (Tao et al. III-C, Tekalp-Ostermann 2.2.3)
//   fit/learn.hpp    tables fitted to data and measured on a stream
#pragma once

#include "mpeg4face/fit/fit.hpp"      // IWYU pragma: export
#include "mpeg4face/fit/json.hpp"     // IWYU pragma: export
#include "mpeg4face/fit/learn.hpp"    // IWYU pragma: export
#include "mpeg4face/fit/node.hpp"     // IWYU pragma: export
#include "mpeg4face/fit/presets.hpp"  // IWYU pragma: export
