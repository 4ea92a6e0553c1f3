// Antialiasing by supersampling (octiso-render --spp N): N renders of one frame with the primary
// rays shifted inside the pixel (Camera::pixel_offset), their colours averaged in linear light.
// Sample 0 is the pixel centre, so the depth and normal AOVs stay those of CONVENTIONS 2; the
// other shifts follow the Halton (2, 3) sequence, so a frame is the same on every run.
#pragma once

#include <array>
#include <functional>

#include "octiso/camera.h"
#include "octiso/frame.h"
#include "octiso/render.h"

namespace octiso {

inline constexpr int kMaxSamplesPerPixel = 256;

/// The shift of sample i (0 <= i < kMaxSamplesPerPixel) in pixels, each component in [-0.5, 0.5):
/// (0, 0) for i = 0, then (halton_2(i) - 0.5, halton_3(i) - 0.5).
std::array<double, 2> subpixel_offset(int i);

/// Renders `camera` with `spp` samples per pixel (1 .. kMaxSamplesPerPixel) into `frame`: the AOVs
/// and stats.hits of the centre sample, the colour averaged over all samples in linear light
/// (8-bit sRGB decoded exactly, the mean encoded again), stats.seconds and stats.rays summed. spp 1 is
/// renderer.render(camera, frame) exactly. `shade`, if given, colours each sample after it is
/// traced (deferred shading, shading.h: it receives the sample's shifted camera). Throws what
/// Renderer::render throws, and Error("--spp", ...) for spp out of range.
using SampleShader = std::function<void(const Camera& sample_camera, Frame& sample)>;
RenderStats render_antialiased(const Renderer& renderer, const Camera& camera, int spp, Frame& frame,
                               const SampleShader& shade = {});
/// The same over any way of rendering one sample (a distributed render, octiso-render under
/// mpirun: each sample traced by all ranks and assembled before it is averaged).
using SampleRenderer = std::function<RenderStats(const Camera& sample_camera, Frame& sample)>;
RenderStats render_antialiased(const SampleRenderer& render_sample, const Camera& camera, int spp, Frame& frame,
                               const SampleShader& shade = {});

}  // namespace octiso
