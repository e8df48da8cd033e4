// SPDX-License-Identifier: GPL-3.0-or-later
// Bit I/O and the adaptive arithmetic coder. The coder is checked bit for bit against a plain
// transcription of the reference algorithm (descending cumulative-frequency arrays, linear
// search), written here independently of the Fenwick-tree implementation.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "codec/arithmetic_coder.hpp"
#include "codec/bit_io.hpp"
#include "mpeg4face/error.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::AdaptiveModel;
using mpeg4face::ArithmeticDecoder;
using mpeg4face::ArithmeticEncoder;
using mpeg4face::BitReader;
using mpeg4face::BitWriter;
using mpeg4face::Error;
using mpeg4face::test::errorOf;

bool contains(const Error& e, const std::string& text) {
  return std::string(e.what()).find(text) != std::string::npos;
}

std::vector<bool> bitsOf(const std::vector<uint8_t>& bytes, uint64_t count) {
  std::vector<bool> bits;
  for (uint64_t i = 0; i < count; ++i) bits.push_back((bytes[i / 8] >> (7 - i % 8)) & 1);
  return bits;
}

// ---- The reference algorithm, transcribed: cumul[0] = total, cumul[n] = 0, symbol s spans
// [cumul[s+1], cumul[s]); counts halved (rounding up) when cumul[0] has reached 16383.
struct PlainModel {
  std::vector<int> freq, cumul;
  explicit PlainModel(int n) : freq(n, 1), cumul(n + 1) {
    for (int j = 0; j <= n; ++j) cumul[j] = n - j;
  }
  void update(int s) {
    const int n = static_cast<int>(freq.size());
    if (cumul[0] == 16383) {
      int cum = 0;
      for (int i = n - 1; i >= 0; --i) {
        freq[i] = (freq[i] + 1) / 2;
        cum += freq[i];
        cumul[i] = cum;
      }
    }
    ++freq[s];
    for (int i = s; i >= 0; --i) ++cumul[i];
  }
};

struct PlainEncoder {
  std::vector<bool> bits;
  int low = 0, high = 65535, opposite = 0, zeroRun = 0;
  void put(bool b) {
    if (zeroRun == 22) {
      bits.push_back(true);
      zeroRun = 0;
    }
    bits.push_back(b);
    zeroRun = b ? 0 : zeroRun + 1;
  }
  void withOpposite(bool b) {
    put(b);
    for (; opposite > 0; --opposite) put(!b);
  }
  void encode(int s, PlainModel& m) {
    const long length = high - low + 1;
    high = static_cast<int>(low - 1 + length * m.cumul[s] / m.cumul[0]);
    low = static_cast<int>(low + length * m.cumul[s + 1] / m.cumul[0]);
    for (;;) {
      if (high < 32768) {
        withOpposite(false);
      } else if (low >= 32768) {
        withOpposite(true);
        low -= 32768;
        high -= 32768;
      } else if (low >= 16384 && high < 49152) {
        ++opposite;
        low -= 16384;
        high -= 16384;
      } else {
        break;
      }
      low *= 2;
      high = 2 * high + 1;
    }
    m.update(s);
  }
  void flush() {
    ++opposite;
    withOpposite(low >= 16384);
    low = 0;
    high = 65535;
    zeroRun = 0;
  }
};

// ---- Bit I/O

TEST(BitIo, WritesMostSignificantBitFirst) {
  BitWriter w;
  w.writeBits(0b101, 3);
  w.writeBits(0x1F, 5);
  w.writeBit(true);
  EXPECT_EQ(w.bitCount(), 9u);
  EXPECT_EQ(w.bytes(), (std::vector<uint8_t>{0xBF, 0x80}));
}

