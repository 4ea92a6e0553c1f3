// PinholeCamera: the primary ray of each pixel exactly as CONVENTIONS 2 defines it
// (f = normalize(look - eye), r = normalize(cross(f, up)), u = cross(r, f), a = tan(fov/2)).
#pragma once

#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "math/ray.h"
#include "math/vec.h"
#include "octiso/camera.h"

namespace octiso {

class PinholeCamera {
public:
    explicit PinholeCamera(const Camera& c)
        : eye_(c.eye), width_(c.width), height_(c.height), dx_(c.pixel_offset[0]), dy_(c.pixel_offset[1]) {
        forward_ = vec_normalized(vec_sub(c.look, c.eye));
        right_ = vec_normalized(vec_cross(forward_, c.up));
        up_ = vec_cross(right_, forward_);
        a_ = std::tan(radians_from_degrees(c.fov_deg * 0.5));
    }

    /// World ray through the centre of pixel (px, py), shifted by the camera's pixel_offset;
    /// py = 0 is the top row. The offset is added after the 0.5, so (0, 0) gives bit for bit
    /// the CONVENTIONS 2 ray.
    Ray ray(int px, int py) const {
        const double sx = screen_x(px), sy = screen_y(py);
        std::array<double, 3> d;
        for (int i = 0; i < 3; ++i) d[i] = forward_[i] + sx * right_[i] + sy * up_[i];
        return Ray{eye_, vec_normalized(d)};
    }

    /// The most pixels block_rays() takes along a side, and in all.
    static constexpr int kMaxBlockSide = 8, kMaxBlockRays = 16;
    /// The rays of the w x h pixels at (x0, y0), row by row into out[0 .. w*h): ray(px, py) bit
    /// for bit (w, h in 1 .. kMaxBlockSide, w * h <= kMaxBlockRays). A column's and a row's
    /// screen coordinate are computed once for the block, and the normalisations two rays at a
    /// time (SSE2 sqrtpd, divpd: the same correctly rounded operations as sqrt and the scalar
    /// divisions). Why: with no surface in view a 512^2 frame of ch2better still took 8-12 ms,
    /// and perf put 15 % of its samples in this per-pixel arithmetic (BENCHMARKS.md, packet
    /// section, eleventh session).
    void block_rays(int x0, int y0, int w, int h, Ray* out) const {
        double sx[kMaxBlockSide], sy[kMaxBlockSide];
        for (int i = 0; i < w; ++i) sx[i] = screen_x(x0 + i);
        for (int j = 0; j < h; ++j) sy[j] = screen_y(y0 + j);
        double d[3][kMaxBlockRays + 1];   // one spare lane: the pairs below may read one past an odd count
        const int n = w * h;
        for (int j = 0; j < h; ++j)
            for (int i = 0; i < w; ++i)
                for (int a = 0; a < 3; ++a) d[a][j * w + i] = forward_[a] + sx[i] * right_[a] + sy[j] * up_[a];
        for (int a = 0; a < 3; ++a) d[a][n] = 1.0;
#if defined(__SSE2__)
        for (int k = 0; k < n; k += 2) {
            const __m128d x = _mm_loadu_pd(&d[0][k]), y = _mm_loadu_pd(&d[1][k]), z = _mm_loadu_pd(&d[2][k]);
            // vec_normalized: sqrt((x*x + y*y) + z*z), then each component divided by it.
            const __m128d len = _mm_sqrt_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(x, x), _mm_mul_pd(y, y)), _mm_mul_pd(z, z)));
            _mm_storeu_pd(&d[0][k], _mm_div_pd(x, len));
            _mm_storeu_pd(&d[1][k], _mm_div_pd(y, len));
            _mm_storeu_pd(&d[2][k], _mm_div_pd(z, len));
        }
        for (int k = 0; k < n; ++k) out[k] = Ray{eye_, {d[0][k], d[1][k], d[2][k]}};
#else
        for (int k = 0; k < n; ++k) out[k] = Ray{eye_, vec_normalized({d[0][k], d[1][k], d[2][k]})};
#endif
    }

private:
    /// The pixel column's and row's screen coordinates (CONVENTIONS 2), as ray() combines them.
    double screen_x(int px) const { return (2.0 * (px + 0.5 + dx_) / width_ - 1.0) * a_ * double(width_) / double(height_); }
    double screen_y(int py) const { return (1.0 - 2.0 * (py + 0.5 + dy_) / height_) * a_; }

    std::array<double, 3> eye_, forward_{}, right_{}, up_{};
    int width_, height_;
    double dx_, dy_;
    double a_ = 0;
};

}  // namespace octiso
