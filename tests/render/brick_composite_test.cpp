// Sort-last rendering without MPI (issue 15): the frames of the slab bricks of a volume
// (RenderOptions::owned_cells), composited by depth, are the whole volume's frame bit for bit,
// for every brick count (empty bricks included), both traversals, Embree on and off, several
// isovalues, and a surface lying exactly on a brick face. The MPI transport over the same
// functions is tested under mpirun (tests/mpi/).
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "octiso/bricks.h"
#include "octiso/build.h"
#include "octiso/depth_composite.h"
#include "octiso/error.h"
#include "octiso/render.h"
#include "render/render_test_util.h"

namespace octiso::test {
namespace {

/// The voxels of plane x of `v` (element y + ny * z), as RenderOptions::ghost_plane holds them.
std::shared_ptr<const std::vector<double>> plane_of(const DenseVolume<float>& v, uint32_t x) {
    auto plane = std::make_shared<std::vector<double>>();
    for (uint32_t z = 0; z < v.dims.z; ++z)
        for (uint32_t y = 0; y < v.dims.y; ++y) plane->push_back(v.values[x + uint64_t(v.dims.x) * (y + uint64_t(v.dims.y) * z)]);
    return plane;
}

/// Every brick rendered alone and composited; with `ghosts`, the bricks read their +x face from a
/// plane of the dense volume (as under mpirun) instead of the neighbour's nodes.
Frame composite_of_bricks(const OctreeData<float>& data, const DenseVolume<float>& v, const Camera& camera,
                          RenderOptions options, int count, bool ghosts) {
    const CompositeLayout layout{options.want_colour, options.want_normal};
    const bool wanted_depth = options.want_depth;
    options.want_depth = true;   // the composite needs it
    const std::vector<CellBox> bricks = slab_bricks(data.view().dims(), count);
    std::vector<std::byte> result, mine(size_t(camera.width) * size_t(camera.height) * layout.sample_bytes());
    for (int r = 0; r < count; ++r) {
        RenderOptions brick_options = options;
        brick_options.owned_cells = bricks[size_t(r)];
        if (ghosts && !bricks[size_t(r)].empty() && bricks[size_t(r)].hi[0] + 1 < v.dims.x)
            brick_options.ghost_plane = plane_of(v, bricks[size_t(r)].hi[0]);
        const Frame f = Renderer(data.view(), Placement{}, brick_options).render(camera);
        pack_composite(f, uint32_t(r), layout, mine);
        if (r == 0) result = mine;
        else composite_nearer(mine.data(), result.data(), size_t(camera.width) * size_t(camera.height), layout);
    }
    Frame out;
    out.width = camera.width, out.height = camera.height;
    if (options.want_colour) out.rgb.resize(size_t(camera.width) * camera.height * 3);
    if (wanted_depth) out.depth.resize(size_t(camera.width) * camera.height);
    if (options.want_normal) out.normal.resize(size_t(camera.width) * camera.height * 3);
    unpack_composite(result, layout, out);
    return out;
}

void expect_same(const Frame& a, const Frame& b, const std::string& what) {
    ASSERT_EQ(a.rgb.size(), b.rgb.size()) << what;
    ASSERT_EQ(a.depth.size(), b.depth.size()) << what;
    ASSERT_EQ(a.normal.size(), b.normal.size()) << what;
    EXPECT_EQ(0, std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size())) << what << ": colour";
    EXPECT_EQ(0, std::memcmp(a.depth.data(), b.depth.data(), 4 * a.depth.size())) << what << ": depth";
    EXPECT_EQ(0, std::memcmp(a.normal.data(), b.normal.data(), 4 * a.normal.size())) << what << ": normal";
    EXPECT_EQ(a.stats.hits, b.stats.hits) << what;
}

TEST(SlabBricks, PartitionTheCellsInOrderOfX) {
    for (const Dims dims : {Dims{2, 2, 2}, Dims{33, 20, 9}, Dims{300, 5, 7}, Dims{1, 4, 4}})
        for (int count : {1, 2, 3, 4, 7, 40}) {
            const std::vector<CellBox> b = slab_bricks(dims, count);
            ASSERT_EQ(b.size(), size_t(count));
            uint32_t x = 0;
            for (const CellBox& box : b) {
                EXPECT_EQ(box.lo[0], x);
                EXPECT_GE(box.hi[0], box.lo[0]);
                EXPECT_EQ(box.hi[1], dims.y - 1);
                EXPECT_EQ(box.hi[2], dims.z - 1);
                x = box.hi[0];
            }
            EXPECT_EQ(x, dims.x >= 2 ? dims.x - 1 : 0u) << "the last brick ends at the last cell";
        }
    // Faces on a power of two where the slabs are wide enough: 256 cells in 2 -> 128 | 128.
    EXPECT_EQ(slab_bricks(Dims{257, 4, 4}, 2)[0].hi[0], 128u);
    EXPECT_THROW(slab_bricks(Dims{4, 4, 4}, 0), Error);
}

TEST(BrickComposite, LayoutFromSampleBytes) {
    for (const bool colour : {false, true})
        for (const bool normal : {false, true}) {
            const CompositeLayout l{colour, normal}, back = CompositeLayout::from_sample_bytes(l.sample_bytes());
            EXPECT_EQ(back.colour, colour);
            EXPECT_EQ(back.normal, normal);
        }
}

TEST(BrickComposite, EqualsTheWholeVolume) {
    const Dims dims{37, 30, 26};
    for (const Field field : {Field::MarschnerLobb, Field::Torus, Field::Sierpinski}) {
        const DenseVolume<float> v = make_field<float>(field, dims, 3);
        const OctreeData<float> data = build_octree(v.view(), {});
        const Camera camera = frame_data_box(dims, Placement{}, 64, 48);
        for (const bool embree : {false, true})
            for (const Traversal traversal : {Traversal::packets, Traversal::single}) {
                RenderOptions o;
                o.isovalues = {40, 75};
                o.want_depth = o.want_normal = true;
                o.use_embree = embree;
                o.traversal = traversal;
                o.threads = 2;
                const Frame whole = Renderer(data.view(), Placement{}, o).render(camera);
                ASSERT_GT(whole.stats.hits, 100u);
                for (int count : {1, 2, 3, 5, 64}) {   // 64 > 36 cells: empty bricks
                    const std::string what = "field " + std::to_string(int(field)) + ", " + std::to_string(count) +
                                             " bricks, embree " + std::to_string(embree) + ", packets " +
                                             std::to_string(traversal == Traversal::packets);
                    for (const bool ghosts : {false, true})
                        expect_same(composite_of_bricks(data, v, camera, o, count, ghosts), whole,
                                    what + (ghosts ? ", ghost planes" : ""));
                }
            }
    }
}

TEST(BrickComposite, SurfaceOnABrickFaceIsClaimedOnce) {
    // f = x: the isosurface f = 16 is the plane x = 16, exactly the face between the two bricks
    // of 32 cells (slab_bricks puts it at 16); seen from both sides and edge on.
    const Dims dims{33, 12, 10};
    DenseVolume<float> v{dims, std::vector<float>(dims.voxels())};
    for (uint32_t z = 0; z < dims.z; ++z)
        for (uint32_t y = 0; y < dims.y; ++y)
            for (uint32_t x = 0; x < dims.x; ++x) v.values[x + dims.x * (y + uint64_t(dims.y) * z)] = float(x);
    const OctreeData<float> data = build_octree(v.view(), {});
    ASSERT_EQ(slab_bricks(dims, 2)[0].hi[0], 16u);
    for (const double azimuth : {0.0, 180.0, 90.0, -55.3}) {
        const Camera camera = orbit_camera(dims, Placement{}, 40, 40, azimuth, 20.0, 1.0);
        RenderOptions o;
        o.isovalues = {16};
        o.want_depth = o.want_normal = true;
        const Frame whole = Renderer(data.view(), Placement{}, o).render(camera);
        for (int count : {2, 4})
            for (const bool ghosts : {false, true})
                expect_same(composite_of_bricks(data, v, camera, o, count, ghosts), whole, "azimuth " + std::to_string(azimuth));
    }
}

}  // namespace
}  // namespace octiso::test
