// SPDX-License-Identifier: GPL-3.0-or-later
// A cloning source given by its FaceDefTables: the shapes that the tables' own
// piecewise-linear functions pass through, so that cloning sees the shapes a modeler would
// have sculpted. Rules in docs/cli.md ("A source given by tables").
#include <algorithm>
#include <cstdlib>
#include <set>

#include "mpeg4face/clone/clone.hpp"
#include "mpeg4face/fat/evaluate.hpp"
#include "mpeg4face/fat/names.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

constexpr int kFullAmount = 63;  // a viseme or expression shown fully

// The FAP values (amounts for FAP 1 / 2) at which one table is sampled. Between and beyond
// its borders each FaceDefMesh is linear, so copies at every non-zero border of a
// multi-interval mesh (and the neutral at 0) give back the same function; a one-interval
// mesh (rule 6) and a FaceDefTransform are linear through 0, so one copy does.
std::vector<int> tableAmplitudes(const FaceDefTables& table) {
  std::set<int> borders;      // of multi-interval meshes
  std::set<int> oneInterval;  // of one-interval meshes
  for (const FaceDefMesh& m : table.faceDefMesh) {
    auto& into = m.intervalCount() > 1 ? borders : oneInterval;
    for (int b : m.intervalBorders) {
      if (b != 0) into.insert(b);
    }
  }
  if (table.fapID == 1) return {kFullAmount};  // the grammar's only viseme amount
  if (table.fapID == 2) {
    // Amounts run 0..63: inner borders matter, those beyond 63 are never reached.
    std::vector<int> out;
    for (int b : borders) {
      if (b > 0 && b < kFullAmount) out.push_back(b);
    }
    out.push_back(kFullAmount);
    return out;
  }
  if (!borders.empty()) return {borders.begin(), borders.end()};
  if (!oneInterval.empty()) {
    // The border of largest magnitude, the positive one on a tie: the widest shape the
    // modeler described.
    const int widest = *std::ranges::max_element(oneInterval, [](int a, int b) {
      return std::abs(a) != std::abs(b) ? std::abs(a) < std::abs(b) : a < b;
    });
    return {widest};
  }
  // Transforms only (eyes, head): the standard's default range of the FAP.
  return {std::max(1, fapInfo(table.fapID).intraRange)};
}

std::string copyLabel(const FaceDefTables& table) {
  if (table.fapID == 1) return {};  // phonemes are not label characters
  if (table.fapID == 2) {
    for (const ExpressionInfo& e : expressionTable()) {
      if (e.number == table.highLevelSelect) return std::string(e.name);
    }
    return {};
  }
  return std::string(fapInfo(table.fapID).name);
}

FapFrame frameFor(const FaceDefTables& table, int amplitude) {
  FapFrame frame;
  if (table.fapID == 1) {
    frame.set(1, 0);
    frame.viseme.select1 = table.highLevelSelect;
    frame.viseme.blend = amplitude;
  } else if (table.fapID == 2) {
    frame.set(2, 0);
    frame.expression.select1 = table.highLevelSelect;
    frame.expression.intensity1 = amplitude;
  } else {
    frame.set(table.fapID, amplitude);
  }
  return frame;
}

}  // namespace

std::vector<FaceShape> shapesFromFaceDefTables(const MpegFace& face, const FapuMeasurement& fapu) {
  const FatEvaluator evaluator(face, fapu);  // validates the face and the FAPU it needs
  const FaceModel& neutral = face.faceSceneGraph;

  std::vector<FaceShape> copies;
  FatState state = evaluator.neutralState();
  for (const FaceDefTables& table : face.faceDefTables) {
    const int highLevelSelect = table.fapID <= 2 ? table.highLevelSelect : 0;
    for (int amplitude : tableAmplitudes(table)) {
      evaluator.evaluate(frameFor(table, amplitude), state);
      FaceShape& copy = copies.emplace_back();
      copy.name = formatShapeKeyName({table.fapID, highLevelSelect, amplitude, copyLabel(table)});
      copy.fapID = table.fapID;
      copy.highLevelSelect = highLevelSelect;
      copy.amplitude = amplitude;
      copy.meshes = meshDisplacements(neutral, state.coord);
      copy.transforms = state.transforms;
    }
  }
  return copies;
}

}  // namespace mpeg4face
