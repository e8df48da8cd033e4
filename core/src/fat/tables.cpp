// SPDX-License-Identifier: GPL-3.0-or-later
#include "mpeg4face/fat/tables.hpp"

#include <algorithm>
#include <string>

#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {

int tableInput(int fapID, int highLevelSelect, const FapFrame& frame) {
  constexpr int kMaxAmount = 63;  // viseme_blend, expression intensities
  const int s = highLevelSelect;
  if (fapID == 1) {
    const Viseme& v = frame.viseme;
    return (v.select1 == s ? v.blend : 0) + (v.select2 == s ? kMaxAmount - v.blend : 0);
  }
  if (fapID == 2) {
    const Expression& e = frame.expression;
    return (e.select1 == s ? e.intensity1 : 0) + (e.select2 == s ? e.intensity2 : 0);
  }
  return frame.value(fapID);
}

double fapScale(const FapuMeasurement& fapu, int fapID) {
  if (fapID == 1 || fapID == 2) return 1.0;
  return fapu.unit(fapInfo(fapID).fapu);
}

void applyFaceDefTransform(const FaceDefTransform& def, double scaledValue, Transform& transform) {
  switch (def.fieldId) {
    case FaceDefTransform::Field::Rotation: {
      const Eigen::Vector3d axis = def.rotationDef.head<3>();
      if (axis.norm() == 0) throw Error({}, 0, "rotationDef", "rotation axis is zero");
      transform.rotation = transform.rotation *
                           Eigen::AngleAxisd(scaledValue * def.rotationDef[3], axis.normalized());
      break;
    }
    case FaceDefTransform::Field::Scale:
      transform.scale += scaledValue * def.scaleDef;
      break;
    case FaceDefTransform::Field::Translation:
      transform.translation += scaledValue * def.translationDef;
      break;
  }
}

void checkIntervalBorders(std::span<const int> intervalBorders) {
  const auto fail = [](const std::string& why) { throw Error({}, 0, "intervalBorders", why); };
  if (intervalBorders.size() < 2)
    fail("needs at least two borders (one interval), has " +
         std::to_string(intervalBorders.size()));
  for (size_t i = 1; i < intervalBorders.size(); ++i)
    if (intervalBorders[i] <= intervalBorders[i - 1])
      fail("borders must increase strictly: " + std::to_string(intervalBorders[i - 1]) +
           " is followed by " + std::to_string(intervalBorders[i]));
  if (intervalBorders.size() > 2 && std::ranges::count(intervalBorders, 0) != 1)
    fail("with several intervals exactly one border must be 0");
}

void intervalWeights(std::span<const int> intervalBorders, double value,
                     std::vector<double>& weights) {
  const size_t n = intervalBorders.size() - 1;
  weights.assign(n, 0.0);
  if (n == 1) {  // rule 6: strictly linear
    weights[0] = value;
    return;
  }
  const auto& I = intervalBorders;
  const size_t k = static_cast<size_t>(std::ranges::find(I, 0) - I.begin());
  if (value >= 0) {
    if (k == n) {  // no positive interval: the last one continues through 0
      weights[n - 1] = -value;
      return;
    }
    for (size_t j = k; j < n; ++j) {
      const double part = value - I[j];
      if (part <= 0) break;
      weights[j] = j + 1 == n ? part : std::min(part, double(I[j + 1]) - I[j]);
    }
  } else {
    if (k == 0) {  // no negative interval: the first one continues through 0
      weights[0] = value;
      return;
    }
    for (size_t j = k; j-- > 0;) {
      const double part = I[j + 1] - value;
      if (part <= 0) break;
      weights[j] = j == 0 ? part : std::min(part, double(I[j + 1]) - I[j]);
    }
  }
}

void borderWeights(std::span<const int> intervalBorders, double value,
                   std::vector<double>& weights) {
  const auto& I = intervalBorders;
  weights.assign(I.size(), 0.0);
  std::size_t j = 0;  // the interval holding the value, or the outermost one it continues
  while (j + 2 < I.size() && value > I[j + 1]) ++j;
  const double t = (value - I[j]) / (double(I[j + 1]) - I[j]);
  weights[j] = 1 - t;
  weights[j + 1] = t;
}

}  // namespace mpeg4face
