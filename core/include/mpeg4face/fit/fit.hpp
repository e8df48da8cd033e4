// SPDX-License-Identifier: GPL-3.0-or-later
// FAP Interpolation Table (FIT, Tao et al. 1999 section III; Tekalp-Ostermann 2.2.3): a FAP
// interpolation graph (FIG) whose nodes are FAP sets and whose links say that a child node's
// FAPs can be computed from a parent node's, with one rational polynomial per child FAP
// (Tao eq. 2, with the impulse terms of eq. 3 on viseme / expression selects). A decoder
// derives the FAPs a stream does not send; an encoder leaves them out. docs/fit.md.
#pragma once

#include <bitset>
#include <string>
#include <vector>

#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face {

// The variables a parent node gives its links' polynomials, in node order: a low-level FAP
// (3..68) is one variable, its value; FAP 1 (viseme) is three, viseme_select1,
// viseme_select2, viseme_blend; FAP 2 (expression) is four, expression_select1,
// expression_select2, expression_intensity1, expression_intensity2 (Tao's F1..F4 of Fig. 7).
// They are numbered as Tao numbers FAP 2's subfields (72..75): 69..71 for FAP 1's.
enum FitVariable : int {
  kVisemeSelect1 = 69,
  kVisemeSelect2 = 70,
  kVisemeBlend = 71,
  kExpressionSelect1 = 72,
  kExpressionSelect2 = 73,
  kExpressionIntensity1 = 74,
  kExpressionIntensity2 = 75,
};
// "viseme_select1", ..., or the FAP's standard name for 3..68.
std::string fitVariableName(int variable);
// The value of a variable in a frame (a FapState too: its current values).
double fitVariableValue(const FapFrame& frame, int variable);
// The variables of a FAP set in node order (FAP 1 and 2 expanded as above).
std::vector<int> fitVariables(const std::vector<int>& faps);

// One product of eq. 2 / 3: coefficient * prod_j F_j ^ exponents[j] (one exponent per
// parent variable), in the numerator optionally times the impulse delta(F_s - a).
struct FitTerm {
  double coefficient = 0;      // c_i (numerator) or b_i (denominator)
  std::vector<int> exponents;  // l_ij or m_ij, 0..15
  int impulseSelect = 0;       // 0: no impulse; else kVisemeSelect1/2 or kExpressionSelect1/2
  int impulseValue = 0;        // a_i: 0..14 for visemes, 0..6 for expressions
  bool operator==(const FitTerm&) const = default;
};

// f = sum(numerator) / sum(denominator) (K = numerator.size(), P = denominator.size()).
struct FitFunction {
  std::vector<FitTerm> numerator;
  std::vector<FitTerm> denominator;
  bool operator==(const FitFunction&) const = default;
};

// A directed link of the FIG: the child node's FAPs computed from the parent node's, one
// function per child FAP in the child node's order.
struct FitLink {
  int parent = 0;  // node index
  int child = 0;
  std::vector<FitFunction> functions;
  bool operator==(const FitLink&) const = default;
};

// The table. For a child node with several parents, the links are tried in the order they
// appear in `links` (the FIG's link priority).
struct FitTable {
  std::vector<std::vector<int>> nodes;  // FAP sets: 1..68 each, FAP 1 and 2 only as parents
  std::vector<FitLink> links;
  bool operator==(const FitTable&) const = default;
};

// --- Authoring ----------------------------------------------------------------------------
// Each returns the index of what it adds. Removing a node removes its links and renumbers
// the nodes after it; functions are set per child FAP.
int addFitNode(FitTable& table, std::vector<int> faps);
void removeFitNode(FitTable& table, int node);
// A link whose functions are all f = 0 (set them with setFitFunction): appended, so it has
// the lowest priority among the child's links.
int addFitLink(FitTable& table, int parent, int child);
void removeFitLink(FitTable& table, int link);
void setFitFunction(FitTable& table, int link, int childFap, FitFunction function);

// f = gain * F for the parent variable `variable` of a parent node holding `parentFaps`.
FitFunction linearFitFunction(const std::vector<int>& parentFaps, int variable, double gain = 1);

// Problems of a table, each naming where it is ("node 3", "link 2 (node 0 -> node 1)",
// "link 2 FAP 51"): an unknown FAP, an empty node, a FAP 1 / 2 in a child node, a link to a
// node that does not exist, a missing or extra function, an exponent count that is not the
// parent's variable count, an exponent outside 0..15, an impulse on something else than a
// select or with a value out of range, a function without a denominator term, a node that is
// neither linked from nor to anything (unreachable and unused). Empty: valid.
std::vector<std::string> fitProblems(const FitTable& table);
// Throws mpeg4face::Error (field "FIT", file `source`) listing fitProblems if there are any.
void validateFitTable(const FitTable& table, const std::string& source = {});

// --- Evaluation ---------------------------------------------------------------------------
// The value of one function for the parent's variables (fitVariables of the parent node)
// and their values. Throws mpeg4face::Error naming `where` if the denominator is 0 or the
// result is not finite.
double evaluateFitFunction(const FitFunction& function, const std::vector<int>& variables,
                           const std::vector<double>& values, const std::string& where);

// Tao's interpolation loop on one frame: repeat { for each node in order that has FAPs the
// frame lacks, take its first link (in priority order) whose parent's FAPs are all
// available, and compute the lacking FAPs (rounded to the nearest integer FAPU) } until a
// pass computes nothing. Sent FAPs are never changed; a FAP computed is available to later
// nodes. Stops on cycles (a pass that computes nothing ends it). FAP 1 / 2 are available when
// the frame sends them. Throws mpeg4face::Error naming the frame, link and FAP for a zero
// denominator or a result that is not finite or does not fit a FAP value. Returns how many
// FAPs it computed.
int interpolateFitFrame(const FitTable& table, FapFrame& frame);
// interpolateFitFrame on every frame; returns the FAPs computed in all.
int interpolateFitStream(const FitTable& table, FapStream& stream);

// What an encoder can leave out of a frame that sends `sent` (bit FAP - 1): the FAPs that
// the table computes back from the rest, chosen link by link in priority order (a FAP is
// left out only if the interpolation loop recovers it from what remains sent).
std::bitset<kFapCount> fitDerivedFaps(const FitTable& table, const std::bitset<kFapCount>& sent);

}  // namespace mpeg4face
