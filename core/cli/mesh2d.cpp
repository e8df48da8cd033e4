// SPDX-License-Identifier: GPL-3.0-or-later
// `mpeg4face mesh2d`: the 2D mesh object (docs/mesh2d.md): design a mesh on an image, track it
// through a video, code it as .m2d and back, render the warped texture, a talking portrait.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "commands.hpp"
#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"
#include "mpeg4face/io/read_any.hpp"
#include "mpeg4face/mesh2d/codec.hpp"
#include "mpeg4face/mesh2d/design.hpp"
#include "mpeg4face/mesh2d/json.hpp"
#include "mpeg4face/mesh2d/portrait.hpp"
#include "mpeg4face/mesh2d/render.hpp"
#include "mpeg4face/mesh2d/track.hpp"
#include "paths.hpp"

namespace mpeg4face::cli {
namespace {

// Options shared by the subcommands; each takes the ones it needs.
struct Args {
  std::vector<std::string> files;
  std::string output, mesh, mask, audio, featurePoints, tracks, m2d;
  int uniformCols = 0, uniformRows = 0, delaunay = 0, topology = 0;
  double step = 0.5, fps = 0;
};

Args parseArgs(const std::vector<std::string>& args, size_t first) {
  Args out;
  for (size_t i = first; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-o") {
      out.output = optionValue(args, i, "an output file");
    } else if (a == "--mesh") {
      out.mesh = optionValue(args, i, "a mesh .json");
    } else if (a == "--mask") {
      out.mask = optionValue(args, i, "a mask image");
    } else if (a == "--audio") {
      out.audio = optionValue(args, i, "an audio file");
    } else if (a == "--feature-points") {
      out.featurePoints = optionValue(args, i, "a CSV of fp,x,y");
    } else if (a == "--tracks") {
      out.tracks = optionValue(args, i, "a CSV of frame,fp,x,y");
    } else if (a == "--m2d") {
      out.m2d = optionValue(args, i, "an output .m2d");
    } else if (a == "--uniform") {
      const std::string& v = optionValue(args, i, "COLSxROWS");
      const size_t x = v.find('x');
      const auto cols = parseInt(v.substr(0, x)),
                 rows = x == v.npos ? std::nullopt : parseInt(v.substr(x + 1));
      if (!cols || !rows || *cols < 1 || *rows < 1 || *cols > 4096 || *rows > 4096) {
        throw UsageError("--uniform takes COLSxROWS cells, e.g. 16x12, not '" + v + "'");
      }
      out.uniformCols = *cols;
      out.uniformRows = *rows;
    } else if (a == "--delaunay") {
      out.delaunay = intArgument(args, i, 8, 65535);
    } else if (a == "--topology") {
      out.topology = intArgument(args, i, 0, 3);
    } else if (a == "--step") {
      out.step = numberArgument(args, i, "a step in pixels", 1.0 / 256);
    } else if (a == "--fps") {
      out.fps = numberArgument(args, i, "frames per second", 1);
    } else if (a.starts_with("-") && a != "-") {
      throw UsageError("unknown option '" + a + "'");
    } else {
      out.files.push_back(a);
    }
  }
  return out;
}

void needFiles(const Args& a, size_t count, const char* what) {
  if (a.files.size() != count) throw UsageError(std::string("needs ") + what);
  if (a.output.empty()) throw UsageError("needs -o OUTPUT");
}

void progress(size_t frame, size_t count) {
  if ((frame + 1) % 25 == 0 || frame + 1 == count) {
    std::fprintf(stderr, "\rframe %zu/%zu", frame + 1, count);
    if (frame + 1 == count) std::fprintf(stderr, "\n");
  }
}

// The texture the intra plane lies on: an image, or the first frame of a video or of a folder
// of frames (a tracked sequence's intra plane is its first frame).
Image readTexture(const std::string& path) {
  const std::string ext = extensionOf(path);
  if (std::filesystem::is_directory(path) || ext == ".mp4" || ext == ".avi" || ext == ".mov" ||
      ext == ".mkv" || ext == ".webm" || ext == ".m4v") {
    return readFrames(path, 1).front();
  }
  return readImage(path);
}

void render(const Image& image, const Mesh2dSequence& s, const Args& a, double fps) {
  Mesh2dVideoOptions options;
  options.fps = a.fps > 0 ? a.fps : fps;
  options.audio = a.audio;
  options.progress = progress;
  if (!a.audio.empty() && extensionOf(a.output) != ".mp4") {
    throw UsageError("--audio needs an .mp4 output");
  }
  renderMesh2d(image, s, a.output, options);
  std::printf("%s: %zu frames\n", a.output.c_str(), s.frames.size());
}

}  // namespace

