// PinholeCamera: the primary ray of each pixel exactly as CONVENTIONS 2 defines it
// (f = normalize(look - eye), r = normalize(cross(f, up)), u = cross(r, f), a = tan(fov/2)).
#pragma once

#include <cmath>

#include "octiso/render.h"
#include "render/ray.h"

namespace octiso {

inline std::array<double, 3> vec_sub(const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline std::array<double, 3> vec_cross(const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double vec_dot(const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline std::array<double, 3> vec_normalized(const std::array<double, 3>& a) {
    const double len = std::sqrt(vec_dot(a, a));
    return {a[0] / len, a[1] / len, a[2] / len};
}

class PinholeCamera {
public:
    explicit PinholeCamera(const Camera& c)
        : eye_(c.eye), width_(c.width), height_(c.height) {
        forward_ = vec_normalized(vec_sub(c.look, c.eye));
        right_ = vec_normalized(vec_cross(forward_, c.up));
        up_ = vec_cross(right_, forward_);
        a_ = std::tan(c.fov_deg * 0.5 * 3.14159265358979323846 / 180.0);
    }

    /// World ray through the centre of pixel (px, py); py = 0 is the top row.
    Ray ray(int px, int py) const {
        const double sx = (2.0 * (px + 0.5) / width_ - 1.0) * a_ * double(width_) / double(height_);
        const double sy = (1.0 - 2.0 * (py + 0.5) / height_) * a_;
        std::array<double, 3> d;
        for (int i = 0; i < 3; ++i) d[i] = forward_[i] + sx * right_[i] + sy * up_[i];
        return Ray{eye_, vec_normalized(d)};
    }

private:
    std::array<double, 3> eye_, forward_{}, right_{}, up_{};
    int width_, height_;
    double a_ = 0;
};

}  // namespace octiso