TEST(BitIo, NextStartCodeStuffing) {
  BitWriter aligned;
  aligned.nextStartCode();  // a whole 0111 1111 byte when aligned
  EXPECT_EQ(aligned.bytes(), (std::vector<uint8_t>{0x7F}));

  BitWriter w;
  w.writeBits(0b101, 3);
  w.writeStartCode(mpeg4face::kFbaObjectPlaneStartCode);  // 101 + 0 + 1111, then the code
  EXPECT_EQ(w.bytes(), (std::vector<uint8_t>{0xAF, 0x00, 0x00, 0x01, 0xBB}));

  BitReader r(w.bytes());
  EXPECT_EQ(r.readBits(3, "x"), 0b101u);
  EXPECT_FALSE(r.nextIsStartCode(mpeg4face::kFbaObjectEndCode));
  EXPECT_TRUE(r.nextIsStartCode(mpeg4face::kFbaObjectPlaneStartCode));
  r.readStartCode(mpeg4face::kFbaObjectPlaneStartCode, "plane");
  EXPECT_EQ(r.position(), 40u);
}

TEST(BitIo, StartCodeNeedsItsStuffing) {
  // 3 bits then 1011 (not 0111) before the code: not next_start_code() stuffing.
  const std::vector<uint8_t> bytes{0xBB, 0x00, 0x00, 0x01, 0xBB};
  BitReader r(bytes);
  r.readBits(3, "x");
  EXPECT_FALSE(r.nextIsStartCode(mpeg4face::kFbaObjectPlaneStartCode));
  const Error e = errorOf([&] { r.readStartCode(mpeg4face::kFbaObjectPlaneStartCode, "plane"); });
  EXPECT_EQ(e.field(), "plane");
  EXPECT_TRUE(contains(e, "at bit 3 (byte 0, bit 3)")) << e.what();
  EXPECT_TRUE(contains(e, "0x000001BB")) << e.what();
}

TEST(BitIo, RandomFieldsRoundTrip) {
  std::mt19937 rng(7);
  std::vector<std::pair<uint32_t, int>> fields;
  BitWriter w;
  for (int i = 0; i < 2000; ++i) {
    const int n = static_cast<int>(rng() % 33);
    const uint32_t v = static_cast<uint32_t>(rng()) & (n == 32 ? ~0u : (1u << n) - 1);
    fields.emplace_back(v, n);
    w.writeBits(v, n);
  }
  BitReader r(w.bytes());
  for (const auto& [v, n] : fields) EXPECT_EQ(r.readBits(n, "field"), v);
  EXPECT_EQ(r.position(), w.bitCount());
}

TEST(BitIo, ReadPastTheEndNamesElementAndOffset) {
  const std::vector<uint8_t> bytes{0xFF, 0x00};
  BitReader r(bytes, "clip.fba");
  r.readBits(13, "a");
  const Error e = errorOf([&] { r.readBits(5, "fap_quant"); });
  EXPECT_EQ(e.file(), "clip.fba");
  EXPECT_EQ(e.field(), "fap_quant");
  EXPECT_TRUE(contains(e, "at bit 13 (byte 1, bit 5)")) << e.what();
  EXPECT_TRUE(contains(e, "3 bits left")) << e.what();
}

// ---- Model

TEST(AdaptiveModel, MatchesTheReferenceCountingRules) {
  std::mt19937 rng(11);
  for (int n : {1, 2, 3, 15, 64, 121, 3721}) {
    AdaptiveModel model(n);
    PlainModel plain(n);
    // Enough updates to halve several times; skewed so halving rounds odd counts.
    for (int step = 0; step < 40000; ++step) {
      const int s = (rng() % 4 == 0) ? static_cast<int>(rng() % n) : (n - 1) / 2;
      model.update(s);
      plain.update(s);
      if (step % 997 == 0 || plain.cumul[0] < 20) {
        ASSERT_EQ(model.total(), static_cast<uint32_t>(plain.cumul[0])) << n << " " << step;
        for (int k = 0; k < n; k += std::max(1, n / 50)) {
          ASSERT_EQ(model.count(k), static_cast<uint32_t>(plain.freq[k]));
          ASSERT_EQ(model.countBelow(k), static_cast<uint32_t>(plain.cumul[0] - plain.cumul[k]));
        }
      }
    }
    EXPECT_LE(model.total(), AdaptiveModel::kMaxTotal);
  }
}

