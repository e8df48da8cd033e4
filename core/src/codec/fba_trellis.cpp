// SPDX-License-Identifier: GPL-3.0-or-later
#include "codec/fba_trellis.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "codec/fba_syntax.hpp"

namespace mpeg4face::fba {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Reconstructions tried per frame: those within K units of the nearest, K chosen so that a
// state's own error stays below what this many bits are worth (a state further off cannot
// pay for itself), bounded for speed.
constexpr double kWindowBits = 48;
constexpr int kMaxK = 96;
// Rate tables re-estimated from the levels found, at most this many times per range.
constexpr int kPasses = 4;

double log2Factorial(int64_t n) {
  return std::lgamma(static_cast<double>(n) + 1.0) / std::numbers::ln2;
}

// What an adaptive model over n symbols (counts from 1, +1 per symbol, no halving below its
// 16383 total) spends on symbols with this histogram, in whatever order they come:
// log2((N + n - 1)! / ((n - 1)! prod c_s!)).
double modelBits(const std::vector<int>& histogram, int64_t count) {
  const auto n = static_cast<int64_t>(histogram.size());
  double bits = log2Factorial(count + n - 1) - log2Factorial(n - 1);
  for (const int c : histogram) bits -= log2Factorial(c);
  return bits;
}

class Trellis {
 public:
  explicit Trellis(const TrellisProblem& p) : p_(p), n_(p.values.size()) {
    unit_ = std::max<int64_t>(p.step, 1);
    const double reach = std::sqrt(kWindowBits * p.lambda / p.weight) / static_cast<double>(unit_);
    // The first window lies within the intra levels a range code reaches (2 cap + 1).
    k_ = static_cast<int>(
        std::clamp(std::ceil(reach), 1.0, static_cast<double>(std::min<int64_t>(kMaxK, p.cap))));
    width_ = 2 * k_ + 1;
    for (const int64_t x : p.values) centre_.push_back(quantise(x, p.step));
    start_.resize(n_);
    back_.resize(n_ * static_cast<size_t>(width_));
  }

  // The levels with the least cost over the range sides chosen by a descent from the sides
  // the nearest levels need.
  TrellisLevels solve() {
    std::vector<int64_t> levels(n_);
    int64_t reconstruction = 0, lo = 0, hi = 0;
    for (size_t t = 0; t < n_; ++t) {
      const int64_t l = std::clamp<int64_t>(
          quantise(p_.values[t] - reconstruction * unit_, p_.step), -p_.cap, p_.cap);
      levels[t] = l;
      reconstruction += l;
      if (t > 0) {
        lo = std::min(lo, l);
        hi = std::max(hi, l);
      }
    }
    const auto sideIndex = [&](int64_t need) {
      const auto it = std::lower_bound(p_.sides.begin(), p_.sides.end(), need);
      return static_cast<int>(it == p_.sides.end() ? p_.sides.size() - 1
                                                   : static_cast<size_t>(it - p_.sides.begin()));
    };
    int a = sideIndex(-lo), b = sideIndex(hi);
    std::vector<int64_t> best = levels;
    double bestCost = evaluate(a, b, best);
    if (bestCost == kInfinity) return finish(levels);
    // Narrow a side while that pays (each narrower range starts from the best levels so far).
    for (bool improved = true; improved;) {
      improved = false;
      int bestA = a, bestB = b;
      std::vector<int64_t> bestHere;
      for (const auto& [da, db] : {std::pair{-1, 0}, std::pair{0, -1}}) {
        if (a + da < 0 || b + db < 0) continue;
        std::vector<int64_t> trial = best;
        const double cost = evaluate(a + da, b + db, trial);
        if (cost < bestCost) {
          bestCost = cost;
          bestA = a + da;
          bestB = b + db;
          bestHere = std::move(trial);
          improved = true;
        }
      }
      if (improved) {
        a = bestA;
        b = bestB;
        best = std::move(bestHere);
      }
    }
    return finish(best);
  }

 private:
  TrellisLevels finish(std::vector<int64_t> levels) const {
    TrellisLevels out;
    for (size_t t = 1; t < levels.size(); ++t) {
      out.interMin = std::min(out.interMin, levels[t]);
      out.interMax = std::max(out.interMax, levels[t]);
    }
    out.levels = std::move(levels);
    return out;
  }

