// compare_frames is the instrument every rendering test and benchmark measures with, so it is
// checked on hand-built frames whose mismatches, depth errors and normal angles are known.
#include <cmath>

#include <gtest/gtest.h>

#include "octiso/error.h"
#include "reference/reference_render.h"

namespace octiso::test {
namespace {

Frame frame_of(std::vector<float> depth, std::vector<float> normal = {}) {
    Frame f;
    f.width = int(depth.size());
    f.height = 1;
    f.depth = std::move(depth);
    f.normal = std::move(normal);
    return f;
}

TEST(CompareFrames, CountsMaskMismatchesAndMeasuresDepthInVoxels) {
    const float inf = INFINITY;
    //                          miss  hit   hit  miss  hit  hit
    const Frame ref = frame_of({inf, 10.0f, 20.0f, inf, 5.0f, 8.0f});
    const Frame got = frame_of({inf, 10.5f, inf, 3.0f, 5.0f, 7.0f});
    const ImageError e = compare_frames(got, ref, 0.5);   // voxel = 0.5 world units
    EXPECT_EQ(e.pixels, 6u);
    EXPECT_EQ(e.mask_mismatch, 2u);                        // pixel 2 missed, pixel 3 invented
    EXPECT_DOUBLE_EQ(e.mask_mismatch_fraction, 2.0 / 6.0);
    EXPECT_EQ(e.both_hit, 3u);                             // errors 1, 0, 2 voxels
    EXPECT_DOUBLE_EQ(e.depth_median, 1.0);
    EXPECT_DOUBLE_EQ(e.depth_max, 2.0);
    EXPECT_DOUBLE_EQ(e.depth_p99, 2.0);
    EXPECT_EQ(e.depth_above_1e3, 2u);                      // the pixels 1 and 2 voxels off
}

TEST(CompareFrames, CountsDepthErrorsAboveAThousandthOfAVoxel) {
    const Frame ref = frame_of({1.0f, 1.0f, 1.0f, 1.0f});
    const Frame got = frame_of({1.0f, 1.0f + 0.5e-3f, 1.0f + 2e-3f, 1.0f - 4e-3f});
    const ImageError e = compare_frames(got, ref, 1.0);
    EXPECT_EQ(e.both_hit, 4u);
    EXPECT_EQ(e.depth_above_1e3, 2u);
}

TEST(CompareFrames, FramesOfDifferentSizesAreRefused) {
    // A shorter frame must not compare as its common prefix (that could hide a whole missing row).
    const Frame ref = frame_of({1.0f, 2.0f, 3.0f});
    EXPECT_THROW(compare_frames(frame_of({1.0f, 2.0f}), ref, 1.0), Error);
    EXPECT_THROW(compare_frames(ref, frame_of({1.0f, 2.0f}), 1.0), Error);
    Frame transposed = ref;
    transposed.width = 1, transposed.height = 3;   // same pixel count, other shape
    EXPECT_THROW(compare_frames(transposed, ref, 1.0), Error);
    Frame short_normals = frame_of({1.0f, 2.0f, 3.0f}, {0, 0, 1, 0, 0, 1});
    EXPECT_THROW(compare_frames(short_normals, frame_of({1.0f, 2.0f, 3.0f}, {0, 0, 1, 0, 0, 1, 0, 0, 1}), 1.0), Error);
}

TEST(CompareFrames, NormalAngleInDegrees) {
    const float s = float(std::sqrt(0.5));
    const Frame ref = frame_of({1, 1, 1}, {0, 0, 1, 0, 0, 1, 1, 0, 0});
    const Frame got = frame_of({1, 1, 1}, {0, 0, 1, s, 0, s, 0, 1, 0});   // 0, 45 and 90 degrees off
    const ImageError e = compare_frames(got, ref, 1.0);
    EXPECT_NEAR(e.normal_median_deg, 45.0, 1e-4);
    EXPECT_NEAR(e.normal_max_deg, 90.0, 1e-4);
}

TEST(CompareFrames, IdenticalFramesHaveNoError) {
    const Frame f = frame_of({INFINITY, 2.0f, 3.0f}, {0, 0, 0, 1, 0, 0, 0, 1, 0});
    const ImageError e = compare_frames(f, f, 1.0);
    EXPECT_EQ(e.mask_mismatch, 0u);
    EXPECT_EQ(e.both_hit, 2u);
    EXPECT_EQ(e.depth_max, 0.0);
    EXPECT_EQ(e.normal_max_deg, 0.0);
}

}  // namespace
}  // namespace octiso::test
