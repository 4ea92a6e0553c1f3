// octiso/debug_trace.h: a re-traced pixel ends where the frame says it does (the same t as the
// frame's depth there, the same miss), its events nest (every cell's piece lies inside the
// clip), and a pixel outside the image is refused with an Error naming --debug-pixel.
#include <gtest/gtest.h>

#include <cmath>

#include "octiso/build.h"
#include "octiso/debug_trace.h"
#include "octiso/error.h"
#include "render/render_test_util.h"

namespace octiso::test {
namespace {

using Kind = PixelTraceEvent::Kind;

template <typename T> class DebugTraceTyped : public ::testing::Test {};
using AllTypes = ::testing::Types<uint8_t, int8_t, uint16_t, int16_t, uint32_t, int32_t, float, double>;
TYPED_TEST_SUITE(DebugTraceTyped, AllTypes);

TYPED_TEST(DebugTraceTyped, EveryPixelEndsAtTheFramesDepth) {
    using T = TypeParam;
    const auto v = make_field<T>(Field::MarschnerLobb, {29, 31, 27});
    const auto data = build_octree(v.view(), {});
    Placement placement;
    placement.spacing = {1.0, 0.75, 1.25};
    RenderOptions options;
    options.isovalues = {47.0, 85.0};
    options.want_depth = true;
    const Camera camera = frame_data_box(v.dims, placement, 24, 20);
    const Frame frame = render(data.view(), placement, camera, options);
    int hits = 0;
    for (int y = 0; y < camera.height; ++y)
        for (int x = 0; x < camera.width; ++x) {
            const PixelTrace trace = trace_pixel(data.view(), placement, camera, options, x, y);
            const float depth = frame.depth[size_t(y) * size_t(camera.width) + size_t(x)];
            ASSERT_FALSE(trace.events.empty());
            EXPECT_EQ(trace.events.front().kind, Kind::clip);
            if (std::isinf(depth)) {
                EXPECT_EQ(trace.iso_index, -1) << x << "," << y;
                continue;
            }
            ++hits;
            ASSERT_GE(trace.iso_index, 0) << x << "," << y;
            EXPECT_EQ(float(trace.t), depth) << x << "," << y;
            const PixelTraceEvent& last = trace.events.back();
            ASSERT_EQ(last.kind, Kind::root) << "a hit's trace ends with its root";
            EXPECT_EQ(last.t0, trace.t);
            EXPECT_EQ(last.iso_index, trace.iso_index);
            ASSERT_GE(trace.events.size(), 4u);
            EXPECT_EQ(trace.events[trace.events.size() - 2].kind, Kind::cell) << "the root's cell comes right before it";
        }
    EXPECT_GT(hits, 50);
}

/// A u8 sphere of side n at isovalue 60, seen by the default camera at width x height.
struct SphereScene {
    SphereScene(uint32_t n, int width, int height)
        : volume(make_field<uint8_t>(Field::Sphere, {n, n, n})), data(build_octree(volume.view(), {})),
          camera(frame_data_box(volume.dims, placement, width, height)) {
        options.isovalues = {60.0};
    }
    PixelTrace trace(int x, int y) const { return trace_pixel(data.view(), placement, camera, options, x, y); }
    DenseVolume<uint8_t> volume;
    OctreeData<uint8_t> data;
    Placement placement;
    Camera camera;
    RenderOptions options;
};

TEST(DebugTrace, EventsNestInsideTheClipAndTheTextNamesThem) {
    const SphereScene scene(40, 16, 16);
    const PixelTrace trace = scene.trace(8, 8);
    ASSERT_GE(trace.iso_index, 0) << "the centre pixel sees the sphere";
    const PixelTraceEvent& clip = trace.events.front();
    int nodes = 0, cells = 0;
    for (const PixelTraceEvent& e : trace.events) {
        if (e.kind == Kind::clip || e.kind == Kind::root) continue;
        nodes += e.kind == Kind::node;
        cells += e.kind == Kind::cell;
        EXPECT_GE(e.t0, clip.t0);
        EXPECT_LE(e.t1, clip.t1);
        EXPECT_LE(e.t0, e.t1);
        if (e.kind == Kind::node) {
            EXPECT_LT(e.depth, scene.data.dmax - 1);
        }
    }
    EXPECT_GE(nodes, 1);
    EXPECT_GE(cells, 1);
    EXPECT_EQ(trace.events[1].kind, Kind::node);
    EXPECT_EQ(trace.events[1].depth, 0) << "the walk starts at the root";
    const std::string text = trace.text();
    EXPECT_NE(text.find("pixel (8,8) of 16x16"), std::string::npos) << text;
    EXPECT_NE(text.find("node depth 0 #0"), std::string::npos) << text;
    EXPECT_NE(text.find("cell ("), std::string::npos) << text;
    EXPECT_NE(text.find("\nhit t "), std::string::npos) << text;
}

TEST(DebugTrace, PixelOutsideTheImageIsRefused) {
    const SphereScene scene(12, 16, 8);
    for (const auto& [x, y] : {std::pair{16, 0}, std::pair{0, 8}, std::pair{-1, 3}, std::pair{3, -1}}) {
        try {
            (void)scene.trace(x, y);
            ADD_FAILURE() << x << "," << y << " was traced";
        } catch (const Error& e) {
            EXPECT_EQ(e.subject(), "--debug-pixel");
            EXPECT_EQ(e.exit_status(), 2);
        }
    }
    EXPECT_NO_THROW((void)scene.trace(15, 7));
}

}  // namespace
}  // namespace octiso::test
