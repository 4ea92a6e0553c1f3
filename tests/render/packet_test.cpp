// Packet traversal and the ISA kernels (issue 11) against single rays: every lane of
// OctreeTracer::trace_packet equals trace() bit for bit (t, isovalue, normal) over all 8 scalar
// types, coherent camera rows and incoherent random rays (mixed direction signs, +-0 components,
// origins inside and outside the data), with invalid lanes left as misses; and whole frames are
// bit-identical across Traversal::single/packets x Isa::baseline/avx2 x Embree on/off.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <limits>
#include <random>

#include "octiso/build.h"
#include "octiso/render.h"
#include "octree/octree_test_util.h"
#include "render/pinhole_camera.h"
#include "render/render_test_util.h"
#include "render/tracer_kernel.h"
#include "render/traverse.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

bool same_hit(const TraceHit& a, const TraceHit& b) {
    return a.iso_index == b.iso_index && std::memcmp(&a.t, &b.t, sizeof(double)) == 0 && a.normal == b.normal;
}

/// Rays: 8-pixel rows of a camera looking at the box (coherent), then random rays (incoherent).
std::vector<Ray> test_rays(Dims dims, uint32_t seed) {
    std::vector<Ray> rays;
    const Camera camera = frame_data_box(dims, Placement{}, 48, 40);
    const PinholeCamera pinhole(camera);
    for (int y = 0; y < camera.height; ++y)
        for (int x = 0; x < camera.width; ++x) rays.push_back(pinhole.ray(x, y));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-0.5, 1.5);
    for (int i = 0; i < 4000; ++i) {
        Ray r;
        r.origin = {u(rng) * dims.x, u(rng) * dims.y, u(rng) * dims.z};
        std::array<double, 3> d{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5};
        if (i % 5 == 0) d[size_t(i % 3)] = (i % 2) ? 0.0 : -0.0;   // +-0 components
        const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(len > 0)) continue;
        for (double& c : d) c /= len;
        r.dir = d;
        rays.push_back(r);
    }
    return rays;
}

template <typename T> void check_type(Pattern pattern) {
    const Dims dims{21, 17, 26};
    const DenseVolume<T> v = make_volume<T>(dims, pattern, 7);
    const OctreeData<T> data = build_octree(v.view(), {});
    double lo = double(v.values[0]), hi = lo;
    for (T x : v.values) lo = std::min(lo, double(x)), hi = std::max(hi, double(x));
    const double isos[2] = {0.5 * lo + 0.5 * hi, 0.3 * lo + 0.7 * hi};   // inside the data's range
    const std::vector<Ray> rays = test_rays(dims, 11);
    for (int iso_count : {1, 2}) {
        const OctreeTracer<T, Neubauer> single(data.view(), Placement{}, isos, iso_count, Neubauer{});
        // Embree's 8 rays and the renderer's direct 16 (a packet of 16 starts at the root with
        // 8 lanes of one direction signs, one of 8 with 4).
        constexpr int kMax = OctreeTracer<T, Neubauer>::kMaxPacket;
        for (int size : {8, kMax})
            for (int lanes : {1, 2, OctreeTracer<T, Neubauer>::kDefaultMinPacketLanes, 9}) {
                OctreeTracer<T, Neubauer> packed(data.view(), Placement{}, isos, iso_count, Neubauer{});
                packed.set_min_packet_lanes(lanes);
                uint64_t hits = 0;
                for (size_t i0 = 0; i0 < rays.size(); i0 += size_t(size)) {
                    const int count = int(std::min<size_t>(size_t(size), rays.size() - i0));
                    int valid[kMax];
                    for (int k = 0; k < kMax; ++k) valid[k] = (i0 / 8 + size_t(k)) % 7 == 3 ? 0 : -1;   // some lanes off
                    TraceHit out[kMax];
                    packed.trace_packet(&rays[i0], count, valid, true, out);
                    for (int k = 0; k < count; ++k) {
                        const TraceHit expected = valid[k] ? single.trace(rays[i0 + size_t(k)], true) : TraceHit{};
                        hits += expected.is_hit();
                        ASSERT_TRUE(same_hit(expected, out[k]))
                            << scalar_type_name(scalar_type_of<T>()) << " ray " << i0 + size_t(k) << ", packets of " << size
                            << ", threshold " << lanes << ", " << iso_count << " isovalue(s)";
                    }
                }
                EXPECT_GT(hits, 10u) << "the data must give the packets something to hit";
            }
    }
}

