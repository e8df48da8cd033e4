// SPDX-License-Identifier: GPL-3.0-or-later
// Image files with OpenCV's imgcodecs; video by piping raw frames into ffmpeg (posix_spawn,
// no shell).
#include "mpeg4face/mesh2d/render.hpp"

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <opencv2/imgcodecs.hpp>

#include "mpeg4face/error.hpp"
#include "mpeg4face/io/files.hpp"

extern char** environ;

namespace mpeg4face {
namespace {

std::string lowerExtension(const std::filesystem::path& path) {
  std::string e = path.extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

// Pipes frames into `ffmpeg` writing `part`; close() waits for it and checks its status.
class FfmpegPipe {
 public:
  FfmpegPipe(const std::vector<std::string>& argv, const std::string& what) : what_(what) {
    int fds[2];
    if (pipe(fds) != 0) throw Error(what_, 0, "ffmpeg", "cannot make a pipe");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
    posix_spawn_file_actions_addclose(&actions, fds[1]);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    const int status =
        posix_spawnp(&pid_, argv[0].c_str(), &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(fds[0]);
    if (status != 0) {
      close(fds[1]);
      throw Error(what_, 0, "ffmpeg",
                  std::string("cannot run ffmpeg (") + std::strerror(status) +
                      "): install Debian's ffmpeg package (scripts/setup.sh does)");
    }
    fd_ = fds[1];
  }
  ~FfmpegPipe() {
    if (fd_ >= 0) {
      close(fd_);
      wait();
    }
  }
  void write(const uint8_t* data, size_t size) {
    while (size > 0) {
      const ssize_t n = ::write(fd_, data, size);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw Error(what_, 0, "ffmpeg", "ffmpeg stopped reading frames");
      data += n;
      size -= static_cast<size_t>(n);
    }
  }
  void finish() {
    close(fd_);
    fd_ = -1;
    const int code = wait();
    if (!WIFEXITED(code) || WEXITSTATUS(code) != 0) {
      throw Error(what_, 0, "ffmpeg",
                  "ffmpeg failed (exit status " +
                      std::to_string(WIFEXITED(code) ? WEXITSTATUS(code) : -1) + ")");
    }
  }

 private:
  int wait() {
    int code = 0;
    while (waitpid(pid_, &code, 0) < 0 && errno == EINTR) {
    }
    return code;
  }
  std::string what_;
  pid_t pid_ = 0;
  int fd_ = -1;
};

// Removes a temporary file or folder unless kept.
struct RemoveOnFailure {
  std::filesystem::path path;
  bool keep = false;
  ~RemoveOnFailure() {
    std::error_code ignored;
    if (!keep) std::filesystem::remove_all(path, ignored);
  }
};

}  // namespace

Image readImage(const std::filesystem::path& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw Error(path.string(), 0, "image", "no such file");
  }
  const cv::Mat mat = cv::imread(path.string(), cv::IMREAD_COLOR);
  if (mat.empty()) {
    throw Error(path.string(), 0, "image", "does not load as an image (PNG, JPEG, ...)");
  }
  Image image(mat.cols, mat.rows, 3);
  for (int y = 0; y < mat.rows; ++y) {
    std::memcpy(image.row(y), mat.ptr(y), size_t(mat.cols) * 3);
  }
  return image;
}

void writeImage(const std::filesystem::path& path, const Image& image) {
  const int type = image.channels == 1 ? CV_8UC1 : image.channels == 3 ? CV_8UC3 : CV_8UC4;
  const cv::Mat mat(image.height, image.width, type, const_cast<uint8_t*>(image.pixels.data()));
  std::vector<uint8_t> bytes;
  if (!cv::imencode(lowerExtension(path), mat, bytes)) {
    throw Error(path.string(), 0, "image", "cannot encode an image of this type");
  }
  writeFileAtomically(path, std::string(bytes.begin(), bytes.end()));
}

Image renderMesh2dFrame(const Image& texture, const Mesh2dSequence& sequence, size_t frame) {
  if (texture.width != sequence.width || texture.height != sequence.height) {
    throw Error({}, 0, "image",
                "is " + std::to_string(texture.width) + "x" + std::to_string(texture.height) +
                    ", the mesh sequence's " + std::to_string(sequence.width) + "x" +
                    std::to_string(sequence.height));
  }
  Image out = texture;
  const Mesh2dTriangles triangles =
      sequence.triangles.rows() > 0 ? sequence.triangles : meshTriangles(sequence);
  warpMesh2d(texture, sequence.frames[0], sequence.frames.at(frame), triangles, out);
  return out;
}

void renderMesh2d(const Image& texture, const Mesh2dSequence& input,
                  const std::filesystem::path& out, const Mesh2dVideoOptions& options) {
  Mesh2dSequence sequence = input;
  if (sequence.triangles.rows() == 0) sequence.triangles = meshTriangles(sequence);
  renderMesh2dFrame(texture, sequence, 0);  // checks the sizes before anything is written
  const size_t count = sequence.frames.size();
  if (lowerExtension(out) == ".mp4") {
    std::filesystem::path part = out;
    part += ".part.mp4";
    RemoveOnFailure guard{part};
    char size[32], rate[32];
    std::snprintf(size, sizeof size, "%dx%d", texture.width, texture.height);
    std::snprintf(rate, sizeof rate, "%g", options.fps);
    std::vector<std::string> argv{"ffmpeg", "-v", "error", "-y", "-f", "rawvideo", "-pix_fmt",
                                  "bgr24",  "-s", size,    "-r", rate, "-i",       "-"};
    if (!options.audio.empty()) {
      if (!std::filesystem::is_regular_file(options.audio)) {
        throw Error(options.audio.string(), 0, "audio", "no such file");
      }
      argv.insert(argv.end(), {"-i", options.audio.string(), "-c:a", "aac"});
    }
    argv.insert(argv.end(), {"-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt",
                             "yuv420p", part.string()});
    signal(SIGPIPE, SIG_IGN);  // a failing ffmpeg is reported by write(), not a signal
    FfmpegPipe ffmpeg(argv, out.string());
    for (size_t f = 0; f < count; ++f) {
      const Image frame = renderMesh2dFrame(texture, sequence, f);
      ffmpeg.write(frame.pixels.data(), frame.pixels.size());
      if (options.progress) options.progress(f, count);
    }
    ffmpeg.finish();
    std::filesystem::rename(part, out);
    guard.keep = true;
    return;
  }
  std::filesystem::path part = out;
  part += ".part";
  std::filesystem::remove_all(part);
  std::filesystem::create_directories(part);
  RemoveOnFailure guard{part};
  for (size_t f = 0; f < count; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05zu.png", f);
    writeImage(part / name, renderMesh2dFrame(texture, sequence, f));
    if (options.progress) options.progress(f, count);
  }
  // Into OUT: earlier frames there are replaced, nothing else in it is touched.
  if (std::filesystem::exists(out) && !std::filesystem::is_directory(out)) {
    throw Error(out.string(), 0, "output", "exists and is not a folder");
  }
  std::filesystem::create_directories(out);
  for (const auto& entry : std::filesystem::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with("frame_") && name.ends_with(".png")) std::filesystem::remove(entry);
  }
  for (const auto& entry : std::filesystem::directory_iterator(part)) {
    std::filesystem::rename(entry.path(), out / entry.path().filename());
  }
}

}  // namespace mpeg4face
