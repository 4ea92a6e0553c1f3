// The persistent Renderer (include/octiso/render.h): a frame rendered tile by tile, in any
// order and split over several calls, equals the whole frame bit for bit; new options on a kept
// Renderer equal a fresh one; reused buffers carry nothing over; bad calls are refused.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "octiso/build.h"
#include "octiso/error.h"
#include "octiso/render.h"
#include "render/render_test_util.h"

namespace octiso::test {
namespace {

bool same_depth(const std::vector<float>& a, const std::vector<float>& b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (!(a[i] == b[i] || (std::isinf(a[i]) && std::isinf(b[i])))) return false;
    return true;
}

void expect_identical(const Frame& a, const Frame& b) {
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    EXPECT_EQ(a.rgb, b.rgb);
    EXPECT_EQ(a.normal, b.normal);
    EXPECT_TRUE(same_depth(a.depth, b.depth));
}

class RendererTest : public ::testing::Test {
protected:
    RendererTest() : volume_(make_field<uint8_t>(Field::MarschnerLobb, {29, 31, 27})), data_(build_octree(volume_.view(), {})) {
        options_.isovalues = {47.0};
        options_.want_depth = options_.want_normal = true;
        camera_ = frame_data_box(volume_.dims, Placement{}, 83, 61);   // odd sizes: cut edge tiles
    }
    DenseVolume<uint8_t> volume_;
    OctreeData<uint8_t> data_;
    RenderOptions options_;
    Camera camera_;
};

TEST_F(RendererTest, TilesInAnyOrderOverSeveralCallsEqualTheWholeFrame) {
    for (bool embree : {true, false}) {
        options_.use_embree = embree;
        options_.tile_size = 8;
        const Renderer renderer(data_.view(), Placement{}, options_);
        const Frame whole = renderer.render(camera_);
        ASSERT_GT(whole.stats.hits, 500u);
        EXPECT_EQ(whole.stats.rays, uint64_t(83) * 61);

        const int count = renderer.tile_grid(camera_.width, camera_.height).count();
        std::vector<int> tiles(static_cast<size_t>(count));
        std::iota(tiles.begin(), tiles.end(), 0);
        std::shuffle(tiles.begin(), tiles.end(), std::mt19937(7));
        Frame parts;
        renderer.prepare_frame(camera_, parts);
        const size_t half = tiles.size() / 2;
        const RenderStats a = renderer.render_tiles(camera_, std::span(tiles).first(half), parts);
        const RenderStats b = renderer.render_tiles(camera_, std::span(tiles).subspan(half), parts);
        EXPECT_EQ(a.rays + b.rays, whole.stats.rays);
        EXPECT_EQ(a.hits + b.hits, whole.stats.hits);
        expect_identical(parts, whole);
    }
}

TEST_F(RendererTest, PartialRenderTouchesOnlyItsTiles) {
    const Renderer renderer(data_.view(), Placement{}, options_);
    Frame frame;
    renderer.prepare_frame(camera_, frame);
    std::fill(frame.depth.begin(), frame.depth.end(), -7.0f);
    const TileGrid grid = renderer.tile_grid(camera_.width, camera_.height);
    const int tile = grid.count() / 2;
    renderer.render_tiles(camera_, std::span(&tile, 1), frame);
    const PixelRect r = grid.rect(tile);
    for (int y = 0; y < camera_.height; ++y)
        for (int x = 0; x < camera_.width; ++x) {
            const bool inside = x >= r.x0 && x < r.x1 && y >= r.y0 && y < r.y1;
            ASSERT_EQ(frame.depth[size_t(y) * camera_.width + x] == -7.0f, !inside) << x << "," << y;
        }
}

TEST_F(RendererTest, NewOptionsOnAKeptRendererEqualAFreshOne) {
    Renderer kept(data_.view(), Placement{}, options_);
    (void)kept.render(camera_);
    for (RootFinder finder : {RootFinder::exact, RootFinder::linear, RootFinder::neubauer}) {
        RenderOptions changed = options_;
        changed.isovalues = {30.0, 85.0};
        changed.root_finder = finder;
        changed.threads = 1;
        kept.set_options(changed);
        const Frame a = kept.render(camera_);
        const Frame b = render(data_.view(), Placement{}, camera_, changed);
        EXPECT_GT(a.stats.hits, 500u);
        EXPECT_EQ(a.stats.threads, 1);
        expect_identical(a, b);
    }
}

TEST_F(RendererTest, ReusedFrameBuffersCarryNothingOver) {
    const Renderer renderer(data_.view(), Placement{}, options_);
    Frame reused;
    renderer.render(camera_, reused);
    Camera aside = camera_;
    aside.eye = {aside.eye[0] * 3, aside.eye[1] * 3, aside.eye[2] * 3};   // mostly misses now
    renderer.render(aside, reused);
    expect_identical(reused, renderer.render(aside));
}

TEST_F(RendererTest, BusyTimeIsTheTilesOwnAndFitsInsideTheLoop) {
    // Issue 12: busy_seconds sums each tile's own wall time. The tiles of one loop run inside its
    // interval, at most `threads` at once, so the sum cannot exceed threads x the loop's wall time;
    // a frame traces something, so it is positive. (A structural bound, not a speed.)
    for (int threads : {1, 2}) {
        RenderOptions o = options_;
        o.threads = threads;
        const Renderer renderer(data_.view(), Placement{}, o);
        const RenderStats stats = renderer.render(camera_).stats;
        EXPECT_EQ(stats.threads, threads);
        EXPECT_GT(stats.busy_seconds, 0.0);
        EXPECT_LE(stats.busy_seconds, double(stats.threads) * stats.seconds + 1e-6) << threads << " threads";
    }
}

TEST_F(RendererTest, EitherTileOrderOnAnyThreadCountGivesTheSameFrame) {
    // Issue 12: sweep hands tiles out through one shared counter instead of TBB's split.
    const Frame reference = Renderer(data_.view(), Placement{}, options_).render(camera_);
    for (TileOrder order : {TileOrder::split, TileOrder::sweep})
        for (int threads : {1, 2, 3, 7}) {
            RenderOptions o = options_;
            o.tile_order = order;
            o.threads = threads;
            const Renderer renderer(data_.view(), Placement{}, o);
            Frame f = renderer.render(camera_);
            expect_identical(f, reference);
            EXPECT_EQ(f.stats.rays, uint64_t(camera_.width) * uint64_t(camera_.height));
            EXPECT_EQ(f.stats.hits, reference.stats.hits);
            // A subset of tiles, in either order, traces exactly the pixels of those tiles.
            const std::vector<int> some{0, 3, 5};
            const TileGrid grid = renderer.tile_grid(camera_.width, camera_.height);
            uint64_t pixels = 0;
            for (int t : some) {
                const PixelRect r = grid.rect(t);
                pixels += uint64_t(r.x1 - r.x0) * uint64_t(r.y1 - r.y0);
            }
            Frame part;
            renderer.prepare_frame(camera_, part);
            EXPECT_EQ(renderer.render_tiles(camera_, some, part).rays, pixels);
        }
}

TEST_F(RendererTest, BadCallsAreRefused) {
    const Renderer renderer(data_.view(), Placement{}, options_);
    Frame frame;
    EXPECT_THROW(renderer.render_tiles(camera_, {}, frame), Error);   // not prepared
    renderer.prepare_frame(camera_, frame);
    const int outside = renderer.tile_grid(camera_.width, camera_.height).count();
    EXPECT_THROW(renderer.render_tiles(camera_, std::span(&outside, 1), frame), Error);
    Camera flat = camera_;
    flat.look = flat.eye;
    EXPECT_THROW(renderer.render(flat), Error);
    RenderOptions none = options_;
    none.isovalues.clear();
    Renderer kept(data_.view(), Placement{}, options_);
    EXPECT_THROW(kept.set_options(none), Error);
    EXPECT_THROW(Renderer(data_.view(), Placement{}, none), Error);
}

TEST_F(RendererTest, IsoRangeOfTheSourceIsEnforced) {
    const RenderLimits limits{std::array<double, 2>{20.0, 60.0}, "ranged.oct"};
    EXPECT_NO_THROW(Renderer(data_.view(), Placement{}, options_, limits));
    RenderOptions outside = options_;
    outside.isovalues = {47.0, 60.0};   // the range is open: HI itself was clamped
    try {
        Renderer(data_.view(), Placement{}, outside, limits);
        FAIL() << "an isovalue on the iso-range's edge must be refused";
    } catch (const Error& e) {
        EXPECT_EQ(e.subject(), "--iso");
        EXPECT_NE(e.problem().find("ranged.oct"), std::string::npos) << e.problem();
        EXPECT_EQ(e.exit_status(), 2);
    }
}

}  // namespace
}  // namespace octiso::test