TEST(PacketTraversal, EveryLaneEqualsItsSingleRayAllTypes) {
    check_type<uint8_t>(Pattern::Blocky);
    check_type<int8_t>(Pattern::Random);
    check_type<uint16_t>(Pattern::Sparse);
    check_type<int16_t>(Pattern::Blocky);
    check_type<uint32_t>(Pattern::Random);
    check_type<int32_t>(Pattern::Sparse);
    check_type<float>(Pattern::Random);
    check_type<double>(Pattern::Blocky);
}

/// Whole frames through the Renderer: every traversal x ISA x Embree combination draws the same
/// bytes (colour, depth, normal) as single rays on the portable kernel.
TEST(PacketTraversal, FramesIdenticalAcrossTraversalIsaAndEmbree) {
    const Dims dims{40, 33, 37};
    const DenseVolume<uint16_t> v = make_volume<uint16_t>(dims, Pattern::Blocky, 3);
    const OctreeData<uint16_t> data = build_octree(v.view(), {});
    const Camera camera = frame_data_box(dims, Placement{}, 97, 61);
    RenderOptions base;
    base.isovalues = {1.5, 3.5};
    base.want_depth = base.want_normal = true;
    base.traversal = Traversal::single;
    base.isa = Isa::baseline;
    base.use_embree = false;
    const Frame reference = render(data.view(), Placement{}, camera, base);
    ASSERT_GT(reference.stats.hits, 1000u);
    std::vector<Isa> isas{Isa::baseline, Isa::automatic};
    if (cpu_has_avx2()) isas.push_back(Isa::avx2);
    for (Traversal traversal : {Traversal::single, Traversal::packets})
        for (Isa isa : isas)
            for (bool embree : {false, true}) {
                RenderOptions o = base;
                o.traversal = traversal, o.isa = isa, o.use_embree = embree;
                const Frame f = render(data.view(), Placement{}, camera, o);
                const std::string what = std::string(traversal == Traversal::packets ? "packets" : "single") + ", isa " +
                                         std::to_string(int(isa)) + (embree ? ", Embree" : ", direct");
                EXPECT_EQ(f.rgb, reference.rgb) << what;
                EXPECT_EQ(0, std::memcmp(f.depth.data(), reference.depth.data(), f.depth.size() * sizeof(float))) << what;
                EXPECT_EQ(0, std::memcmp(f.normal.data(), reference.normal.data(), f.normal.size() * sizeof(float))) << what;
            }
}

