// view/session.h on a scaled NIfTI (scl_slope/scl_inter, CONVENTIONS 2b): /info, the histogram,
// the isovalue a frame is asked for and the command it offers are real values; the frame is the
// image of the stored isovalue, and octiso-render run with the offered command writes the same
// pixels. Each file is converted from a NIfTI written byte by byte (tests/io/nifti_test_file.h),
// and every expectation is worked out here from the voxels and the slope by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "io/nifti_test_file.h"
#include "octiso/any_octree.h"
#include "octiso/convert.h"
#include "octiso/error.h"
#include "octiso/image.h"
#include "test_util/run_shell.h"
#include "test_util/scratch_dir.h"
#include "test_util/skip.h"
#include "view/png.h"
#include "view/session.h"

namespace octiso::view {
namespace {

constexpr Dims kDims{22, 20, 18};

/// Ten times the distance from a point off the grid's centre: a sphere for every isovalue, as i16.
std::vector<int16_t> ball_values() {
    std::vector<int16_t> v(kDims.voxels());
    for (uint32_t z = 0; z < kDims.z; ++z)
        for (uint32_t y = 0; y < kDims.y; ++y)
            for (uint32_t x = 0; x < kDims.x; ++x) {
                const double dx = x - 10.3, dy = y - 9.6, dz = z - 8.2;
                v[x + kDims.x * (y + size_t(kDims.y) * z)] = int16_t(std::lround(10 * std::sqrt(dx * dx + dy * dy + dz * dz)));
            }
    return v;
}

/// Writes the values as a NIfTI with scl_slope/scl_inter and converts it (with `iso_range` in
/// real values, if given) to `out`.
void write_scaled_oct(const std::string& nii, const std::string& out, float slope, float inter,
                      std::optional<std::array<double, 2>> iso_range = {}) {
    test::Nifti1 n;
    n.dim[1] = int16_t(kDims.x), n.dim[2] = int16_t(kDims.y), n.dim[3] = int16_t(kDims.z);
    n.slope = slope, n.inter = inter;
    const std::vector<int16_t> v = ball_values();
    test::write_file(nii, n.bytes(std::string(reinterpret_cast<const char*>(v.data()), v.size() * 2)));
    BuildOptions options;
    options.iso_range = iso_range;
    convert(ConvertSource::file(nii), out, options);
}

FrameRequest request(double iso, int w, int h) {
    FrameRequest r;
    r.iso = iso, r.azimuth_deg = 35, r.elevation_deg = 25, r.zoom = 1.2, r.width = w, r.height = h;
    return r;
}

class ViewSessionScale : public ::testing::Test {
protected:
    test::ScratchDir dir_{"octiso_view_scale"};
    std::string nii_ = dir_.file("ball.nii"), path_ = dir_.file("ball.oct");
};

TEST_F(ViewSessionScale, InfoAndHistogramAreInRealValues) {
    // A negative slope: real = -0.25 * stored + 40, so the real range's ends are the stored ones swapped.
    write_scaled_oct(nii_, path_, -0.25f, 40);
    const std::vector<int16_t> v = ball_values();
    const auto [smin, smax] = std::minmax_element(v.begin(), v.end());
    const double lo = -0.25 * *smax + 40, hi = -0.25 * *smin + 40;
    const ViewSession session(path_, 2);
    const std::string& info = session.info_json();
    char expected_range[96];
    std::snprintf(expected_range, sizeof expected_range, "\"value_range\":[%g,%g]", lo, hi);
    EXPECT_NE(info.find(expected_range), std::string::npos) << info;
    EXPECT_NE(info.find("\"value_scale\":[-0.25,40]"), std::string::npos) << info;

    const Histogram& h = session.histogram();
    EXPECT_EQ(h.lo, lo);
    EXPECT_EQ(h.hi, hi);
    ASSERT_EQ(h.counts.size(), 128u);
    std::vector<uint64_t> expected(128, 0);
    for (const int16_t s : v) {
        const double real = -0.25 * s + 40;   // exact in binary: a quarter of an integer, plus 40
        expected[std::min<size_t>(127, size_t((real - lo) / (hi - lo) * 128))]++;
    }
    EXPECT_EQ(h.counts, expected);
    // The histogram is of the real values: the voxels far from the centre (small real values) lie
    // in the first bins, the centre's (the largest real value) in the last.
    EXPECT_GT(h.counts.back(), 0u);
    EXPECT_GT(h.counts.front(), 0u);
}

// A step too large to decode (the 2048x2048x1920 step: 7.5 GiB dense) gets its histogram from
// the tree: forced here with a limit of 0 bytes. Without a scale it is the dense path's, bin for
// bin; with a negative slope the same voxels over the same real range, in reversed bins (a value
// on a bin edge may land one bin over, so the test asserts the totals and the ends).
TEST_F(ViewSessionScale, HistogramFromTheTreeMatchesTheDecodedOne) {
    write_scaled_oct(nii_, path_, 1.0f, 0.0f);
    const AnyOctree plain = AnyOctree::open(path_);
    const Histogram dense = value_histogram(plain, 128, uint64_t(1) << 30), tree = value_histogram(plain, 128, 0);
    EXPECT_EQ(tree.lo, dense.lo);
    EXPECT_EQ(tree.hi, dense.hi);
    EXPECT_EQ(tree.counts, dense.counts);

    write_scaled_oct(nii_, path_, -0.25f, 40);
    const AnyOctree scaled = AnyOctree::open(path_);
    const Histogram d = value_histogram(scaled, 128, uint64_t(1) << 30), t = value_histogram(scaled, 128, 0);
    EXPECT_EQ(t.lo, d.lo);
    EXPECT_EQ(t.hi, d.hi);
    ASSERT_EQ(t.counts.size(), 128u);
    uint64_t total = 0;
    for (const uint64_t c : t.counts) total += c;
    EXPECT_EQ(total, kDims.voxels());
    EXPECT_GT(t.counts.front(), 0u);   // the corners' small real values
    EXPECT_GT(t.counts.back(), 0u);    // the centre's largest
}

TEST_F(ViewSessionScale, FrameAtARealIsovalueIsTheStoredIsovaluesImageAndTheCommandReproducesIt) {
    const std::string tools = OCTISO_TOOLS_DIR;
    if (!std::filesystem::exists(tools + "/octiso-render")) {
        OCTISO_SKIP("octiso-render not built");
    }
    write_scaled_oct(nii_, path_, 0.5f, -10);   // real = 0.5 * stored - 10
    ViewSession session(path_, 2);
    const double real_iso = 25.25, stored_iso = (25.25 + 10) / 0.5;   // 70.5: between voxel values, no tie
    const FrameReply reply = session.render(request(real_iso, 40, 30));

    const AnyOctree tree = AnyOctree::open(path_);
    RenderOptions options;
    options.isovalues = {stored_iso};
    const Frame expected = tree.render(session.camera_for(request(real_iso, 40, 30)), options);
    EXPECT_GT(expected.stats.hits, 100u);
    EXPECT_EQ(reply.body, encode_png(expected)) << "the frame of the stored isovalue";
    options.isovalues = {real_iso};
    EXPECT_NE(tree.render(session.camera_for(request(real_iso, 40, 30)), options).rgb, expected.rgb)
        << "the real value taken as a stored one draws another surface: the test would prove nothing";

    const std::string prefix = "octiso-render " + path_ + " --iso 25.25 ";
    ASSERT_EQ(reply.command.rfind(prefix, 0), 0u) << reply.command;
    const std::string tail = " -o frame.png";
    ASSERT_EQ(reply.command.substr(reply.command.size() - tail.size()), tail) << reply.command;
    const std::string flags = reply.command.substr(prefix.size(), reply.command.size() - prefix.size() - tail.size());
    const std::string out = dir_.file("frame.png");
    const std::string command = "'" + tools + "/octiso-render' '" + path_ + "' --iso 25.25 " + flags + " -o '" + out + "' 2>/dev/null";
    ASSERT_EQ(test::run_shell(command), 0) << command;
    const FloatImage written = read_image(out);
    ASSERT_EQ(written.width, 40);
    ASSERT_EQ(written.height, 30);
    ASSERT_EQ(written.channels, 3);
    size_t differing = 0;
    for (size_t i = 0; i < expected.rgb.size(); ++i) differing += std::lround(written.pixels[i] * 255.0f) != expected.rgb[i];
    EXPECT_EQ(differing, 0u);
}

TEST_F(ViewSessionScale, IsoRangeIsCheckedAndNamedInRealValues) {
    // Converted with --iso-range 0,60 in real values: stored (20, 140).
    write_scaled_oct(nii_, path_, 0.5f, -10, std::array<double, 2>{0.0, 60.0});
    EXPECT_NE(ViewSession(path_, 1, 25.25).info_json().find("\"iso_range\":[0,60]"), std::string::npos);
    ViewSession session(path_, 1);
    EXPECT_GT(session.render(request(59.5, 8, 8)).stats.rays, 0u);
    for (const double outside : {60.0, 65.0, -1.0}) {
        try {
            session.render(request(outside, 8, 8));
            ADD_FAILURE() << outside << " lies outside the iso-range";
        } catch (const Error& e) {
            EXPECT_EQ(e.subject(), "iso");
            EXPECT_NE(std::string(e.what()).find("outside the file's iso-range (0, 60)"), std::string::npos) << e.what();
        }
    }
    // Stored 130 lies inside the stored range, but the real value 130 does not: it is refused.
    EXPECT_THROW(ViewSession(path_, 1, 130.0), Error);
}

}  // namespace
}  // namespace octiso::view
