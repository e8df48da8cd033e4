// SPDX-License-Identifier: GPL-3.0-or-later
// Face captures as the Live Link Face app records them (iPhone, ARKit): CSV with a header
//   Timecode,BlendShapeCount,EyeBlinkLeft,...,TongueOut,HeadYaw,HeadPitch,HeadRoll,
//   LeftEyeYaw,LeftEyePitch,LeftEyeRoll,RightEyeYaw,RightEyePitch,RightEyeRoll
// and one row per captured frame: the timecode hh:mm:ss:frame.fraction, the channel count
// (61), the 52 ARKit blendshape weights (0..1) and the head's and eyes' angles (radians).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace mpeg4face {

// The 61 channels in Live Link Face's column order: the 52 ARKit weights (EyeBlinkLeft ...
// TongueOut), then the 9 angles (HeadYaw ... RightEyeRoll).
std::span<const std::string_view> liveLinkChannelNames();
inline constexpr int kLiveLinkWeightCount = 52;
inline constexpr int kLiveLinkChannelCount = 61;
// Column of an angle channel in LiveLinkCapture::values.
enum LiveLinkAngle : int {
  kHeadYaw = 52,
  kHeadPitch,
  kHeadRoll,
  kLeftEyeYaw,
  kLeftEyePitch,
  kLeftEyeRoll,
  kRightEyeYaw,
  kRightEyePitch,
  kRightEyeRoll
};

struct LiveLinkCapture {
  // Always liveLinkChannelNames(), whatever the file's column order.
  std::vector<std::string> channels;
  // Per frame, seconds since the timecode's midnight: hh * 3600 + mm * 60 + ss +
  // frame.fraction / frameRate. Never decreasing.
  std::vector<double> times;
  Eigen::MatrixXd values;  // frames x 61, in `channels` order
  // The timecode's frame rate: the smallest of 24, 25, 30, 48, 50, 60, 100, 120 above every
  // frame number of the file when the capture crosses a second (so the wrap shows the rate),
  // else 60 (Live Link Face's rate) unless a frame number says more.
  double frameRate = 60;
  int clampedWeights = 0;             // weights outside 0..1 that were clamped
  std::vector<std::string> warnings;  // one per kind: clamped weights, ignored columns

  int frameCount() const { return static_cast<int>(times.size()); }
};

// Reads a Live Link Face CSV. Columns are found by their header names (any order; unknown
// columns are ignored with a warning). Throws mpeg4face::Error naming the file, line and
// column for: an empty file, a file with only its header, a missing column, a row with too
// few or too many cells, a cell that is not a number or is NaN / infinite, a malformed
// timecode, a timecode going backwards. Weights outside 0..1 are clamped, counted and
// reported with one warning.
LiveLinkCapture readLiveLinkCsv(const std::filesystem::path& path);
LiveLinkCapture parseLiveLinkCsv(std::string_view text, const std::string& fileName);

// The capture in Live Link Face's layout (61 channels in its order, timecodes from `times`
// at `frameRate`), written atomically. Throws mpeg4face::Error for a capture whose values
// are not frames x 61 or whose frame rate is not positive.
void writeLiveLinkCsv(const std::filesystem::path& path, const LiveLinkCapture& capture);
std::string formatLiveLinkCsv(const LiveLinkCapture& capture);

}  // namespace mpeg4face
