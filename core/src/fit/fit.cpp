// SPDX-License-Identifier: GPL-3.0-or-later
// The FIT model: authoring, validation, Tao's interpolation loop. docs/fit.md.
#include "mpeg4face/fit/fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

constexpr int kMaxExponent = 15;  // the BIFS FIT node's exponent range

bool isHighLevel(int fap) { return fap == 1 || fap == 2; }

std::string nodeName(int node) { return "node " + std::to_string(node); }
std::string linkName(const FitTable& table, int link) {
  const FitLink& l = table.links[static_cast<std::size_t>(link)];
  return "link " + std::to_string(link) + " (" + nodeName(l.parent) + " -> " + nodeName(l.child) +
         ")";
}

bool validNode(const FitTable& table, int node) {
  return node >= 0 && node < static_cast<int>(table.nodes.size());
}

// Whether FAP `fap` of the frame, or its FAP 1 / 2 part, is there to compute from.
bool available(const FapFrame& frame, int fap) { return frame.has(fap); }

double power(double base, int exponent) {
  double out = 1;
  for (int i = 0; i < exponent; ++i) out *= base;
  return out;
}

double sumOfTerms(const std::vector<FitTerm>& terms, const std::vector<double>& variables,
                  const std::vector<int>& variableIds, bool impulses) {
  double sum = 0;
  for (const FitTerm& term : terms) {
    if (impulses && term.impulseSelect != 0) {
      const auto at = std::find(variableIds.begin(), variableIds.end(), term.impulseSelect);
      if (at == variableIds.end() ||
          variables[static_cast<std::size_t>(at - variableIds.begin())] != term.impulseValue) {
        continue;
      }
    }
    double product = term.coefficient;
    for (std::size_t j = 0; j < term.exponents.size() && j < variables.size(); ++j) {
      product *= power(variables[j], term.exponents[j]);
    }
    sum += product;
  }
  return sum;
}

// The availability part of the interpolation loop: which FAPs become available from `have`.
std::bitset<kFapCount> closure(const FitTable& table, std::bitset<kFapCount> have) {
  for (bool changed = true; changed;) {
    changed = false;
    for (int node = 0; node < static_cast<int>(table.nodes.size()); ++node) {
      const auto& faps = table.nodes[static_cast<std::size_t>(node)];
      const bool lacking = std::any_of(faps.begin(), faps.end(), [&](int f) {
        return !isHighLevel(f) && f >= 1 && f <= kFapCount &&
               !have[static_cast<std::size_t>(f - 1)];
      });
      if (!lacking) continue;
      for (const FitLink& link : table.links) {
        if (link.child != node || !validNode(table, link.parent)) continue;
        const auto& parent = table.nodes[static_cast<std::size_t>(link.parent)];
        if (!std::all_of(parent.begin(), parent.end(), [&](int f) {
              return f >= 1 && f <= kFapCount && have[static_cast<std::size_t>(f - 1)];
            })) {
          continue;
        }
        for (int f : faps) {
          if (!isHighLevel(f) && f >= 1 && f <= kFapCount)
            have.set(static_cast<std::size_t>(f - 1));
        }
        changed = true;
        break;
      }
    }
  }
  return have;
}

}  // namespace

double fitVariableValue(const FapFrame& frame, int variable) {
  switch (variable) {
    case kVisemeSelect1:
      return frame.viseme.select1;
    case kVisemeSelect2:
      return frame.viseme.select2;
    case kVisemeBlend:
      return frame.viseme.blend;
    case kExpressionSelect1:
      return frame.expression.select1;
    case kExpressionSelect2:
      return frame.expression.select2;
    case kExpressionIntensity1:
      return frame.expression.intensity1;
    case kExpressionIntensity2:
      return frame.expression.intensity2;
    default:
      return frame.value(variable);
  }
}

std::string fitVariableName(int variable) {
  switch (variable) {
    case kVisemeSelect1:
      return "viseme_select1";
    case kVisemeSelect2:
      return "viseme_select2";
    case kVisemeBlend:
      return "viseme_blend";
    case kExpressionSelect1:
      return "expression_select1";
    case kExpressionSelect2:
      return "expression_select2";
    case kExpressionIntensity1:
      return "expression_intensity1";
    case kExpressionIntensity2:
      return "expression_intensity2";
    default:
      return std::string(fapInfo(variable).name);
  }
}

