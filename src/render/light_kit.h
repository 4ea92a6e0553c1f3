// The light kit of octiso-render's default shading (issue 17, item 6), after VTK's vtkLightKit:
// a key light above and to the right of the eye and a weak fill light below on the other side,
// both fixed to the camera, a little ambient, and a white Blinn-Phong highlight from each. Lights
// are directions in the camera's own frame, so a view turns the lights with it. Pure arithmetic:
// shade_frame (src/api/shading.cpp) calls it once per hit pixel.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

#include "math/vec.h"

namespace octiso {

/// One directional light: azimuth (degrees, + towards the camera's right) and elevation (degrees,
/// + towards its up) of the direction from the surface to the light, 0,0 being the eye; intensity.
struct KitLight {
    double azimuth_deg, elevation_deg, intensity;
};

inline constexpr size_t kKitLights = 2;

struct LightKit {
    // Deviation from vtkLightKit's defaults (key at azimuth 10, elevation 50, 0.75; fill at -10,
    // -75, key:fill 3; a headlight and two back lights): with those (plus ambient 0.06), on
    // ch2better at 80.5 the head and back lights flatten the folds (foreground luminance spread
    // 22.2, the plain headlight's 21.9). A stronger key further off the eye, a weak fill and no headlight show the
    // sulci: spread 48.9 (VTK 47.7, vdb_render 57.5; README, "Light that shows shape").
    std::array<KitLight, kKitLights> lights{{{30, 50, 1.0}, {-40, -15, 0.17}}};
    double ambient = 0.025;      ///< so that a crease no light reaches is not black
    double specular = 0.35;      ///< white highlight weight per unit of light intensity
    double shininess = 20.0;     ///< Blinn-Phong exponent
};

/// The camera's frame as CONVENTIONS 2 builds it: forward, right, up.
struct CameraFrame {
    Vec3 forward, right, up;
};

/// World directions (surface -> light) of the kit's lights for a camera frame.
inline std::array<Vec3, kKitLights> light_directions(const LightKit& kit, const CameraFrame& cam) {
    std::array<Vec3, kKitLights> out;
    for (size_t i = 0; i < kit.lights.size(); ++i) {
        const double az = radians_from_degrees(kit.lights[i].azimuth_deg), el = radians_from_degrees(kit.lights[i].elevation_deg);
        const double r = std::cos(el) * std::sin(az), u = std::sin(el), b = -std::cos(el) * std::cos(az);   // b: along forward
        for (int a = 0; a < 3; ++a) out[i][a] = r * cam.right[a] + u * cam.up[a] + b * cam.forward[a];
    }
    return out;
}

/// How much of the kit's light reaches a hit (issue 17 item 7, api/look.cpp): `key`, the key
/// light's transmittance along its shadow ray; `ambient`, the unoccluded fraction of the
/// hemisphere, which scales the ambient term and the broad fill light. 1, 1: fully lit, and
/// the colour is bit for bit that of before (x * 1.0 == x).
struct KitVisibility {
    double key = 1.0, ambient = 1.0;
};

/// The key light: lights[0], the one shadow rays aim at.
inline constexpr size_t kKeyLight = 0;

/// Linear RGB of a hit with unit `normal` facing the ray, seen along unit `dir`, albedo `albedo`.
inline std::array<double, 3> shade_light_kit(const LightKit& kit, const std::array<Vec3, kKitLights>& to_light, const Vec3& normal,
                                             const Vec3& dir, const float albedo[3], const KitVisibility& visible = {}) {
    double diffuse = kit.ambient * visible.ambient, highlight = 0;
    for (size_t i = 0; i < to_light.size(); ++i) {
        const double intensity = kit.lights[i].intensity * (i == kKeyLight ? visible.key : visible.ambient);
        const double nl = vec_dot(normal, to_light[i]);
        if (!(nl > 0)) continue;   // the light is behind the surface (NaN-safe)
        diffuse += intensity * nl;
        const Vec3 half = vec_normalized({to_light[i][0] - dir[0], to_light[i][1] - dir[1], to_light[i][2] - dir[2]});
        const double nh = vec_dot(normal, half);
        if (nh > 0) highlight += intensity * std::pow(nh, kit.shininess);
    }
    std::array<double, 3> rgb;
    for (int a = 0; a < 3; ++a) rgb[a] = double(albedo[a]) * diffuse + kit.specular * highlight;
    return rgb;
}

}  // namespace octiso
