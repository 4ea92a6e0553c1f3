// axis_view_camera (include/octiso/camera.h): each named view looks at the data centre exactly
// along its axis of the data, from the distance orbit_camera frames at, with z up (y up for top
// and bottom); iso is frame_data_box bit for bit; names round-trip; a bad zoom is refused.
#include <cmath>

#include <gtest/gtest.h>

#include "octiso/camera.h"
#include "octiso/error.h"

namespace octiso::test {
namespace {

TEST(AxisView, EachViewLooksAlongItsDataAxisAtTheCentre) {
    const Dims dims{40, 30, 20};
    const Placement placement{{0.5, 1.0, 2.0}, {-3.0, 4.0, 5.0}};
    const Camera ref = orbit_camera(dims, placement, 64, 48, 0, 0);
    const double distance = ref.eye[0] - ref.look[0];
    struct Want {
        AxisView view;
        std::array<double, 3> eye_dir, up;
    };
    const Want wants[] = {{AxisView::front, {0, -1, 0}, {0, 0, 1}}, {AxisView::back, {0, 1, 0}, {0, 0, 1}},
                          {AxisView::left, {-1, 0, 0}, {0, 0, 1}},  {AxisView::right, {1, 0, 0}, {0, 0, 1}},
                          {AxisView::top, {0, 0, 1}, {0, 1, 0}},    {AxisView::bottom, {0, 0, -1}, {0, 1, 0}}};
    for (const Want& w : wants) {
        SCOPED_TRACE(std::string(axis_view_name(w.view)));
        const Camera c = axis_view_camera(dims, placement, 64, 48, w.view);
        EXPECT_EQ(c.look, ref.look);
        EXPECT_EQ(c.up, w.up);
        for (int a = 0; a < 3; ++a) EXPECT_EQ(c.eye[a], c.look[a] + w.eye_dir[a] * distance);
        EXPECT_NO_THROW(validate_camera(c));
        const Camera z = axis_view_camera(dims, placement, 64, 48, w.view, 4.0);
        for (int a = 0; a < 3; ++a) EXPECT_DOUBLE_EQ(z.eye[a] - z.look[a], (c.eye[a] - c.look[a]) / 4.0);
    }
}

TEST(AxisView, IsoIsTheDefaultFramingExactly) {
    const Dims dims{13, 7, 21};
    const Placement placement{{1, 2, 3}, {5, 6, 7}};
    const Camera a = axis_view_camera(dims, placement, 30, 20, AxisView::iso), b = frame_data_box(dims, placement, 30, 20);
    EXPECT_EQ(a.eye, b.eye);
    EXPECT_EQ(a.look, b.look);
    EXPECT_EQ(a.up, b.up);
    EXPECT_EQ(a.fov_deg, b.fov_deg);
}

TEST(AxisView, NamesRoundTripAndBadInputIsRefused) {
    for (const char* name : {"front", "back", "left", "right", "top", "bottom", "iso"}) {
        const auto v = parse_axis_view(name);
        ASSERT_TRUE(v.has_value()) << name;
        EXPECT_EQ(axis_view_name(*v), name);
    }
    EXPECT_FALSE(parse_axis_view("Front").has_value());
    EXPECT_FALSE(parse_axis_view("").has_value());
    EXPECT_THROW(axis_view_camera({8, 8, 8}, {}, 8, 8, AxisView::top, 0.0), Error);
    EXPECT_THROW(axis_view_camera({8, 8, 8}, {}, 8, 8, AxisView::top, -1.0), Error);
    Camera c = frame_data_box({8, 8, 8}, {}, 8, 8);
    c.pixel_offset = {1.5, 0};
    EXPECT_THROW(validate_camera(c), Error);
    c.pixel_offset = {0, std::nan("")};
    EXPECT_THROW(validate_camera(c), Error);
}

}  // namespace
}  // namespace octiso::test
