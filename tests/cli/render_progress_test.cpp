// render_in_batches (src/cli/render_progress.h): a frame traced in batches of tiles, as octiso-render
// does while its progress line is on, is Renderer::render's frame bit for bit (colour, depth,
// normal, rays and hits), for one tile a batch, uneven batches and one batch; the callback sees
// every tile counted once, in order.
#include <gtest/gtest.h>

#include "cli/render_progress.h"
#include "octiso/any_octree.h"
#include "octiso/loaded_volume.h"
#include "octiso/synthetic.h"

namespace octiso::test {
namespace {

TEST(RenderInBatches, FrameIsRendersBitForBitWhateverTheBatches) {
    const AnyOctree tree = AnyOctree::build(synthetic_step("marschner-lobb", {24, 24, 24}, 0), {});
    RenderOptions o;
    o.isovalues = {0.3, 0.6};
    o.want_colour = o.want_depth = o.want_normal = true;
    const Renderer renderer = tree.make_renderer(o);
    const Camera camera = frame_data_box(tree.dims(), tree.placement(), 61, 43);   // edge tiles cut
    Frame whole;
    renderer.render(camera, whole);
    ASSERT_GT(whole.stats.hits, 0u);
    const int count = renderer.tile_grid(61, 43).count();
    ASSERT_GT(count, 8);
    struct Case { int first; double seconds; };
    for (const Case c : {Case{1, 0.0}, Case{3, 0.0}, Case{5, 1e-9}, Case{count, 0.25}, Case{16, 0.25}}) {
        SCOPED_TRACE(c.first);
        Frame batched;
        batched.depth.assign(7, 1.0f);   // a stale buffer of another size is resized, as render() does
        int last = 0, calls = 0;
        const RenderStats s = cli::render_in_batches(renderer, camera, batched, [&](int done, int n) {
            EXPECT_EQ(n, count);
            EXPECT_GT(done, last);
            last = done, ++calls;
        }, c.first, c.seconds);
        EXPECT_EQ(last, count);
        if (c.seconds == 0.0) {
            EXPECT_EQ(calls, 1 + count - c.first);   // one tile a batch after the first
        }
        EXPECT_EQ(batched.rgb, whole.rgb);
        EXPECT_EQ(batched.depth, whole.depth);
        EXPECT_EQ(batched.normal, whole.normal);
        EXPECT_EQ(s.rays, whole.stats.rays);
        EXPECT_EQ(s.hits, whole.stats.hits);
        EXPECT_EQ(batched.stats.hits, whole.stats.hits);
    }
}

}  // namespace
}  // namespace octiso::test
