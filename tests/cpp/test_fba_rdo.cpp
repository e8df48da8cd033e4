// SPDX-License-Identifier: GPL-3.0-or-later
// The predictive encoder's RDO quantisation (FbaEncodeOptions::rdoLambda, issue 20 part 2):
// the standard syntax only, so the ordinary decoder reads every encoding back to the encoder's
// reconstruction; it spends fewer bits than the nearest-level encoder at the same fap_quant;
// and lambda 0 is today's encoder (test_fba_codec pins its bytes). The saving at equal robust
// PSNR is bench/bench_codec_rd's.
#include <gtest/gtest.h>

#include <string>

#include "mpeg4face/error.hpp"
#include "mpeg4face/fap_file.hpp"
#include "mpeg4face/fap_measure.hpp"
#include "mpeg4face/fap_rd.hpp"
#include "mpeg4face/fba_codec.hpp"
#include "test_support.hpp"

namespace {

using mpeg4face::FbaEncodeOptions;

TEST(FbaRdo, DecodesToTheReconstructionAndSpendsFewerBits) {
  for (const char* name : {"joy", "disgust", "test"}) {
    const auto stream =
        mpeg4face::readFapFile(mpeg4face::test::kData / "xface-fap" / (std::string(name) + ".fap"));
    for (const int q : {0, 2, 8}) {
      const auto plain = mpeg4face::encodeFba(stream, {.fapQuant = q});
      for (const double lambda : {1e-3, 5e-3}) {
        const FbaEncodeOptions options{.fapQuant = q, .rdoLambda = lambda};
        const auto rdo = mpeg4face::encodeFba(stream, options);
        EXPECT_EQ(mpeg4face::decodeFba(rdo.bytes), rdo.reconstruction) << name << " q" << q;
        EXPECT_LT(rdo.stats.bits, plain.stats.bits) << name << " q" << q << " " << lambda;
        // Clipped are only values no range code reaches, as without RDO (where RDO keeps a
        // value out of a range it chose, that is its decision); the loops differ a little.
        EXPECT_LE(rdo.stats.clippedValues,
                  plain.stats.clippedValues + mpeg4face::fapSampleCount(stream) / 100)
            << name << " q" << q;
        // A larger lambda trades quality for bits, but the motion stays: the robust PSNR
        // stays above 15 dB.
        const auto c = mpeg4face::compareFapStreams(
            stream, mpeg4face::comparableReconstruction(stream, rdo.reconstruction));
        ASSERT_TRUE(c.robustPsnr) << name;
        EXPECT_GT(*c.robustPsnr, 15.0) << name << " q" << q << " " << lambda;
      }
    }
  }
}

TEST(FbaRdo, PcaPredictiveComponentsTakeItToo) {
  const auto stream = mpeg4face::readFapFile(mpeg4face::test::kData / "xface-fap/joy.fap");
  FbaEncodeOptions options{.mode = mpeg4face::FapCodingMode::Pca, .fapQuant = 4};
  const auto plain = mpeg4face::encodeFba(stream, options);
  options.rdoLambda = 2e-3;
  const auto rdo = mpeg4face::encodeFba(stream, options);
  EXPECT_EQ(mpeg4face::decodeFba(rdo.bytes), rdo.reconstruction);
  EXPECT_LE(rdo.stats.bits, plain.stats.bits);
}

TEST(FbaRdo, BadLambda) {
  const auto stream = mpeg4face::readFapFile(mpeg4face::test::kData / "xface-fap/joy.fap");
  EXPECT_THROW(mpeg4face::encodeFba(stream, {.rdoLambda = -1.0}), mpeg4face::Error);
  const auto r = mpeg4face::test::runCli(
      "encode " + (mpeg4face::test::kData / "xface-fap/joy.fap").string() + " -o " +
      (mpeg4face::test::scratchDir() / "x.fba").string() + " --rdo-lambda x");
  EXPECT_EQ(r.status, 2) << r.out;
}

}  // namespace
