// Level of detail (issue 14, RenderOptions::lod, src/render/lod.h) against independent references:
// - lattice_value (format 4) returns the dense voxel at every lattice point of every unit;
// - where the cut stops every ray at one lattice unit u, the LOD frame is the exact reference
//   frame of the dense array decimated by u (every u-th voxel, spacing u): same hit mask, depths
//   and normals within the root finder's bar, for packets and single rays, with Embree and without;
// - close up (the cut allows less than 2 voxels anywhere) the frame is the exact one bit for bit,
//   and lod 0 is the exact frame;
// - shadow and AO rays see the primary rays' coarse surface (the look of the decimated array);
// - packets stop where single rays stop, bit for bit.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "octiso/any_octree.h"
#include "octiso/build.h"
#include "octiso/error.h"
#include "octiso/look.h"
#include "octiso/render.h"
#include "render/render_test_util.h"

namespace octiso::test {
namespace {

template <typename T> DenseVolume<T> decimate(const DenseVolume<T>& v, uint32_t u) {
    const Dims d{(v.dims.x - 1) / u + 1, (v.dims.y - 1) / u + 1, (v.dims.z - 1) / u + 1};
    DenseVolume<T> out{d, std::vector<T>(d.voxels())};
    for (uint32_t z = 0; z < d.z; ++z)
        for (uint32_t y = 0; y < d.y; ++y)
            for (uint32_t x = 0; x < d.x; ++x)
                out.values[x + uint64_t(d.x) * (y + uint64_t(d.y) * z)] =
                    v.values[x * u + uint64_t(v.dims.x) * (y * u + uint64_t(v.dims.y) * z * u)];
    return out;
}

bool same_frame(const Frame& a, const Frame& b) {
    if (a.width != b.width || a.height != b.height || a.normal != b.normal || a.rgb != b.rgb) return false;
    for (size_t i = 0; i < a.depth.size(); ++i)
        if (!(a.depth[i] == b.depth[i] || (std::isinf(a.depth[i]) && std::isinf(b.depth[i])))) return false;
    return a.depth.size() == b.depth.size();
}

template <typename T> void expect_lattice_values(Field field, Dims dims) {
    const DenseVolume<T> v = make_field<T>(field, dims);
    const OctreeData<T> data = build_octree(v.view(), {});
    const Octree<T> tree = data.view();
    uint32_t trace[kMaxDepth] = {};
    for (uint32_t unit = 1; unit <= tree.side() / 2; unit *= 2)
        for (uint32_t z = 0; z < dims.z; z += unit)
            for (uint32_t y = 0; y < dims.y; y += unit)
                for (uint32_t x = 0; x < dims.x; x += unit) {
                    const T want = v.values[x + uint64_t(dims.x) * (y + uint64_t(dims.y) * z)];
                    // From the root (depth 0).
                    ASSERT_EQ(tree.lattice_value(Coord{}, Coord{x, y, z}, unit, 0, trace), want)
                        << "unit " << unit << " at " << x << "," << y << "," << z;
                    // As the traversal does: from the lower corner of the coarse cell whose upper
                    // corner q is, with that corner's trace down to the node whose children have
                    // side unit (or the leaf or cap parent above it), climbing to q's ancestor.
                    const Coord start{x >= unit ? x - unit : 0u, y >= unit ? y - unit : 0u, z >= unit ? z - unit : 0u};
                    int d = 0;
                    uint32_t index = 0;
                    for (;;) {
                        trace[d] = index;
                        const auto& n = tree.node(d, index);
                        const int c = octant_of(start, tree.child_bit(d));
                        if (tree.child_bit(d) <= unit || n.is_scalar_leaf(c) || d + 1 == tree.cap_depth()) break;
                        index = tree.child_index(d, index, n, c);
                        ++d;
                    }
                    ASSERT_EQ(tree.lattice_value(start, Coord{x, y, z}, unit, d, trace), want)
                        << "unit " << unit << " at " << x << "," << y << "," << z << " from depth " << d;
                }
}

TEST(Lod, LatticeValuesAreTheVoxelsAtTheLatticePoints) {
    expect_lattice_values<uint8_t>(Field::MarschnerLobb, {33, 29, 41});
    expect_lattice_values<uint8_t>(Field::Sierpinski, {27, 27, 27});   // large scalar leaves
    expect_lattice_values<int16_t>(Field::Noise, {17, 40, 23});
    expect_lattice_values<float>(Field::Torus, {64, 48, 40});
}

/// A camera far enough out, with a narrow view, that F x the pixel footprint lies inside
/// [u, 2u) voxels over the whole volume (1.5 u (1 +- 1/40)): the cut is unit u everywhere.
Camera far_camera(Dims dims, int size, uint32_t unit, double& factor) {
    const std::array<double, 3> centre{(dims.x - 1) / 2.0, (dims.y - 1) / 2.0, (dims.z - 1) / 2.0};
    const double radius = std::sqrt(double(dims.x) * dims.x + double(dims.y) * dims.y + double(dims.z) * dims.z) / 2;
    const std::array<double, 3> dir{0.6, -0.7, 0.39};
    const double len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    const double distance = 40 * radius;   // near and far points within 1 +- 1/40 of it
    std::array<double, 3> eye;
    for (int a = 0; a < 3; ++a) eye[a] = centre[a] + dir[a] / len * distance;
    const double fov = 2 * std::atan(1.1 * radius / distance) * 180 / M_PI;
    Camera c = look_at(eye, centre, {0, 0, 1}, fov, size);
    const double pixel = 2 * std::tan(fov / 2 * M_PI / 180) / size;   // lod.h's pixel width per distance
    factor = 1.5 * unit / (pixel * distance);                          // 1.5 u at the centre distance
    return c;
}

template <typename T> void expect_uniform_cut_matches_decimated(Field field, Dims dims, uint32_t unit, double iso) {
    SCOPED_TRACE(std::string(scalar_type_name(scalar_type_of<T>())) + " unit " + std::to_string(unit));
    const DenseVolume<T> v = make_field<T>(field, dims);
    const OctreeData<T> data = build_octree(v.view(), {});
    double factor = 0;
    const Camera camera = far_camera(dims, 61, unit, factor);
    const DenseVolume<T> coarse = decimate(v, unit);
    Placement coarse_placement;
    coarse_placement.spacing = {double(unit), double(unit), double(unit)};
    const Frame reference = render_reference(coarse.view(), coarse_placement, camera, {iso});
    for (const bool embree : {true, false})
        for (const Traversal traversal : {Traversal::packets, Traversal::single}) {
            SCOPED_TRACE(std::string(embree ? "embree " : "direct ") + (traversal == Traversal::packets ? "packets" : "single"));
            RenderOptions o;
            o.isovalues = {iso};
            o.want_depth = o.want_normal = true;
            o.use_embree = embree;
            o.traversal = traversal;
            o.lod = factor;
            const Frame frame = Renderer(data.view(), Placement{}, o).render(camera);
            ASSERT_GT(frame.stats.hits, 0u);
            EXPECT_EQ(frame.stats.hits_by_cell_log2[size_t(std::countr_zero(unit))], frame.stats.hits)
                << "every hit in a cell of " << unit << " voxels";
            expect_agreement(compare_frames(frame, reference, double(unit)), "LOD against the decimated reference");
        }
}

TEST(Lod, UniformCutIsTheExactFrameOfTheDecimatedArray) {
    // Extents of k u + 1 voxels, so that the lattice reaches the last voxel on every axis.
    expect_uniform_cut_matches_decimated<uint8_t>(Field::MarschnerLobb, {65, 65, 65}, 4, 47);
    expect_uniform_cut_matches_decimated<uint8_t>(Field::Sphere, {65, 49, 57}, 8, 60);
    expect_uniform_cut_matches_decimated<uint8_t>(Field::Torus, {65, 65, 33}, 2, 50);
    expect_uniform_cut_matches_decimated<int16_t>(Field::MarschnerLobb, {65, 65, 65}, 4, 47);
    expect_uniform_cut_matches_decimated<float>(Field::Torus, {81, 81, 49}, 16, 50.5);
    expect_uniform_cut_matches_decimated<double>(Field::Sierpinski, {81, 81, 81}, 4, 60);   // scalar leaves
}

/// Pixels of two colour frames that differ by more than 2 in some channel.
size_t differing_pixels(const Frame& a, const Frame& b) {
    size_t n = 0;
    for (size_t i = 0; i < a.rgb.size(); i += 3) {
        bool differ = false;
        for (int k = 0; k < 3; ++k) differ |= std::abs(int(a.rgb[i + k]) - int(b.rgb[i + k])) > 2;
        n += differ;
    }
    return n;
}

TEST(Lod, ShadowAndAoRaysSeeTheSameCoarseSurface) {
    // Where the cut is uniform at unit u, the look (shadows, AO) of the LOD frame is the look of
    // the decimated array traced exactly, up to the root finder's rounding at grazing rays.
    const uint32_t unit = 4;
    const DenseVolume<uint8_t> v = make_field<uint8_t>(Field::MarschnerLobb, {65, 65, 65});
    const DenseVolume<uint8_t> coarse = decimate(v, unit);
    Placement coarse_placement;
    coarse_placement.spacing = {double(unit), double(unit), double(unit)};
    const AnyOctree tree = AnyOctree::build(v.view(), Placement{}, {});
    const AnyOctree coarse_tree = AnyOctree::build(coarse.view(), coarse_placement, {});
    double factor = 0;
    const Camera camera = far_camera(v.dims, 96, unit, factor);
    // AO reach is in voxels of the tree: the same 12 world units for both.
    auto shaded = [&](const AnyOctree& t, double lod, double look_lod) {
        Look look;
        look.shadows = true;
        look.ao_samples = 4;
        look.ao_distance_voxels = 12.0 / std::fabs(t.placement().spacing[0]);
        RenderOptions o;
        o.isovalues = {47};
        o.want_colour = false, o.want_depth = o.want_normal = true;
        o.lod = lod;
        Frame f = t.render(camera, o);
        o.lod = look_lod;
        LookShader(t, o, look, ShadingModel::kit).shade(camera, Shading{}, f);
        return f;
    };
    const Frame reference = shaded(coarse_tree, 0, 0), lod = shaded(tree, factor, factor);
    size_t hits = 0;
    for (float d : reference.depth) hits += std::isfinite(d);
    ASSERT_GT(hits, 1000u);
    EXPECT_LE(differing_pixels(lod, reference), hits / 200) << "of " << hits << " hit pixels";
    // Not vacuous: secondary rays through the full-resolution field shade the coarse hits otherwise.
    EXPECT_GT(differing_pixels(shaded(tree, factor, 0), reference), hits / 20);
}

TEST(Lod, CloseUpAndLodZeroAreTheExactFrame) {
    const DenseVolume<uint8_t> v = make_field<uint8_t>(Field::MarschnerLobb, {40, 36, 44});
    const OctreeData<uint8_t> data = build_octree(v.view(), {});
    const Camera camera = frame_data_box(v.dims, Placement{}, 97, 83);   // under one voxel per pixel
    RenderOptions o;
    o.isovalues = {47};
    o.want_depth = o.want_normal = true;
    const Frame exact = Renderer(data.view(), Placement{}, o).render(camera);
    for (const double f : {0.0, 0.5, 1.0}) {
        o.lod = f;
        for (const Traversal t : {Traversal::packets, Traversal::single}) {
            o.traversal = t;
            const Frame frame = Renderer(data.view(), Placement{}, o).render(camera);
            EXPECT_TRUE(same_frame(frame, exact)) << "lod " << f;
            EXPECT_EQ(frame.stats.hits_by_cell_log2[0], frame.stats.hits);
        }
    }
    // A factor that does coarsen this view changes it (the test above is not vacuous).
    o.lod = 16;
    const Frame coarse = Renderer(data.view(), Placement{}, o).render(camera);
    EXPECT_FALSE(same_frame(coarse, exact));
    EXPECT_LT(coarse.stats.hits_by_cell_log2[0], coarse.stats.hits);
}

/// A near eye makes the cut vary over the image, from full resolution to units of 16 and more:
/// primary packets, whose lanes stopped at a whole coarse cell or a cap share its corners
/// (traverse.h, coarse_lanes, coarse_corners), give every pixel the single rays' depth and
/// normal bit for bit, in both kernels, on a smooth field and on one of scalar leaves, and stop at
/// every unit from 1 to 16.
TEST(Lod, PacketsStopWhereSingleRaysStop) {
    const std::vector<Isa> isas = kernel_isas();
    struct Case {
        Field field;
        double iso;
    };
    for (const Case& k : {Case{Field::MarschnerLobb, 47}, Case{Field::Sierpinski, 60}}) {
        const DenseVolume<uint8_t> v = make_field<uint8_t>(k.field, {97, 90, 101});
        const OctreeData<uint8_t> data = build_octree(v.view(), {});
        Camera camera;
        camera.eye = {-6, -9, 112}, camera.look = {60, 50, 40}, camera.up = {0, 0, 1};
        camera.fov_deg = 70, camera.width = 128, camera.height = 96;
        unsigned stop_units = 0;   // bit u: some hit in a cell of 2^u voxels
        for (const double f : {2.0, 8.0, 24.0}) {
            RenderOptions o;
            o.isovalues = {k.iso};
            o.want_depth = o.want_normal = true;
            o.lod = f;
            o.traversal = Traversal::single;
            const Frame single = Renderer(data.view(), Placement{}, o).render(camera);
            ASSERT_GT(single.stats.hits, 0u);
            for (size_t u = 0; u < single.stats.hits_by_cell_log2.size(); ++u)
                if (single.stats.hits_by_cell_log2[u]) stop_units |= 1u << u;
            for (const Isa isa : isas) {
                o.traversal = Traversal::packets, o.isa = isa;
                const Frame packets = Renderer(data.view(), Placement{}, o).render(camera);
                EXPECT_TRUE(same_frame(packets, single)) << "field " << int(k.field) << ", lod " << f << ", isa " << int(isa);
                EXPECT_EQ(packets.stats.hits_by_cell_log2, single.stats.hits_by_cell_log2);
            }
        }
        EXPECT_EQ(stop_units & 0x1Fu, 0x1Fu) << "hits in cells of 1, 2, 4, 8 and 16 voxels, field " << int(k.field);
    }
}

TEST(Lod, BadFactorsAreRefused) {
    const DenseVolume<uint8_t> v = make_field<uint8_t>(Field::Sphere, {9, 9, 9});
    const OctreeData<uint8_t> data = build_octree(v.view(), {});
    RenderOptions o;
    o.isovalues = {60};
    for (const double f : std::array{-1.0, std::nan(""), double(INFINITY)}) {
        o.lod = f;
        EXPECT_THROW(Renderer(data.view(), Placement{}, o), Error) << f;
    }
    o.lod = 1;
    o.owned_cells = CellBox{{0, 0, 0}, {4, 8, 8}};
    EXPECT_THROW(Renderer(data.view(), Placement{}, o), Error);
}

}  // namespace
}  // namespace octiso::test
