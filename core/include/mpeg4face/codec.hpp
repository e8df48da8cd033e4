// SPDX-License-Identifier: GPL-3.0-or-later
// Coding of FAP streams: the FBA bitstream of ISO/IEC 14496-2 in its predictive, DCT and PCA
// modes, and how well a coding does. The bit I/O, the arithmetic coder and the DCT are internals
// (src/codec/).
//
//   codec/fba_codec.hpp     encodeFba / decodeFba: a FapStream to bytes and back
//   codec/pca.hpp           the PCA mode's KLT of FAP groups
//   codec/measure.hpp       PSNR (Tao et al. eq. 8, robust), per-FAP errors, bit rates
//   codec/motion_error.hpp  a decoded stream's error where it shows: feature-point motion
//   codec/rd.hpp            rate-distortion sweeps and the automatic choice of mode and fap_quant
#pragma once

#include "mpeg4face/codec/fba_codec.hpp"     // IWYU pragma: export
#include "mpeg4face/codec/measure.hpp"       // IWYU pragma: export
#include "mpeg4face/codec/motion_error.hpp"  // IWYU pragma: export
#include "mpeg4face/codec/pca.hpp"           // IWYU pragma: export
#include "mpeg4face/codec/rd.hpp"            // IWYU pragma: export
