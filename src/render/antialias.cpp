// Supersampled frames (include/octiso/antialias.h): one Renderer, spp passes with shifted rays,
// colour accumulated in linear light per pixel. Only the colour buffer is averaged: a depth or a
// normal averaged across a silhouette would be a value no surface has.
#include "octiso/antialias.h"

#include <cmath>
#include <vector>

#include "octiso/error.h"
#include "render/shade.h"

namespace octiso {

namespace {

/// Radical inverse of i in `base` (the Halton sequence), in [0, 1).
double radical_inverse(int i, int base) {
    double result = 0, scale = 1.0 / base;
    for (; i > 0; i /= base, scale /= base) result += double(i % base) * scale;
    return result;
}

/// 8-bit sRGB -> linear, the exact curve (the inverse of what SrgbTable encodes).
struct LinearFromSrgb8 {
    float table[256];
    LinearFromSrgb8() {
        for (int i = 0; i < 256; ++i) {
            const double s = i / 255.0;
            table[i] = float(s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4));
        }
    }
};

}  // namespace

std::array<double, 2> subpixel_offset(int i) {
    if (i <= 0) return {0.0, 0.0};
    return {radical_inverse(i, 2) - 0.5, radical_inverse(i, 3) - 0.5};
}

RenderStats render_antialiased(const Renderer& renderer, const Camera& camera, int spp, Frame& frame, const SampleShader& shade) {
    return render_antialiased(SampleRenderer([&](const Camera& c, Frame& f) { return renderer.render(c, f); }), camera, spp,
                              frame, shade);
}

RenderStats render_antialiased(const SampleRenderer& render_sample, const Camera& camera, int spp, Frame& frame,
                               const SampleShader& shade) {
    if (spp < 1 || spp > kMaxSamplesPerPixel)
        throw Error("--spp", "expected 1 .. " + std::to_string(kMaxSamplesPerPixel) + " samples per pixel, found " + std::to_string(spp));
    RenderStats stats = render_sample(camera, frame);
    if (shade) shade(camera, frame);
    if (spp == 1 || frame.rgb.empty()) return stats;
    static const LinearFromSrgb8 to_linear;
    std::vector<float> sum(frame.rgb.size());
    for (size_t i = 0; i < sum.size(); ++i) sum[i] = to_linear.table[frame.rgb[i]];
    Frame sample;
    for (int s = 1; s < spp; ++s) {
        Camera shifted = camera;
        shifted.pixel_offset = subpixel_offset(s);
        const RenderStats more = render_sample(shifted, sample);
        stats.seconds += more.seconds;
        stats.busy_seconds += more.busy_seconds;
        stats.rays += more.rays;
        if (shade) shade(shifted, sample);
        for (size_t i = 0; i < sum.size(); ++i) sum[i] += to_linear.table[sample.rgb[i]];
    }
    const SrgbTable& to_srgb8 = SrgbTable::instance();
    const float inv = 1.0f / float(spp);
    for (size_t i = 0; i < sum.size(); ++i) frame.rgb[i] = to_srgb8(sum[i] * inv);
    frame.stats = stats;
    return stats;
}

}  // namespace octiso