/// Close up (about 7 pixels per voxel) every lane of a packet crosses the same caps, so their
/// cells are walked as a packet (OctreeTracer::packet_cap, from kMinCapPacketLanes lanes): frames
/// of both kernels equal the single-ray frame bit for bit, with one and two isovalues, on a
/// blocky field (leaves and caps) and a noisy one (caps almost everywhere).
TEST(PacketTraversal, CloseUpFramesWhosePacketsShareCapsAreIdentical) {
    const Dims dims{13, 10, 15};
    for (Pattern pattern : {Pattern::Blocky, Pattern::Random}) {
        const DenseVolume<uint8_t> v = make_volume<uint8_t>(dims, pattern, 5);
        const OctreeData<uint8_t> data = build_octree(v.view(), {});
        double lo = v.values[0], hi = lo;
        for (uint8_t x : v.values) lo = std::min(lo, double(x)), hi = std::max(hi, double(x));
        const Camera camera = frame_data_box(dims, Placement{}, 96, 88);
        RenderOptions single;
        single.want_depth = single.want_normal = true;
        single.traversal = Traversal::single;
        single.isa = Isa::baseline;
        single.use_embree = false;
        for (int iso_count : {1, 2}) {
            single.isovalues = {0.5 * lo + 0.5 * hi};
            if (iso_count == 2) single.isovalues.push_back(0.2 * lo + 0.8 * hi + 0.25);
            const Frame reference = render(data.view(), Placement{}, camera, single);
            ASSERT_GT(reference.stats.hits, 2000u) << "the close view must be mostly surface";
            const std::vector<Isa> isas = kernel_isas();
            for (Isa isa : isas) {
                RenderOptions o = single;
                o.traversal = Traversal::packets, o.isa = isa;
                const Frame f = render(data.view(), Placement{}, camera, o);
                const std::string what = "pattern " + std::to_string(int(pattern)) + ", isa " + std::to_string(int(isa)) +
                                         ", " + std::to_string(iso_count) + " isovalue(s)";
                EXPECT_EQ(0, std::memcmp(f.depth.data(), reference.depth.data(), f.depth.size() * sizeof(float))) << what;
                EXPECT_EQ(0, std::memcmp(f.normal.data(), reference.normal.data(), f.normal.size() * sizeof(float))) << what;
                EXPECT_EQ(f.rgb, reference.rgb) << what;
            }
        }
    }
}

/// The scalar leaves of `side` in `tree` (children of the nodes at depth dmax - log2(side) - 1).
uint64_t scalar_leaves_of_side(const Octree<uint8_t>& tree, uint32_t side) {
    const int d = tree.dmax() - std::countr_zero(side) - 1;
    uint64_t leaves = 0;
    for (uint64_t i = 0; i < tree.node_count(d); ++i)
        for (int c = 0; c < 8; ++c) leaves += tree.node(d, i).is_scalar_leaf(c);
    return leaves;
}

/// A label volume (labels 0, 10, 20, 30) seen from four octants at width x height, with
/// isovalues between the labels and equal to them (then every cell of a leaf is walked): every
/// frame of packets on both kernels must equal the single-ray frame bit for bit.
void expect_label_views_of_packets_equal_single_rays(const Octree<uint8_t>& tree, int width, int height) {
    const std::vector<Isa> isas = kernel_isas();
    RenderOptions single;
    single.want_depth = single.want_normal = true;
    single.traversal = Traversal::single;
    single.isa = Isa::baseline;
    single.use_embree = false;
    for (const std::vector<double>& isos : {std::vector<double>{15.0}, std::vector<double>{10.0}, std::vector<double>{20.0, 5.0}}) {
        single.isovalues = isos;
        for (double azimuth : {30.0, 130.0, 215.0, 300.0}) {
            const Camera camera = orbit_camera(tree.dims(), Placement{}, width, height, azimuth, azimuth > 180 ? -25.0 : 35.0, 1.0);
            const Frame reference = render(tree, Placement{}, camera, single);
            ASSERT_GT(reference.stats.hits, 3000u);
            for (Isa isa : isas) {
                RenderOptions o = single;
                o.traversal = Traversal::packets, o.isa = isa;
                const Frame f = render(tree, Placement{}, camera, o);
                const std::string what = "iso " + std::to_string(isos[0]) + ", azimuth " + std::to_string(azimuth) + ", isa " +
                                         std::to_string(int(isa));
                EXPECT_EQ(0, std::memcmp(f.depth.data(), reference.depth.data(), f.depth.size() * sizeof(float))) << what;
                EXPECT_EQ(0, std::memcmp(f.normal.data(), reference.normal.data(), f.normal.size() * sizeof(float))) << what;
            }
        }
    }
}