std::vector<int> fitVariables(const std::vector<int>& faps) {
  std::vector<int> out;
  for (int fap : faps) {
    if (fap == 1) {
      out.insert(out.end(), {kVisemeSelect1, kVisemeSelect2, kVisemeBlend});
    } else if (fap == 2) {
      out.insert(out.end(), {kExpressionSelect1, kExpressionSelect2, kExpressionIntensity1,
                             kExpressionIntensity2});
    } else {
      out.push_back(fap);
    }
  }
  return out;
}

int addFitNode(FitTable& table, std::vector<int> faps) {
  table.nodes.push_back(std::move(faps));
  return static_cast<int>(table.nodes.size()) - 1;
}

void removeFitNode(FitTable& table, int node) {
  if (!validNode(table, node)) throw Error({}, 0, "FIT", "no " + nodeName(node) + " to remove");
  table.nodes.erase(table.nodes.begin() + node);
  std::erase_if(table.links, [&](const FitLink& l) { return l.parent == node || l.child == node; });
  for (FitLink& l : table.links) {
    if (l.parent > node) --l.parent;
    if (l.child > node) --l.child;
  }
}

int addFitLink(FitTable& table, int parent, int child) {
  for (int node : {parent, child}) {
    if (!validNode(table, node))
      throw Error({}, 0, "FIT", "a link to " + nodeName(node) + ", which does not exist");
  }
  const std::size_t variables = fitVariables(table.nodes[static_cast<std::size_t>(parent)]).size();
  FitLink link{parent, child, {}};
  for (std::size_t i = 0; i < table.nodes[static_cast<std::size_t>(child)].size(); ++i) {
    link.functions.push_back({{}, {FitTerm{1.0, std::vector<int>(variables, 0)}}});
  }
  table.links.push_back(std::move(link));
  return static_cast<int>(table.links.size()) - 1;
}

void removeFitLink(FitTable& table, int link) {
  if (link < 0 || link >= static_cast<int>(table.links.size())) {
    throw Error({}, 0, "FIT", "no link " + std::to_string(link) + " to remove");
  }
  table.links.erase(table.links.begin() + link);
}

void setFitFunction(FitTable& table, int link, int childFap, FitFunction function) {
  if (link < 0 || link >= static_cast<int>(table.links.size())) {
    throw Error({}, 0, "FIT", "no link " + std::to_string(link));
  }
  FitLink& l = table.links[static_cast<std::size_t>(link)];
  const auto& child = table.nodes[static_cast<std::size_t>(l.child)];
  const auto at = std::find(child.begin(), child.end(), childFap);
  if (at == child.end()) {
    throw Error(
        {}, 0, "FIT",
        linkName(table, link) + ": FAP " + std::to_string(childFap) + " is not in the child node");
  }
  l.functions.resize(child.size());
  l.functions[static_cast<std::size_t>(at - child.begin())] = std::move(function);
}

FitFunction linearFitFunction(const std::vector<int>& parentFaps, int variable, double gain) {
  const std::vector<int> variables = fitVariables(parentFaps);
  const auto at = std::find(variables.begin(), variables.end(), variable);
  if (at == variables.end()) {
    throw Error({}, 0, "FIT", fitVariableName(variable) + " is not a variable of the parent node");
  }
  FitTerm term{gain, std::vector<int>(variables.size(), 0)};
  term.exponents[static_cast<std::size_t>(at - variables.begin())] = 1;
  return {{term}, {FitTerm{1.0, std::vector<int>(variables.size(), 0)}}};
}