  // Passes of the dynamic programme under the range [-sides[a], sides[b]], each with the rate
  // table of the levels before; `levels` goes in as the start and comes out as the best found.
  // Returns its cost (distortion + lambda * model bits), infinite if the range cannot follow.
  double evaluate(int a, int b, std::vector<int64_t>& levels) {
    const int64_t lo = -p_.sides[static_cast<size_t>(a)], hi = p_.sides[static_cast<size_t>(b)];
    const auto count = static_cast<int64_t>(n_) - 1;
    std::vector<int> histogram(static_cast<size_t>(hi - lo + 1));
    const auto fill = [&](const std::vector<int64_t>& l) {
      std::fill(histogram.begin(), histogram.end(), 0);
      for (size_t t = 1; t < l.size(); ++t) {
        ++histogram[static_cast<size_t>(std::clamp(l[t], lo, hi) - lo)];
      }
    };
    fill(levels);
    double bestCost = kInfinity;
    std::vector<double> bits(histogram.size());
    std::vector<int64_t> trial(n_);
    for (int pass = 0; pass < kPasses; ++pass) {
      const double total = static_cast<double>(count + static_cast<int64_t>(histogram.size()));
      for (size_t s = 0; s < bits.size(); ++s) {
        bits[s] = std::log2(total / (histogram[s] + 1.0));
      }
      const double distortion = run(lo, hi, bits, trial);
      if (distortion == kInfinity) break;
      fill(trial);
      const double cost = distortion + p_.lambda * modelBits(histogram, count);
      if (cost >= bestCost) break;
      bestCost = cost;
      levels = trial;
    }
    return bestCost;
  }

  // One Viterbi pass: the levels in [lo, hi] (the intra level within the cap) minimising
  // weight * e^2 + lambda * bits[level - lo]; returns their weighted squared error.
  double run(int64_t lo, int64_t hi, const std::vector<double>& bits,
             std::vector<int64_t>& levels) {
    const auto w = static_cast<size_t>(width_);
    cost_.assign(w, kInfinity);
    start_[0] = std::clamp<int64_t>(centre_[0] - k_, -p_.cap, p_.cap - width_ + 1);
    for (size_t s = 0; s < w; ++s) {
      const int64_t j = start_[0] + static_cast<int64_t>(s);
      if (j >= -p_.cap && j <= p_.cap) cost_[s] = error(0, j);
    }
    for (size_t t = 1; t < n_; ++t) {
      const int64_t previous = start_[t - 1];
      const int64_t reachLo = previous + lo, reachHi = previous + width_ - 1 + hi;
      start_[t] =
          std::clamp<int64_t>(centre_[t] - k_, reachLo, std::max(reachLo, reachHi - width_ + 1));
      next_.assign(w, kInfinity);
      int32_t* back = &back_[t * w];
      for (size_t s = 0; s < w; ++s) {
        const int64_t j = start_[t] + static_cast<int64_t>(s);
        // Levels l with j - l inside the previous window and l in [lo, hi].
        const int64_t lMin = std::max(lo, j - (previous + width_ - 1)),
                      lMax = std::min(hi, j - previous);
        double best = kInfinity;
        int32_t from = -1;
        for (int64_t l = lMin; l <= lMax; ++l) {
          const auto i = static_cast<size_t>(j - l - previous);
          const double c = cost_[i] + p_.lambda * bits[static_cast<size_t>(l - lo)];
          if (c < best) {
            best = c;
            from = static_cast<int32_t>(i);
          }
        }
        back[s] = from;
        if (from >= 0) next_[s] = best + error(t, j);
      }
      std::swap(cost_, next_);
    }
    const auto last = std::min_element(cost_.begin(), cost_.end());
    if (*last == kInfinity) return kInfinity;
    auto s = static_cast<size_t>(last - cost_.begin());
    double distortion = 0;
    for (size_t t = n_; t-- > 0;) {
      const int64_t j = start_[t] + static_cast<int64_t>(s);
      distortion += error(t, j);
      if (t == 0) {
        levels[0] = j;
        break;
      }
      s = static_cast<size_t>(back_[t * w + s]);
      levels[t] = j - (start_[t - 1] + static_cast<int64_t>(s));
    }
    return distortion;
  }

  double error(size_t t, int64_t j) const {
    const auto e = static_cast<double>(p_.values[t] - j * unit_);
    return p_.weight * e * e;
  }

  const TrellisProblem& p_;
  size_t n_;
  int64_t unit_;
  int k_, width_;
  std::vector<int64_t> centre_, start_;
  std::vector<int32_t> back_;
  std::vector<double> cost_, next_;
};

}  // namespace

TrellisLevels trellisQuantise(const TrellisProblem& problem) { return Trellis(problem).solve(); }

}  // namespace mpeg4face::fba
