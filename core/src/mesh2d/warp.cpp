// SPDX-License-Identifier: GPL-3.0-or-later
// Triangle-by-triangle affine texture warping: a span per row, the source position stepped
// along it, a bilinear sample in 8.8 fixed point weights.
#include "mpeg4face/mesh2d/warp.hpp"

#include <algorithm>
#include <cmath>

#include "mpeg4face/error.hpp"

namespace mpeg4face {
namespace {

template <int Channels>
void fillTriangle(const Image& texture, const Eigen::Vector2d (&p)[3],
                  const Eigen::Vector2d (&s)[3], Image& out) {
  // The affine map current -> texture: s = s0 + (x - p0) * ax + (y - p0) * ay.
  const Eigen::Vector2d e1 = p[1] - p[0], e2 = p[2] - p[0];
  const double det = e1.x() * e2.y() - e1.y() * e2.x();
  if (std::abs(det) < 1e-12) return;  // degenerate: covers no pixel centre's area
  const Eigen::Vector2d f1 = s[1] - s[0], f2 = s[2] - s[0];
  const Eigen::Vector2d ax = (f1 * e2.y() - f2 * e1.y()) / det;
  const Eigen::Vector2d ay = (f2 * e1.x() - f1 * e2.x()) / det;
  constexpr double kOne = 65536;
  const int64_t maxU = int64_t{texture.width - 1} << 16, maxV = int64_t{texture.height - 1} << 16;
  // The sample's top-left texel stops one short of the last, so its neighbours exist (a
  // 1-pixel-wide texture uses the same texel twice).
  const int lastU = std::max(0, texture.width - 2), lastV = std::max(0, texture.height - 2);
  const int stepX = texture.width > 1 ? Channels : 0;
  const size_t stepY = texture.height > 1 ? size_t(texture.width) * Channels : 0;
  const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({p[0].y(), p[1].y(), p[2].y()}))));
  const int y1 = std::min(out.height - 1,
                          static_cast<int>(std::floor(std::max({p[0].y(), p[1].y(), p[2].y()}))));
  constexpr double kEps = 1e-9;  // pixel centres on a shared edge are filled by both sides
  for (int y = y0; y <= y1; ++y) {
    // The row's span: where it crosses the three edges.
    double left = -1e300, right = 1e300;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d& a = p[k];
      const Eigen::Vector2d& b = p[(k + 1) % 3];
      // Inside is where cross(b - a, q - a) has the sign of det.
      const double cx = -(b.y() - a.y()),
                   c0 = (b.x() - a.x()) * (y - a.y()) + (b.y() - a.y()) * a.x();
      // cross = cx * x + c0 ; keep cross * sign(det) >= -eps.
      const double sx = det > 0 ? cx : -cx, s0 = det > 0 ? c0 : -c0;
      if (std::abs(sx) < 1e-15) {
        if (s0 < -kEps) left = 1e300;
      } else if (sx > 0) {
        left = std::max(left, (-kEps - s0) / sx);
      } else {
        right = std::min(right, (-kEps - s0) / sx);
      }
    }
    const int x0 = std::max(0, static_cast<int>(std::ceil(left)));
    const int x1 = std::min(out.width - 1, static_cast<int>(std::floor(right)));
    if (x0 > x1) continue;
    // The source position in 16.16 fixed point, stepped along the row.
    const Eigen::Vector2d src = s[0] + (x0 - p[0].x()) * ax + (y - p[0].y()) * ay;
    int64_t u = std::llround(src.x() * kOne), v = std::llround(src.y() * kOne);
    const int64_t du = std::llround(ax.x() * kOne), dv = std::llround(ax.y() * kOne);
    uint8_t* o = out.row(y) + size_t(x0) * Channels;
    const int64_t uEnd = u + du * (x1 - x0), vEnd = v + dv * (x1 - x0);
    if (std::min(u, uEnd) >= 0 && std::max(u, uEnd) < maxU && std::min(v, vEnd) >= 0 &&
        std::max(v, vEnd) < maxV) {
      // The whole span samples inside the texture (the usual case): no clamping per pixel.
      const uint8_t* base = texture.pixels.data();
      const size_t stride = size_t(texture.width) * Channels;
      for (int x = x0; x <= x1; ++x, u += du, v += dv, o += Channels) {
        const auto iu = static_cast<size_t>(u >> 16), iv = static_cast<size_t>(v >> 16);
        const auto wu = static_cast<int>(((u & 0xffff) + 128) >> 8);  // 0..256
        const auto wv = static_cast<int>(((v & 0xffff) + 128) >> 8);
        const uint8_t* t = base + iv * stride + iu * Channels;
        for (int c = 0; c < Channels; ++c) {
          const int top = t[c] * (256 - wu) + t[c + Channels] * wu;
          const int bottom = t[stride + c] * (256 - wu) + t[stride + c + Channels] * wu;
          o[c] = static_cast<uint8_t>((top * (256 - wv) + bottom * wv + 32768) >> 16);
        }
      }
      continue;
    }
    for (int x = x0; x <= x1; ++x, u += du, v += dv, o += Channels) {
      const int64_t cu = std::clamp<int64_t>(u, 0, maxU), cv = std::clamp<int64_t>(v, 0, maxV);
      const int iu = std::min(static_cast<int>(cu >> 16), lastU);
      const int iv = std::min(static_cast<int>(cv >> 16), lastV);
      const auto wu = static_cast<int>(((cu - (int64_t{iu} << 16)) + 128) >> 8);  // 0..256
      const auto wv = static_cast<int>(((cv - (int64_t{iv} << 16)) + 128) >> 8);
      const uint8_t* t = texture.row(iv) + size_t(iu) * Channels;
      for (int c = 0; c < Channels; ++c) {
        const int top = t[c] * (256 - wu) + t[c + stepX] * wu;
        const int bottom = t[stepY + c] * (256 - wu) + t[stepY + c + stepX] * wu;
        o[c] = static_cast<uint8_t>((top * (256 - wv) + bottom * wv + 32768) >> 16);
      }
    }
  }
}

}  // namespace

void warpMesh2d(const Image& texture, const Mesh2dNodes& intra, const Mesh2dNodes& current,
                const Mesh2dTriangles& triangles, Image& out) {
  if (texture.width <= 0 || texture.height <= 0 ||
      texture.pixels.size() != size_t(texture.width) * texture.height * texture.channels) {
    throw Error({}, 0, "texture", "is empty or not sized width x height x channels");
  }
  if (out.channels != texture.channels ||
      out.pixels.size() != size_t(out.width) * out.height * out.channels) {
    throw Error({}, 0, "image", "needs the texture's channel count");
  }
  if (intra.rows() != current.rows()) throw Error({}, 0, "frames", "node counts differ");
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    Eigen::Vector2d p[3], s[3];
    for (int k = 0; k < 3; ++k) {
      const int n = triangles(t, k);
      if (n < 0 || n >= current.rows()) {
        throw Error({}, 0, "triangles[" + std::to_string(t) + "]", "node out of range");
      }
      p[k] = current.row(n).transpose();
      s[k] = intra.row(n).transpose();
    }
    switch (texture.channels) {
      case 1:
        fillTriangle<1>(texture, p, s, out);
        break;
      case 3:
        fillTriangle<3>(texture, p, s, out);
        break;
      case 4:
        fillTriangle<4>(texture, p, s, out);
        break;
      default:
        throw Error({}, 0, "texture", "needs 1, 3 or 4 channels");
    }
  }
}

}  // namespace mpeg4face
