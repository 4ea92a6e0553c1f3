// AnyOctree (include/octiso/any_octree.h) against the typed API it wraps: for all 8 scalar types,
// build -> save -> open -> render gives the frame the typed path gives, bit for bit; info, decode
// and the iso-range refusal answer what the typed pieces answer; a file step keeps its mapping
// alive after the caller drops the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <memory>

#include "octiso/any_octree.h"
#include "octiso/build.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/reader.h"
#include "octiso/render.h"
#include "render/render_test_util.h"
#include "test_util/scratch_dir.h"

namespace octiso::test {
namespace {

Placement skewed_placement() {
    Placement p;
    p.spacing = {1.0, 1.5, 0.75};
    p.origin = {-4.0, 2.0, 10.0};
    return p;
}

RenderOptions all_outputs(double iso) {
    RenderOptions o;
    o.isovalues = {iso};
    o.want_colour = o.want_depth = o.want_normal = true;
    return o;
}

Camera view_of(Dims dims, const Placement& p) {
    const std::array<double, 3> centre{p.origin[0] + (dims.x - 1) * p.spacing[0] / 2,
                                       p.origin[1] + (dims.y - 1) * p.spacing[1] / 2,
                                       p.origin[2] + (dims.z - 1) * p.spacing[2] / 2};
    return look_at({centre[0] + 45, centre[1] - 38, centre[2] + 30}, centre, {0, 0, 1}, 38, 40);
}

/// Colour bytes, and depth and normal bit patterns (floats compared as bytes: NaN-safe, -0 exact).
void expect_identical_frames(const Frame& a, const Frame& b) {
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    EXPECT_TRUE(a.rgb == b.rgb);
    ASSERT_EQ(a.depth.size(), b.depth.size());
    ASSERT_EQ(a.normal.size(), b.normal.size());
    EXPECT_EQ(0, std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)));
    EXPECT_EQ(0, std::memcmp(a.normal.data(), b.normal.data(), a.normal.size() * sizeof(float)));
    EXPECT_EQ(a.stats.hits, b.stats.hits);
}

template <typename T> void expect_same_arrays(const Octree<T>& a, const Octree<T>& b) {
    ASSERT_EQ(a.dmax(), b.dmax());
    for (int d = 0; d + 1 < a.dmax(); ++d) {
        ASSERT_EQ(a.node_count(d), b.node_count(d)) << "depth " << d;
        if (a.node_count(d) != 0) {
            EXPECT_EQ(0, std::memcmp(&a.node(d, 0), &b.node(d, 0), a.node_count(d) * sizeof(InteriorNode<T>)));
        }
    }
    ASSERT_EQ(a.cap_count(), b.cap_count());
    ASSERT_EQ(a.cap_bytes(), b.cap_bytes());
    if (a.cap_bytes() != 0) {
        EXPECT_EQ(0, std::memcmp(a.arrays().caps, b.arrays().caps, a.cap_bytes()));
    }
}

template <typename T> class AnyOctreeTyped : public ::testing::Test {};
TYPED_TEST_SUITE(AnyOctreeTyped, AllScalarTypes);

TYPED_TEST(AnyOctreeTyped, BuildSaveOpenRenderEqualsTheTypedPath) {
    using T = TypeParam;
    ScratchDir dir("octiso_any_octree");
    const Dims dims{21, 17, 19};
    const auto v = make_field<T>(Field::Torus, dims);
    const Placement placement = skewed_placement();
    const Camera camera = view_of(dims, placement);
    const RenderOptions options = all_outputs(47.0);

    const OctreeData<T> typed = build_octree(v.view(), BuildOptions{});
    const Frame expected = render(typed.view(), placement, camera, options);
    ASSERT_GT(expected.stats.hits, 0u) << "the view must show the surface";

    const AnyOctree built = AnyOctree::build(v.view(), placement, BuildOptions{});
    EXPECT_EQ(built.type(), scalar_type_of<T>());
    EXPECT_EQ(built.dims(), dims);
    EXPECT_EQ(built.placement().spacing, placement.spacing);
    EXPECT_EQ(built.file(), nullptr);
    ASSERT_NE(built.as<T>(), nullptr);
    expect_same_arrays(*built.as<T>(), typed.view());
    expect_identical_frames(built.render(camera, options), expected);

    const std::string path = dir.file("t.oct");
    built.save(path);
    const AnyOctree opened = AnyOctree::open(path);
    EXPECT_EQ(opened.type(), scalar_type_of<T>());
    EXPECT_EQ(opened.dims(), dims);
    EXPECT_EQ(opened.placement().origin, placement.origin);
    ASSERT_NE(opened.file(), nullptr);
    EXPECT_EQ(opened.file()->info().step_count, 1u);
    expect_same_arrays(*opened.as<T>(), typed.view());
    expect_identical_frames(opened.render(camera, options), expected);
    // A persistent renderer gives the same frame twice, and keeps the file mapped after every
    // AnyOctree handle of it is gone.
    const Renderer renderer = AnyOctree::open(path).make_renderer(options);
    expect_identical_frames(renderer.render(camera), expected);
    expect_identical_frames(renderer.render(camera), expected);
}

