// PinholeCamera: the primary ray of each pixel exactly as CONVENTIONS 2 defines it
// (f = normalize(look - eye), r = normalize(cross(f, up)), u = cross(r, f), a = tan(fov/2)).
#pragma once

#include <cmath>

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
        const double sx = (2.0 * (px + 0.5 + dx_) / width_ - 1.0) * a_ * double(width_) / double(height_);
        const double sy = (1.0 - 2.0 * (py + 0.5 + dy_) / height_) * a_;
        std::array<double, 3> d;
        for (int i = 0; i < 3; ++i) d[i] = forward_[i] + sx * right_[i] + sy * up_[i];
        return Ray{eye_, vec_normalized(d)};
    }

private:
    std::array<double, 3> eye_, forward_{}, right_{}, up_{};
    int width_, height_;
    double dx_, dy_;
    double a_ = 0;
};

}  // namespace octiso