TEST(AdaptiveModel, FindInvertsCountBelow) {
  AdaptiveModel model(37);
  std::mt19937 rng(3);
  for (int i = 0; i < 500; ++i) model.update(static_cast<int>(rng() % 37) / 3);
  for (uint32_t t = 0; t < model.total(); ++t) {
    const int s = model.find(t);
    ASSERT_LE(model.countBelow(s), t);
    ASSERT_LT(t, model.countBelow(s) + model.count(s));
  }
}

TEST(AdaptiveModel, StartsAtOneAndRejectsBadSizes) {
  AdaptiveModel model(5);
  EXPECT_EQ(model.total(), 5u);
  EXPECT_DOUBLE_EQ(model.idealBits(2), std::log2(5.0));
  EXPECT_THROW(AdaptiveModel(0), Error);
  EXPECT_THROW(AdaptiveModel(AdaptiveModel::kMaxSymbols + 1), Error);
}

// ---- Coder

// Symbols drawn from a skewed distribution over n.
std::vector<int> skewedSymbols(std::mt19937& rng, int n, size_t count) {
  std::geometric_distribution<int> g(0.35);
  std::vector<int> out;
  for (size_t i = 0; i < count; ++i) out.push_back(std::min(n - 1, g(rng)));
  return out;
}

TEST(ArithmeticCoder, BitExactWithTheReferenceTranscription) {
  std::mt19937 rng(5);
  for (int n : {1, 2, 9, 121, 3721}) {
    const std::vector<int> symbols = skewedSymbols(rng, n, 20000);
    BitWriter w;
    ArithmeticEncoder enc(w);
    AdaptiveModel model(n);
    PlainEncoder plainEnc;
    PlainModel plain(n);
    for (size_t i = 0; i < symbols.size(); ++i) {
      enc.encode(symbols[i], model);
      plainEnc.encode(symbols[i], plain);
      if (i % 5000 == 4999) {  // several segments
        enc.flush();
        plainEnc.flush();
      }
    }
    ASSERT_EQ(w.bitCount(), plainEnc.bits.size()) << n;
    EXPECT_EQ(bitsOf(w.bytes(), w.bitCount()), plainEnc.bits) << n;
  }
}

TEST(ArithmeticCoder, SegmentsAndPlainFieldsRoundTrip) {
  std::mt19937 rng(9);
  struct Segment {
    int n;
    std::vector<int> symbols;
    uint32_t field;  // 7 plain bits after the segment
  };
  std::vector<Segment> segments;
  BitWriter w;
  for (int k = 0; k < 300; ++k) {
    Segment s{1 + static_cast<int>(rng() % 200), {}, static_cast<uint32_t>(rng() % 128)};
    const size_t count = rng() % 40;  // 0 symbols is a valid (2-bit) segment
    for (size_t i = 0; i < count; ++i) s.symbols.push_back(static_cast<int>(rng() % s.n));
    ArithmeticEncoder enc(w);
    AdaptiveModel model(s.n);
    for (int x : s.symbols) enc.encode(x, model);
    enc.flush();
    w.writeBits(s.field, 7);
    segments.push_back(std::move(s));
  }
  BitReader r(w.bytes());
  for (const Segment& s : segments) {
    ArithmeticDecoder dec(r);
    AdaptiveModel model(s.n);
    for (int x : s.symbols) ASSERT_EQ(dec.decode(model), x);
    dec.finish("segment");
    ASSERT_EQ(r.readBits(7, "field"), s.field);
  }
  EXPECT_EQ(r.position(), w.bitCount());
}