TYPED_TEST(AnyOctreeTyped, InfoMatchesBuildStatsFileSizesAndTheData) {
    using T = TypeParam;
    ScratchDir dir("octiso_any_octree");
    const Dims dims{13, 9, 11};
    const auto v = make_volume<T>(dims, Pattern::Sparse, 5);
    const OctreeData<T> typed = build_octree(v.view(), BuildOptions{});
    const AnyOctree built = AnyOctree::build(v.view(), skewed_placement(), BuildOptions{});
    const AnyOctreeInfo a = built.info();
    EXPECT_EQ(a.type, scalar_type_of<T>());
    EXPECT_EQ(a.dmax, typed.dmax);
    EXPECT_EQ(a.sizes.nodes_per_depth, typed.stats.nodes_per_depth);
    EXPECT_EQ(a.sizes.scalar_leaves_per_depth, typed.stats.scalar_leaves_per_depth);
    EXPECT_EQ(a.sizes.interior_bytes, typed.stats.interior_bytes);
    EXPECT_EQ(a.sizes.cap_bytes, typed.stats.cap_bytes);
    EXPECT_EQ(a.dense_bytes, dims.voxels() * sizeof(T));
    // Every voxel is a corner of some data cell here, so the root's ranges give the data's range.
    ASSERT_TRUE(a.value_range);
    const auto [lo, hi] = std::minmax_element(v.values.begin(), v.values.end());
    EXPECT_EQ((*a.value_range)[0], double(*lo));
    EXPECT_EQ((*a.value_range)[1], double(*hi));

    const std::string path = dir.file("i.oct");
    built.save(path);
    const AnyOctree opened = AnyOctree::open(path);
    const AnyOctreeInfo b = opened.info();
    const StepSizes file_sizes = opened.file()->step_sizes(0);
    EXPECT_EQ(b.sizes.nodes_per_depth, file_sizes.nodes_per_depth);
    EXPECT_EQ(b.sizes.scalar_leaves_per_depth, file_sizes.scalar_leaves_per_depth);
    EXPECT_EQ(b.sizes.interior_bytes, a.sizes.interior_bytes);
    EXPECT_EQ(b.sizes.minmax_bytes, a.sizes.minmax_bytes);
    EXPECT_EQ(b.sizes.cap_bytes, a.sizes.cap_bytes);
    EXPECT_EQ(b.value_range, a.value_range);
    EXPECT_EQ(b.source, path);
}

TYPED_TEST(AnyOctreeTyped, DecodeGivesTheInputInEitherByteOrder) {
    using T = TypeParam;
    const Dims dims{10, 7, 5};
    const auto v = make_volume<T>(dims, Pattern::Random, 3);
    const AnyOctree tree = AnyOctree::build(v.view(), Placement{}, BuildOptions{});
    const size_t bytes = v.values.size() * sizeof(T);
    ASSERT_EQ(tree.dense_bytes(), bytes);

    std::vector<std::byte> native(bytes);
    tree.decode(native);
    EXPECT_EQ(0, std::memcmp(native.data(), v.values.data(), bytes));

    // Opposite byte order, into a buffer that is deliberately misaligned for T.
    const std::endian other = std::endian::native == std::endian::little ? std::endian::big : std::endian::little;
    std::vector<std::byte> storage(bytes + 1);
    tree.decode(std::span<std::byte>(storage.data() + 1, bytes), other);
    for (size_t i = 0; i < v.values.size(); ++i) {
        T x;
        std::memcpy(&x, storage.data() + 1 + i * sizeof(T), sizeof(T));
        const T back = VolumeView<T>::byte_swapped(x);
        ASSERT_EQ(0, std::memcmp(&back, &v.values[i], sizeof(T))) << i;
    }
    std::vector<std::byte> wrong(bytes - 1);
    EXPECT_THROW(tree.decode(wrong), Error);
}