/// Scalar leaves of side 4 (children of the nodes at depth dmax-3) are crossed by a packet as cap
/// parents of constant caps (OctreeTracer::packet_leaf_cap_parent), by a single ray with the leaf
/// walk (scalar_leaf): labels in uniform 4^3 and 8^3 blocks; with an isovalue equal to a label
/// the cap at the leaf's origin, whose corners all lie inside the leaf, is walked too.
TEST(PacketTraversal, SideFourLeavesAsCapParentsEqualTheLeafWalk) {
    const Dims dims{45, 38, 41};
    const DenseVolume<uint8_t> v = label_blocks<uint8_t>(dims, 3);
    const OctreeData<uint8_t> data = build_octree(v.view(), {});
    ASSERT_GT(scalar_leaves_of_side(data.view(), 4), 100u);   // the premise: the path under test has leaves to walk
    expect_label_views_of_packets_equal_single_rays(data.view(), 120, 104);
}

/// Scalar leaves of side 8 to 32, which a packet reaches from the beam (beam_node) and walks lane
/// by lane, and which any packet path for them must cross exactly as the single ray's leaf walk:
/// labels in uniform blocks of sides 4 to 32. (It failed, as it should, on a packet path that
/// skipped the shell blocks of these leaves; BENCHMARKS.md, packets, stop 47.)
TEST(PacketTraversal, LeavesOfSideEightToThirtyTwoEqualTheSingleRayLeafWalk) {
    const Dims dims{90, 77, 85};   // a cube of 128, its last blocks cut by the data box
    const DenseVolume<uint8_t> v = nested_label_blocks<uint8_t>(dims, 5);
    const OctreeData<uint8_t> data = build_octree(v.view(), {});
    for (uint32_t side : {8u, 16u, 32u}) ASSERT_GT(scalar_leaves_of_side(data.view(), side), 8u) << "side " << side;
    expect_label_views_of_packets_equal_single_rays(data.view(), 128, 112);
}

/// The beam (OctreeTracer::beam_node: packets of rays from one origin cross the upper levels as
/// one) against single rays in both kernels: packets of 16 rays from origins on mid-planes of
/// several levels, aimed at node corners and at edge and face points of lattices of 2 to 16
/// voxels, so that plane times tie with each other, with the box's and with the hand-off node's
/// faces, hit exactly what each ray hits alone; so do packets whose lanes leave the box, start
/// inside it or are switched off.
TEST(PacketTraversal, BeamOfOneOriginEqualsSingleRaysThroughNodeCornersAndFaces) {
    const Dims dims{70, 66, 73};   // a cube of 128: the beam spans depths 0 to 3
    const std::vector<Isa> isas = kernel_isas();
    const std::array<double, 3> origins[] = {{64, 32, -16}, {-8, 64, 32}, {96, -12.5, 96}, {32, 16, 80}, {35.25, 33, 36}};
    for (Pattern pattern : {Pattern::Blocky, Pattern::Random}) {
        const DenseVolume<uint8_t> v = make_volume<uint8_t>(dims, pattern, 9);
        const OctreeData<uint8_t> data = build_octree(v.view(), {});
        RenderOptions o;
        o.isovalues = pattern == Pattern::Blocky ? std::vector<double>{1.5, 3.5} : std::vector<double>{127.5, 200.5};
        for (Isa isa : isas) {
            const TracerKernel kernel = make_tracer_kernel(data.view(), Placement{}, o, isa);
            uint64_t hits = 0, packets = 0;
            for (const auto& eye : origins)
                for (int step : {2, 4, 8, 16})
                    for (int plane = 0; plane < 3; ++plane)
                        for (int u0 = -step; u0 < 72; u0 += 4 * step)
                            for (int v0 = -step; v0 < 72; v0 += 4 * step) {
                                Ray rays[kMaxTracePacket];
                                int valid[kMaxTracePacket];
                                for (int k = 0; k < kMaxTracePacket; ++k) {
                                    // a 4x4 block of lattice points on the plane through the box's middle
                                    std::array<double, 3> target{};
                                    target[size_t(plane)] = 32;
                                    target[size_t((plane + 1) % 3)] = u0 + step * (k % 4);
                                    target[size_t((plane + 2) % 3)] = v0 + step * (k / 4);
                                    std::array<double, 3> d;
                                    for (int a = 0; a < 3; ++a) d[size_t(a)] = target[size_t(a)] - eye[size_t(a)];
                                    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                                    for (double& c : d) c /= len;
                                    rays[k] = Ray{eye, d};
                                    valid[k] = (packets + uint64_t(k)) % 13 == 5 ? 0 : -1;
                                }
                                TraceHit out[kMaxTracePacket];
                                kernel.trace_packet(kernel.user, rays, kMaxTracePacket, valid, true, out);
                                ++packets;
                                for (int k = 0; k < kMaxTracePacket; ++k) {
                                    const TraceHit expected = valid[k] ? kernel.trace(kernel.user, rays[k], true) : TraceHit{};
                                    hits += expected.is_hit();
                                    ASSERT_TRUE(same_hit(expected, out[k]))
                                        << "isa " << int(isa) << ", pattern " << int(pattern) << ", eye " << eye[0] << ","
                                        << eye[1] << "," << eye[2] << ", step " << step << ", plane " << plane << ", block "
                                        << u0 << "," << v0 << ", lane " << k;
                                }
                            }
            EXPECT_GT(hits, packets * 4) << "most packets must reach the surfaces";
        }
    }
}

