// SPDX-License-Identifier: GPL-3.0-or-later
// Measuring the FAPU of a face model from its feature points, and checking the recommended
// feature-point location constraints of Tekalp-Ostermann Table 6.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {

// One neutral-face distance (ES0, IRISD0, ENS0, MNS0 or MW0) in model units.
struct FapuDistance {
  bool measured = false;
  double value = 0.0;                   // model units; the unit itself is value / 1024
  std::vector<std::string> pointsUsed;  // feature points the value came from
  // How, in words, e.g. "|3.5 - 3.6|"; when not measured, why not (the points it needs, or
  // that the value is not positive).
  std::string method;
};

struct FapuMeasurement {
  FapuDistance ES0, IRISD0, ENS0, MNS0, MW0;
  // The unit (value / 1024) in model units for the linear FAPUs, 1e-5 for AU, 0 if unmeasured.
  double unit(FapuKind kind) const;
  // The five distances with their names, in the order ES0, IRISD0, ENS0, MNS0, MW0.
  struct NamedDistance {
    std::string_view name;
    const FapuDistance* distance;
  };
  std::array<NamedDistance, 5> distances() const;
  // Missing distances as names, e.g. {"ENS0"}.
  std::vector<std::string> missing() const;
};

// Which points are used:
//   ES0    |3.5 - 3.6| (pupil centres); else the eye-corner midpoints (3.7+3.11)/2, (3.8+3.12)/2
//   IRISD0 mean of 3.1.y - 3.3.y and 3.2.y - 3.4.y (whichever eyes are bound)
//   ENS0   eye level (mean y of the pupil centres, as for ES0) - 9.15.y
//   MNS0   9.15.y - 2.2.y
//   MW0    |8.3 - 8.4|; else |2.4 - 2.5|
FapuMeasurement measureFapu(const FaceModel& model);

struct ConstraintWarning {
  std::string featurePoint;  // "2.1"
  char axis;                 // 'x', 'y' or 'z'
  std::string message;       // "2.1.x differs from 7.1.x by 4.2% of ES0"
  bool advisory;             // the paper allows an alternative location
};

// Checks every Table 6 constraint whose points are all bound. The scale is ES0 if measured,
// else the bounding-box diagonal of the bound feature points; an equality is violated when
// the two sides differ by more than `tolerance` * scale, an inequality when it fails by
// more than that. A distance that is not positive (e.g. a face that is not Y-up) is left
// unmeasured with the reason in `method`.
std::vector<ConstraintWarning> checkLocationConstraints(const FaceModel& model,
                                                        const FapuMeasurement& fapu,
                                                        double tolerance = 0.02);

}  // namespace mpeg4face
