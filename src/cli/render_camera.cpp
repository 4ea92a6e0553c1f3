#include "cli/render_camera.h"

#include "cli/common/report.h"
#include "octiso/error.h"

namespace octiso::cli {

void CameraFlags::declare(FlagSpec& spec) {
    for (const char* name : {"--eye", "--look", "--up", "--fov", "--size", "--view", "--azimuth", "--elevation", "--zoom", "--orbit"})
        spec.values.emplace_back(name);
}

CameraFlags CameraFlags::take(const Flags& args) {
    CameraFlags f;
    f.eye = args.value("--eye"), f.look = args.value("--look"), f.up = args.value("--up"), f.fov = args.value("--fov");
    f.size = args.value("--size"), f.view = args.value("--view"), f.azimuth = args.value("--azimuth");
    f.elevation = args.value("--elevation"), f.zoom = args.value("--zoom"), f.orbit = args.value("--orbit");
    return f;
}

std::vector<Camera> cameras_for(const CameraFlags& f, const OctInfo& info) {
    int w = 512, h = 512;
    if (f.size) {
        const auto wh = parse_size(*f.size, "--size");
        w = wh[0], h = wh[1];
    }
    if (f.view && (f.azimuth || f.elevation))
        throw Error("--view", "combines with --zoom, not with --azimuth/--elevation (give a view or angles)");
    if (f.orbit && f.view) throw Error("--orbit", "circles at --elevation around z; it does not combine with --view");
    if (f.orbit && (f.eye || f.look || f.up))
        throw Error("--orbit", "moves the eye itself; give --azimuth (start), --elevation and --zoom instead of --eye/--look/--up");
    const double zoom = f.zoom ? parse_double(*f.zoom, "--zoom") : 1.0;
    const double azimuth = f.azimuth ? parse_double(*f.azimuth, "--azimuth") : kDefaultAzimuthDeg;
    const double elevation = f.elevation ? parse_double(*f.elevation, "--elevation") : kDefaultElevationDeg;
    const int frames = f.orbit ? int(parse_int(*f.orbit, "--orbit", 1, 100000)) : 1;

    std::vector<Camera> cameras;
    for (int i = 0; i < frames; ++i) {
        Camera c;
        if (f.view) {
            const auto view = parse_axis_view(*f.view);
            if (!view) throw Error("--view", "expected front, back, left, right, top, bottom or iso, found '" + *f.view + "'");
            c = axis_view_camera(info.dims, info.placement, w, h, *view, zoom);
        } else if (f.azimuth || f.elevation || f.zoom || f.orbit) {
            c = orbit_camera(info.dims, info.placement, w, h, azimuth + 360.0 * double(i) / double(frames), elevation, zoom);
        } else {
            c = frame_data_box(info.dims, info.placement, w, h);   // bit for bit the framing of every release so far
        }
        if (f.eye) c.eye = parse_vec3(*f.eye, "--eye");
        if (f.look) c.look = parse_vec3(*f.look, "--look");
        if (f.up) c.up = parse_vec3(*f.up, "--up");
        if (f.fov) c.fov_deg = parse_double(*f.fov, "--fov");
        validate_camera(c);
        cameras.push_back(c);
    }
    return cameras;
}

std::string camera_flags_text(const Camera& c) {
    const auto comma = [](const std::array<double, 3>& v) { return number(v[0]) + "," + number(v[1]) + "," + number(v[2]); };
    return "--eye " + comma(c.eye) + " --look " + comma(c.look) + " --up " + comma(c.up) + " --fov " + number(c.fov_deg) +
           " --size " + std::to_string(c.width) + "x" + std::to_string(c.height);
}

}  // namespace octiso::cli
