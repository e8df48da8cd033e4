// SPDX-License-Identifier: GPL-3.0-or-later
// The KLT (principal component analysis) of FAP groups, Tao et al. (1999) section IV: what the
// PCA coding mode (FapCodingMode::Pca, docs/pca-mode.md) sends in its stream header. The
// mode itself is reached through codec/fba_codec.hpp.
#pragma once

#include <Eigen/Dense>
#include <span>
#include <vector>

#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face {

// Tao et al. eqs. (4)-(6) on `samples` (one row per frame): the mean row, the covariance's
// eigenvalues in descending order and its unit eigenvectors as the columns of `axes`, in the
// same order. A single sample has covariance 0.
struct Klt {
  Eigen::VectorXd mean;
  Eigen::VectorXd eigenvalues;
  Eigen::MatrixXd axes;
};
Klt computeKlt(const Eigen::MatrixXd& samples);

// The fewest leading eigenvalues (descending, non-negative) whose sum reaches `energy`
// (0 < energy <= 1) of the total: Tao's alpha. 0 when the total is 0.
int componentsForEnergy(std::span<const double> eigenvalues, double energy);

// What the PCA mode keeps of one FAP group of the standard (spec.hpp, groups 2..10).
struct PcaGroup {
  int group = 0;                // 2..10
  std::vector<int> faps;        // the group's FAPs the stream sends, ascending (m of them)
  int components = 0;           // k <= m, by options.pcaEnergy
  Eigen::VectorXd eigenvalues;  // of the weighted covariance (docs/pca-mode.md), descending
};

// The groups of `stream` (frames as encodeFba takes them) the PCA mode codes, with their
// kept component counts. Throws mpeg4face::Error for bad PCA options.
std::vector<PcaGroup> pcaGroups(const FapStream& stream, const FbaEncodeOptions& options);

}  // namespace mpeg4face
