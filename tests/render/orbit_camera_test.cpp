// orbit_camera (include/octiso/camera.h): at the default angles it is frame_data_box up to
// rounding; every orbit looks at the data centre from the same distance; zoom divides it; bad
// angles are refused naming the flag.
#include <cmath>

#include <gtest/gtest.h>

#include "octiso/camera.h"
#include "octiso/error.h"

namespace octiso::test {
namespace {

double distance(const Camera& c) {
    double s = 0;
    for (int a = 0; a < 3; ++a) s += (c.eye[a] - c.look[a]) * (c.eye[a] - c.look[a]);
    return std::sqrt(s);
}

TEST(OrbitCamera, DefaultAnglesAreTheDefaultFraming) {
    const Dims dims{40, 30, 20};
    const Placement placement{{0.5, 1.0, 2.0}, {-3.0, 4.0, 5.0}};
    const Camera a = frame_data_box(dims, placement, 90, 60);
    const Camera b = orbit_camera(dims, placement, 90, 60, kDefaultAzimuthDeg, kDefaultElevationDeg);
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(a.eye[k], b.eye[k], 1e-12 * distance(a));
        EXPECT_EQ(a.look[k], b.look[k]);
        EXPECT_EQ(a.up[k], b.up[k]);
    }
    EXPECT_EQ(a.fov_deg, b.fov_deg);
}

TEST(OrbitCamera, OrbitsKeepCentreAndDistanceAndZoomDividesIt) {
    const Dims dims{17, 17, 33};
    const Placement placement{};
    const Camera ref = frame_data_box(dims, placement, 64, 64);
    for (double az : {0.0, 90.0, 180.0, -135.0, 720.0})
        for (double el : {-80.0, 0.0, 45.0}) {
            const Camera c = orbit_camera(dims, placement, 64, 64, az, el);
            EXPECT_NEAR(distance(c), distance(ref), 1e-9 * distance(ref));
            for (int k = 0; k < 3; ++k) EXPECT_EQ(c.look[k], ref.look[k]);
            // The eye's height above the centre follows the elevation.
            EXPECT_NEAR(c.eye[2] - c.look[2], distance(ref) * std::sin(el * M_PI / 180), 1e-9 * distance(ref));
        }
    const Camera near = orbit_camera(dims, placement, 64, 64, 30, 10, 4.0);
    EXPECT_NEAR(distance(near), distance(ref) / 4.0, 1e-9 * distance(ref));
}

TEST(OrbitCamera, BadAnglesAreRefusedNamingTheFlag) {
    auto subject = [](double az, double el, double zoom) {
        try {
            orbit_camera({8, 8, 8}, Placement{}, 16, 16, az, el, zoom);
        } catch (const Error& e) {
            return e.subject();
        }
        return std::string("accepted");
    };
    EXPECT_EQ(subject(NAN, 0, 1), "--azimuth");
    EXPECT_EQ(subject(0, 90, 1), "--elevation");
    EXPECT_EQ(subject(0, -95, 1), "--elevation");
    EXPECT_EQ(subject(0, 0, 0), "--zoom");
    EXPECT_EQ(subject(0, 0, INFINITY), "--zoom");
    EXPECT_EQ(subject(10, 20, 2), "accepted");
}

}  // namespace
}  // namespace octiso::test