/// Single rays start in the deepest node whose one child holds their whole piece
/// (OctreeTracer::start_below_root); trace_packet starts every lane at the root, as a packet or
/// alone. Short pieces like ambient-occlusion rays (origins inside the data, [t_min, t_max] a few
/// voxels long), many of them on node mid-planes of every level with +-0 direction components so
/// that the start side is decided by the tie rules, must hit exactly what the descent from the
/// root hits, in both kernels, also where the child a ray would start in is culled (the blocky
/// and sparse data lack the isovalues in many nodes).
TEST(PacketTraversal, ShortRaysStartingBelowTheRootEqualTheDescentFromTheRoot) {
    const Dims dims{70, 66, 73};   // a cube of 128: seven levels above the caps
    const std::vector<Isa> isas = kernel_isas();
    for (Pattern pattern : {Pattern::Blocky, Pattern::Random, Pattern::Sparse}) {
        const DenseVolume<uint8_t> v = make_volume<uint8_t>(dims, pattern, 13);
        const OctreeData<uint8_t> data = build_octree(v.view(), {});
        RenderOptions o;
        o.isovalues = pattern == Pattern::Random ? std::vector<double>{127.5, 200.5} : std::vector<double>{1.5, 3.5};
        for (Isa isa : isas) {
            const TracerKernel kernel = make_tracer_kernel(data.view(), Placement{}, o, isa);
            std::mt19937 rng(23);
            std::uniform_real_distribution<double> u(0, 1);
            uint64_t hits = 0, rays_traced = 0;
            for (int i = 0; i < 6000; i += kMaxTracePacket) {
                Ray rays[kMaxTracePacket];
                for (int k = 0; k < kMaxTracePacket; ++k) {
                    const int n = i + k;
                    Ray& r = rays[k];
                    for (int a = 0; a < 3; ++a) {
                        const uint32_t extent = a == 0 ? dims.x : a == 1 ? dims.y : dims.z;
                        r.origin[size_t(a)] = u(rng) * (extent - 1);
                        // on a mid-plane of a node of side 2 .. 128 (a multiple of 1 .. 64)
                        if ((n + a) % 3 == 0) r.origin[size_t(a)] = double((1 << (n % 7)) * int(u(rng) * (extent - 1) / (1 << (n % 7))));
                    }
                    std::array<double, 3> d{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5};
                    if (n % 4 == 0) d[size_t(n % 3)] = (n % 8) ? 0.0 : -0.0;
                    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                    for (double& c : d) c /= len;
                    r.dir = d;
                    r.t_min = n % 5 == 0 ? 0.0 : 0.02 + 2 * u(rng);
                    const double reach[] = {0.3, 1.5, 4, 10, 40};
                    r.t_max = r.t_min + reach[n % 5];
                }
                TraceHit out[kMaxTracePacket];
                kernel.trace_packet(kernel.user, rays, kMaxTracePacket, nullptr, true, out);
                for (int k = 0; k < kMaxTracePacket; ++k) {
                    const TraceHit alone = kernel.trace(kernel.user, rays[k], true);
                    hits += alone.is_hit();
                    ++rays_traced;
                    ASSERT_TRUE(same_hit(alone, out[k])) << "isa " << int(isa) << ", pattern " << int(pattern) << ", ray "
                                                         << i + k;
                }
            }
            EXPECT_GT(hits, rays_traced / 20) << "the short rays must reach surfaces";
            EXPECT_LT(hits, rays_traced) << "and miss some";
        }
    }
}