std::vector<std::string> fitProblems(const FitTable& table) {
  std::vector<std::string> problems;
  std::vector<bool> linked(table.nodes.size(), false);
  for (std::size_t n = 0; n < table.nodes.size(); ++n) {
    const auto& faps = table.nodes[n];
    if (faps.empty()) problems.push_back(nodeName(static_cast<int>(n)) + " is empty");
    for (int f : faps) {
      if (f < 1 || f > kFapCount) {
        problems.push_back(nodeName(static_cast<int>(n)) + " has unknown FAP " + std::to_string(f));
      }
    }
  }
  for (std::size_t k = 0; k < table.links.size(); ++k) {
    const FitLink& link = table.links[k];
    if (!validNode(table, link.parent) || !validNode(table, link.child)) {
      problems.push_back("link " + std::to_string(k) + " joins " + nodeName(link.parent) + " and " +
                         nodeName(link.child) + ", which are not both in the table");
      continue;
    }
    const std::string name = linkName(table, static_cast<int>(k));
    linked[static_cast<std::size_t>(link.parent)] = linked[static_cast<std::size_t>(link.child)] =
        true;
    const auto& parent = table.nodes[static_cast<std::size_t>(link.parent)];
    const auto& child = table.nodes[static_cast<std::size_t>(link.child)];
    const std::vector<int> variables = fitVariables(parent);
    for (std::size_t i = 0; i < child.size(); ++i) {
      if (isHighLevel(child[i])) {
        problems.push_back(name + ": FAP " + std::to_string(child[i]) +
                           " cannot be interpolated (a viseme or expression is sent, not derived)");
      }
      if (i >= link.functions.size()) {
        problems.push_back(name + ": child FAP " + std::to_string(child[i]) + " has no function");
      }
    }
    if (link.functions.size() > child.size()) {
      problems.push_back(name + " has " + std::to_string(link.functions.size()) +
                         " functions for a child node of " + std::to_string(child.size()) +
                         " FAPs");
    }
    for (std::size_t i = 0; i < link.functions.size() && i < child.size(); ++i) {
      const std::string where = name + " FAP " + std::to_string(child[i]);
      const FitFunction& fn = link.functions[i];
      if (fn.denominator.empty()) problems.push_back(where + " has no denominator term");
      for (const auto* terms : {&fn.numerator, &fn.denominator}) {
        const bool numerator = terms == &fn.numerator;
        for (std::size_t t = 0; t < terms->size(); ++t) {
          const FitTerm& term = (*terms)[t];
          const std::string at =
              where + (numerator ? " numerator" : " denominator") + " term " + std::to_string(t);
          if (term.exponents.size() != variables.size()) {
            problems.push_back(at + " has " + std::to_string(term.exponents.size()) +
                               " exponents, the parent node " + std::to_string(variables.size()) +
                               " variables");
          }
          for (int e : term.exponents) {
            if (e < 0 || e > kMaxExponent) {
              problems.push_back(at + " has exponent " + std::to_string(e) + " outside 0..15");
            }
          }
          if (!std::isfinite(term.coefficient))
            problems.push_back(at + " has a coefficient that is not finite");
          if (term.impulseSelect == 0) continue;
          if (!numerator) {
            problems.push_back(at + " has an impulse (only numerator terms may)");
            continue;
          }
          const bool viseme =
              term.impulseSelect == kVisemeSelect1 || term.impulseSelect == kVisemeSelect2;
          const bool expression =
              term.impulseSelect == kExpressionSelect1 || term.impulseSelect == kExpressionSelect2;
          if (!viseme && !expression) {
            problems.push_back(at + " has an impulse on " + std::to_string(term.impulseSelect) +
                               ", not on a viseme or expression select");
          } else if (std::find(variables.begin(), variables.end(), term.impulseSelect) ==
                     variables.end()) {
            problems.push_back(at + " has an impulse on " + fitVariableName(term.impulseSelect) +
                               ", which the parent node does not have");
          } else if (term.impulseValue < 0 || term.impulseValue > (viseme ? 14 : 6)) {
            problems.push_back(at + " has an impulse value " + std::to_string(term.impulseValue) +
                               " outside 0.." + (viseme ? "14" : "6"));
          }
        }
      }
    }
  }
  for (std::size_t n = 0; n < table.nodes.size(); ++n) {
    if (!linked[n]) {
      problems.push_back(nodeName(static_cast<int>(n)) +
                         " is unreachable: no link leads to or from it");
    }
  }
  return problems;
}

