// SPDX-License-Identifier: GPL-3.0-or-later
// A FAP Interpolation Table in the BIFS FIT node's fields. docs/fit.md.
#include "mpeg4face/fit/node.hpp"

#include "mpeg4face/error.hpp"

namespace mpeg4face {

FitNodeFields fitNodeFields(const FitTable& table) {
  validateFitTable(table);
  FitNodeFields f;
  for (const auto& node : table.nodes) {
    f.FAPs.insert(f.FAPs.end(), node.begin(), node.end());
    f.FAPs.push_back(-1);
  }
  for (const FitLink& link : table.links) {
    f.Graph.insert(f.Graph.end(), {link.parent, link.child});
    for (const FitFunction& fn : link.functions) {
      f.numeratorTerms.push_back(static_cast<int>(fn.numerator.size()));
      f.denominatorTerms.push_back(static_cast<int>(fn.denominator.size()));
      for (const FitTerm& t : fn.numerator) {
        f.numeratorExp.insert(f.numeratorExp.end(), t.exponents.begin(), t.exponents.end());
        f.numeratorImpulse.insert(f.numeratorImpulse.end(), {t.impulseSelect, t.impulseValue});
        f.numeratorCoefs.push_back(t.coefficient);
      }
      for (const FitTerm& t : fn.denominator) {
        f.denominatorExp.insert(f.denominatorExp.end(), t.exponents.begin(), t.exponents.end());
        f.denominatorCoefs.push_back(t.coefficient);
      }
    }
  }
  return f;
}

namespace {

// Reads a field front to back, failing with the field's name when it runs out.
template <typename T>
struct Cursor {
  const std::vector<T>& values;
  const char* name;
  const std::string& source;
  std::size_t at = 0;

  T next() {
    if (at >= values.size()) {
      throw Error(source, 0, std::string("FIT.") + name,
                  std::string("FIT.") + name + " has " + std::to_string(values.size()) +
                      " values, fewer than the graph and term counts need");
    }
    return values[at++];
  }
  void requireUsed() const {
    if (at != values.size()) {
      throw Error(source, 0, std::string("FIT.") + name,
                  std::string("FIT.") + name + " has " + std::to_string(values.size()) +
                      " values, more than the graph and term counts use (" + std::to_string(at) +
                      ")");
    }
  }
};

}  // namespace

FitTable fitTableFromNode(const FitNodeFields& f, const std::string& source) {
  FitTable table;
  std::vector<int> node;
  for (int fap : f.FAPs) {
    if (fap == -1) {
      table.nodes.push_back(std::move(node));
      node.clear();
    } else {
      node.push_back(fap);
    }
  }
  if (!node.empty()) {
    throw Error(source, 0, "FIT.FAPs", "FIT.FAPs does not end its last node with -1");
  }
  if (f.Graph.size() % 2 != 0) {
    throw Error(source, 0, "FIT.Graph", "FIT.Graph has an odd number of values (pairs expected)");
  }
  Cursor<int> nTerms{f.numeratorTerms, "numeratorTerms", source};
  Cursor<int> dTerms{f.denominatorTerms, "denominatorTerms", source};
  Cursor<int> nExp{f.numeratorExp, "numeratorExp", source};
  Cursor<int> dExp{f.denominatorExp, "denominatorExp", source};
  Cursor<int> impulse{f.numeratorImpulse, "numeratorImpulse", source};
  Cursor<double> nCoef{f.numeratorCoefs, "numeratorCoefs", source};
  Cursor<double> dCoef{f.denominatorCoefs, "denominatorCoefs", source};
  constexpr int kMaxTerms = 1 << 16;  // against a corrupt count allocating without bound
  for (std::size_t g = 0; g < f.Graph.size(); g += 2) {
    FitLink& link = table.links.emplace_back();
    link.parent = f.Graph[g];
    link.child = f.Graph[g + 1];
    for (int n : {link.parent, link.child}) {
      if (n < 0 || n >= static_cast<int>(table.nodes.size())) {
        throw Error(source, 0, "FIT.Graph",
                    "FIT.Graph refers to node " + std::to_string(n) + " of " +
                        std::to_string(table.nodes.size()));
      }
    }
    const std::size_t variables =
        fitVariables(table.nodes[static_cast<std::size_t>(link.parent)]).size();
    for (std::size_t c = 0; c < table.nodes[static_cast<std::size_t>(link.child)].size(); ++c) {
      FitFunction& fn = link.functions.emplace_back();
      const auto readTerms = [&](Cursor<int>& count, std::vector<FitTerm>& terms, Cursor<int>& exps,
                                 Cursor<double>& coefs, bool numerator) {
        const int k = count.next();
        if (k < 0 || k > kMaxTerms) {
          throw Error(source, 0, std::string("FIT.") + count.name,
                      std::string("FIT.") + count.name + " has a count of " + std::to_string(k));
        }
        for (int t = 0; t < k; ++t) {
          FitTerm& term = terms.emplace_back();
          for (std::size_t v = 0; v < variables; ++v) term.exponents.push_back(exps.next());
          if (numerator) {
            term.impulseSelect = impulse.next();
            term.impulseValue = impulse.next();
          }
          term.coefficient = coefs.next();
        }
      };
      readTerms(nTerms, fn.numerator, nExp, nCoef, true);
      readTerms(dTerms, fn.denominator, dExp, dCoef, false);
    }
  }
  for (const auto* c : {&nTerms, &dTerms, &nExp, &dExp, &impulse}) c->requireUsed();
  nCoef.requireUsed();
  dCoef.requireUsed();
  validateFitTable(table, source);
  return table;
}

}  // namespace mpeg4face