/// The lanes' starts (the AVX2 kernel computes them four lanes at a time, packet_start.h) on the
/// rays that take the scalar start's every branch: +-0, subnormal, infinite and NaN direction
/// components, NaN and infinite origins, rays parallel to a face outside, inside and in the face,
/// [t_min, t_max] empty, a point, starting or ending inside the box; under an anisotropic spacing
/// and a shifted origin. Each lane must equal its single ray on both kernels, and in a volume
/// without cells every lane misses.
TEST(PacketTraversal, LaneStartsOfHostileRaysEqualSingleRays) {
    const Dims dims{23, 19, 27};
    const Placement placement{{0.3, 1.7, 2.0}, {-5.5, 3.25, 0.0}};
    const DenseVolume<uint8_t> v = make_volume<uint8_t>(dims, Pattern::Blocky, 5);
    const OctreeData<uint8_t> data = build_octree(v.view(), {});
    RenderOptions o;
    o.isovalues = {1.5, 3.5};
    const uint32_t extent[3] = {dims.x, dims.y, dims.z};
    std::array<double, 3> lo, hi, mid;
    for (int a = 0; a < 3; ++a) {
        lo[a] = placement.origin[a];
        hi[a] = placement.origin[a] + placement.spacing[a] * (double(extent[a]) - 1);
        mid[a] = 0.5 * (lo[a] + hi[a]);
    }
    const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const auto toward = [](std::array<double, 3> from, std::array<double, 3> to) {
        std::array<double, 3> d;
        for (int a = 0; a < 3; ++a) d[a] = to[a] - from[a];
        const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (double& c : d) c /= len;
        return d;
    };
    std::vector<Ray> rays;
    for (int i = 0; i < 1600; ++i) {
        std::array<double, 3> from, to;
        for (int a = 0; a < 3; ++a) {
            from[a] = lo[a] + (hi[a] - lo[a]) * (2.5 * u(rng) - 0.75);
            to[a] = lo[a] + (hi[a] - lo[a]) * u(rng);
        }
        Ray r{from, toward(from, to)};
        const int a = i % 3, kind = (i / 3) % 16;
        switch (kind) {
        case 1: r.dir[a] = 0.0; break;
        case 2: r.dir[a] = -0.0; break;
        case 3: r.dir[a] = 1e-310; break;   // 1 / d overflows: the axis counts as parallel
        case 4: r.dir[a] = -inf; break;
        case 5: r.dir[a] = nan; break;
        case 6: r.origin[a] = nan; break;
        case 7: r.origin[a] = inf; break;
        case 8: r.dir[a] = 0.0, r.origin[a] = (i % 2) ? lo[a] : hi[a]; break;               // in a face
        case 9: r.dir[a] = 0.0, r.origin[a] = (i % 2) ? lo[a] - 0.25 : hi[a] + 1e-9; break;  // beside the box
        case 10: r.t_min = 3.0, r.t_max = 2.0; break;                                          // empty
        case 11: r.t_min = r.t_max = 1.25 * placement.spacing[size_t(a)]; break;               // a point
        case 12: r.origin = mid, r.t_min = u(rng) * 4; break;                                   // starts inside
        case 13: r.t_max = u(rng) * 20; break;                                                  // ends wherever
        case 14: r.origin = lo, r.dir = toward(lo, hi); break;                                  // corner to corner
        case 15: r.t_min = -5, r.t_max = 0; break;
        default: break;
        }
        rays.push_back(r);
    }
    const std::vector<Isa> isas = kernel_isas();
    for (Isa isa : isas) {
        const TracerKernel kernel = make_tracer_kernel(data.view(), placement, o, isa);
        uint64_t hits = 0;
        for (int count : {kMaxTracePacket, 13, 5})
            for (size_t i0 = 0; i0 < rays.size(); i0 += size_t(count)) {
                const int n = int(std::min<size_t>(size_t(count), rays.size() - i0));
                int valid[kMaxTracePacket];
                for (int k = 0; k < kMaxTracePacket; ++k) valid[k] = (i0 + size_t(k)) % 11 == 4 ? 0 : -1;
                TraceHit out[kMaxTracePacket];
                kernel.trace_packet(kernel.user, &rays[i0], n, valid, true, out);
                for (int k = 0; k < n; ++k) {
                    const TraceHit expected = valid[k] ? kernel.trace(kernel.user, rays[i0 + size_t(k)], true) : TraceHit{};
                    hits += expected.is_hit();
                    ASSERT_TRUE(same_hit(expected, out[k]))
                        << "isa " << int(isa) << ", packets of " << count << ", ray " << i0 + size_t(k) << ", kind "
                        << ((i0 + size_t(k)) / 3) % 16;
                }
            }
        EXPECT_GT(hits, 900u) << "the three passes over 1 600 rays must reach the surfaces often (about a third do)";
    }
    // A volume without cells (an extent of 1): nothing is ever hit, and no lane is traversed.
    const Dims flat{9, 1, 6};
    const DenseVolume<uint8_t> thin = make_volume<uint8_t>(flat, Pattern::Blocky, 5);
    const OctreeData<uint8_t> thin_data = build_octree(thin.view(), {});
    for (Isa isa : isas) {
        const TracerKernel kernel = make_tracer_kernel(thin_data.view(), placement, o, isa);
        for (size_t i0 = 0; i0 + kMaxTracePacket <= 320; i0 += kMaxTracePacket) {
            TraceHit out[kMaxTracePacket];
            kernel.trace_packet(kernel.user, &rays[i0], kMaxTracePacket, nullptr, true, out);
            for (int k = 0; k < kMaxTracePacket; ++k) {
                ASSERT_FALSE(out[k].is_hit()) << "isa " << int(isa) << ", flat volume, ray " << i0 + size_t(k);
                ASSERT_TRUE(same_hit(kernel.trace(kernel.user, rays[i0 + size_t(k)], true), out[k]));
            }
        }
    }
}

TEST(PacketTraversal, Avx2KernelRunsWhereTheCpuHasIt) {
    if (!cpu_has_avx2()) {
        OCTISO_SKIP("this CPU has no AVX2/FMA: only the portable kernel can run");
    }
    EXPECT_EQ(resolve_isa(Isa::automatic), Isa::avx2);
    EXPECT_EQ(resolve_isa(Isa::avx2), Isa::avx2);
    EXPECT_EQ(resolve_isa(Isa::baseline), Isa::baseline);
}

}  // namespace
}  // namespace octiso::test
