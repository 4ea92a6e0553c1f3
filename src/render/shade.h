// Shading of a primary hit: Lambert from a headlight (the light sits at the eye) plus ambient,
// one albedo per isovalue, and the 8-bit sRGB encoding of CONVENTIONS 2. The frame loop calls
// shade_pixel once per pixel; nothing here allocates.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "math/hit.h"
#include "math/vec.h"
#include "octiso/limits.h"

namespace octiso {

// Colours per isovalue (linear RGB): the first is a warm bone tone, then blue, green, rose ...
inline constexpr float kAlbedo[kMaxIsovalues][3] = {{0.90f, 0.62f, 0.36f}, {0.35f, 0.58f, 0.92f}, {0.45f, 0.80f, 0.42f},
                                                    {0.88f, 0.40f, 0.52f}, {0.85f, 0.82f, 0.35f}, {0.55f, 0.45f, 0.85f},
                                                    {0.40f, 0.80f, 0.80f}, {0.75f, 0.75f, 0.75f}};
inline constexpr float kBackground[3] = {0.015f, 0.017f, 0.022f};
inline constexpr float kAmbient = 0.18f;

/// Linear [0,1] -> 8-bit sRGB through a 4096-entry table (the exact curve costs a powf per
/// channel, ~5 % of a cheap frame); the table's step is far below one 8-bit level.
class SrgbTable {
public:
    SrgbTable() {
        for (int i = 0; i < kSize; ++i) {
            const float c = float(i) / float(kSize - 1);
            const float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
            table_[i] = uint8_t(std::lround(s * 255.0f));
        }
    }
    uint8_t operator()(float linear) const {
        // Written so that NaN maps to 0 (std::clamp passes NaN through, and int(NaN) is
        // undefined: it indexed the table at INT_MIN, issue 18).
        const float c = linear > 0.0f ? (linear < 1.0f ? linear : 1.0f) : 0.0f;
        return table_[int(c * float(kSize - 1) + 0.5f)];
    }
    static const SrgbTable& instance() {
        static const SrgbTable table;
        return table;
    }

private:
    static constexpr int kSize = 4096;
    uint8_t table_[kSize];
};

/// The 8-bit sRGB colour of one pixel whose primary ray (unit world direction `dir`) got `hit`.
inline void shade_pixel(const SrgbTable& to_srgb8, const TraceHit& hit, const Vec3& dir, uint8_t rgb8[3]) {
    float rgb[3];
    if (hit.is_hit()) {
        const float lambert = float(std::fabs(vec_dot(hit.normal, dir)));
        for (int a = 0; a < 3; ++a) rgb[a] = kAlbedo[hit.iso_index][a] * (kAmbient + (1.0f - kAmbient) * lambert);
    } else {
        for (int a = 0; a < 3; ++a) rgb[a] = kBackground[a];
    }
    for (int a = 0; a < 3; ++a) rgb8[a] = to_srgb8(rgb[a]);
}

}  // namespace octiso