void validateFitTable(const FitTable& table, const std::string& source) {
  const std::vector<std::string> problems = fitProblems(table);
  if (problems.empty()) return;
  std::string message = "invalid FAP interpolation table: ";
  for (std::size_t i = 0; i < problems.size(); ++i) message += (i ? "; " : "") + problems[i];
  throw Error(source, 0, "FIT", message);
}

double evaluateFitFunction(const FitFunction& function, const std::vector<int>& variables,
                           const std::vector<double>& values, const std::string& where) {
  const double numerator = sumOfTerms(function.numerator, values, variables, true);
  const double denominator = sumOfTerms(function.denominator, values, variables, false);
  if (denominator == 0) throw Error({}, 0, where, where + ": the denominator is 0");
  const double value = numerator / denominator;
  if (!std::isfinite(value)) throw Error({}, 0, where, where + ": the result is not finite");
  return value;
}

int interpolateFitFrame(const FitTable& table, FapFrame& frame) {
  int computed = 0;
  for (int pass = 1; pass > 0; computed += pass) {
    pass = 0;
    for (int node = 0; node < static_cast<int>(table.nodes.size()); ++node) {
      const auto& faps = table.nodes[static_cast<std::size_t>(node)];
      const bool lacking = std::any_of(faps.begin(), faps.end(), [&](int f) {
        return !isHighLevel(f) && f >= 1 && f <= kFapCount && !available(frame, f);
      });
      if (!lacking) continue;
      for (int k = 0; k < static_cast<int>(table.links.size()); ++k) {
        const FitLink& link = table.links[static_cast<std::size_t>(k)];
        if (link.child != node || !validNode(table, link.parent)) continue;
        const auto& parent = table.nodes[static_cast<std::size_t>(link.parent)];
        if (!std::all_of(parent.begin(), parent.end(),
                         [&](int f) { return f >= 1 && f <= kFapCount && available(frame, f); })) {
          continue;
        }
        const std::vector<int> variables = fitVariables(parent);
        std::vector<double> values;
        for (int v : variables) values.push_back(fitVariableValue(frame, v));
        // Computed together: a FAP of this node computed first is not an input of the others.
        std::vector<std::pair<int, int>> results;
        for (std::size_t i = 0; i < faps.size(); ++i) {
          const int f = faps[i];
          if (isHighLevel(f) || f < 1 || f > kFapCount || available(frame, f)) continue;
          const std::string where = "frame " + std::to_string(frame.number) + " " +
                                    linkName(table, k) + " FAP " + std::to_string(f);
          if (i >= link.functions.size()) throw Error({}, 0, where, where + ": no function");
          const double value =
              std::round(evaluateFitFunction(link.functions[i], variables, values, where));
          if (std::abs(value) > std::numeric_limits<int>::max()) {
            throw Error(
                {}, 0, where,
                where + ": the result " + std::to_string(value) + " does not fit a FAP value");
          }
          results.emplace_back(f, static_cast<int>(value));
        }
        for (const auto& [f, value] : results) frame.set(f, value);
        pass += static_cast<int>(results.size());
        break;
      }
    }
  }
  return computed;
}

int interpolateFitStream(const FitTable& table, FapStream& stream) {
  validateFitTable(table);
  int computed = 0;
  for (FapFrame& frame : stream.frames) computed += interpolateFitFrame(table, frame);
  return computed;
}

std::bitset<kFapCount> fitDerivedFaps(const FitTable& table, const std::bitset<kFapCount>& sent) {
  std::bitset<kFapCount> kept = sent;
  for (const FitLink& link : table.links) {
    if (!validNode(table, link.child)) continue;
    for (int f : table.nodes[static_cast<std::size_t>(link.child)]) {
      if (isHighLevel(f) || f < 1 || f > kFapCount || !kept[static_cast<std::size_t>(f - 1)])
        continue;
      kept.reset(static_cast<std::size_t>(f - 1));
      if (!closure(table, kept)[static_cast<std::size_t>(f - 1)])
        kept.set(static_cast<std::size_t>(f - 1));
    }
  }
  return sent & ~kept;
}

}  // namespace mpeg4face
