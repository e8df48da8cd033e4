// SPDX-License-Identifier: GPL-3.0-or-later
// Least-squares fitting of FIT functions, and the send-a-subset trial. docs/fit.md.
#include "mpeg4face/fit/learn.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "mpeg4face/codec/rd.hpp"
#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

// Exponent vectors of n variables with total degree 0..degree, lowest degree first.
std::vector<std::vector<int>> monomials(int n, int degree) {
  std::vector<std::vector<int>> out;
  std::vector<int> e(static_cast<std::size_t>(n), 0);
  for (int total = 0; total <= degree; ++total) {
    // Every way to spread `total` over n variables, first variable highest first.
    const auto spread = [&](auto&& self, int j, int left) -> void {
      if (j == n - 1) {
        e[static_cast<std::size_t>(j)] = left;
        out.push_back(e);
        return;
      }
      for (int k = left; k >= 0; --k) {
        e[static_cast<std::size_t>(j)] = k;
        self(self, j + 1, left - k);
      }
    };
    if (n == 0) {
      if (total == 0) out.push_back({});
    } else {
      spread(spread, 0, total);
    }
  }
  return out;
}

// Least squares with columns scaled to unit largest magnitude (monomials of FAP values span
// many orders of magnitude). Returns the coefficients and the residual RMS.
std::pair<Eigen::VectorXd, double> leastSquares(Eigen::MatrixXd a, const Eigen::VectorXd& b) {
  Eigen::VectorXd scale(a.cols());
  for (Eigen::Index c = 0; c < a.cols(); ++c) {
    const double m = a.col(c).cwiseAbs().maxCoeff();
    scale(c) = m > 0 ? m : 1;
    a.col(c) /= scale(c);
  }
  const Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
  const double rms = std::sqrt((a * x - b).squaredNorm() / static_cast<double>(b.size()));
  return {x.cwiseQuotient(scale), rms};
}

}  // namespace

std::vector<FitFunctionFit> learnFitTable(FitTable& table, std::span<const FapStream> streams,
                                          int degree) {
  if (degree < 1 || degree > 15) throw Error({}, 0, "degree", "the degree must be 1..15");
  validateFitTable(table);
  std::vector<std::vector<FapState>> states;
  for (const FapStream& s : streams) states.push_back(resolveFapStream(s));
  std::vector<FitFunctionFit> report;
  for (int k = 0; k < static_cast<int>(table.links.size()); ++k) {
    FitLink& link = table.links[static_cast<std::size_t>(k)];
    const auto& parent = table.nodes[static_cast<std::size_t>(link.parent)];
    const auto& child = table.nodes[static_cast<std::size_t>(link.child)];
    const std::vector<int> variables = fitVariables(parent);
    const bool expression = parent == std::vector<int>{2};
    const bool highLevel = std::any_of(parent.begin(), parent.end(), [](int f) { return f <= 2; });
    const std::vector<std::vector<int>> basis =
        expression ? std::vector<std::vector<int>>{}
                   : monomials(static_cast<int>(variables.size()), degree);
    const int terms = expression ? 6 : static_cast<int>(basis.size());
    for (std::size_t i = 0; i < child.size(); ++i) {
      FitFunctionFit& r = report.emplace_back();
      r.link = k;
      r.fap = child[i];
      r.terms = terms;
      if (highLevel && !expression) {
        r.note = "a parent with FAP 1 or with FAP 2 and others is not fitted";
        continue;
      }
      std::vector<std::vector<double>> rows;
      std::vector<double> targets;
      for (const auto& stream : states) {
        for (const FapState& s : stream) {
          if (!s.sent(child[i]) ||
              !std::all_of(parent.begin(), parent.end(), [&](int f) { return s.sent(f); })) {
            continue;
          }
          std::vector<double>& row = rows.emplace_back();
          if (expression) {
            for (int j = 1; j <= 6; ++j) {
              row.push_back((s.expression.select1 == j ? s.expression.intensity1 : 0) +
                            (s.expression.select2 == j ? s.expression.intensity2 : 0));
            }
          } else {
            for (const auto& e : basis) {
              double m = 1;
              for (std::size_t v = 0; v < e.size(); ++v) {
                m *= std::pow(fitVariableValue(s, variables[v]), e[v]);
              }
              row.push_back(m);
            }
          }
          targets.push_back(s.value(child[i]));
        }
      }
      r.samples = static_cast<int>(rows.size());
      if (r.samples < terms) {
        r.note = "too few frames: " + std::to_string(r.samples) + " for " + std::to_string(terms) +
                 " terms";
        continue;
      }
      Eigen::MatrixXd a(r.samples, terms);
      Eigen::VectorXd b(r.samples);
      for (int s = 0; s < r.samples; ++s) {
        for (int t = 0; t < terms; ++t)
          a(s, t) = rows[static_cast<std::size_t>(s)][static_cast<std::size_t>(t)];
        b(s) = targets[static_cast<std::size_t>(s)];
      }
      const auto [x, rms] = leastSquares(std::move(a), b);
      r.rms = rms;
      r.fitted = true;
      FitFunction f;
      f.denominator.push_back({1.0, std::vector<int>(variables.size(), 0)});
      for (int t = 0; t < terms; ++t) {
        if (x(t) == 0) continue;
        if (expression) {
          f.numerator.push_back({x(t), {0, 0, 1, 0}, kExpressionSelect1, t + 1});
          f.numerator.push_back({x(t), {0, 0, 0, 1}, kExpressionSelect2, t + 1});
        } else {
          f.numerator.push_back({x(t), basis[static_cast<std::size_t>(t)]});
        }
      }
      link.functions[i] = std::move(f);
    }
  }
  return report;
}

FapStream withoutDerivedFaps(const FitTable& table, FapStream stream) {
  validateFitTable(table);
  for (FapFrame& frame : stream.frames) {
    const std::bitset<kFapCount> derived = fitDerivedFaps(table, frame.mask);
    for (std::size_t i = 2; i < derived.size(); ++i) {
      if (derived[i]) {
        frame.mask.reset(i);
        frame.values[i] = 0;
      }
    }
  }
  return stream;
}

FitTrial tryFitTable(const FitTable& table, const FapStream& stream,
                     const FbaEncodeOptions& options) {
  FitTrial trial;
  const FapStream sent = withoutDerivedFaps(table, stream);
  std::bitset<kFapCount> derived;
  for (std::size_t f = 0; f < stream.frames.size(); ++f) {
    derived |= stream.frames[f].mask & ~sent.frames[f].mask;
  }
  trial.derivedFaps = static_cast<int>(derived.count());
  trial.bitsAll = encodeFba(stream, options).stats.bits;
  const FbaEncoding coded = encodeFba(sent, options);
  trial.bitsSent = coded.stats.bits;
  FapStream decoded = comparableReconstruction(stream, coded.reconstruction);
  trial.interpolated = interpolateFitStream(table, decoded);
  trial.all = compareFapStreams(stream, decoded);
  FapStream original = stream, interpolated = decoded;
  for (std::size_t f = 0; f < original.frames.size(); ++f) {
    original.frames[f].mask &= derived;
    interpolated.frames[f].mask &= derived;
  }
  trial.derived = compareFapStreams(original, interpolated);
  return trial;
}

}  // namespace mpeg4face