TEST(ArithmeticCoder, UniformCodingIsAFreshModel) {
  std::mt19937 rng(4);
  std::vector<std::pair<int, int>> symbols;  // (symbol, n)
  BitWriter uniform, fresh;
  ArithmeticEncoder a(uniform), b(fresh);
  for (int i = 0; i < 5000; ++i) {
    const int n = 1 + static_cast<int>(rng() % 3721);
    const int s = static_cast<int>(rng() % static_cast<unsigned>(n));
    symbols.emplace_back(s, n);
    a.encodeUniform(s, n);
    AdaptiveModel model(n);
    b.encode(s, model);
  }
  a.flush();
  b.flush();
  EXPECT_EQ(uniform.bytes(), fresh.bytes());
  BitReader r(uniform.bytes());
  ArithmeticDecoder dec(r);
  for (const auto& [s, n] : symbols) ASSERT_EQ(dec.decodeUniform(n), s);
  dec.finish("segment");
  EXPECT_EQ(r.position(), uniform.bitCount());
}

// Raw bits are uniform symbols of 2^count values, scaled by a shift: the same bits as
// encodeUniform, mixed with adaptive symbols, and they decode back.
TEST(ArithmeticCoder, RawBitsAreUniformSymbolsOfAPowerOfTwo) {
  std::mt19937 rng(5);
  std::vector<std::pair<uint32_t, int>> symbols;  // (bits, count)
  BitWriter raw, uniform;
  ArithmeticEncoder a(raw), b(uniform);
  AdaptiveModel modelA(7), modelB(7);
  for (int i = 0; i < 20000; ++i) {
    const int count = 1 + static_cast<int>(rng() % mpeg4face::kMaxRawBits);
    const auto bits = static_cast<uint32_t>(rng() % (1u << count));
    symbols.emplace_back(bits, count);
    a.encodeBits(bits, count);
    b.encodeUniform(static_cast<int>(bits), 1 << count);
    const int s = static_cast<int>(rng() % 7);
    a.encode(s, modelA);
    b.encode(s, modelB);
  }
  a.flush();
  b.flush();
  EXPECT_EQ(raw.bytes(), uniform.bytes());
  BitReader r(raw.bytes());
  ArithmeticDecoder dec(r);
  AdaptiveModel model(7);
  for (const auto& [bits, count] : symbols) {
    ASSERT_EQ(dec.decodeBits(count), bits);
    dec.decode(model);
  }
  dec.finish("segment");
  EXPECT_EQ(r.position(), raw.bitCount());
}

TEST(AdaptiveModel, ResetRestoresCountsOfOne) {
  AdaptiveModel model(10);
  for (int i = 0; i < 100; ++i) model.update(3);
  EXPECT_EQ(model.count(3), 101u);
  model.reset();
  EXPECT_EQ(model.total(), 10u);
  EXPECT_EQ(model.count(3), 1u);
  EXPECT_EQ(model.countBelow(7), 7u);
  model.update(9);
  EXPECT_EQ(model.total(), 11u);
  EXPECT_EQ(model.countBelow(9), 9u);
  EXPECT_EQ(model.count(3), 1u);
}

TEST(ArithmeticCoder, StuffsAOneAfter22Zeros) {
  // The last symbol sits at the bottom of the interval, so coding it again and again writes
  // long runs of 0 bits.
  BitWriter w;
  w.writeBit(true);
  ArithmeticEncoder enc(w);
  AdaptiveModel model(2);
  const int kCount = 200000;
  for (int i = 0; i < kCount; ++i) enc.encode(1, model);
  enc.flush();

  const std::vector<bool> bits = bitsOf(w.bytes(), w.bitCount());
  int run = 0, longest = 0, stuffed = 0;
  for (bool b : bits) {
    if (!b && run == 22) ADD_FAILURE() << "23 zeros in a row";
    if (b && run == 22) ++stuffed;
    run = b ? 0 : run + 1;
    longest = std::max(longest, run);
  }
  EXPECT_EQ(longest, 22);
  EXPECT_GT(stuffed, 0);

  BitReader r(w.bytes());
  r.readBit("lead");
  ArithmeticDecoder dec(r);
  AdaptiveModel decModel(2);
  for (int i = 0; i < kCount; ++i) ASSERT_EQ(dec.decode(decModel), 1);
  dec.finish("segment");
  EXPECT_EQ(r.position(), w.bitCount());
}

