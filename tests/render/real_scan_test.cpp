// The octree renderer against the exact reference on real MRI scans (Debian's mricron-data,
// installed by scripts/setup.sh; skipped if absent): u8 anatomy (ch2) at several isovalues and
// cameras, as stored and with an anisotropic spacing override, and the same data as f32 after a
// round trip through the .oct file (mmap'd view, not the in-memory tree).
#include <gtest/gtest.h>

#include <filesystem>
#include <unistd.h>

#include "octiso/build.h"
#include "octiso/oct_file.h"
#include "octiso/reader.h"
#include "octiso/render.h"
#include "reference/reference_render.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

const char* kScan = "/usr/share/mricron/templates/ch2.nii.gz";

template <typename T>
void expect_agreement(const Octree<T>& tree, const VolumeView<T>& dense, const Placement& placement, const Camera& cam,
                      double iso) {
    RenderOptions options;
    options.isovalues = {iso};
    options.want_colour = false;
    options.want_depth = options.want_normal = true;
    const Frame frame = render(tree, placement, cam, options);
    const Frame ref = render_reference(dense, placement, cam, {iso});
    const double voxel = std::min({placement.spacing[0], placement.spacing[1], placement.spacing[2]});
    const ImageError e = compare_frames(frame, ref, voxel);
    SCOPED_TRACE(::testing::Message() << "iso " << iso << " eye " << cam.eye[0] << "," << cam.eye[1] << "," << cam.eye[2]);
    EXPECT_EQ(e.mask_mismatch, 0u) << e.mask_mismatch << " of " << e.pixels << " pixels differ";
    EXPECT_LE(e.depth_above_1e3, 4u) << "pixels with depth error > 1e-3 voxel (max " << e.depth_max << ")";
    EXPECT_LE(e.depth_max, 0.018);   // the measured bar of render_test_util.h (Neubauer N=5)
    EXPECT_GT(e.both_hit, uint64_t(cam.width) * cam.height / 20) << "the surface must fill part of the view";
}

TEST(RealScan, Ch2AnatomyU8AtSeveralIsovaluesAndCameras) {
    if (!std::filesystem::exists(kScan)) {
        OCTISO_SKIP(kScan << " not installed");
    }
    const LoadedVolume vol = open_volume(kScan, {});
    ASSERT_EQ(vol.type(), ScalarType::u8);
    const VolumeView<uint8_t> dense = vol.view<uint8_t>();
    const auto data = build_octree(dense, {});
    for (const Placement& placement : {vol.placement(), Placement{{0.8, 1.0, 1.7}, {-90, 20, 5}}}) {
        const Camera framing = frame_data_box(vol.dims(), placement, 64, 56);
        Camera side = framing;
        side.eye = {framing.look[0] - 400, framing.look[1] + 30, framing.look[2] + 10};
        Camera top = framing;
        top.eye = {framing.look[0], framing.look[1], framing.look[2] + 400};
        top.up = {0, 1, 0};
        for (double iso : {40.5, 90.0, 128.0})
            for (const Camera& cam : {framing, side, top}) expect_agreement(data.view(), dense, placement, cam, iso);
    }
}

TEST(RealScan, Ch2AsFloatThroughTheOctFile) {
    if (!std::filesystem::exists(kScan)) {
        OCTISO_SKIP(kScan << " not installed");
    }
    const LoadedVolume vol = open_volume(kScan, {});
    const VolumeView<uint8_t> bytes = vol.view<uint8_t>();
    std::vector<float> values(bytes.dims.voxels());
    for (uint64_t i = 0; i < values.size(); ++i) values[i] = float(bytes.load(i)) * 0.37f - 11.0f;
    const VolumeView<float> dense{reinterpret_cast<const std::byte*>(values.data()), bytes.dims, false};
    const auto data = build_octree(dense, {});
    const std::string path = (std::filesystem::temp_directory_path() / ("octiso_ch2_" + std::to_string(::getpid()) + ".oct")).string();
    OctInfo info;
    info.type = ScalarType::f32;
    info.dims = dense.dims;
    info.placement = vol.placement();
    {
        OctWriter writer(path, info);
        writer.add_step(data.view());
        writer.finish();
    }
    const OctFile file = OctFile::open(path);
    const Camera cam = frame_data_box(dense.dims, info.placement, 64, 64);
    expect_agreement(file.step<float>(0), dense, info.placement, cam, 90.0 * 0.37 - 11.0 + 0.123);
    std::filesystem::remove(path);
}

}  // namespace
}  // namespace octiso::test
