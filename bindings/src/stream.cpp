// SPDX-License-Identifier: GPL-3.0-or-later
// FAP streams and their coding: FapStream with numpy arrays in and out (one row per frame,
// one column per FAP), .fap files, the FBA codec, PSNR, and text to speech. Unlike the model
// classes, FapStream wraps the core struct itself: its arrays are new copies on every read,
// and a stream is changed as a whole (FapStream.from_arrays).
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>

#include "bindings.hpp"
#include "mpeg4face/codec/fba_codec.hpp"
#include "mpeg4face/codec/measure.hpp"
#include "mpeg4face/codec/rd.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/fap_file.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "mpeg4face/speech/speech.hpp"
#include "mpeg4face/stream/fap_stream.hpp"

namespace mpeg4face::python {
namespace {

using namespace pybind11::literals;
using Path = std::filesystem::path;

constexpr py::ssize_t kFaps = kFapCount;

// A new (rows, columns) array, zeroed, each row then filled by `row(i, pointer to the row)`.
template <typename T, typename Row>
py::array_t<T> rowsOf(std::size_t rows, py::ssize_t columns, Row row) {
  py::array_t<T> out({static_cast<py::ssize_t>(rows), columns});
  auto view = out.template mutable_unchecked<2>();
  for (std::size_t i = 0; i < rows; ++i) {
    for (py::ssize_t c = 0; c < columns; ++c) view(static_cast<py::ssize_t>(i), c) = T{};
    row(i, &view(static_cast<py::ssize_t>(i), 0));
  }
  return out;
}

// `value` as an int array of shape (rows, columns), or ValueError naming `field`.
py::array_t<int64_t> intRows(py::handle value, const std::string& field, py::ssize_t rows,
                             py::ssize_t columns) {
  py::array_t<int64_t, py::array::c_style | py::array::forcecast> a;
  try {
    a = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(value);
  } catch (const py::error_already_set&) {
  }
  if (!a || a.ndim() != 2 || a.shape(0) != rows || a.shape(1) != columns) {
    throw py::value_error(field + ": expected an array of shape (" + std::to_string(rows) + ", " +
                          std::to_string(columns) + ")");
  }
  return a;
}

int fitsInt(int64_t v, const std::string& field) {
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
    throw py::value_error(field + ": " + std::to_string(v) + " does not fit an int");
  }
  return static_cast<int>(v);
}

FapStream fromArrays(py::handle numbers, py::handle mask, py::handle values, py::handle visemes,
                     py::handle expressions, double frameRate, std::string name) {
  const py::array_t<int32_t> n = checkedIndices(numbers, "frame_numbers");
  const auto frames = n.shape(0);
  const auto m = py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(mask);
  if (!m || m.ndim() != 2 || m.shape(0) != frames || m.shape(1) != kFaps) {
    throw py::value_error("mask: expected a boolean array of shape (" + std::to_string(frames) +
                          ", 68)");
  }
  const auto v = intRows(values, "values", frames, kFaps);
  std::optional<py::array_t<int64_t>> vis, expr;
  if (!visemes.is_none()) vis = intRows(visemes, "visemes", frames, 4);
  if (!expressions.is_none()) expr = intRows(expressions, "expressions", frames, 6);
  FapStream stream;
  stream.name = std::move(name);
  stream.frameRate = frameRate;
  const auto nv = n.unchecked<1>();
  const auto mv = m.unchecked<2>();
  const auto vv = v.unchecked<2>();
  for (py::ssize_t i = 0; i < frames; ++i) {
    const std::string row = "[" + std::to_string(i) + "]";
    FapFrame& f = stream.frames.emplace_back();
    f.number = nv(i);
    for (py::ssize_t fap = 0; fap < kFaps; ++fap) {
      if (!mv(i, fap)) continue;
      f.mask.set(static_cast<std::size_t>(fap));
      if (fap >= 2) f.values[static_cast<std::size_t>(fap)] = fitsInt(vv(i, fap), "values" + row);
    }
    if (f.has(1)) {
      if (!vis) throw py::value_error("visemes: needed, since mask sets FAP 1 (column 0)");
      const auto x = vis->unchecked<2>();
      f.viseme = {fitsInt(x(i, 0), "visemes" + row), fitsInt(x(i, 1), "visemes" + row),
                  fitsInt(x(i, 2), "visemes" + row), x(i, 3) != 0};
    }
    if (f.has(2)) {
      if (!expr) throw py::value_error("expressions: needed, since mask sets FAP 2 (column 1)");
      const auto x = expr->unchecked<2>();
      f.expression = {fitsInt(x(i, 0), "expressions" + row),
                      fitsInt(x(i, 1), "expressions" + row),
                      fitsInt(x(i, 2), "expressions" + row),
                      fitsInt(x(i, 3), "expressions" + row),
                      x(i, 4) != 0,
                      x(i, 5) != 0};
    }
  }
  return stream;
}

void fillViseme(const Viseme& v, int32_t* row) {
  row[0] = v.select1, row[1] = v.select2, row[2] = v.blend, row[3] = v.def;
}
void fillExpression(const Expression& e, int32_t* row) {
  row[0] = e.select1, row[1] = e.intensity1, row[2] = e.select2, row[3] = e.intensity2;
  row[4] = e.initFace, row[5] = e.def;
}

py::object psnrOrNone(const std::optional<double>& db) {
  return db ? py::object(py::float_(*db)) : py::object(py::none());
}

struct PyEncoding {
  py::bytes data;
  FbaEncoding encoding;  // bytes left empty: `data` holds them
  double bitsPerSecond = 0;
  std::optional<double> psnr;
  std::optional<double> robustPsnr;
};

void bindFapStream(py::module_& m) {
  py::class_<FapStream> cls(
      m, "FapStream",
      "A stream of Face Animation Parameters as a .fap file or an FBA bitstream carries it: "
      "frames that send some FAPs each.\n\n"
      "Array properties are new numpy arrays, one row per frame: frame_numbers (N,), mask (N, "
      "68) bool (column i is FAP i + 1), values (N, 68) int32 in FAPU (columns 0, 1 unused), "
      "visemes (N, 4) (select1, select2, blend, def) and expressions (N, 6) (select1, "
      "intensity1, select2, intensity2, init_face, def). resolved() gives what a decoder "
      "animates with.");
  cls.def(py::init<>());
  cls.def_static("from_arrays", &fromArrays, "frame_numbers"_a, "mask"_a, "values"_a,
                 "visemes"_a = py::none(), "expressions"_a = py::none(), "frame_rate"_a = 25.0,
                 "name"_a = "",
                 "A stream from arrays shaped as the properties (visemes / expressions needed "
                 "where mask sets FAP 1 / 2).");
  cls.def_property(
      "name", [](const FapStream& s) { return toPy(s.name); },
      [](FapStream& s, std::string v) { s.name = std::move(v); }, "The .fap header's name.");
  cls.def_readwrite("frame_rate", &FapStream::frameRate, "Frames per second.");
  cls.def_property_readonly(
      "duration", [](const FapStream& s) { return streamDuration(s); },
      "Seconds from the first frame number to one past the last (skipped numbers count).");
  cls.def("__len__", [](const FapStream& s) { return s.frames.size(); });
  cls.def_property_readonly("frame_numbers", [](const FapStream& s) {
    py::array_t<int32_t> out(static_cast<py::ssize_t>(s.frames.size()));
    for (std::size_t i = 0; i < s.frames.size(); ++i) out.mutable_at(i) = s.frames[i].number;
    return out;
  });
  cls.def_property_readonly("mask", [](const FapStream& s) {
    return rowsOf<bool>(s.frames.size(), kFaps, [&](std::size_t i, bool* row) {
      for (int f = 0; f < kFapCount; ++f) row[f] = s.frames[i].mask[static_cast<std::size_t>(f)];
    });
  });
  cls.def_property_readonly("values", [](const FapStream& s) {
    return rowsOf<int32_t>(s.frames.size(), kFaps, [&](std::size_t i, int32_t* row) {
      for (int f = 2; f < kFapCount; ++f) {
        if (s.frames[i].mask[static_cast<std::size_t>(f)])
          row[f] = s.frames[i].values[static_cast<std::size_t>(f)];
      }
    });
  });
  cls.def_property_readonly("visemes", [](const FapStream& s) {
    return rowsOf<int32_t>(s.frames.size(), 4, [&](std::size_t i, int32_t* row) {
      fillViseme(s.frames[i].viseme, row);
    });
  });
  cls.def_property_readonly("expressions", [](const FapStream& s) {
    return rowsOf<int32_t>(s.frames.size(), 6, [&](std::size_t i, int32_t* row) {
      fillExpression(s.frames[i].expression, row);
    });
  });
  cls.def(
      "resolved",
      [](const FapStream& s) {
        const std::vector<FapState> states = resolveFapStream(s);
        py::dict out;
        py::array_t<int32_t> numbers(static_cast<py::ssize_t>(states.size()));
        for (std::size_t i = 0; i < states.size(); ++i) numbers.mutable_at(i) = states[i].number;
        out["frame_numbers"] = numbers;
        out["active"] = rowsOf<bool>(states.size(), kFaps, [&](std::size_t i, bool* row) {
          for (int f = 0; f < kFapCount; ++f) row[f] = states[i].mask[static_cast<std::size_t>(f)];
        });
        out["values"] = rowsOf<int32_t>(states.size(), kFaps, [&](std::size_t i, int32_t* row) {
          for (int f = 2; f < kFapCount; ++f)
            row[f] = states[i].values[static_cast<std::size_t>(f)];
        });
        out["visemes"] = rowsOf<int32_t>(states.size(), 4, [&](std::size_t i, int32_t* row) {
          fillViseme(states[i].viseme, row);
        });
        out["expressions"] = rowsOf<int32_t>(states.size(), 6, [&](std::size_t i, int32_t* row) {
          fillExpression(states[i].expression, row);
        });
        return out;
      },
      "What a decoder animates with after each frame (docs/fap-format.md, Resolution): a dict "
      "of frame_numbers, active (N, 68) bool (sent so far, or mirrored from its left/right "
      "partner), values, visemes and expressions, each FAP holding its last value.");
  cls.def("__eq__", [](const FapStream& a, const FapStream& b) { return a == b; });
  cls.def("__repr__", [](const FapStream& s) {
    char rate[32];
    std::snprintf(rate, sizeof rate, "%g", s.frameRate);
    return "<FapStream '" + std::string(toPy(s.name)) + "': " + std::to_string(s.frames.size()) +
           " frames at " + rate + " Hz>";
  });
}

void bindCodec(py::module_& m) {
  py::class_<PyEncoding> enc(m, "FbaEncoding", "An encoded FBA bitstream and what it costs.");
  enc.def_readonly("data", &PyEncoding::data, "The bitstream (bytes), as a .fba file holds it.");
  enc.def_property_readonly(
      "bits", [](const PyEncoding& e) { return e.encoding.stats.bits; },
      "Bits of the whole stream, start and end codes included.");
  enc.def_readonly("bits_per_second", &PyEncoding::bitsPerSecond);
  enc.def_property_readonly(
      "psnr", [](const PyEncoding& e) { return psnrOrNone(e.psnr); },
      "PSNR in dB of the decoded stream against the input (Tao et al. eq. 8): inf when exact, "
      "None when no FAP varies.");
  enc.def_property_readonly(
      "robust_psnr", [](const PyEncoding& e) { return psnrOrNone(e.robustPsnr); },
      "The robust PSNR in dB, 10 log10(1 / mean MSE_i/R_i^2) over the FAPs that move "
      "(docs/rate-distortion.md): inf only when all are exact, None when no FAP varies.");
  enc.def_property_readonly("intra_frames",
                            [](const PyEncoding& e) { return e.encoding.stats.intraFrames; });
  enc.def_property_readonly(
      "reconstruction", [](const PyEncoding& e) { return e.encoding.reconstruction; },
      "What a decoder gets back (decode_fba(data)).");
  enc.def("__repr__", [](const PyEncoding& e) {
    return "<FbaEncoding " + std::to_string(e.encoding.stats.bits) + " bits>";
  });

  m.def(
      "encode_fba",
      [](const FapStream& stream, const std::string& mode, int fapQuant, int intraPeriod,
         const std::string& pcaTemporal, int pcaBasisBits, double rdoLambda) {
        FbaEncodeOptions options;
        const auto parsed = parseCodingMode(mode);
        const auto temporal = parseCodingMode(pcaTemporal);
        if (!parsed) throw py::value_error("unknown mode '" + mode + "' (predictive, dct, pca)");
        if (!temporal || *temporal == FapCodingMode::Pca) {
          throw py::value_error("pca_temporal must be predictive or dct, not '" + pcaTemporal +
                                "'");
        }
        options.mode = *parsed;
        options.fapQuant = fapQuant;
        options.intraPeriod = intraPeriod;
        options.pcaTemporal = *temporal;
        options.pcaBasisBits = pcaBasisBits;
        options.rdoLambda = rdoLambda;
        PyEncoding out;
        std::string bytes;
        {
          py::gil_scoped_release release;
          out.encoding = encodeFba(stream, options);
          bytes.assign(out.encoding.bytes.begin(), out.encoding.bytes.end());
          out.encoding.bytes.clear();
          const FapComparison quality = compareFapStreams(
              stream, comparableReconstruction(stream, out.encoding.reconstruction));
          out.psnr = quality.psnr;
          out.robustPsnr = quality.robustPsnr;
          out.bitsPerSecond =
              stream.frames.empty()
                  ? 0.0
                  : bitsPerSecond(static_cast<double>(out.encoding.stats.bits), stream);
        }
        out.data = py::bytes(bytes);
        return out;
      },
      "stream"_a, "mode"_a = "predictive", "fap_quant"_a = 1, "intra_period"_a = 0,
      "pca_temporal"_a = "predictive", "pca_basis_bits"_a = 4, "rdo_lambda"_a = 0.0,
      "Codes a stream as an MPEG-4 FBA bitstream (docs/bitstream.md; dct and pca are the "
      "project's own modes). fap_quant 0..31 (0: lossless, predictive only). rdo_lambda > 0: "
      "RDO quantisation of predictive values (docs/rate-distortion.md).");
  m.def(
      "decode_fba",
      [](const py::bytes& data, const std::string& source, bool strict) {
        const std::string bytes = data;
        py::gil_scoped_release release;
        FbaDecodeLimits limits;
        limits.strict = strict;
        return decodeFba({reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()}, source,
                         limits);
      },
      "data"_a, "source"_a = "", "strict"_a = false,
      "Decodes an FBA bitstream; errors name `source`. strict: read as 14496-2's syntax "
      "reads, as a standard decoder does (docs/bitstream.md, \"Strict decoding\").");
  m.def(
      "psnr",
      [](const FapStream& original, const FapStream& decoded) {
        return psnrOrNone(compareFapStreams(original, decoded).psnr);
      },
      "original"_a, "decoded"_a,
      "PSNR in dB of a decoded stream against its original (Tao et al. eq. 8; same frames "
      "needed): inf when exact, None when no FAP varies.");
  m.def(
      "robust_psnr",
      [](const FapStream& original, const FapStream& decoded) {
        return psnrOrNone(compareFapStreams(original, decoded).robustPsnr);
      },
      "original"_a, "decoded"_a,
      "The robust PSNR in dB, 10 log10(1 / mean MSE_i/R_i^2) over the FAPs that move "
      "(docs/rate-distortion.md; same frames needed): inf only when every FAP is exact, None "
      "when no FAP varies.");
}

void bindFiles(py::module_& m) {
  m.def("read_fap", &readFapFile, "path"_a, "Reads a .fap file (versions 2.0 to 2.2).",
        py::call_guard<py::gil_scoped_release>());
  m.def(
      "write_fap", [](const FapStream& stream, const Path& path) { writeFapFile(path, stream); },
      "stream"_a, "path"_a, "Writes a .fap file (through a temporary file: all or nothing).",
      py::call_guard<py::gil_scoped_release>());
  m.def("read_fap_stream", &readFapStream, "path"_a,
        "Reads a .fap file or decodes a .fba file (named after the file).",
        py::call_guard<py::gil_scoped_release>());
  m.def(
      "write_file_atomically",
      [](const Path& path, const py::bytes& data) {
        std::string contents = data;
        py::gil_scoped_release release;
        writeFileAtomically(path, contents);
      },
      "path"_a, "data"_a,
      "Writes bytes (e.g. FbaEncoding.data) through a temporary file beside `path` and a "
      "rename, as the core writes its files: a failure leaves `path` as it was.");
}

void bindSpeech(py::module_& m) {
  m.def(
      "speak",
      [](const std::string& text, const Path& audio, double frameRate, const std::string& voice,
         double transition, const std::string& program) {
        py::gil_scoped_release release;
        return speak(text, FlitePhonemeSource(program, voice), audio, frameRate,
                     VisemeOptions{transition});
      },
      "text"_a, "audio"_a, "frame_rate"_a = 25.0, "voice"_a = "", "transition"_a = 0.08,
      "program"_a = "flite",
      "Text with bookmarks such as <FAP 2 1 40 0 0 800 3> to a FAP stream; flite speaks it "
      "into the .wav `audio`, frame n playing at n / frame_rate seconds into it "
      "(docs/speech.md).");
}

}  // namespace

void bindStream(py::module_& m) {
  bindFapStream(m);
  bindCodec(m);
  bindFiles(m);
  bindSpeech(m);
}

}  // namespace mpeg4face::python