TEST(ArithmeticCoder, TruncatedSegmentIsAnError) {
  std::mt19937 rng(1);
  BitWriter w;
  w.writeBits(0x5, 3);
  ArithmeticEncoder enc(w);
  AdaptiveModel model(50);
  const std::vector<int> symbols = skewedSymbols(rng, 50, 300);
  for (int x : symbols) enc.encode(x, model);
  enc.flush();
  std::vector<uint8_t> bytes = w.bytes();
  bytes.resize(bytes.size() / 2);

  BitReader r(bytes, "cut.fba");
  r.readBits(3, "x");
  ArithmeticDecoder dec(r);
  AdaptiveModel decModel(50);
  for (size_t i = 0; i < symbols.size(); ++i) dec.decode(decModel);  // reads zeros past the end
  const Error e = errorOf([&] { dec.finish("low-level FAP data"); });
  EXPECT_EQ(e.field(), "low-level FAP data");
  EXPECT_TRUE(contains(e, "at bit 3 ")) << e.what();
  EXPECT_TRUE(contains(e, "runs past the end")) << e.what();
}

TEST(ArithmeticCoder, MissingStuffedOneIsAnError) {
  // 64 zero bytes: decoding keeps picking the bottom symbol of a wide model and reads far
  // past 22 zeros, where a valid segment would have a stuffed 1.
  const std::vector<uint8_t> zeros(64, 0);
  BitReader r(zeros);
  ArithmeticDecoder dec(r);
  AdaptiveModel model(256);
  for (int i = 0; i < 20; ++i) dec.decode(model);
  const Error e = errorOf([&] { dec.finish("segment"); });
  EXPECT_TRUE(contains(e, "at bit 22 ")) << e.what();
  EXPECT_TRUE(contains(e, "stuffed 1")) << e.what();
}

// ---- Efficiency: bits spent against the model's own ideal code length.

struct Efficiency {
  double idealBits = 0;
  uint64_t actualBits = 0;
  size_t symbols = 0;
  double overheadPerSymbol() const {
    return (static_cast<double>(actualBits) - idealBits) / static_cast<double>(symbols);
  }
};

Efficiency measure(const std::vector<int>& symbols, int n) {
  Efficiency eff;
  BitWriter w;
  ArithmeticEncoder enc(w);
  AdaptiveModel model(n);
  for (int x : symbols) {
    eff.idealBits += model.idealBits(x);
    enc.encode(x, model);
  }
  enc.flush();
  eff.actualBits = w.bitCount();
  eff.symbols = symbols.size();
  return eff;
}