int runMesh2d(const std::vector<std::string>& args) {
  if (args.empty())
    throw UsageError("needs a subcommand: design, track, encode, decode, render, portrait");
  const std::string& sub = args[0];
  const Args a = parseArgs(args, 1);
  if (sub == "design") {
    needFiles(a, 1, "one IMAGE");
    if ((a.uniformCols > 0) == (a.delaunay > 0))
      throw UsageError("needs --uniform COLSxROWS or --delaunay N");
    const Image image = readImage(a.files[0]);
    Mesh2dSequence s;
    if (a.uniformCols > 0) {
      if (!a.mask.empty()) throw UsageError("--mask goes with --delaunay");
      s = designUniformMesh2d(image.width, image.height, a.uniformCols, a.uniformRows, a.topology);
      s.triangles = meshTriangles(s);
    } else {
      const Image mask = a.mask.empty() ? Image() : readImage(a.mask);
      s = designDelaunayMesh2d(image, a.delaunay, a.mask.empty() ? nullptr : &mask);
    }
    writeMesh2dJson(a.output, s);
    std::printf("%s: %s mesh, %ld nodes, %ld triangles\n", a.output.c_str(),
                s.type == Mesh2dType::Uniform ? "uniform" : "delaunay",
                static_cast<long>(s.frames[0].rows()), static_cast<long>(s.triangles.rows()));
    return 0;
  }
  if (sub == "track") {
    needFiles(a, 1, "one VIDEO or FRAME_DIR");
    if (a.mesh.empty()) throw UsageError("needs --mesh MESH.json");
    const Mesh2dSequence mesh = readMesh2dJson(a.mesh);
    const std::vector<Image> frames = readFrames(a.files[0]);
    Mesh2dTrackOptions options;
    options.progress = progress;
    const Mesh2dSequence tracked = trackMesh2d(frames, mesh, options);
    writeMesh2dJson(a.output, tracked);
    std::printf("%s: %zu frames tracked\n", a.output.c_str(), tracked.frames.size());
    return 0;
  }
  if (sub == "encode") {
    needFiles(a, 1, "one SEQ.json");
    const Mesh2dSequence s = readMesh2dJson(a.files[0]);
    Mesh2dCodingStats stats;
    const std::vector<uint8_t> bytes = encodeMesh2d(s, a.step, nullptr, &stats);
    writeFileAtomically(a.output, std::string(bytes.begin(), bytes.end()));
    uint64_t inter = 0;
    for (uint64_t b : stats.interBits) inter += b;
    const double nodes = static_cast<double>(s.frames[0].rows());
    const double interFrames = static_cast<double>(stats.interBits.size());
    std::printf("%s: %llu bits (%zu bytes); intra plane %llu bits (%.2f bits/node)",
                a.output.c_str(), static_cast<unsigned long long>(stats.totalBits), bytes.size(),
                static_cast<unsigned long long>(stats.headerBits + stats.intraBits),
                static_cast<double>(stats.headerBits + stats.intraBits) / nodes);
    if (interFrames > 0) {
      std::printf("; motion %.2f bits/node/frame (raw float32 x, y: 64)",
                  static_cast<double>(inter) / (nodes * interFrames));
    }
    std::printf("\n");
    return 0;
  }
  if (sub == "decode") {
    needFiles(a, 1, "one IN.m2d");
    const std::string data = readFile(a.files[0]);
    const Mesh2dSequence s = decodeMesh2d(
        std::span(reinterpret_cast<const uint8_t*>(data.data()), data.size()), a.files[0]);
    writeMesh2dJson(a.output, s);
    std::printf("%s: %zu frames, %ld nodes\n", a.output.c_str(), s.frames.size(),
                static_cast<long>(s.frames[0].rows()));
    return 0;
  }
  if (sub == "render") {
    needFiles(a, 2, "IMAGE (or VIDEO or FRAME_DIR) and SEQ.json");
    const Image image = readTexture(a.files[0]);
    render(image, readMesh2dJson(a.files[1]), a, 25);
    return 0;
  }
  if (sub == "portrait") {
    needFiles(a, a.tracks.empty() ? 2 : 1,
              a.tracks.empty() ? "IMAGE and STREAM.fap (or --tracks)" : "IMAGE only with --tracks");
    if (a.featurePoints.empty()) throw UsageError("needs --feature-points FP.csv");
    const Image image = readImage(a.files[0]);
    const PortraitFeaturePoints points =
        parsePortraitFeaturePoints(readFile(a.featurePoints), a.featurePoints);
    Mesh2dSequence mesh;
    double fps = 25;
    if (a.tracks.empty()) {
      const FapStream stream = readFapStream(a.files[1]);
      mesh = portraitMesh2d(image.width, image.height, points, stream);
      fps = stream.frameRate;
    } else {
      mesh = portraitMesh2d(image.width, image.height, points,
                            parsePortraitTracks(readFile(a.tracks), points, a.tracks));
    }
    // Through the codec, as a receiver would get it.
    Mesh2dCodingStats stats;
    Mesh2dSequence decoded;
    const std::vector<uint8_t> bytes = encodeMesh2d(mesh, a.step, &decoded, &stats);
    if (!a.m2d.empty()) writeFileAtomically(a.m2d, std::string(bytes.begin(), bytes.end()));
    std::fprintf(stderr, "portrait: %ld nodes, %zu frames, coded in %llu bits\n",
                 static_cast<long>(mesh.frames[0].rows()), mesh.frames.size(),
                 static_cast<unsigned long long>(stats.totalBits));
    render(image, decoded, a, fps);
    return 0;
  }
  throw UsageError("unknown subcommand '" + sub + "'");
}

}  // namespace mpeg4face::cli
