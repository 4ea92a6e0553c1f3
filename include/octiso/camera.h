// Camera: the perspective pinhole of CONVENTIONS 2 in world units, and the default framing of a
// data box. The pixel rays themselves are src/render/pinhole_camera.h.
#pragma once

#include <array>
#include <optional>
#include <string_view>

#include "octiso/volume.h"

namespace octiso {

/// Perspective pinhole, world units (CONVENTIONS 2). fov_deg is the vertical field of view.
struct Camera {
    std::array<double, 3> eye{0, 0, 0}, look{0, 0, 1}, up{0, 1, 0};
    double fov_deg = 40.0;
    int width = 512, height = 512;
    /// Shift of every primary ray in pixels, x right and y down: pixel (px, py) is traced at
    /// (px + 0.5 + dx, py + 0.5 + dy) in the formula of CONVENTIONS 2. (0, 0), the default, is that
    /// formula exactly; antialiasing (antialias.h) renders several shifts and averages them.
    std::array<double, 2> pixel_offset{0.0, 0.0};
};

/// A camera that frames the data box of `dims` placed by `placement` from a three-quarter view
/// (orbit_camera at kDefaultAzimuthDeg, kDefaultElevationDeg, zoom 1).
Camera frame_data_box(Dims dims, const Placement& placement, int width, int height);

/// The three-quarter view of frame_data_box: from +x, -y, +z (direction 0.9, -1.3, 0.8) with z up.
inline constexpr double kDefaultAzimuthDeg = -55.30484646876604;    // atan2(-1.3, 0.9)
inline constexpr double kDefaultElevationDeg = 26.837787558336064;  // asin(0.8 / |(0.9, -1.3, 0.8)|)

/// A camera on a sphere around the centre of the data box, looking at the centre with z up:
/// azimuth in degrees counter-clockwise from +x in the xy plane, elevation in degrees above it
/// (|elevation| < 90), at the distance where the box's bounding sphere fills the narrower field
/// of view, divided by `zoom` (> 0). frame_data_box is this at the default angles and zoom 1.
Camera orbit_camera(Dims dims, const Placement& placement, int width, int height, double azimuth_deg,
                    double elevation_deg, double zoom = 1.0);

/// The named views of octiso-render --view, in the data's own axes (z up unless looking along z):
/// front looks along +y (eye on the -y side), back along -y, left along +x (eye on -x), right
/// along -x, top along -z (eye above, +y up in the image), bottom along +z (+y up), iso the default
/// three-quarter view of frame_data_box.
enum class AxisView { front, back, left, right, top, bottom, iso };
std::optional<AxisView> parse_axis_view(std::string_view name);
std::string_view axis_view_name(AxisView view);

/// The camera of `view`, framed as orbit_camera frames (the bounding sphere fills the narrower
/// field of view, divided by `zoom` > 0). iso at zoom 1 is frame_data_box exactly.
Camera axis_view_camera(Dims dims, const Placement& placement, int width, int height, AxisView view, double zoom = 1.0);

/// Throws Error(flag, ...) unless the camera defines a ray for every pixel: positive size, fov in
/// (0, 180), look != eye, up not parallel to the view direction, pixel_offset finite within
/// [-1, 1] pixels.
void validate_camera(const Camera& camera);

}  // namespace octiso
