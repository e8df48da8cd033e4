// SPDX-License-Identifier: GPL-3.0-or-later
// The ASCII FAP file (".fap") of the reference encoder, Xface, Greta and others: an optional
// header line `version name frame_rate frame_count`, then per frame a mask line of 68 0/1
// tokens and a line with the frame number and the values of the masked FAPs. The accepted
// grammar, the quirks handled and what writing normalises are in docs/fap-format.md.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face {

// Bounds that turn absurd input into an error instead of an allocation or an overflow.
// 10^7 frames are 4.6 days at 25 Hz. 10^6 is more than a full turn in AU (628,319) and 976
// neutral distances in the other FAPU.
inline constexpr int kMaxFapFrames = 10'000'000;
inline constexpr int kMaxFapMagnitude = 1'000'000;
inline constexpr double kMaxFapFrameRate = 1000.0;
// Version 2.0 files hold low-level FAP values (3..68) in units 20 times finer than FAPU.
inline constexpr int kFapVersion20Scale = 20;

// Throws mpeg4face::Error naming the file, the line and the field (mask, FAP 3 open_jaw,
// FAP 1 viseme_blend, ...) at fault.
FapStream readFapFile(const std::filesystem::path& path);
FapStream parseFap(std::string_view text, const std::string& fileName);

// The .fap text of `stream`, in its version (2.0 values are written in 2.0 units); throws
// mpeg4face::Error naming the frame and FAP if the stream cannot be written as a file that
// reads back the same (a value out of range, frame numbers not increasing, ...).
std::string fapText(const FapStream& stream);
void writeFapFile(const std::filesystem::path& path, const FapStream& stream);

}  // namespace mpeg4face
