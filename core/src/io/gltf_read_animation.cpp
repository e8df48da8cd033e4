// SPDX-License-Identifier: GPL-3.0-or-later
// glTF reader: animations, as morph-weight and Transform channels.
#include <algorithm>
#include <cmath>
#include <tuple>

#include "io/gltf_reader.hpp"

namespace mpeg4face::gltf_reader {

void Reader::readAnimations() {
  for (size_t a = 0; a < gltf_.animations.size(); ++a) {
    const tinygltf::Animation& anim = gltf_.animations[a];
    const std::string ap = "animations[" + str(a) + "]";
    MorphWeightAnimation out;
    out.name = anim.name.empty() ? "animation" + str(a) : anim.name;
    std::vector<std::pair<int, int>> done;  // (mesh, sampler) already read
    for (size_t c = 0; c < anim.channels.size(); ++c) {
      const tinygltf::AnimationChannel& channel = anim.channels[c];
      const std::string cp = ap + ".channels[" + str(c) + "]";
      const std::string& path = channel.target_path;
      const bool weights = path == "weights";
      if (!weights && path != "translation" && path != "rotation" && path != "scale") {
        continue;  // e.g. KHR_animation_pointer: not part of the face model
      }
      const int node = channel.target_node;
      if (node < 0 || static_cast<size_t>(node) >= gltf_.nodes.size()) {
        fail(cp + ".target.node", "node " + std::to_string(node) + " does not exist");
      }
      const int sampler = channel.sampler;
      if (sampler < 0 || static_cast<size_t>(sampler) >= anim.samplers.size()) {
        fail(cp + ".sampler", "sampler " + std::to_string(sampler) + " does not exist");
      }
      const std::string sp = ap + ".samplers[" + std::to_string(sampler) + "]";
      if (!weights) {
        if (transformOf_[node] < 0) {
          fail(cp + ".target.node", "node " + std::to_string(node) +
                                        " is a helper node of mpeg4face's own (see its "
                                        "extras), which cannot be animated");
        }
        out.transformChannels.push_back(
            readTransformChannel(anim.samplers[sampler], sp, transformOf_[node], path));
        continue;
      }
      const int mesh = gltf_.nodes[node].mesh;
      if (mesh < 0) fail(cp + ".target.node", "node " + std::to_string(node) + " has no mesh");
      // Instances of one mesh animated by one sampler are one channel of the face model.
      if (std::find(done.begin(), done.end(), std::pair{mesh, sampler}) != done.end()) continue;
      done.emplace_back(mesh, sampler);
      out.channels.push_back(readChannel(anim.samplers[sampler], sp, cp, mesh));
    }
    if (!out.channels.empty() || !out.transformChannels.empty()) {
      model_.animations.push_back(std::move(out));
    }
  }
}

// The interpolation of a sampler and the number of outputs per key it needs (3 for cubic
// splines: in-tangent, value, out-tangent).
std::pair<MorphWeightChannel::Interpolation, size_t> Reader::interpolation(
    const tinygltf::AnimationSampler& sampler, const std::string& sp) const {
  if (sampler.interpolation == "LINEAR") return {MorphWeightChannel::Interpolation::Linear, 1};
  if (sampler.interpolation == "STEP") return {MorphWeightChannel::Interpolation::Step, 1};
  if (sampler.interpolation == "CUBICSPLINE") {
    return {MorphWeightChannel::Interpolation::CubicSpline, 3};
  }
  fail(sp + ".interpolation", "unknown interpolation '" + sampler.interpolation + "'");
}

std::vector<double> Reader::keyTimes(const tinygltf::AnimationSampler& sampler,
                                     const std::string& sp) {
  std::vector<double> times =
      readAccessor(sampler.input, sp + ".input", {.type = TINYGLTF_TYPE_SCALAR});
  if (times.empty()) fail(sp + ".input", "has no key times");
  for (size_t i = 0; i < times.size(); ++i) {
    if (!std::isfinite(times[i]) || (i > 0 && times[i] < times[i - 1])) {
      fail(sp + ".input", "key times must be finite and increasing (key " + str(i) + ")");
    }
  }
  return times;
}

MorphWeightChannel Reader::readChannel(const tinygltf::AnimationSampler& sampler,
                                       const std::string& sp, const std::string& cp, int mesh) {
  MorphWeightChannel channel;
  channel.mesh = mesh;
  size_t factor = 1;
  std::tie(channel.interpolation, factor) = interpolation(sampler, sp);
  const size_t targets = model_.meshes[mesh].morphTargets.size();
  if (targets == 0) {
    fail(cp, "animates the weights of mesh '" + model_.meshes[mesh].name +
                 "', which has no morph targets");
  }
  channel.times = keyTimes(sampler, sp);
  const uint64_t expected = channel.times.size() * targets * factor;
  channel.weights =
      readAccessor(sampler.output, sp + ".output",
                   {.type = TINYGLTF_TYPE_SCALAR, .floats = true, .normalizedInts = true});
  if (channel.weights.size() != expected) {
    fail(sp + ".output", "has " + str(channel.weights.size()) + " values; " +
                             str(channel.times.size()) + " keys x " + str(targets) +
                             " morph targets" + (factor == 3 ? " x 3 (cubic spline)" : "") +
                             " need " + str(expected));
  }
  return channel;
}

TransformChannel Reader::readTransformChannel(const tinygltf::AnimationSampler& sampler,
                                              const std::string& sp, int transform,
                                              const std::string& path) {
  TransformChannel channel;
  channel.transform = transform;
  size_t factor = 1;
  std::tie(channel.interpolation, factor) = interpolation(sampler, sp);
  const bool rotation = path == "rotation";
  channel.path = rotation                ? TransformChannel::Path::Rotation
                 : path == "translation" ? TransformChannel::Path::Translation
                                         : TransformChannel::Path::Scale;
  channel.times = keyTimes(sampler, sp);
  // glTF allows normalized integers for rotations only.
  const AccessorSpec spec = {.type = rotation ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3,
                             .floats = true,
                             .normalizedInts = rotation};
  channel.values =
      readAccessor(sampler.output, sp + ".output", spec, channel.times.size() * factor);
  if (channel.path == TransformChannel::Path::Translation) {
    // The node's translation is the Transform's plus its centre (see readNodes); the
    // tangents of a cubic spline need no offset.
    const Eigen::Vector3d& center = model_.transforms[transform].center;
    for (size_t key = 0; key < channel.times.size(); ++key) {
      double* value = channel.values.data() + (key * factor + (factor == 3 ? 1 : 0)) * 3;
      for (int i = 0; i < 3; ++i) value[i] -= center[i];
    }
  }
  return channel;
}

}  // namespace mpeg4face::gltf_reader