TYPED_TEST(AnyOctreeTyped, BuildFromALoadedVolumeEqualsTheTypedBuild) {
    using T = TypeParam;
    const Dims dims{12, 6, 9};
    auto owned = std::make_shared<std::vector<T>>(make_volume<T>(dims, Pattern::Blocky, 1).values);
    const LoadedVolume volume(owned, reinterpret_cast<const std::byte*>(owned->data()), scalar_type_of<T>(), dims,
                              skewed_placement(), false, "blocky", VolumeFormat::synthetic);
    const AnyOctree tree = AnyOctree::build(volume, BuildOptions{});
    EXPECT_EQ(tree.placement().spacing, skewed_placement().spacing);
    EXPECT_EQ(tree.info().source, "blocky");
    const OctreeData<T> typed = build_octree(volume.view<T>(), BuildOptions{});
    expect_same_arrays(*tree.as<T>(), typed.view());
}

TEST(AnyOctree, AsOtherTypeIsNull) {
    const auto v = make_volume<int16_t>({5, 5, 5}, Pattern::Random, 2);
    const AnyOctree tree = AnyOctree::build(v.view(), Placement{}, BuildOptions{});
    EXPECT_NE(tree.as<int16_t>(), nullptr);
    EXPECT_EQ(tree.as<uint16_t>(), nullptr);
    EXPECT_EQ(tree.as<float>(), nullptr);
}

TEST(AnyOctree, NoValueRangeWithoutCells) {
    const auto v = make_volume<float>({6, 1, 4}, Pattern::Random, 4);
    EXPECT_FALSE(AnyOctree::build(v.view(), Placement{}, BuildOptions{}).info().value_range);
}

TEST(AnyOctree, RendererRefusesIsovaluesOutsideTheIsoRange) {
    ScratchDir dir("octiso_any_octree");
    const auto v = make_field<uint8_t>(Field::Sphere, {16, 16, 16});
    BuildOptions opt;
    opt.iso_range = std::array<double, 2>{10.0, 100.0};
    opt.source_name = "sphere-in-memory";
    const AnyOctree built = AnyOctree::build(v.view(), Placement{}, opt);
    EXPECT_EQ(built.render_limits().iso_range, opt.iso_range);
    try {
        built.make_renderer(all_outputs(5.0));
        ADD_FAILURE() << "isovalue 5 lies outside (10, 100)";
    } catch (const Error& e) {
        EXPECT_EQ(e.exit_status(), 2);
        EXPECT_NE(std::string(e.what()).find("sphere-in-memory"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(built.make_renderer(all_outputs(50.0)));

    const std::string path = dir.file("r.oct");
    built.save(path);
    const AnyOctree opened = AnyOctree::open(path);
    EXPECT_EQ(opened.info().iso_range, opt.iso_range);
    try {
        opened.render(view_of({16, 16, 16}, Placement{}), all_outputs(120.0));
        ADD_FAILURE() << "isovalue 120 lies outside (10, 100)";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
}

TEST(AnyOctree, SeriesStepsOutliveTheFileHandleAndBadStepsThrow) {
    ScratchDir dir("octiso_any_octree");
    const Dims dims{9, 8, 7};
    const auto a = make_volume<uint16_t>(dims, Pattern::Sparse, 1), b = make_volume<uint16_t>(dims, Pattern::Blocky, 2);
    const AnyOctree ta = AnyOctree::build(a.view(), Placement{}, BuildOptions{});
    const AnyOctree tb = AnyOctree::build(b.view(), Placement{}, BuildOptions{});
    const std::string path = dir.file("s.oct");
    {
        OctWriter writer(path, ta.oct_info());
        ta.append_to(writer);
        tb.append_to(writer);
        writer.finish();
    }
    auto file = std::make_shared<const OctFile>(OctFile::open(path));
    const AnyOctree step1 = AnyOctree::step(file, 1);
    try {
        AnyOctree::step(file, 2);
        ADD_FAILURE() << "step 2 does not exist";
    } catch (const Error& e) {
        EXPECT_EQ(e.exit_status(), 2);
    }
    file.reset();   // the step keeps the mapping alive
    std::vector<std::byte> out(step1.dense_bytes());
    step1.decode(out);
    EXPECT_EQ(0, std::memcmp(out.data(), b.values.data(), out.size()));

    // A step of another type is refused by the writer, not written.
    const auto f = make_volume<float>(dims, Pattern::Random, 3);
    OctWriter writer(dir.file("mixed.oct"), ta.oct_info());
    EXPECT_THROW(AnyOctree::build(f.view(), Placement{}, BuildOptions{}).append_to(writer), Error);
}

}  // namespace
}  // namespace octiso::test
