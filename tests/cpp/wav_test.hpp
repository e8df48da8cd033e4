// SPDX-License-Identifier: GPL-3.0-or-later
// Reading the .wav files flite writes, for the speech tests.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace mpeg4face::test {

// A mono 16-bit PCM .wav file (what flite writes): its sample rate and samples.
struct Wav {
  double rate = 0;
  std::vector<std::int16_t> samples;
  double seconds() const { return static_cast<double>(samples.size()) / rate; }
  // The mean |sample| from `from` to `to` seconds.
  double loudness(double from, double to) const {
    const auto a = static_cast<std::size_t>(from * rate), b = static_cast<std::size_t>(to * rate);
    double sum = 0;
    for (std::size_t i = a; i < b && i < samples.size(); ++i) sum += std::abs(samples[i]);
    return b > a ? sum / static_cast<double>(b - a) : 0;
  }
};
inline Wav readWav(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const auto u = [&](std::size_t at, int n) {
    std::uint32_t v = 0;
    for (int k = n - 1; k >= 0; --k) v = v << 8 | static_cast<unsigned char>(bytes[at + k]);
    return v;
  };
  Wav wav;
  if (bytes.size() < 44 || bytes.compare(0, 4, "RIFF") != 0 || bytes.compare(8, 4, "WAVE") != 0) {
    ADD_FAILURE() << path << " is not a RIFF/WAVE file";
    return wav;
  }
  EXPECT_EQ(u(22, 2), 1u) << "mono";
  EXPECT_EQ(u(34, 2), 16u) << "16-bit";
  wav.rate = u(24, 4);
  for (std::size_t at = 12; at + 8 <= bytes.size(); at += 8 + u(at + 4, 4)) {
    if (bytes.compare(at, 4, "data") != 0) continue;
    for (std::size_t i = at + 8; i + 1 < bytes.size() && i < at + 8 + u(at + 4, 4); i += 2) {
      wav.samples.push_back(static_cast<std::int16_t>(u(i, 2)));
    }
  }
  return wav;
}

}  // namespace mpeg4face::test
