// SPDX-License-Identifier: GPL-3.0-or-later
// The steps `mpeg4face animate` chains, shared with the commands that run each alone
// (landmarks, clone, check).
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mpeg4face/clone/clone.hpp"
#include "mpeg4face/fat/motion_check.hpp"
#include "mpeg4face/model/face_model.hpp"
#include "mpeg4face/model/face_shape.hpp"
#include "mpeg4face/model/landmarks.hpp"

namespace mpeg4face::cli {

// What `clone` clones from: a neutral and its copies (FAP, viseme and expression shapes).
struct CloneSource {
  FaceModel neutral;
  std::vector<FaceShape> copies;
  std::string kind;  // "tables" or "shape keys"
  // Its shape keys and animations not in the grammar (an ARKit head's own): not cloned.
  std::vector<std::string> ignored;
};

// A .wrl with tables; a glTF written with tables (writeFatGltf), else a glTF head whose
// shape keys are named copies (fat/names.hpp), the others in `ignored`. `featurePoints`: a
// CSV bound over the file's.
CloneSource readCloneSource(const std::string& path,
                            const std::optional<std::string>& featurePoints,
                            std::vector<std::string>& warnings);
// Throws mpeg4face::Error naming `path` and the points cloning needs that `model` lacks,
// telling the user to bind them with `option`.
void requireCloneFeaturePoints(const FaceModel& model, const std::string& path,
                               const char* option);
// The cloned face written: a .wrl with its tables, or a glTF with its tables plus each cloned
// copy's vertex motion as a shape key named like the copy, so that the file can be edited
// and fed to `fat generate` again.
void writeClonedFace(const ClonedFace& cloned, const std::string& path);

// The ICT sample head samples/build.sh makes: the default template of `landmarks` and source
// of `animate`. Throws UsageError naming `option` if it has not been built.
std::string sampleIctHead(const char* option);

// The options `landmarks` and `animate` share: where the points come from.
struct LandmarkArgs {
  std::optional<std::string> featurePoints;  // --feature-points CSV
  std::optional<std::string> templateHead;   // --template T
  std::vector<std::string> pins;             // --pin FP=..., repeatable
};
// Takes args[i] into `out` if it is one of those options (moving i onto its value).
bool takeLandmarkOption(const std::vector<std::string>& args, std::size_t& i,
                        LandmarkArgs& out);

// Finds `head`'s feature points from `templateHead` (model/landmarks.hpp), its own points and
// `pins` (--pin texts: FP=VERTEX, FP=MESH:VERTEX, FP=x,y,z) kept, and binds them in `head`;
// free points on a surface become its vertices (what that binds is added to `warnings`).
LandmarkResult placeFeaturePoints(FaceModel& head, const FaceModel& templateHead,
                                  const std::vector<std::string>& pins,
                                  std::vector<std::string>& warnings);

// The motion check's text summary, as `check` prints it.
void printMotionCheckSummary(const std::string& head, const MotionCheck& check);

// Progress on stderr: a line per stage, or one line updated in place on a terminal.
class ProgressPrinter {
 public:
  explicit ProgressPrinter(std::string command)
      : command_(std::move(command)), tty_(isatty(fileno(stderr)) != 0) {}
  ProgressPrinter(const ProgressPrinter&) = delete;
  ProgressPrinter& operator=(const ProgressPrinter&) = delete;
  ~ProgressPrinter() { finish(); }  // also when an error unwinds: its message on a line of its own
  void finish() {
    if (tty_ && !stage_.empty()) std::fputc('\n', stderr);
    stage_.clear();
  }
  void operator()(std::string_view stage, double fraction) {
    const int percent = static_cast<int>(std::lround(100 * std::clamp(fraction, 0.0, 1.0)));
    if (tty_) {
      if (stage == stage_ && percent == percent_) return;
      std::fprintf(stderr, "\r%s: %3d%% %-48.*s", command_.c_str(), percent,
                   static_cast<int>(stage.size()), stage.data());
      std::fflush(stderr);
    } else if (stage != stage_) {
      std::fprintf(stderr, "%s: %3d%% %.*s\n", command_.c_str(), percent,
                   static_cast<int>(stage.size()), stage.data());
    }
    stage_ = stage;
    percent_ = percent;
  }

 private:
  std::string command_;
  bool tty_;
  std::string stage_;
  int percent_ = -1;
};


}  // namespace mpeg4face::cli
