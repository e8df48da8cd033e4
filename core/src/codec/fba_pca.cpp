// SPDX-License-Identifier: GPL-3.0-or-later
#include "codec/fba_pca.hpp"

#include <algorithm>
#include <bitset>
#include <cmath>
#include <string>

#include "codec/dct_transform.hpp"
#include "codec/fba_dct.hpp"
#include "codec/fba_predictive.hpp"
#include "mpeg4face/codec/pca.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/spec.hpp"

namespace mpeg4face {
namespace {

constexpr int kFirstPcaGroup = 2;  // group 1 is FAP 1 and 2, coded as they are

int quantStep(int fap) { return fapTable()[static_cast<size_t>(fap - 1)].quantStep; }

void checkPcaOptions(const FbaEncodeOptions& options) {
  if (options.pcaTemporal != FapCodingMode::Predictive &&
      options.pcaTemporal != FapCodingMode::Dct) {
    throw Error({}, 0, "pcaTemporal", "the components are coded by the predictive or DCT mode");
  }
  if (!(options.pcaEnergy > 0.0 && options.pcaEnergy <= 1.0)) {
    throw Error({}, 0, "pcaEnergy", std::to_string(options.pcaEnergy) + " is outside (0, 1]");
  }
  if (options.pcaBasisBits < 1 || options.pcaBasisBits > fba::kMaxPcaBasisBits) {
    throw Error({}, 0, "pcaBasisBits",
                std::to_string(options.pcaBasisBits) + " is outside 1.." +
                    std::to_string(fba::kMaxPcaBasisBits));
  }
}

// One group's analysis: the resolved values of its sent FAPs (rows: frames) and their KLT in
// quantiser steps (each FAP divided by its QP, so that a step weighs alike in every FAP).
struct GroupAnalysis {
  PcaGroup info;
  Eigen::MatrixXd values;  // FAPU
  Klt klt;                 // of values / QP
};

// The fewest components that leave no FAP of the group a residual variance above what the
// quantiser adds at fapQuant, relative to the FAP's range: (2^((fapQuant - 31) / 6))^2 / 12 of
// R_i^2, the DCT mode's step as a fraction of the range (docs/dct-mode.md). The energy rule
// alone drops the components of the FAPs that move least, which the robust PSNR weighs most:
// with it PCA reached 25 dB robust on no Xface stream at any fap_quant.
int componentsForResidual(const GroupAnalysis& a, int fapQuant) {
  const double relativeStep = std::exp2((fapQuant - 31) / 6.0);
  const double allowed = relativeStep * relativeStep / 12;
  const Eigen::Index m = a.values.cols();
  const Eigen::VectorXd range = a.values.colwise().maxCoeff() - a.values.colwise().minCoeff();
  for (Eigen::Index k = 0; k < m; ++k) {
    bool enough = true;
    for (Eigen::Index i = 0; enough && i < m; ++i) {
      // Variance of FAP i along the dropped axes, in FAPU^2 (the KLT is of values / QP_i).
      const double qp = quantStep(a.info.faps[static_cast<size_t>(i)]);
      double residual = 0;
      for (Eigen::Index j = k; j < m; ++j)
        residual += a.klt.eigenvalues(j) * std::pow(a.klt.axes(i, j) * qp, 2);
      enough = residual <= allowed * range(i) * range(i);
    }
    if (enough) return static_cast<int>(k);
  }
  return static_cast<int>(m);
}

std::vector<GroupAnalysis> analyse(std::span<const FapFrame> frames,
                                   const FbaEncodeOptions& options) {
  checkPcaOptions(options);
  std::bitset<kFapCount> sent;
  for (const FapFrame& f : frames) sent |= f.mask;
  std::vector<GroupAnalysis> groups;
  for (const FapGroupInfo& g : fapGroupTable()) {
    if (g.number < kFirstPcaGroup) continue;
    GroupAnalysis a;
    a.info.group = g.number;
    for (int fap = g.firstFap; fap <= g.lastFap; ++fap) {
      if (sent[static_cast<size_t>(fap - 1)]) a.info.faps.push_back(fap);
    }
    if (a.info.faps.empty()) continue;
    a.values.resize(static_cast<Eigen::Index>(frames.size()),
                    static_cast<Eigen::Index>(a.info.faps.size()));
    groups.push_back(std::move(a));
  }
  // The values a decoder holds after each frame (resolved one frame at a time: a stream of
  // states would be as large as the stream).
  FapState state;
  for (size_t t = 0; t < frames.size(); ++t) {
    applyFrame(state, frames[t]);
    for (GroupAnalysis& a : groups) {
      for (size_t i = 0; i < a.info.faps.size(); ++i) {
        a.values(static_cast<Eigen::Index>(t), static_cast<Eigen::Index>(i)) =
            state.value(a.info.faps[i]);
      }
    }
  }
  for (GroupAnalysis& a : groups) {
    Eigen::VectorXd perStep(static_cast<Eigen::Index>(a.info.faps.size()));
    for (size_t i = 0; i < a.info.faps.size(); ++i) {
      perStep(static_cast<Eigen::Index>(i)) = 1.0 / quantStep(a.info.faps[i]);
    }
    a.klt = computeKlt(a.values * perStep.asDiagonal());
    a.info.eigenvalues = a.klt.eigenvalues;
    a.info.components = std::max(
        componentsForEnergy(std::span<const double>(a.klt.eigenvalues.data(),
                                                    static_cast<size_t>(a.klt.eigenvalues.size())),
                            options.pcaEnergy),
        componentsForResidual(a, options.fapQuant));
  }
  return groups;
}

}  // namespace

Klt computeKlt(const Eigen::MatrixXd& samples) {
  Klt klt;
  const Eigen::Index m = samples.cols();
  klt.mean = samples.rows() > 0 ? Eigen::VectorXd(samples.colwise().mean().transpose())
                                : Eigen::VectorXd::Zero(m);
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(m, m);
  if (samples.rows() > 1) {
    const Eigen::MatrixXd centred = samples.rowwise() - klt.mean.transpose();
    covariance = centred.transpose() * centred / static_cast<double>(samples.rows() - 1);
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(covariance);
  // Eigen gives ascending order; Tao numbers them descending.
  klt.eigenvalues = solver.eigenvalues().reverse().cwiseMax(0.0);
  klt.axes = solver.eigenvectors().rowwise().reverse();
  return klt;
}

int componentsForEnergy(std::span<const double> eigenvalues, double energy) {
  double total = 0.0;
  for (const double l : eigenvalues) total += std::max(l, 0.0);
  if (!(total > 0.0)) return 0;
  double kept = 0.0;
  int k = 0;
  for (const double l : eigenvalues) {
    if (kept >= energy * total) break;
    kept += std::max(l, 0.0);
    ++k;
  }
  return k;
}

std::vector<PcaGroup> pcaGroups(const FapStream& stream, const FbaEncodeOptions& options) {
  std::vector<PcaGroup> groups;
  for (GroupAnalysis& a : analyse(stream.frames, options)) groups.push_back(std::move(a.info));
  return groups;
}

namespace fba {
namespace {

// The header's bits with kPcaStuffingRun stuffing.
class StuffedWriter {
 public:
  explicit StuffedWriter(BitWriter& out) : out_(out) {}
  void writeBit(bool bit) {
    out_.writeBit(bit);
    zeros_ = bit ? 0 : zeros_ + 1;
    if (zeros_ == kPcaStuffingRun) writeBit(true);
  }
  void writeBits(uint32_t value, int count) {
    for (int b = count - 1; b >= 0; --b) writeBit(((value >> b) & 1) != 0);
  }

 private:
  BitWriter& out_;
  int zeros_ = 0;
};

// Reads what StuffedWriter wrote, dropping its stuffing; or, with `stuffed` false, a header
// as written before issue 44, bit for bit.
class StuffedReader {
 public:
  // `zeros`: the zeros in a row just read.
  StuffedReader(BitReader& in, bool stuffed, int zeros)
      : in_(in), stuffed_(stuffed), zeros_(zeros) {}
  bool readBit(std::string_view element) {
    const bool bit = in_.readBit(element);
    zeros_ = bit ? 0 : zeros_ + 1;
    if (stuffed_ && zeros_ == kPcaStuffingRun && !readBit("pca_stuffing_bit")) {
      in_.failAt(in_.position() - 1, "pca_stuffing_bit",
                 "is 0 after " + std::to_string(kPcaStuffingRun) + " zeros (it must be 1)");
    }
    return bit;
  }
  uint32_t readBits(int count, std::string_view element) {
    uint32_t v = 0;
    for (int b = 0; b < count; ++b) v = (v << 1) | (readBit(element) ? 1 : 0);
    return v;
  }
  uint64_t position() const { return in_.position(); }
  [[noreturn]] void failAt(uint64_t position, std::string_view element, const std::string& what) {
    in_.failAt(position, element, what);
  }

 private:
  BitReader& in_;
  bool stuffed_;
  int zeros_;
};

void writeUe(StuffedWriter& out, uint64_t value) {
  // Exp-Golomb: n zeros, then the n + 1 bits of value + 1.
  const uint64_t v = value + 1;
  int n = 0;
  while ((v >> (n + 1)) != 0) ++n;
  for (int b = 0; b < n; ++b) out.writeBit(false);
  for (int b = n; b >= 0; --b) out.writeBit(((v >> b) & 1) != 0);
}

void writeSe(StuffedWriter& out, int64_t value) {
  // 0, 1, -1, 2, -2, ... as 0, 1, 2, 3, 4, ...
  writeUe(out,
          value > 0 ? 2 * static_cast<uint64_t>(value) - 1 : 2 * static_cast<uint64_t>(-value));
}

uint64_t readUe(StuffedReader& in, std::string_view element) {
  const uint64_t start = in.position();
  int n = 0;
  while (!in.readBit(element)) {
    if (++n > 40) in.failAt(start, element, "an Exp-Golomb code longer than 40 leading zeros");
  }
  uint64_t v = 1;
  for (int b = 0; b < n; ++b) v = (v << 1) | (in.readBit(element) ? 1 : 0);
  return v - 1;
}

int64_t readSe(StuffedReader& in, std::string_view element, int64_t bound) {
  const uint64_t start = in.position();
  const uint64_t code = readUe(in, element);
  const int64_t magnitude = static_cast<int64_t>((code + 1) / 2);
  if (magnitude > bound) {
    in.failAt(start, element, std::to_string(magnitude) + " exceeds " + std::to_string(bound));
  }
  return code % 2 == 1 ? magnitude : -magnitude;
}

const FapGroupInfo& groupInfo(int group) { return fapGroupTable()[static_cast<size_t>(group - 1)]; }

int64_t roundShift(int64_t x, int bits) {
  const int64_t half = int64_t{1} << (bits - 1);
  return x >= 0 ? (x + half) >> bits : -((-x + half) >> bits);
}

}  // namespace

int pcaComponentSlot(int group, int j) { return groupInfo(group).firstFap + j; }

void encodePca(std::span<const FapFrame> frames, const FbaEncodeOptions& options,
               const FrameRateCode& rate, EncodeOutput& output) {
  const std::vector<GroupAnalysis> groups = analyse(frames, options);
  const uint64_t headerStart = output.out.bitCount();
  PcaHeader header;
  header.basisBits = options.pcaBasisBits;
  const double scale = std::ldexp(1.0, options.pcaBasisBits);

  std::vector<FapFrame> components(frames.size());
  for (size_t t = 0; t < frames.size(); ++t) {
    components[t].number = frames[t].number;
    components[t].mask[0] = frames[t].mask[0];
    components[t].mask[1] = frames[t].mask[1];
    components[t].viseme = frames[t].viseme;
    components[t].expression = frames[t].expression;
  }
  for (const GroupAnalysis& a : groups) {
    PcaHeaderGroup& h = header.groups.emplace_back();
    h.group = a.info.group;
    h.faps = a.info.faps;
    const int k = a.info.components;
    const auto m = static_cast<Eigen::Index>(h.faps.size());
    h.components = k;
    // The decoder's basis: component j is sent in slot s_j in that slot's quantiser steps, so
    // the weighted axis u_ij becomes QP_i u_ij / QP(s_j) FAPU per slot unit.
    Eigen::MatrixXd basis(m, k);
    Eigen::VectorXd weight(m);
    for (Eigen::Index i = 0; i < m; ++i) {
      const int qp = quantStep(h.faps[static_cast<size_t>(i)]);
      weight(i) = 1.0 / qp;
      h.mean.push_back(std::llround(a.klt.mean(i) * qp));
      for (int j = 0; j < k; ++j) {
        const int64_t w =
            std::llround(scale * qp * a.klt.axes(i, j) / quantStep(pcaComponentSlot(h.group, j)));
        h.basis.push_back(w);
        basis(i, j) = static_cast<double>(w) / scale;
      }
    }
    if (k == 0) continue;
    // The components the decoder's (quantised) basis reproduces best, in the weighted norm:
    // the weighted basis's pseudo-inverse applied to every frame at once.
    const Eigen::MatrixXd project =
        Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(weight.asDiagonal() * basis)
            .pseudoInverse() *
        weight.asDiagonal();
    Eigen::VectorXd mean(m);
    for (Eigen::Index i = 0; i < m; ++i)
      mean(i) = static_cast<double>(h.mean[static_cast<size_t>(i)]);
    const Eigen::MatrixXd v = (a.values.rowwise() - mean.transpose()) * project.transpose();
    const int firstSlot = pcaComponentSlot(h.group, 0);
    for (size_t t = 0; t < frames.size(); ++t) {
      for (int j = 0; j < k; ++j) {
        const double r = std::round(v(static_cast<Eigen::Index>(t), j));
        const double c = std::clamp(r, double{-kDctMaxValue}, double{kDctMaxValue});
        if (c != r) ++output.stats.clippedValues;
        components[t].set(firstSlot + j, static_cast<int>(c));
      }
    }
  }

  output.out.writeStartCode(kPcaHeaderStartCode);
  StuffedWriter out(output.out);
  out.writeBits(kPcaHeaderStuffed, 4);
  out.writeBits(static_cast<uint32_t>(header.basisBits), 4);
  for (const FapGroupInfo& g : fapGroupTable()) {
    if (g.number < kFirstPcaGroup) continue;
    const auto h = std::find_if(header.groups.begin(), header.groups.end(),
                                [&](const PcaHeaderGroup& x) { return x.group == g.number; });
    for (int fap = g.firstFap; fap <= g.lastFap; ++fap) {
      out.writeBit(h != header.groups.end() &&
                   std::find(h->faps.begin(), h->faps.end(), fap) != h->faps.end());
    }
    if (h == header.groups.end()) continue;
    writeUe(out, static_cast<uint64_t>(h->components));
    for (const int64_t mean : h->mean) writeSe(out, mean);
    for (const int64_t w : h->basis) writeSe(out, w);
  }
  const uint64_t headerBits = output.out.bitCount() - headerStart;

  FbaEncodeOptions temporal = options;
  temporal.mode = options.pcaTemporal;
  FapStream decodedComponents;
  EncodeOutput componentOutput{output.out, output.stats, decodedComponents};
  if (options.pcaTemporal == FapCodingMode::Dct) {
    encodeDct(components, temporal, rate, componentOutput);
  } else {
    encodePredictive(components, temporal, rate, componentOutput);
  }
  if (!output.stats.frameBits.empty()) output.stats.frameBits.front() += headerBits;
  output.reconstruction.frames = reconstructPca(header, decodedComponents.frames, {});
}

PcaHeader readPcaHeader(BitReader& raw) {
  PcaHeader header;
  // pca_header_format 0; before issue 44 these 4 bits were pca_basis_bits (1..15).
  const uint32_t format = raw.readBits(4, "pca_header_format");
  const bool stuffed = format == kPcaHeaderStuffed;
  StuffedReader in(raw, stuffed, stuffed ? 4 : 0);
  header.basisBits = static_cast<int>(stuffed ? in.readBits(4, "pca_basis_bits") : format);
  if (header.basisBits < 1) in.failAt(in.position() - 4, "pca_basis_bits", "is 0 (1..15)");
  for (const FapGroupInfo& g : fapGroupTable()) {
    if (g.number < kFirstPcaGroup) continue;
    PcaHeaderGroup h;
    h.group = g.number;
    const std::string where = " (FAP group " + std::to_string(g.number) + ")";
    const std::string maskElement = "pca_fap_mask" + where;
    for (int fap = g.firstFap; fap <= g.lastFap; ++fap) {
      if (in.readBit(maskElement)) h.faps.push_back(fap);
    }
    if (h.faps.empty()) continue;
    const uint64_t at = in.position();
    const uint64_t k = readUe(in, "pca_components" + where);
    if (k > h.faps.size()) {
      in.failAt(at, "pca_components" + where,
                std::to_string(k) + " components of " + std::to_string(h.faps.size()) + " FAPs");
    }
    h.components = static_cast<int>(k);
    const std::string meanElement = "pca_mean" + where;
    for (size_t i = 0; i < h.faps.size(); ++i) {
      h.mean.push_back(readSe(in, meanElement, kMaxFbaValue));
    }
    const std::string basisElement = "pca_basis" + where;
    for (size_t i = 0; i < h.faps.size() * k; ++i) {
      h.basis.push_back(readSe(in, basisElement, kMaxPcaBasisEntry));
    }
    header.groups.push_back(std::move(h));
  }
  return header;
}

std::vector<FapFrame> reconstructPca(const PcaHeader& header, std::span<const FapFrame> components,
                                     std::string_view source) {
  std::bitset<kFapCount> slots;
  for (const PcaHeaderGroup& h : header.groups) {
    for (int j = 0; j < h.components; ++j) {
      slots.set(static_cast<size_t>(pcaComponentSlot(h.group, j) - 1));
    }
  }
  std::vector<FapFrame> frames(components.size());
  for (size_t t = 0; t < components.size(); ++t) {
    const FapFrame& c = components[t];
    FapFrame& f = frames[t];
    for (int fap = 3; fap <= kFapCount; ++fap) {
      if (c.has(fap) != slots[static_cast<size_t>(fap - 1)]) [[unlikely]] {
        throw Error(std::string(source), 0, "FAP " + std::to_string(fap),
                    "frame " + std::to_string(t) + " (number " + std::to_string(c.number) + "): " +
                        (c.has(fap) ? "sent, but it carries no PCA component"
                                    : "carries a PCA component and is not sent"));
      }
    }
    f.number = c.number;
    f.mask[0] = c.mask[0];
    f.mask[1] = c.mask[1];
    f.viseme = c.viseme;
    f.expression = c.expression;
    for (const PcaHeaderGroup& h : header.groups) {
      const size_t k = static_cast<size_t>(h.components);
      const int firstSlot = pcaComponentSlot(h.group, 0);
      for (size_t i = 0; i < h.faps.size(); ++i) {
        int64_t sum = 0;
        for (size_t j = 0; j < k; ++j) {
          sum += h.basis[i * k + j] * c.value(firstSlot + static_cast<int>(j));
        }
        const int64_t x = h.mean[i] + roundShift(sum, header.basisBits);
        f.set(h.faps[i], static_cast<int>(std::clamp<int64_t>(x, -kMaxFbaValue, kMaxFbaValue)));
      }
    }
  }
  return frames;
}

}  // namespace fba
}  // namespace mpeg4face
