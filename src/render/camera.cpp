// The default framing of a data box, the orbit and the named axis views around it, and the
// camera checks of CONVENTIONS 2.
#include <algorithm>
#include <cmath>

#include "math/vec.h"
#include "octiso/camera.h"
#include "octiso/error.h"

namespace octiso {

namespace {

/// The camera looking at the data box's centre from unit direction `view` (centre -> eye), z up,
/// far enough that the box's bounding sphere fits the narrower of the two fields of view, divided
/// by `zoom`.
Camera camera_towards_box(Dims dims, const Placement& placement, int width, int height, const Vec3& view, double zoom,
                          const Vec3& up = {0, 0, 1}) {
    std::array<double, 3> lo, hi, centre;
    double radius2 = 0;
    for (int a = 0; a < 3; ++a) {
        const uint32_t n = a == 0 ? dims.x : a == 1 ? dims.y : dims.z;
        lo[a] = placement.origin[a];
        hi[a] = placement.origin[a] + double(n > 0 ? n - 1 : 0) * placement.spacing[a];
        centre[a] = 0.5 * (lo[a] + hi[a]);
        radius2 += 0.25 * (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    const double radius = std::max(std::sqrt(radius2), 1e-9);
    Camera c;
    c.width = width;
    c.height = height;
    c.fov_deg = 35.0;
    const double half_fov = radians_from_degrees(c.fov_deg * 0.5);
    const double aspect = double(width) / double(height);
    const double narrow = aspect < 1 ? std::atan(std::tan(half_fov) * aspect) : half_fov;
    const double distance = radius / std::sin(narrow) * 1.02 / zoom;
    for (int a = 0; a < 3; ++a) c.eye[a] = centre[a] + view[a] * distance;
    c.look = centre;
    c.up = up;
    return c;
}

}  // namespace

Camera frame_data_box(Dims dims, const Placement& placement, int width, int height) {
    // The vector itself, not its angles: cos/sin of kDefault*Deg would move the eye by an ulp.
    return camera_towards_box(dims, placement, width, height, vec_normalized({0.9, -1.3, 0.8}), 1.0);
}

Camera orbit_camera(Dims dims, const Placement& placement, int width, int height, double azimuth_deg,
                    double elevation_deg, double zoom) {
    if (!std::isfinite(azimuth_deg)) throw Error("--azimuth", "must be a finite number of degrees");
    if (!(std::fabs(elevation_deg) < 90)) throw Error("--elevation", "must lie in (-90, 90) degrees (z is up)");
    if (!(zoom > 0) || !std::isfinite(zoom)) throw Error("--zoom", "must be a positive number");
    const double az = radians_from_degrees(azimuth_deg), el = radians_from_degrees(elevation_deg);
    const Vec3 view{std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
    return camera_towards_box(dims, placement, width, height, view, zoom);
}

namespace {
constexpr std::string_view kAxisViewNames[] = {"front", "back", "left", "right", "top", "bottom", "iso"};
}

std::optional<AxisView> parse_axis_view(std::string_view name) {
    for (int i = 0; i < 7; ++i)
        if (name == kAxisViewNames[i]) return AxisView(i);
    return std::nullopt;
}

std::string_view axis_view_name(AxisView view) { return kAxisViewNames[int(view)]; }

Camera axis_view_camera(Dims dims, const Placement& placement, int width, int height, AxisView view, double zoom) {
    if (!(zoom > 0) || !std::isfinite(zoom)) throw Error("--zoom", "must be a positive number");
    // Each vector points from the centre to the eye.
    switch (view) {
        case AxisView::front: return camera_towards_box(dims, placement, width, height, {0, -1, 0}, zoom);
        case AxisView::back: return camera_towards_box(dims, placement, width, height, {0, 1, 0}, zoom);
        case AxisView::left: return camera_towards_box(dims, placement, width, height, {-1, 0, 0}, zoom);
        case AxisView::right: return camera_towards_box(dims, placement, width, height, {1, 0, 0}, zoom);
        case AxisView::top: return camera_towards_box(dims, placement, width, height, {0, 0, 1}, zoom, {0, 1, 0});
        case AxisView::bottom: return camera_towards_box(dims, placement, width, height, {0, 0, -1}, zoom, {0, 1, 0});
        case AxisView::iso: break;
    }
    return camera_towards_box(dims, placement, width, height, vec_normalized({0.9, -1.3, 0.8}), zoom);
}

void validate_camera(const Camera& camera) {
    if (camera.width < 1 || camera.height < 1) throw Error("--size", "width and height must be positive");
    if (!(camera.fov_deg > 0 && camera.fov_deg < 180)) throw Error("--fov", "must lie in (0, 180) degrees");
    const Vec3 f = vec_sub(camera.look, camera.eye);
    if (!(vec_dot(f, f) > 0)) throw Error("--look", "must differ from --eye");
    const Vec3 side = vec_cross(f, camera.up);
    if (!(vec_dot(side, side) > 1e-24 * vec_dot(f, f) * std::max(vec_dot(camera.up, camera.up), 1e-300)))
        throw Error("--up", "must not be parallel to the viewing direction (or zero)");
    for (const double d : camera.pixel_offset)
        if (!(std::fabs(d) <= 1.0)) throw Error("--spp", "a pixel offset must lie within [-1, 1] pixels");
}

}  // namespace octiso
