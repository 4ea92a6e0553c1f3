// .oct files (src/format): write -> map -> identical node arrays for every scalar type, time
// series, the info a file carries, writer failure paths, and decode_to_dense against point
// location and the input array. Rejection of damaged files lives in oct_reject_test.cpp.
#include <cstring>
#include <thread>

#include "format/oct_test_util.h"
#include "octiso/decode.h"
#include "octiso/error.h"

namespace octiso::test {
namespace {

template <typename T> class OctFileRoundTrip : public ::testing::Test {};
TYPED_TEST_SUITE(OctFileRoundTrip, AllScalarTypes);

/// Byte-for-byte equality of every array of two octrees of the same grid.
template <typename T> void expect_same_arrays(const Octree<T>& a, const Octree<T>& b) {
    ASSERT_EQ(a.dims(), b.dims());
    ASSERT_EQ(a.dmax(), b.dmax());
    for (int d = 0; d + 1 < a.dmax(); ++d) {
        ASSERT_EQ(a.node_count(d), b.node_count(d)) << "depth " << d;
        if (a.node_count(d) != 0) {
            EXPECT_EQ(0, std::memcmp(&a.node(d, 0), &b.node(d, 0), a.node_count(d) * sizeof(InteriorNode<T>)))
                << "depth " << d;
        }
    }
    ASSERT_EQ(a.cap_count(), b.cap_count());
    ASSERT_EQ(a.cap_bytes(), b.cap_bytes());
    if (a.cap_bytes() != 0) {
        EXPECT_EQ(0, std::memcmp(a.arrays().caps, b.arrays().caps, a.cap_bytes()));
    }
}

template <typename T> void expect_dense_equal(const Octree<T>& tree, const DenseVolume<T>& v) {
    std::vector<T> out(v.values.size());
    decode_to_dense(tree, out.data());
    // Compare bytes: exact for floats, including signed zeros.
    ASSERT_EQ(0, std::memcmp(out.data(), v.values.data(), out.size() * sizeof(T)));
    for (uint32_t z = 0; z < v.dims.z; ++z)
        for (uint32_t y = 0; y < v.dims.y; ++y)
            for (uint32_t x = 0; x < v.dims.x; ++x)
                ASSERT_EQ(tree.point_locate({x, y, z}), v.at(x, y, z)) << x << "," << y << "," << z;
}

TYPED_TEST(OctFileRoundTrip, WriteThenOpenGivesIdenticalArraysAndInfo) {
    using T = TypeParam;
    ScratchDir dir;
    const std::string path = dir.file("a.oct");
    const Dims dims{13, 7, 10};
    uint32_t seed = 5;
    for (Pattern p : {Pattern::Blocky, Pattern::Sparse, Pattern::Random, Pattern::Constant}) {
        SCOPED_TRACE(int(p));
        const auto v = make_volume<T>(dims, p, seed++);
        const auto built = build_octree(v.view(), {});
        const OctInfo info = info_for(scalar_type_of<T>(), dims);
        write_oct<T>(path, info, {built.view()});

        const OctFile f = OctFile::open(path);
        EXPECT_EQ(f.info().type, scalar_type_of<T>());
        EXPECT_EQ(f.info().dims, dims);
        EXPECT_EQ(f.info().dmax, dmax_for(dims));
        EXPECT_EQ(f.info().placement.spacing, info.placement.spacing);
        EXPECT_EQ(f.info().placement.origin, info.placement.origin);
        EXPECT_EQ(f.info().iso_range, info.iso_range);
        EXPECT_EQ(f.info().tolerance, 0.0);
        EXPECT_EQ(f.info().step_count, 1u);
        EXPECT_EQ(f.file_bytes(), std::filesystem::file_size(path));
        EXPECT_EQ(f.file_bytes() % 8, 0u);

        const Octree<T> mapped = f.step<T>(0);
        expect_same_arrays(built.view(), mapped);
        expect_dense_equal(mapped, v);
        // Zero copy: a second request hands out the same memory.
        EXPECT_EQ(&f.step<T>(0).node(0, 0), &mapped.node(0, 0));
        // Sections are 64-byte aligned in a page-aligned mapping.
        EXPECT_EQ(reinterpret_cast<uintptr_t>(&mapped.node(0, 0)) % 64, 0u);

        // Sizes agree with what the builder counted independently.
        const StepSizes s = f.step_sizes(0);
        EXPECT_EQ(s.nodes_per_depth, built.stats.nodes_per_depth);
        EXPECT_EQ(s.scalar_leaves_per_depth, built.stats.scalar_leaves_per_depth);
        EXPECT_EQ(s.interior_bytes, built.stats.interior_bytes);
        EXPECT_EQ(s.minmax_bytes, built.stats.minmax_bytes);
        EXPECT_EQ(s.cap_bytes, built.stats.cap_bytes);
    }
}

// decode_layers (octiso-info --extract-raw's slabs): every window of layers, across odd grids
// and the cube's padding, is exactly that slice of the input; nothing outside it is written.
TYPED_TEST(OctFileRoundTrip, DecodeLayersGivesEveryWindowOfTheInput) {
    using T = TypeParam;
    uint32_t seed = 11;
    for (const Dims dims : {Dims{1, 1, 1}, Dims{13, 7, 10}, Dims{5, 3, 33}})
        for (Pattern p : {Pattern::Blocky, Pattern::Sparse, Pattern::Random}) {
            SCOPED_TRACE(std::to_string(dims.z) + " layers, pattern " + std::to_string(int(p)));
            const auto v = make_volume<T>(dims, p, seed++);
            const auto built = build_octree(v.view(), {});
            const Octree<T> tree = built.view();
            const size_t layer = size_t(dims.x) * dims.y;
            for (uint32_t z0 = 0; z0 <= dims.z; ++z0)
                for (uint32_t z1 = z0; z1 <= dims.z; ++z1) {
                    std::vector<T> out(layer * (z1 - z0) + 1);
                    std::memset(static_cast<void*>(out.data()), 0x5c, out.size() * sizeof(T));
                    decode_layers(tree, z0, z1, out.data());
                    ASSERT_EQ(0, std::memcmp(out.data(), v.values.data() + layer * z0, layer * (z1 - z0) * sizeof(T)))
                        << "layers " << z0 << ".." << z1;
                    const std::vector<unsigned char> guard(sizeof(T), 0x5c);
                    ASSERT_EQ(0, std::memcmp(&out.back(), guard.data(), sizeof(T))) << "wrote past layers " << z0 << ".." << z1;
                }
        }
}

TYPED_TEST(OctFileRoundTrip, TimeSeriesKeepsEveryStep) {
    using T = TypeParam;
    ScratchDir dir;
    const std::string path = dir.file("series.oct");
    const Dims dims{9, 17, 5};
    std::vector<DenseVolume<T>> vols;
    std::vector<OctreeData<T>> built;
    const Pattern patterns[] = {Pattern::Sparse, Pattern::Constant, Pattern::Random, Pattern::Blocky};
    for (uint32_t k = 0; k < 4; ++k) {
        vols.push_back(make_volume<T>(dims, patterns[k], 100 + k));
        built.push_back(build_octree(vols.back().view(), {}));
    }
    OctInfo info = info_for(scalar_type_of<T>(), dims);
    info.iso_range.reset();
    {
        OctWriter w(path, info);
        uint64_t last = w.bytes_written();
        for (const auto& b : built) {
            w.add_step(b.view());
            EXPECT_GT(w.bytes_written(), last);   // streamed as added, not held until finish
            last = w.bytes_written();
        }
        w.finish();
        EXPECT_EQ(w.bytes_written(), std::filesystem::file_size(path));
    }
    const OctFile f = OctFile::open(path);
    ASSERT_EQ(f.info().step_count, 4u);
    EXPECT_FALSE(f.info().iso_range.has_value());
    // Visit steps out of order: each is validated lazily on its own.
    for (uint32_t k : {2u, 0u, 3u, 1u}) {
        SCOPED_TRACE(k);
        const Octree<T> tree = f.step<T>(k);
        expect_same_arrays(built[k].view(), tree);
        expect_dense_equal(tree, vols[k]);
    }
    EXPECT_THROW(f.step<T>(4), Error);
    EXPECT_THROW(f.step_sizes(4), Error);
}

TEST(OctFile, RequestingTheWrongScalarTypeThrows) {
    ScratchDir dir;
    const auto v = make_volume<uint16_t>({6, 6, 6}, Pattern::Blocky, 1);
    const auto b = build_octree(v.view(), {});
    write_oct<uint16_t>(dir.file("a.oct"), info_for(ScalarType::u16, v.dims), {b.view()});
    const OctFile f = OctFile::open(dir.file("a.oct"));
    EXPECT_THROW(f.step<int16_t>(0), Error);
    EXPECT_THROW(f.step<float>(0), Error);
    EXPECT_THROW(f.step<uint8_t>(0), Error);
    EXPECT_NO_THROW(f.step<uint16_t>(0));
}

TEST(OctFile, ConcurrentFirstAccessValidatesOnceAndAgrees) {
    ScratchDir dir;
    const auto v = make_volume<float>({40, 21, 33}, Pattern::Sparse, 3);
    const auto b = build_octree(v.view(), {});
    write_oct<float>(dir.file("a.oct"), info_for(ScalarType::f32, v.dims), {b.view(), b.view()});
    const OctFile f = OctFile::open(dir.file("a.oct"));
    std::vector<const void*> roots(8);
    std::vector<std::thread> threads;
    for (int i = 0; i < 8; ++i)
        threads.emplace_back([&, i] { roots[size_t(i)] = &f.step<float>(uint32_t(i % 2)).node(0, 0); });
    for (auto& t : threads) t.join();
    for (int i = 2; i < 8; ++i) EXPECT_EQ(roots[size_t(i)], roots[size_t(i % 2)]);
    EXPECT_NE(roots[0], roots[1]);
}

TEST(OctFile, MovedFileKeepsItsViewsValid) {
    ScratchDir dir;
    const auto v = make_volume<int32_t>({11, 3, 8}, Pattern::Random, 9);
    const auto b = build_octree(v.view(), {});
    write_oct<int32_t>(dir.file("a.oct"), info_for(ScalarType::i32, v.dims), {b.view()});
    OctFile f = OctFile::open(dir.file("a.oct"));
    const Octree<int32_t> tree = f.step<int32_t>(0);
    OctFile g = std::move(f);
    expect_dense_equal(tree, v);
    expect_same_arrays(g.step<int32_t>(0), tree);
}

TEST(OctWriter, DestructorWithoutFinishLeavesNothing) {
    ScratchDir dir;
    const auto v = make_volume<uint8_t>({8, 8, 8}, Pattern::Blocky, 1);
    const auto b = build_octree(v.view(), {});
    {
        OctWriter w(dir.file("a.oct"), info_for(ScalarType::u8, v.dims));
        w.add_step(b.view());
        EXPECT_FALSE(std::filesystem::exists(dir.file("a.oct")));
    }
    EXPECT_TRUE(dir.entries().empty());
}

TEST(OctWriter, RefusesMismatchedOrEmptyInput) {
    ScratchDir dir;
    const auto v = make_volume<uint8_t>({8, 8, 8}, Pattern::Blocky, 1);
    const auto b = build_octree(v.view(), {});
    const auto other = make_volume<uint8_t>({9, 8, 8}, Pattern::Blocky, 1);
    const auto bo = build_octree(other.view(), {});
    const auto f = make_volume<float>({8, 8, 8}, Pattern::Blocky, 1);
    const auto bf = build_octree(f.view(), {});
    {
        OctWriter w(dir.file("a.oct"), info_for(ScalarType::u8, v.dims));
        EXPECT_THROW(w.add_step(bf.view()), Error);   // wrong scalar type
        EXPECT_THROW(w.add_step(bo.view()), Error);   // wrong grid
        EXPECT_THROW(w.finish(), Error);              // no steps
    }
    EXPECT_TRUE(dir.entries().empty());
    OctInfo bad = info_for(ScalarType::u8, v.dims);
    bad.placement.spacing[1] = 0.0;
    EXPECT_THROW(OctWriter(dir.file("b.oct"), bad), Error);
    bad = info_for(ScalarType::u8, v.dims);
    bad.tolerance = std::nan("");
    EXPECT_THROW(OctWriter(dir.file("b.oct"), bad), Error);
    bad = info_for(ScalarType::u8, v.dims);
    bad.iso_range = std::array<double, 2>{2.0, 1.0};
    EXPECT_THROW(OctWriter(dir.file("b.oct"), bad), Error);
    EXPECT_TRUE(dir.entries().empty());
}

TEST(OctWriter, RefusesAnInconsistentTree) {
    ScratchDir dir;
    const auto v = make_volume<uint8_t>({8, 8, 8}, Pattern::Random, 1);
    const auto b = build_octree(v.view(), {});
    // The root's group base one past the start of depth 1: the last child runs off the end.
    const uint64_t base = 1;
    OctreeArrays<uint8_t> a = b.view().arrays();
    a.group_base[0] = &base;
    {
        OctWriter w(dir.file("a.oct"), info_for(ScalarType::u8, v.dims));
        EXPECT_THROW(w.add_step(Octree<uint8_t>(a)), Error);
    }
    EXPECT_TRUE(dir.entries().empty());
}

// ---- decode_to_dense on a tree made by hand, independent of the builder ----

TEST(DecodeToDense, HandMadeTreeMatchesPointLocationOnEveryVoxel) {
    // dmax 2 (side 4) over a 3x4x2 grid: root children 0 (lower corner) and 5 stored as caps,
    // the rest scalar leaves (some of them pure padding).
    const Dims dims{3, 4, 2};
    InteriorNode<int16_t> root{};
    root.child_mask = 0b00100001;
    root.child_offset = 0;
    const uint64_t base = 0;
    root.cap_bits = 16;   // caps stored whole (octree.h): 8 int16 voxels each, then the read slack
    for (int c = 0; c < 8; ++c) root.scalar[c] = int16_t(-100 * c - 1);
    std::vector<int16_t> caps(2 * 8 + kCapReadSlack / sizeof(int16_t), 0);
    for (int i = 0; i < 2; ++i)
        for (int o = 0; o < 8; ++o) caps[size_t(8 * i + o)] = int16_t(10 * i + o);
    OctreeArrays<int16_t> a;
    a.dims = dims;
    a.dmax = 2;
    a.nodes[0] = &root;
    a.node_count[0] = 1;
    a.group_base[0] = &base;
    a.caps = reinterpret_cast<const uint8_t*>(caps.data());
    a.cap_bytes = 2 * 16;
    a.cap_count = 2;
    const Octree<int16_t> tree(a);

    // Expected values written out from the layout rules, not through the octree code.
    auto expected = [&](uint32_t x, uint32_t y, uint32_t z) -> int16_t {
        const int c = (x >= 2 ? 4 : 0) | (y >= 2 ? 2 : 0) | (z >= 2 ? 1 : 0);
        const int o = ((x & 1) << 2) | ((y & 1) << 1) | (z & 1);
        if (c == 0) return int16_t(o);
        if (c == 5) return int16_t(10 + o);
        return int16_t(-100 * c - 1);
    };
    std::vector<int16_t> out(dims.voxels(), int16_t(12345));
    decode_to_dense(tree, out.data());
    for (uint32_t z = 0; z < dims.z; ++z)
        for (uint32_t y = 0; y < dims.y; ++y)
            for (uint32_t x = 0; x < dims.x; ++x) {
                const int16_t got = out[x + dims.x * (y + dims.y * z)];
                EXPECT_EQ(got, expected(x, y, z)) << x << "," << y << "," << z;
                EXPECT_EQ(got, tree.point_locate({x, y, z}));
            }
}

TEST(DecodeToDense, DeepTreesEqualTheInputArray) {
    // Non-cubic grids with many levels, so that the parallel split happens above the caps.
    const Dims shapes[] = {{70, 45, 33}, {1, 1, 200}, {129, 2, 3}, {1, 1, 1}};
    uint32_t seed = 40;
    for (const Dims& dims : shapes)
        for (Pattern p : {Pattern::Sparse, Pattern::Blocky, Pattern::Random}) {
            SCOPED_TRACE(::testing::Message() << dims.x << "x" << dims.y << "x" << dims.z << " " << int(p));
            const auto v = make_volume<double>(dims, p, seed++);
            const auto b = build_octree(v.view(), {});
            expect_dense_equal(b.view(), v);
        }
}

}  // namespace
}  // namespace octiso::test
