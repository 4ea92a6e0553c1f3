// Camera: the perspective pinhole of CONVENTIONS 2 in world units, and the default framing of a
// data box. The pixel rays themselves are src/render/pinhole_camera.h.
#pragma once

#include <array>

#include "octiso/volume.h"

namespace octiso {

/// Perspective pinhole, world units (CONVENTIONS 2). fov_deg is the vertical field of view.
struct Camera {
    std::array<double, 3> eye{0, 0, 0}, look{0, 0, 1}, up{0, 1, 0};
    double fov_deg = 40.0;
    int width = 512, height = 512;
};

/// A camera that frames the data box of `dims` placed by `placement` from a three-quarter view.
Camera frame_data_box(Dims dims, const Placement& placement, int width, int height);

/// Throws Error(flag, ...) unless the camera defines a ray for every pixel: positive size, fov in
/// (0, 180), look != eye, up not parallel to the view direction.
void validate_camera(const Camera& camera);

}  // namespace octiso