TEST(ArithmeticCoder, SpendsAtMostAHundredthOfABitPerSymbolOverTheModel) {
  std::mt19937 rng(2024);
  const size_t kCount = 1000000;
  std::vector<std::pair<std::string, Efficiency>> cases;
  cases.emplace_back("geometric over 32", measure(skewedSymbols(rng, 32, kCount), 32));
  {
    std::vector<int> s;
    for (size_t i = 0; i < kCount; ++i) s.push_back(static_cast<int>(rng() % 256));
    cases.emplace_back("uniform over 256", measure(s, 256));
  }
  {
    std::vector<int> s;
    for (size_t i = 0; i < kCount; ++i) s.push_back(rng() % 50 == 0 ? 1 : 0);
    cases.emplace_back("binary p=0.02", measure(s, 2));
  }
  {
    // FAP-like: quantised differences of a slow random walk, centred in a 121-symbol range.
    std::normal_distribution<double> d(0.0, 3.0);
    std::vector<int> s;
    for (size_t i = 0; i < kCount; ++i) {
      s.push_back(std::clamp(60 + static_cast<int>(std::lround(d(rng))), 0, 120));
    }
    cases.emplace_back("gaussian over 121", measure(s, 121));
  }
  {
    // The DCT mode's raw bits (B(n), docs/dct-mode.md): n bits cost n bits ideally.
    Efficiency eff;
    BitWriter w;
    ArithmeticEncoder enc(w);
    for (size_t i = 0; i < kCount; ++i) {
      const int count = 1 + static_cast<int>(rng() % mpeg4face::kMaxRawBits);
      enc.encodeBits(static_cast<uint32_t>(rng() % (1u << count)), count);
      eff.idealBits += count;
    }
    enc.flush();
    eff.actualBits = w.bitCount();
    eff.symbols = kCount;
    cases.emplace_back("raw 1..8 bits", eff);
  }
  {
    // The DCT mode's adaptive binary contexts: ideal = -log2 of each context's probability
    // before the bit (exact, not BinaryContext::idealBits's table), over bits of three sources.
    Efficiency eff;
    BitWriter w;
    ArithmeticEncoder enc(w);
    std::array<mpeg4face::BinaryContext, 3> contexts{};
    for (size_t i = 0; i < kCount; ++i) {
      const size_t c = i % 3;
      const bool bit = rng() % 1000 < std::array{20u, 500u, 900u}[c];
      const double p = contexts[c].zero / 4096.0;
      eff.idealBits -= std::log2(bit ? 1 - p : p);
      enc.encodeBit(bit, contexts[c]);
    }
    enc.flush();
    eff.actualBits = w.bitCount();
    eff.symbols = kCount;
    cases.emplace_back("binary contexts", eff);
  }
  for (const auto& [name, eff] : cases) {
    std::printf("%-20s ideal %.4f bit/symbol, actual %.4f, overhead %+.6f\n", name.c_str(),
                eff.idealBits / static_cast<double>(eff.symbols),
                static_cast<double>(eff.actualBits) / static_cast<double>(eff.symbols),
                eff.overheadPerSymbol());
    EXPECT_LE(eff.overheadPerSymbol(), 0.01) << name;
    EXPECT_GE(eff.overheadPerSymbol(), -0.001) << name;  // no coder beats its model
  }
}

// BinaryContext: starts at 1/2, moves 1/16 of the way towards each bit, never reaches 0 or 1;
// the decoder gives back every bit.
TEST(BinaryContext, AdaptsAndRoundTrips) {
  mpeg4face::BinaryContext c;
  EXPECT_EQ(c.zero, 2048);
  c.update(false);
  EXPECT_EQ(c.zero, 2048 + 128);
  c.update(true);
  EXPECT_EQ(c.zero, 2176 - 136);
  for (int i = 0; i < 1000; ++i) c.update(true);
  EXPECT_EQ(c.zero, 15);
  for (int i = 0; i < 1000; ++i) c.update(false);
  EXPECT_EQ(c.zero, 4081);
  EXPECT_NEAR(c.idealBits(false), -std::log2(4081 / 4096.0), 0.01);

  std::mt19937 rng(7);
  std::vector<bool> bits;
  for (int i = 0; i < 200000; ++i) bits.push_back(rng() % 100 < (i / 1000 % 2 ? 3u : 60u));
  BitWriter w;
  {
    ArithmeticEncoder enc(w);
    std::array<mpeg4face::BinaryContext, 2> contexts{};
    for (size_t i = 0; i < bits.size(); ++i) {
      enc.encodeBit(bits[i], contexts[i % 2]);
      if (i % 7 == 0) enc.encodeBits(static_cast<uint32_t>(i % 2), 1);  // bypass bits between
    }
    enc.flush();
  }
  w.writeBits(0x5A, 8);  // a plain field after the segment
  const std::vector<uint8_t> bytes = w.bytes();
  BitReader r(bytes);
  ArithmeticDecoder dec(r);
  std::array<mpeg4face::BinaryContext, 2> contexts{};
  for (size_t i = 0; i < bits.size(); ++i) {
    ASSERT_EQ(dec.decodeBit(contexts[i % 2]), bits[i]) << i;
    if (i % 7 == 0) {
      ASSERT_EQ(dec.decodeBits(1), i % 2) << i;
    }
  }
  dec.finish("test");
  EXPECT_EQ(r.readBits(8, "field"), 0x5Au);
}

}  // namespace
