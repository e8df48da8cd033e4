// SPDX-License-Identifier: GPL-3.0-or-later
// Fitting a FAP Interpolation Table to data, and measuring a table on a stream: what Tao et
// al. VII-A do by hand (send a subset, interpolate the rest, compare). docs/fit.md.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/codec/measure.hpp"
#include "mpeg4face/fit/fit.hpp"

namespace mpeg4face {

// One function fitted: its link, child FAP, the frames it was fitted on and the root mean
// square residual there (FAPU). `fitted` false: too few frames (fewer than terms) or a link
// it cannot fit; the function was left as it was, `note` says why.
struct FitFunctionFit {
  int link = 0;
  int fap = 0;
  int samples = 0;
  int terms = 0;
  double rms = 0;
  bool fitted = false;
  std::string note;
};

// Fits every function of every link of `table` by least squares (Eigen, column-pivoting QR,
// columns scaled) on the frames of `streams` where the parent's FAPs and the child FAP are
// all sent (resolved states: a FAP holds its last value; a mirrored value does not count).
// The numerator becomes every monomial of the parent's variables of total degree 0..degree
// (a constant included: with it the learned tables did better on held-out frames,
// docs/fit.md), the denominator 1; for a parent {2} (expression), Tao's Fig. 7
// form: sum_j p_j (delta(select1 - j) intensity1 + delta(select2 - j) intensity2), j = 1..6.
// Links from other parents with FAP 1 or 2 are left as they are. degree is 1..15.
std::vector<FitFunctionFit> learnFitTable(FitTable& table, std::span<const FapStream> streams,
                                          int degree = 1);

// A stream sent through a table: the FAPs the table derives (fitDerivedFaps per frame) left
// out, the rest coded with `options`, decoded, and the missing FAPs interpolated.
struct FitTrial {
  int derivedFaps = 0;    // distinct FAPs left out in some frame
  int interpolated = 0;   // values the decoder computed
  uint64_t bitsAll = 0;   // the stream coded whole
  uint64_t bitsSent = 0;  // the stream coded without the derived FAPs
  // The derived FAPs: the original's against the interpolated (Tao eq. 8 over those FAPs).
  FapComparison derived;
  // Every FAP: the original against what the decoder ends with.
  FapComparison all;
};
FitTrial tryFitTable(const FitTable& table, const FapStream& stream,
                     const FbaEncodeOptions& options = {});

// The stream without the FAPs the table derives (what `mpeg4face encode --fit` codes).
FapStream withoutDerivedFaps(const FitTable& table, FapStream stream);

}  // namespace mpeg4face
