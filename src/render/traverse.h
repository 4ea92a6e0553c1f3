// OctreeTracer<T, Finder>: first hit of one ray with the isosurfaces of an Octree<T> (Knoll et al.
// 2006, Sec. 4.3 and App. C), in index space on the closed data box [0, n-1]^3.
//
// Interior nodes: the ray's times at the three mid-planes decide the first child and the order
// of the rest; a child is entered only if an isovalue lies in its [min, max]. Every plane time is
// IndexRay::plane_t, the same expression the cell walk and the reference tracer use, so a ray
// splits at exactly the same t at every level and no interval is lost or doubled.
// Deviation from App. C: the first child is chosen by comparing times, not positions (no
// position/time rounding mismatch), and +-0 direction components never divide (plane_t gives +inf).
// Packets (Knoll, Wald, Hansen 2009): lanes with the same direction signs share each node's load,
// cull and child order; each lane's pieces are node()'s numbers. Lanes of one origin cross the
// upper levels as a beam, culled by interval bounds on their plane times (Reshetov et al. 2005's
// interval frustum, here only deciding which subtrees to enter), and get their exact pieces at
// the hand-off as the node's slab interval, which equals the mid-plane descent's bit for bit.
// Caps and scalar leaves: a short DDA over their cells. A scalar leaf's inner cells have all 8
// corners equal to the leaf value, so unless an isovalue equals it only the shell of cells at its
// +x/+y/+z faces (whose forward corners lie in neighbours) is walked.
// Corners: a cap's cells read their corners from its 3x3x3 corner lattice (CapBlocks): the cap's
// own voxels, and those of its 7 forward neighbour blocks, each located once per cap visit by
// neighbour finding on the parent trace this traversal keeps (App. B.2) and decoded into the
// lattice when a cell first needs it (locating each block once: +3-5 % frames/s on octree data,
// `octiso-bench grid`; the lattice shared by a packet's lanes: 0.84-1.00 x the frame time,
// scripts/build_ab.py; BENCHMARKS.md, grid and packet sections).
// The corner source is a policy only for the grid benchmark's "octree over array data" variant
// (Knoll 2006 Table 3); with the default, OctreeCornerSource, the policy costs nothing.
// The recorder is a policy only for `--debug-pixel` (octiso/debug_trace.h): with the default,
// NoRecorder, every recording call sits behind `if constexpr (Recorder::kOn)` and is not compiled.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "octiso/octree.h"
#include "render/cell.h"
#include "render/cell_dda.h"
#include "render/cell_hit.h"
#include "render/live_children.h"
#include "render/lod.h"
#include "render/packet_size.h"
#include "render/packet_start.h"
#include "render/pending_roots.h"
#include "render/simd4.h"
#include "math/ray.h"
#include "render/roots.h"
#include "util/check.h"
#include "util/isa.h"

#if defined(__AVX2__)
#include <immintrin.h>   // the AVX2 kernel's PacketSplit: _mm256_movemask_pd
#endif

namespace octiso {
OCTISO_ISA_BEGIN

/// Blocks of a cap's corner lattice (OctreeTracer::CapBlocks) whose voxels the cell of octant `oct`
/// reads: every block r with r & ~oct == 0.
constexpr unsigned cap_blocks_of_octant(int oct) {
    unsigned m = 0;
    for (int r = 0; r < 8; ++r)
        if ((r & ~oct) == 0) m |= 1u << r;
    return m;
}

/// The default corner source: the octree itself (in-cap reads and neighbour finding). Any other
/// Corners type provides `void gather(Coord cell, double corner[8]) const` and replaces every
/// corner read (e.g. ArrayCorners<T> in src/reference/macrocell.h); the octree then only culls.
struct OctreeCornerSource {};

/// The default recorder: records nothing. A recording type sets kOn = true and provides the
/// const calls of PixelTraceRecorder (src/render/debug_trace.cpp): clip, enter_node, cull,
/// scalar_leaf, enter_cap, cell, root.
struct NoRecorder {
    static constexpr bool kOn = false;
};

/// kOwned: the sort-last tracer (set_owned_cells); a parameter, not a flag, because its tests on
/// every cell and corner cost 4 % of a frame when compiled in and unused (A/B, BENCHMARKS.md MPI).
template <typename T, class Finder, class Corners = OctreeCornerSource, class Recorder = NoRecorder, bool kOwned = false>
class OctreeTracer {
    static constexpr bool kOwnCorners = std::is_same_v<Corners, OctreeCornerSource>;

public:
    OctreeTracer(const Octree<T>& tree, const Placement& placement, const double* isovalues, int iso_count,
                 const Finder& finder, const Corners& corners = Corners{}, const Recorder& recorder = Recorder{})
        : tree_(tree), scene_(tree.dims(), placement, isovalues, iso_count), live_(isovalues, iso_count), finder_(finder),
          corners_(corners), recorder_(recorder) {
        OCTISO_CHECK(tree.dmax() >= 2 && tree.dmax() < kMaxDepth, "dmax ", tree.dmax());
    }

    /// First hit along the world ray; the normal is computed only if `want_normal`.
    /// Thread-safe: all per-ray state lives on the caller's stack.
    TraceHit trace(const Ray& ray_world, bool want_normal) const {
        Walk w;
        const BoxClip clip = w.start(scene_, ray_world, want_normal);
        if constexpr (Recorder::kOn) recorder_.clip(clip.t_in, clip.t_out);
        if (!clip.empty()) {
            int d = 0;
            uint32_t index = 0;
            Coord o{};
            if (start_below_root(w, d, index, o, clip.t_in, clip.t_out)) node(w, d, index, o, clip.t_in, clip.t_out);
        }
        if (w.pending) finish_hit(finder_, w);
        return w.hit;
    }

    /// Roots that need refining are refined when the trace ends (nearest_root's kDefer,
    /// pending_roots.h): a packet's four at a time, with their normals. Not with the recorder,
    /// which reports each root as it is found. scripts/build_ab.py against 7581811, 512^2, 1
    /// thread, 15 pairs: 0.94-0.97 x the trace at the minimum on ch2better @100.5 and @25.5 and ch2
    /// @100.5, 1.03 on aal (medians 0.88-0.96; build_ab_deferred_refine_normal.json); the
    /// refinement alone, normals one by one, 0.99-1.01 x at the minimum in a 21-pair run
    /// (build_ab_deferred_refine_only.json): the normals' divisions and square root are the gain.
    static constexpr bool kDeferRoots = !Recorder::kOn;
    /// Every corner a traversal of an integer file tests is one of its voxels (or, at a coarse
    /// level, a stored scalar of its type), so the cell's cubic skips its scaling (cell.h).
    using CornerKind = CornerKindOf<T>;

    /// The most rays one trace_packet() call takes (packet_size.h).
    static constexpr int kMaxPacket = kMaxTracePacket;
    /// A packet keeps traversing a subtree together while at least this many of its lanes enter
    /// it; fewer lanes continue as single rays. Measured by `octiso-bench packets` (BENCHMARKS.md,
    /// packet section): since the one-pass child cull, primary rays take 0.97-0.98 x the frame
    /// time at 1 or 2 lanes against 4, at 3 0.98-0.99 x (packets_session4_threshold.json; at 2
    /// against 4 as an A/B of builds: build_ab_packet_threshold_2.json).
    static constexpr int kDefaultMinPacketLanes = 2;
    /// Lanes sharing their direction signs that start a packet at the root; fewer start as single
    /// rays. Apart from the descent's threshold: a group of 2 or 3 random rays with the same signs
    /// rarely shares a node, and incoherent rays through the packet entry lost 5-10 % against
    /// single rays when 2 such lanes started a packet (BENCHMARKS.md, packet section). A packet of
    /// more than 8 rays needs half of them: 4 of 16 random rays share their signs often enough that
    /// incoherent rays in groups of 16 lost 3-6 % (plume, mixing 256^3) with a plain 4.
    static constexpr int kMinStartLanes = 4;
    static int min_start_lanes(int count) { return std::max(kMinStartLanes, count / 2); }
    /// A packet of primary rays (one origin, no zero direction component) crosses the levels above
    /// the nodes of side 2^kBeamHandOffLog2Side as one beam (beam_node): a child is culled for the
    /// whole packet by interval bounds on its lanes' plane times instead of each lane's pieces,
    /// and the lanes' exact pieces are computed at the hand-off. Exact (the same pieces, the same
    /// hits bit for bit). Measured with scripts/build_ab.py, orbit of 4, 512^2, 7 pairs, against the
    /// packets from the root: 0.93-0.98 x the trace time at the minimum on 8 files (real scans,
    /// 256^3 and 64^3 fields) at 1 thread, 0.79-0.99 x on 5 at 2 threads (build_ab_beam_third.json,
    /// build_ab_beam_2threads.json); the hand-off at side 4 or 16 instead of 8 within 1 % of it
    /// (build_ab_beam_side4_vs_8.json, build_ab_beam_side16_vs_8.json). Level-of-detail frames
    /// keep the packets from the root: a beam that stops where the cut stops packet_node was tried
    /// and gave 0.95-0.96 x the LOD F = 1 trace on plume and mixing 1024^3 (cut at the caps) but
    /// 1.06 x on mixing 2048^3, the case, where the cut is at units 4 and 8
    /// (build_ab_lod_beam.json, build_ab_lod_nobeam_vs_beam.json).
    static constexpr int kBeamHandOffLog2Side = 3;
    /// The depth at which the beam hands its lanes to packet_node (nodes of side 8); 0 or less: no beam.
    int beam_depth() const { return tree_.dmax() - kBeamHandOffLog2Side; }
    /// For the benchmark's A/B of the threshold and for tests that force one path; not thread-safe
    /// against a frame in flight.
    void set_min_packet_lanes(int lanes) { min_packet_lanes_ = std::max(1, lanes); }

    /// Sort-last (RenderOptions::owned_cells): only the cells of `box` are tested and subtrees
    /// wholly outside it are skipped where min/max culling would skip them. The child intervals
    /// are computed exactly as without the box, so a hit inside it is the whole volume's hit bit
    /// for bit; cells are half-open along the ray, so a surface on a box face is claimed by the
    /// box whose cell the ray enters there, once. Not thread-safe against a frame in flight.
    /// `ghost_plane` (may be null): the voxels of x = box.hi[0], element y + ny * z, read in
    /// place of the octree for the +x corners of the box's last cells (RenderOptions::ghost_plane).
    void set_owned_cells(const CellBox& box, const double* ghost_plane = nullptr) {
        static_assert(kOwned, "set_owned_cells needs OctreeTracer<..., kOwned = true>");
        owned_ = box;
        ghost_ = ghost_plane;
    }

    /// Level of detail for the frames that follow (lod.h; off by default): nodes the cut allows
    /// are traced as coarse cells of their lattice instead of being descended. Set between
    /// frames, never during one (the Renderer holds a lock around it).
    void set_lod(const LodCut& cut) const { lod_ = cut; }

    /// First hits of rays[0 .. count), count <= kMaxPacket; lanes with valid[k] == 0 (valid may be
    /// null: all valid) are misses. Every hit equals trace(rays[k]) bit for bit: each lane sees the
    /// same child intervals, culls and cell walks as alone (see packet_node). Thread-safe.
    void trace_packet(const Ray* rays, int count, const int* valid, bool want_normal, TraceHit* hits) const {
        OCTISO_DCHECK(count >= 0 && count <= kMaxPacket, "packet of ", count);
        Packet p;
        unsigned by_flip[8] = {};
#if defined(__AVX2__)
        start_lanes(p, rays, count, valid, want_normal, by_flip);
#else
        for (int k = 0; k < kMaxPacket; ++k) {
            p.t0[k] = std::numeric_limits<double>::infinity(), p.t1[k] = -std::numeric_limits<double>::infinity();
            if (k >= count || (valid && !valid[k])) continue;
            const BoxClip clip = p.lane[k].start(scene_, rays[k], want_normal);
            if (clip.empty()) continue;
            p.t0[k] = clip.t_in, p.t1[k] = clip.t_out;
            const auto& dir = p.lane[k].ray.dir;
            by_flip[(dir[0] < 0 ? 4 : 0) | (dir[1] < 0 ? 2 : 0) | (dir[2] < 0 ? 1 : 0)] |= 1u << k;
        }
#endif
        for (int flip = 0; flip < 8; ++flip) {
            const unsigned lanes = by_flip[flip];
            if (!lanes) continue;
            if (std::popcount(lanes) < std::max(min_start_lanes(count), min_packet_lanes_)) {
                for (unsigned m = lanes; m; m &= m - 1) {
                    const int k = std::countr_zero(m);
                    node(p.lane[k], 0, 0, Coord{}, p.t0[k], p.t1[k]);
                }
                continue;
            }
            Beam beam;
            if (beam_depth() > 0 && !restricted_ && !lod_.on() && beam.bound(p, lanes, flip))
                beam_node(p, beam, 0, 0, Coord{}, lanes, flip);
            else
                packet_node(p, 0, 0, Coord{}, lanes, flip, p.t0, p.t1);
        }
        unsigned pending = 0;
        for (int k = 0; k < count; ++k) pending |= unsigned(p.lane[k].pending) << k;
        if (pending) finish_hits(finder_, p.lane, pending);
        for (int k = 0; k < count; ++k) hits[k] = p.lane[k].hit;
    }

private:
    /// Whether the cube [o, o + side)^3 of cells meets the owned box.
    bool overlaps_owned(const Coord& o, uint32_t side) const {
        const uint32_t lo[3] = {o.x, o.y, o.z};
        for (int a = 0; a < 3; ++a)
            if (uint64_t(lo[a]) + side <= owned_.lo[a] || lo[a] >= owned_.hi[a]) return false;
        return true;
    }
    /// Whether the cube [o, o + side)^3 of cells lies wholly in the owned box.
    bool inside_owned(const Coord& o, uint32_t side) const {
        const uint32_t lo[3] = {o.x, o.y, o.z};
        for (int a = 0; a < 3; ++a)
            if (lo[a] < owned_.lo[a] || uint64_t(lo[a]) + side > owned_.hi[a]) return false;
        return true;
    }
    /// Corner k (x offset 1) of such a cell, from the ghost plane.
    double ghost_value(const Coord& v, int k) const {
        const uint64_t y = v.y + ((k >> 1) & 1), z = v.z + ((k >> 2) & 1);
        return ghost_[z * tree_.dims().y + y];
    }
    bool owns_cell(const int64_t cell[3]) const {
        for (int a = 0; a < 3; ++a)
            if (cell[a] < int64_t(owned_.lo[a]) || cell[a] >= int64_t(owned_.hi[a])) return false;
        return true;
    }

    static Coord child_origin_of(const Coord& o, int c, uint32_t half) {
        return {o.x + ((c & 4) ? half : 0), o.y + ((c & 2) ? half : 0), o.z + ((c & 1) ? half : 0)};
    }

    struct Walk : RayState {
        uint32_t trace[kMaxDepth];   ///< parent trace: node index at each depth down to the current one
    };

    /// Whether the ray is on the upper side of the plane p[a] == plane at time t (the side it
    /// occupies on [t, t + dt) for small dt): decided from times, never from positions. A ray lying
    /// in the plane takes the upper side, except in the data box's top face (plane == box_hi),
    /// whose only cells lie below it (the box is closed, CONVENTIONS 2b).
    bool upper_at(const IndexRay& r, int a, double plane, double t_plane, double t) const {
        const double d = r.dir[a];
        if (d > 0) return t_plane <= t;
        if (d < 0) return t < t_plane;
        return r.origin[a] > plane || (r.origin[a] == plane && plane < scene_.box_hi[a]);
    }

    /// A single ray starts in the deepest interior node whose one child piece holds its whole
    /// piece [t0, t1) of the data box: node() there sees the same piece as when reached from the
    /// root, since each node above would hand it on whole (no mid-plane time inside (t0, t1), the
    /// start side by upper_at at t0: for_each_child_piece's own decisions), and a child that
    /// node() would cull ends the ray as a miss here too (returns false). Only short pieces gain:
    /// ambient-occlusion rays of a few voxels from a surface skip the upper levels' node visits,
    /// which are cheap beside their cell walks near the surface: the `--ao 8` pass took 0.976-1.004 x
    /// its time at the minimum, 0.944-0.991 x at the median on 4 of 5 files (scripts/build_ab.py,
    /// 11 pairs, build_ab_ao_start_below_root.json); primary rays (pieces across the root's
    /// mid-planes) never descend here. Issue 11's "rays start at the deepest node containing their
    /// entry point", for the rays where it can apply without a bottom-up walk.
    /// The recorder, sort-last boxes and level-of-detail cuts keep the descent from the root.
    /// Fills w.trace for the levels passed (neighbour finding climbs it). The loop's per-axis
    /// decisions repeat for_each_child_piece's on purpose: the two sharing one inlined helper made
    /// the packet frames 1.05-1.07 x slower (GCC's code for the hot walk changed; 7 and 9 pairs,
    /// build_ab_review_start_child_packets*.json), so PacketTraversal.ShortRaysStartingBelowThe-
    /// RootEqualTheDescentFromTheRoot keeps them equal instead.
    bool start_below_root(Walk& w, int& d, uint32_t& index, Coord& o, double t0, double t1) const {
        if constexpr (Recorder::kOn || kOwned) return true;
        if (restricted_ || lod_.on() || !(t0 < t1)) return true;
        const IndexRay& r = w.ray;
        while (d < tree_.dmax() - 2) {
            const uint32_t half = tree_.child_bit(d);
            const uint32_t origin[3] = {o.x, o.y, o.z};
            int c = 0;
            for (int a = 0; a < 3; ++a) {
                const double mid = double(origin[a] + half);
                const double tm = r.plane_t(a, mid);
                if (tm > t0 && tm < t1) return true;   // crossed inside: node(d) splits the piece
                if (upper_at(r, a, mid, tm, t0)) c |= 4 >> a;
            }
            const InteriorNode<T>& n = tree_.node(d, index);
            if (n.is_scalar_leaf(c)) return true;
            if (!LiveChildren<T>::holds(n, live_.of(n), c, scene_.isovalues, scene_.iso_count)) return false;
            w.trace[d] = index;
            index = tree_.child_index_at(tree_.first_child(d, index, n), n, c);
            o = child_origin_of(o, c, half);
            ++d;
        }
        return true;
    }

    // Node origins travel by reference: a Coord passed by value is assembled with 32-bit stores
    // and reloaded as a 64-bit register pair, a store-forwarding stall that cost 18 % of node()
    // (perf annotate, plume 256^3 at 1024^2).
    bool node(Walk& w, int d, uint32_t index, const Coord& o, double t0, double t1) const {
        OCTISO_DCHECK(d >= 0 && d <= tree_.dmax() - 2, "interior depth ", d, ", dmax ", tree_.dmax());
        OCTISO_DCHECK(index < tree_.node_count(d), "node ", index, " of ", tree_.node_count(d), " at depth ", d);
        w.trace[d] = index;
        const InteriorNode<T>& n = tree_.node(d, index);
        const uint64_t first = tree_.first_child(d, index, n);
        const uint32_t half = tree_.child_bit(d);
        if constexpr (Recorder::kOn) recorder_.enter_node(d, index, o, 2 * half, t0, t1);
        const unsigned live = live_.of(n);
        if (!live && !Recorder::kOn) return false;   // the recorder still lists the culls
        CapParent parent(n, first);   // its neighbours: the caps' at depth dmax-2, coarse corners' above
        bool hit = false;
        for_each_child_piece(w.ray, o, half, t0, t1, [&](int c, double t_cur, double t_next) {
            const bool culled = !LiveChildren<T>::holds(n, live, c, scene_.isovalues, scene_.iso_count);
            if constexpr (Recorder::kOn)
                if (culled)
                    recorder_.cull(d, c, child_origin_of(o, c, half), half, n.bounds.lower(c), n.bounds.upper(c),
                                   t_cur, t_next);
            if (culled) return false;
            const Coord co = child_origin_of(o, c, half);
            if (restricted_ && !overlaps_owned(co, half)) return false;
            if (!restricted_ && lod_.on()) [[unlikely]] {
                // A leaf is walked on the coarsest lattice its distance allows; a stored child
                // stops only where the whole child is one coarse cell, else it is descended.
                const uint32_t unit = lod_.unit(co, half);
                if (unit > 1 && (n.is_scalar_leaf(c) || unit == half))
                    return hit = coarse_child(w, w.trace, d, n, c, co, half, unit, t_cur, t_next, parent);
            }
            if (n.is_scalar_leaf(c)) {
                hit = kLeafCaps && d == tree_.dmax() - 2 ? leaf_cap(w, parent, c, n.scalar[c], co, t_cur, t_next)
                                                         : scalar_leaf(w, w.trace, d, co, half, n.scalar[c], t_cur, t_next);
            } else if (d == tree_.dmax() - 2) {
                CapBlocks blocks(parent, c);
                hit = cap(w, w.trace, tree_.cap_at(first, n, c), co, t_cur, t_next, blocks);
            } else hit = node(w, d + 1, tree_.child_index_at(first, n, c), co, t_cur, t_next);
            return hit;
        });
        return hit;
    }

    /// The children of the node at `o` (children of side `half`) that ray `r` crosses on
    /// [t0, t1), in the order it crosses them: visit(c, t_cur, t_next) for each non-empty piece
    /// [t_cur, t_next), until visit returns true. The split times are the ray's mid-plane times
    /// (plane_t), ordered by a 3-element sorting network and folded by a running max: the one
    /// arithmetic both node() and packet_node() split at, so a packet lane gets its single-ray
    /// pieces bit for bit.
    template <class Visit>
    OCTISO_ALWAYS_INLINE bool for_each_child_piece(const IndexRay& r, const Coord& o, uint32_t half, double t0,
                                                   double t1, Visit&& visit) const {
        const uint32_t origin[3] = {o.x, o.y, o.z};
        double tm[3];
        int c = 0;
        for (int a = 0; a < 3; ++a) {
            const double mid = double(origin[a] + half);
            tm[a] = r.plane_t(a, mid);
            if (upper_at(r, a, mid, tm[a], t0)) c |= 4 >> a;
        }
        int order[3] = {0, 1, 2};
        if (tm[order[1]] < tm[order[0]]) std::swap(order[0], order[1]);
        if (tm[order[2]] < tm[order[1]]) std::swap(order[1], order[2]);
        if (tm[order[1]] < tm[order[0]]) std::swap(order[0], order[1]);
        double t_cur = t0;
        for (int i = 0; i <= 3; ++i) {
            double t_next = t1;
            if (i < 3 && tm[order[i]] > t0 && tm[order[i]] < t1) t_next = tm[order[i]];
            else if (i < 3) continue;   // this axis is not crossed inside [t0, t1)
            if (t_next > t_cur && visit(c, t_cur, t_next)) return true;
            if (i == 3) break;
            t_cur = std::max(t_cur, t_next);
            c ^= 4 >> order[i];
        }
        return false;
    }

    /// A cap parent (depth dmax-2, side 4) and its forward neighbours at the same depth: entry q
    /// (octant bits) is the node whose cube holds the parent's origin + 4 (q>>2&1, q>>1&1, q&1),
    /// or the scalar leaf above that depth covering it; entry 0 is the parent itself. Entries are
    /// located on first use and shared by every cap of the parent that a ray or a packet visits:
    /// a cap's forward block outside its parent is a child of one of them, so it is read directly
    /// instead of by a climb and descent per block: 0.93-1.01 x the frame time (min of 5 pairs,
    /// medians 0.95-0.98; build_ab_cap_parent.json, BENCHMARKS.md packet section).
    struct CapParent {
        const InteriorNode<T>* node[8];   ///< entries in `ready` and not in `is_leaf`
        uint64_t first[8];                ///< their first children (byte offsets into the caps)
        T leaf[8];                        ///< entries in `is_leaf`: the covering leaf's value
        unsigned ready = 1, is_leaf = 0;
        CapParent(const InteriorNode<T>& n, uint64_t first_child) {
            node[0] = &n;
            first[0] = first_child;
        }
        /// A scalar leaf of the cap parents' side taken as one (packet_leaf_cap_parent): entry 0,
        /// the parent itself, covered by the leaf.
        explicit CapParent(T value) : ready(1), is_leaf(1) {
            node[0] = nullptr;
            first[0] = 0;
            leaf[0] = value;
        }
    };

    /// The corner lattice of one cap: the 3x3x3 voxels that its 8 cells' corners are, at
    /// lattice[9 x + 3 y + z] (x, y, z = 0..2 from the cap's origin), filled block by block on
    /// first use and then read directly. Block 0 is the cap itself; block r = 1..7 (octant bits) is
    /// its forward neighbour 2x2x2 at co + 2 * (r>>2&1, r>>1&1, r&1), a cap or part of one scalar
    /// leaf, located by neighbour finding; only its voxels on the lattice are decoded (4 of a face
    /// block, 2 of an edge block, 1 of the corner block). One per cap visit; a packet shares it
    /// between its lanes, so each voxel is decoded once per packet instead of once per corner per
    /// lane (BENCHMARKS.md, packet section: the lattice A/B).
    struct CapBlocks {
        double lattice[27];   ///< unset until its block's bit is in `ready`
        unsigned ready = 0;   ///< bit r: block r's lattice voxels are in place
        CapParent& parent;    ///< the cap's parent and its neighbours
        int octant;           ///< the cap's octant in its parent
        CapBlocks(CapParent& p, int c) : parent(p), octant(c) {}
    };

    /// One packet of rays sharing their direction signs: per lane its walk, its piece [t0, t1) of
    /// the data box; the parent trace is the packet's (all its lanes are in the same nodes).
    struct Packet {
        Walk lane[kMaxPacket];
        // Every lane's entry is set, unused ones to an empty piece: packet_node reads all of them.
        alignas(32) double t0[kMaxPacket], t1[kMaxPacket];
#if defined(__AVX2__)
        /// The lanes' index rays by axis (lane k at [a][k]; unused lanes zero) for the AVX2
        /// kernel's four-lane PacketSplit.
        alignas(32) double origin[3][kMaxPacket], dir[3][kMaxPacket], inv_dir[3][kMaxPacket];
#endif
        uint32_t trace[kMaxDepth];
    };

#if defined(__AVX2__)
    /// trace_packet's lane starts four lanes at a time (packet_start.h): every lane's piece
    /// [t0, t1) and direction-sign group as RayState::start and the loop of the portable kernel
    /// give them, bit for bit, its index ray (the same bits wherever the data have cells: a lane
    /// of a volume without cells starts empty and is never traversed), and the lanes' rays by axis
    /// for PacketSplit.
    void start_lanes(Packet& p, const Ray* rays, int count, const int* valid, bool want_normal, unsigned by_flip[8]) const {
        for (int k0 = 0; k0 < kMaxPacket; k0 += 4) {
            LaneStarts4 s;
            start_four_lanes(scene_, rays, k0, count, valid, s);
            for (int a = 0; a < 3; ++a) {
                store4(&p.origin[a][k0], s.origin[a]);
                store4(&p.dir[a][k0], s.dir[a]);
                store4(&p.inv_dir[a][k0], s.inv_dir[a]);
            }
            store4(&p.t0[k0], s.t_in);
            store4(&p.t1[k0], s.t_out);
            for (int j = 0; j < 4; ++j) {
                if (!s.given[j]) continue;
                const int k = k0 + j;
                Walk& w = p.lane[k];
                w.world_dir = rays[k].dir;
                w.want_normal = want_normal;
                for (int a = 0; a < 3; ++a)
                    w.ray.origin[a] = s.origin[a][j], w.ray.dir[a] = s.dir[a][j], w.ray.inv_dir[a] = s.inv_dir[a][j];
                w.t_exit = s.t_out[j];
                if (!s.live[j]) continue;
                by_flip[(s.dir[0][j] < 0 ? 4 : 0) | (s.dir[1][j] < 0 ? 2 : 0) | (s.dir[2][j] < 0 ? 1 : 0)] |= 1u << k;
            }
        }
    }
#endif

#if defined(__AVX2__)
    /// The lanes' pieces of a node's children, four lanes at a time (the AVX2 kernel): per lane its
    /// mid-plane times, the side of each plane it starts on, and whether it crosses the plane
    /// inside [t0, t1). Its piece of child c is then [max(t0, times of the planes between its
    /// start child and c), min(t1, times of the other planes it crosses)): the running max and the
    /// next crossing of node()'s walk (for_each_child_piece), the same numbers by the same
    /// operations, so the same pieces bit for bit; a child it does not reach gets an empty piece.
    /// Computed only for the children that survive the cull: 0.69-0.95 x the frame time of the
    /// per-lane walk below (BENCHMARKS.md, packet section, the A/B). The portable kernel keeps the
    /// walk: there GCC lowers these 4-wide vectors to SSE halves so badly that frames took
    /// 1.7-2.0 x as long, and a scalar version of this split lost to the walk as well.
    struct PacketSplit {
        static constexpr int kHalves = kMaxPacket / 4;
        /// Per axis a, side s of the child on that axis (0 lower, 1 upper) and half h, the axis'
        /// part in enter(): `from` the lanes' plane time where the child lies across the plane
        /// from the lane's start (else -inf, which the running max never takes), `to` the time
        /// where it lies on the start side and the lane crosses the plane (else +inf, which the
        /// running min never takes), `reach` whether the lane can be on that side at all. With
        /// them precomputed a child costs three max, three min and three ands per half, and the
        /// pieces are the per-axis selects' numbers bit for bit: max(x, -inf) and min(x, +inf)
        /// are x, NaN included (lo < -inf and +inf < hi are false). 0.85-0.93 x the frame time of
        /// the selects per child (1 thread; 0.88-0.90 x at 2 threads; build_ab_packet_split_sides*.json).
        /// Skipping a half without active lanes as well gained nothing (1.00-1.05 x at the minimum).
        V4d from[3][2][kHalves], to[3][2][kHalves];
        V4l reach[3][2][kHalves];
        const double* t0 = nullptr;
        const double* t1 = nullptr;
        alignas(32) double lo_[kMaxPacket], hi_[kMaxPacket];

        void split(const OctreeTracer& tr, const Packet& p, const Coord& o, uint32_t half, unsigned /*active*/,
                   const double* t0_in, const double* t1_in) {
            t0 = t0_in, t1 = t1_in;
            const uint32_t origin[3] = {o.x, o.y, o.z};
            const double inf_ = std::numeric_limits<double>::infinity();
            const V4d zero{}, inf{inf_, inf_, inf_, inf_}, minus_inf = -inf;
            for (int h = 0; h < kHalves; ++h) {
                V4d T0, T1;
                load4(T0, t0 + 4 * h), load4(T1, t1 + 4 * h);
                for (int a = 0; a < 3; ++a) {
                    V4d O, D, I;
                    load4(O, p.origin[a] + 4 * h), load4(D, p.dir[a] + 4 * h), load4(I, p.inv_dir[a] + 4 * h);
                    const double mid = double(origin[a] + half);
                    const V4d M{mid, mid, mid, mid};
                    const V4d t = D == zero ? inf : (M - O) * I;   // IndexRay::plane_t
                    // upper_at: by time where the ray moves along the axis, else by position.
                    const V4l top_face_rule = mid < tr.scene_.box_hi[a] ? V4l{} - 1 : V4l{};
                    const V4l in_plane_up = (O > M) | ((O == M) & top_face_rule);
                    const V4l up = D > zero ? V4l(t <= T0) : D < zero ? V4l(T0 < t) : in_plane_up;
                    const V4l crossed = (t > T0) & (t < T1);
                    for (int s = 0; s < 2; ++s) {
                        const V4l between = s ? ~up : up;   // up ^ (side s's mask)
                        from[a][s][h] = between ? t : minus_inf;
                        to[a][s][h] = (~between & crossed) ? t : inf;
                        reach[a][s][h] = ~between | crossed;
                    }
                }
            }
        }
        /// The lanes of `active` that enter child c; their pieces are then at lo(c), hi(c).
        unsigned enter(unsigned c, unsigned active) {
            unsigned entered = 0;
            for (int h = 0; h < kHalves; ++h) {
                V4d lo, hi;
                load4(lo, t0 + 4 * h), load4(hi, t1 + 4 * h);
                V4l ok = V4l{} - 1;
                for (int a = 0; a < 3; ++a) {
                    const int s = (c >> (2 - a)) & 1;
                    const V4d f = from[a][s][h], e = to[a][s][h];
                    lo = lo < f ? f : lo;   // std::max(lo, t) where the plane lies between
                    hi = e < hi ? e : hi;   // std::min(hi, t) where it is crossed ahead
                    ok &= reach[a][s][h];
                }
                ok &= hi > lo;
                store4(lo_ + 4 * h, lo), store4(hi_ + 4 * h, hi);
                entered |= unsigned(_mm256_movemask_pd(__m256d(ok))) << (4 * h);
            }
            return entered & active;
        }
        const double* lo(unsigned) const { return lo_; }
        const double* hi(unsigned) const { return hi_; }
    };
#else
    /// The lanes' pieces of a node's children, lane by lane (the portable kernel): each lane's
    /// own mid-plane walk, node()'s for_each_child_piece, so every piece is the single-ray one.
    struct PacketSplit {
        unsigned lanes_in[8] = {};
        double lo_[8][kMaxPacket], hi_[8][kMaxPacket];

        void split(const OctreeTracer& tr, const Packet& p, const Coord& o, uint32_t half, unsigned active,
                   const double* t0, const double* t1) {
            for (unsigned m = active; m; m &= m - 1) {
                const int k = std::countr_zero(m);
                tr.for_each_child_piece(p.lane[k].ray, o, half, t0[k], t1[k], [&](int c, double lo, double hi) {
                    lanes_in[c] |= 1u << k;
                    lo_[c][k] = lo, hi_[c][k] = hi;
                    return false;
                });
            }
        }
        unsigned enter(unsigned c, unsigned active) const { return lanes_in[c] & active; }
        const double* lo(unsigned c) const { return lo_[c]; }
        const double* hi(unsigned c) const { return hi_[c]; }
    };
#endif

    /// What packet_node and beam_node read of the node (d, index) on entering it, which goes on
    /// the packet's parent trace: the record, its first child, its children's side and the
    /// children an isovalue may lie in (LiveChildren).
    struct PacketNodeAt {
        const InteriorNode<T>& n;
        uint64_t first;
        uint32_t half;
        unsigned live;
    };
    OCTISO_ALWAYS_INLINE PacketNodeAt packet_at(Packet& p, int d, uint32_t index) const {
        p.trace[d] = index;
        const InteriorNode<T>& n = tree_.node(d, index);
        return {n, tree_.first_child(d, index, n), tree_.child_bit(d), live_.of(n)};
    }

    /// Knoll, Wald, Hansen 2009 for primary rays, exact: the lanes in `active` (all with the
    /// direction signs `flip`, bit 4>>a set where dir[a] < 0) traverse node (d, index) together.
    /// Children are visited in the order c = i ^ flip, i = 0..7: a ray with those signs only ever
    /// moves to children with more bits of c ^ flip set, so this order is front to back for every
    /// lane. Each child is culled once for the packet (the test is the same for every lane), and
    /// a lane's interval in a child is exactly the single-ray one: its entry is the latest of t0
    /// and the mid-plane times of the axes it has crossed to reach the child, its exit the
    /// earliest of t1 and the times of the axes it has yet to cross; the pieces are the same
    /// numbers node() splits at, so the first hit of every lane is the single-ray hit.
    /// Returns the lanes of `active` that did not hit.
    unsigned packet_node(Packet& p, int d, uint32_t index, const Coord& o, unsigned active, int flip,
                         const double* t0, const double* t1) const {
        OCTISO_DCHECK(d >= 0 && d <= tree_.dmax() - 2, "interior depth ", d, ", dmax ", tree_.dmax());
        OCTISO_DCHECK(index < tree_.node_count(d), "node ", index, " of ", tree_.node_count(d), " at depth ", d);
        const auto [n, first, half, live] = packet_at(p, d, index);
        if (!live) return active;
        PacketSplit split;
        split.split(*this, p, o, half, active, t0, t1);
        CapParent parent(n, first);   // its neighbours: the caps' at depth dmax-2, coarse corners' above
        for (unsigned m = in_visit_order(live, flip); m && active; m &= m - 1) {
            const unsigned c = unsigned(std::countr_zero(m) ^ flip);
            if (!LiveChildren<T>::holds(n, live, int(c), scene_.isovalues, scene_.iso_count)) continue;
            const unsigned entered = split.enter(c, active);
            if (!entered) continue;
            const double* c0 = split.lo(c);
            const double* c1 = split.hi(c);
            const Coord co = child_origin_of(o, int(c), half);
            if (restricted_ && !overlaps_owned(co, half)) continue;
            unsigned hit = 0;
            if (!restricted_ && lod_.on()) [[unlikely]] {
                // The cut is the node's, not the ray's (lod.h): every lane stops here or none.
                const uint32_t unit = lod_.unit(co, half);
                const bool leaf = n.is_scalar_leaf(int(c));
                if (unit > 1 && (leaf || unit == half)) {
                    hit = coarse_lanes(p, parent, n, d, int(c), co, half, unit, entered, c0, c1);
                    active &= ~hit;
                    continue;
                }
            }
            if (d == tree_.dmax() - 2 && n.is_scalar_leaf(int(c)) && kLeafCaps) {
                hit = packet_leaf_cap(p, parent, int(c), n.scalar[c], co, entered, flip, c0, c1);
            } else if (d == tree_.dmax() - 2 && !n.is_scalar_leaf(int(c))) {
                CapBlocks blocks(parent, int(c));   // located once for every lane that crosses this cap
                hit = cap_lanes(p, tree_.cap_at(first, n, int(c)), co, entered, flip, c0, c1, blocks);
            } else if (d == tree_.dmax() - 3 && n.is_scalar_leaf(int(c)) && kLeafCaps) {
                hit = packet_leaf_cap_parent(p, n.scalar[c], co, entered, flip, c0, c1);
            } else {
                hit = lanes_into_child(p, n, d, first, c, co, half, entered, flip, c0, c1);
            }
            active &= ~hit;
        }
        return active;
    }

    /// The lanes `entered` of a packet into child c (origin co, side half) of node n at depth d,
    /// each on its piece [c0[k], c1[k]), where the child is a scalar leaf walked lane by lane or an
    /// interior node: the subtree as a packet, or lane by lane below min_packet_lanes_ lanes.
    /// (packet_node's caps are its own, and with kLeafCaps its scalar leaves of side 2 and 4.)
    /// Returns the lanes that hit.
    OCTISO_ALWAYS_INLINE unsigned lanes_into_child(Packet& p, const InteriorNode<T>& n, int d, uint64_t first, unsigned c,
                                                   const Coord& co, uint32_t half, unsigned entered, int flip, const double* c0,
                                                   const double* c1) const {
        unsigned hit = 0;
        if (n.is_scalar_leaf(int(c))) {
            for (unsigned m = entered; m; m &= m - 1) {
                const int k = std::countr_zero(m);
                if (scalar_leaf(p.lane[k], p.trace, d, co, half, n.scalar[c], c0[k], c1[k])) hit |= 1u << k;
            }
        } else if (std::popcount(entered) < min_packet_lanes_) {
            for (unsigned m = entered; m; m &= m - 1) {
                const int k = std::countr_zero(m);
                Walk& w = p.lane[k];
                std::copy(p.trace, p.trace + d + 1, w.trace);
                if (node(w, d + 1, tree_.child_index_at(first, n, int(c)), co, c0[k], c1[k])) hit |= 1u << k;
            }
        } else {
            hit = entered & ~packet_node(p, d + 1, tree_.child_index_at(first, n, int(c)), co, entered, flip, c0, c1);
        }
        return hit;
    }

    /// The cells of a cap as a packet: the default tracer only (the sort-last one's owned-cell and
    /// ghost tests and the recorder's calls stay in cap(), lane by lane).
    static constexpr bool kPacketCaps = !kOwned && kOwnCorners && !Recorder::kOn;
    /// Lanes in a cap from which its cells are walked as a packet (packet_cap); fewer walk alone.
    /// Worth it only where nearly the whole packet crosses the cap, as close up: from 5 lanes,
    /// 0.85-1.00 x the frame time at --zoom 3 and 0.91 x on plume 64^3 (8 pixels a voxel), the
    /// whole-view real scans and 256^3 fields within the noise, 0.98-1.04 x at the minimum
    /// (build_ab_packet_cap_cells*.json); from 2 lanes the whole views gained 1-4 % but plume 64^3
    /// lost 6 % (the split and the enter of all 8 cells for 2-3 lanes cost more than the walks).
    /// From 3, 4 or 7 lanes on the real scans since: 1.005-1.073 x and 0.996-1.016 x at the minimum
    /// (build_ab_cap_packet_from_{3,4}_lanes_stop51.json, build_ab_cap_packet_from_7_lanes_stop52.json).
    static constexpr int kMinCapPacketLanes = 5;

    /// The lanes of `active` that hit in the cap `ref` at `co` (its lattice `blocks`), each on its
    /// piece [t0[k], t1[k]): walked as a packet (packet_cap) from kMinCapPacketLanes lanes, else
    /// lane by lane (cap).
    OCTISO_ALWAYS_INLINE unsigned cap_lanes(Packet& p, const CapRef<T>& ref, const Coord& co, unsigned active, int flip,
                                            const double* t0, const double* t1, CapBlocks& blocks) const {
        if (kPacketCaps && std::popcount(active) >= kMinCapPacketLanes)
            return active & ~packet_cap(p, ref, co, active, flip, t0, t1, blocks);
        unsigned hit = 0;
        for (unsigned m = active; m; m &= m - 1) {
            const int k = std::countr_zero(m);
            if (cap(p.lane[k], p.trace, ref, co, t0[k], t1[k], blocks)) hit |= 1u << k;
        }
        return hit;
    }

    /// A scalar leaf of side 2 (a child of a cap parent) is walked as a cap whose 8 voxels are its
    /// value: its corner lattice (the forward blocks through the cap parent's neighbours, shared
    /// with the caps beside it and between the lanes) and the cap's split walk, in place of the
    /// leaf walk's DDA and a neighbour search per corner beyond it. The same cells with the same
    /// pieces and corners (the cap walk's pieces are the DDA's, walk_cap_cells), so the same
    /// hits bit for bit; the leaf's one inner cell, whose corners all equal its value, is culled
    /// by its corner range instead of skipped. The default tracer only, as packet caps.
    /// 0.96-0.97 x the frame time on ch2better and ch2 @25.5 and aal @0.5, where 4-190 % as many
    /// such leaves as caps sit under the cap parents (build_ab_leaf_caps_apart.json).
    static constexpr bool kLeafCaps = kPacketCaps;
    /// A cap whose 8 voxels all read `v` (kLeafCaps): deltas of zero from the base v.
    static CapRef<T> constant_cap(T v) {
        if constexpr (sizeof(T) == 1) {
            return CapRef<T>{0, 1, ScalarKey<T>::of(v)};
        } else {
            static constexpr uint8_t kZeroDeltas[16] = {};   // a record of 0-bit deltas: 8 bytes read
            return CapRef<T>{kZeroDeltas, 0, v};
        }
    }

    /// kLeafCaps for one ray (node()) and for the lanes `active` of a packet (packet_node; returns
    /// the lanes that hit), apart from the caps' path so that it stays as it was: with the
    /// leaf folded into the cap branch, files with few such leaves read 1.01-1.06 x the frame time
    /// at the minimum (build_ab_leaf_caps_folded*.json; BENCHMARKS.md, packets, seventh session).
    [[gnu::noinline]] bool leaf_cap(Walk& w, CapParent& parent, int c, T value, const Coord& co, double t0, double t1) const {
        CapBlocks blocks(parent, c);
        return cap(w, w.trace, constant_cap(value), co, t0, t1, blocks);
    }
    [[gnu::noinline]] unsigned packet_leaf_cap(Packet& p, CapParent& parent, int c, T value, const Coord& co, unsigned active,
                                               int flip, const double* t0, const double* t1) const {
        CapBlocks blocks(parent, c);
        return cap_lanes(p, constant_cap(value), co, active, flip, t0, t1, blocks);
    }

    /// A scalar leaf of side 4 (a child of a node at depth dmax-3) crossed by the lanes `entered`
    /// as a cap parent whose 8 caps are constant caps of its value: the packet split at its
    /// mid-planes, each quarter a side-2 leaf for packet_leaf_cap, its corner lattice read through
    /// the leaf's forward neighbours at the cap parents' depth (located once for all its caps and
    /// lanes) instead of the leaf walk's DDA and a neighbour descent per corner beyond the leaf.
    /// The cap at the leaf's origin has every corner inside the leaf: skipped unless an isovalue
    /// equals the value (then scalar_leaf walks every cell too). The same cells with the same
    /// pieces (the split's plane times are the DDA's) and corners, so the same hits bit for bit.
    /// Against the leaf walk, 11 pairs: 0.92 / 0.96 x the trace at the minimum on aal @0.5 and
    /// ch2better @25.5, where such leaves are common, 1.00 x on ch2better @100.5, which walks none
    /// (build_ab_side4_leaf_caps*.json, BENCHMARKS.md packet section, twelfth session).
    /// Returns the lanes that hit.
    [[gnu::noinline]] unsigned packet_leaf_cap_parent(Packet& p, T value, const Coord& o, unsigned entered, int flip,
                                                      const double* t0, const double* t1) const {
        const bool iso_equals_value = scene_.any_iso_in(double(value), double(value));
        CapParent parent(value);
        PacketSplit split;
        split.split(*this, p, o, 2, entered, t0, t1);
        unsigned active = entered;
        for (unsigned i = 0; i < 8 && active; ++i) {
            const unsigned c = i ^ unsigned(flip);
            if (c == 0 && !iso_equals_value) continue;
            const unsigned lanes = split.enter(c, active);
            if (!lanes) continue;
            active &= ~packet_leaf_cap(p, parent, int(c), value, child_origin_of(o, int(c), 2), lanes, flip, split.lo(c), split.hi(c));
        }
        return entered & ~active;
    }

    /// The lanes of `active` (signs `flip`) through the cap at `co` (ref, its corner lattice
    /// `blocks`), each on its piece [t0[k], t1[k]): the cap's 8 cells are a node's children of
    /// side 1, split once for the packet (PacketSplit) and visited in packet_node's order, front
    /// to back for every lane; a cell's corners are gathered and its range culled once for the
    /// lanes that cross it, then each tests its own piece. The pieces are cap()'s (its walk is
    /// for_each_child_piece with children of side 1, whose numbers PacketSplit reproduces), so
    /// every lane's first hit is its single-ray hit bit for bit. Returns the lanes that did not hit.
    unsigned packet_cap(Packet& p, const CapRef<T>& ref, const Coord& co, unsigned active, int flip, const double* t0,
                        const double* t1, CapBlocks& blocks) const {
        PacketSplit split;
        split.split(*this, p, co, 1, active, t0, t1);
        for (unsigned i = 0; i < 8 && active; ++i) {
            const unsigned c = i ^ unsigned(flip);
            const unsigned entered = split.enter(c, active);
            if (!entered) continue;
            const uint32_t x = (c >> 2) & 1u, y = (c >> 1) & 1u, z = c & 1u;
            const int64_t cell[3] = {int64_t(co.x) + x, int64_t(co.y) + y, int64_t(co.z) + z};
            if (past_last_cell(cell)) continue;   // padding, as in visit_cell
            const double* at = cap_cell_lattice(blocks, kCellBlocks[c], ref, co, x, y, z, p.trace);
            double corner[8];
            for (int k = 0; k < 8; ++k) corner[k] = at[kCellCorner[k]];
            double lo, hi;
            corner_range(corner, lo, hi);
            if (!scene_.any_iso_in(lo, hi)) continue;   // intersect_cell's cull, once for the packet
            const Coord v{uint32_t(cell[0]), uint32_t(cell[1]), uint32_t(cell[2])};
            const double* c0 = split.lo(c);
            const double* c1 = split.hi(c);
            for (unsigned m = entered; m; m &= m - 1) {
                const int k = std::countr_zero(m);
                Walk& w = p.lane[k];
                if (intersect_cell_in_range<Finder, kDeferRoots, CornerKind>(finder_, scene_, w, v, corner, lo, hi, c0[k],
                                                                             c1[k], c1[k] == w.t_exit))
                    active &= ~(1u << k);
            }
        }
        return active;
    }

    /// A packet's lanes as one beam, for the cull of the upper levels (beam_node): their common
    /// index origin, per axis the least and the largest reciprocal direction, the earliest entry
    /// into the data box and the latest exit. Only for lanes that share their origin (primary rays
    /// of a pinhole camera) and have no zero direction component (bound() says whether they do):
    /// rays from different origins make the bound too loose to cull (incoherent rays through the
    /// packet entry), and a ray parallel to a plane takes its side by position, not by time.
    struct Beam {
        double origin[3], inv_lo[3], inv_hi[3];
        double t0_lo, t1_hi;
#if defined(__AVX2__)
        V4d O, I_lo, I_hi;   ///< the same by axis (x, y, z; the fourth unused)
        V4l down;            ///< the axes along which the lanes move down (flip)
#endif
        bool bound(const Packet& p, unsigned lanes, int flip) {
            const double inf = std::numeric_limits<double>::infinity();
            const IndexRay& r0 = p.lane[std::countr_zero(lanes)].ray;
            t0_lo = inf, t1_hi = -inf;
            for (int a = 0; a < 3; ++a) origin[a] = r0.origin[a], inv_lo[a] = inf, inv_hi[a] = -inf;
            for (unsigned m = lanes; m; m &= m - 1) {
                const int k = std::countr_zero(m);
                const IndexRay& r = p.lane[k].ray;
                for (int a = 0; a < 3; ++a) {
                    if (r.dir[a] == 0 || r.origin[a] != origin[a]) return false;
                    inv_lo[a] = std::min(inv_lo[a], r.inv_dir[a]), inv_hi[a] = std::max(inv_hi[a], r.inv_dir[a]);
                }
                t0_lo = std::min(t0_lo, p.t0[k]), t1_hi = std::max(t1_hi, p.t1[k]);
            }
#if defined(__AVX2__)
            O = V4d{origin[0], origin[1], origin[2], 0.0};
            I_lo = V4d{inv_lo[0], inv_lo[1], inv_lo[2], 0.0}, I_hi = V4d{inv_hi[0], inv_hi[1], inv_hi[2], 0.0};
            down = V4l{(flip & 4) ? -1LL : 0LL, (flip & 2) ? -1LL : 0LL, (flip & 1) ? -1LL : 0LL, 0LL};
#endif
            return true;
        }
        /// False only where no lane's piece of the cube [o, o + side)^3 is non-empty. A lane's piece
        /// is [max(t0, entry plane times), min(t1, exit plane times)) (beam_pieces), and a plane's
        /// time, (plane - origin) * inv_dir rounded, is monotone in inv_dir, so over the lanes it
        /// lies between the products with the least and the largest inv_dir: the bound holds for
        /// the rounded times themselves, no margin needed.
        bool may_enter(const Coord& o, uint32_t side, int flip) const {
#if defined(__AVX2__)
            (void)flip;
            // By axis in one register each (x, y, z; the fourth lane is left out of the max and min).
            const V4d lower{double(o.x), double(o.y), double(o.z), 0.0};
            const double s = double(side);
            const V4d upper = lower + V4d{s, s, s, 0.0};
            const V4d in = (down ? upper : lower) - O, out = (down ? lower : upper) - O;
            const V4d e0 = in * I_lo, e1 = in * I_hi, x0 = out * I_lo, x1 = out * I_hi;
            const V4d e = e1 < e0 ? e1 : e0, x = x0 < x1 ? x1 : x0;
            const double lo = std::max(std::max(t0_lo, e[0]), std::max(e[1], e[2]));
            const double hi = std::min(std::min(t1_hi, x[0]), std::min(x[1], x[2]));
            return lo < hi;
#else
            const uint32_t lo_face[3] = {o.x, o.y, o.z};
            double lo = t0_lo, hi = t1_hi;
            for (int a = 0; a < 3; ++a) {
                const bool down = (flip >> (2 - a)) & 1;
                const double lower = double(lo_face[a]), upper = double(lo_face[a] + side);
                const double in = (down ? upper : lower) - origin[a], out = (down ? lower : upper) - origin[a];
                lo = std::max(lo, std::min(in * inv_lo[a], in * inv_hi[a]));
                hi = std::min(hi, std::max(out * inv_lo[a], out * inv_hi[a]));
            }
            return lo < hi;
#endif
        }
    };

    /// Each lane's piece of the cube [o, o + side)^3 directly, as the box's slab interval
    /// [max(t0, entry plane times), min(t1, exit plane times)): the piece the mid-plane descent
    /// (for_each_child_piece, PacketSplit) reaches it with, bit for bit. Along each axis that
    /// descent raises the entry by the time of every mid-plane it crosses into the cube's side
    /// and lowers the exit likewise; the cube's faces are the last such planes, the earlier ones
    /// have no later (earlier) times (plane_t is monotone in the plane), and a plane crossed
    /// before t0 or after t1 leaves max/min where they are; a child the descent does not enter
    /// has an empty slab. For lanes with no zero direction component (Beam::bound). Returns the
    /// lanes of `active` with a non-empty piece [lo[k], hi[k]).
    unsigned beam_pieces(const Packet& p, const Coord& o, uint32_t side, unsigned active, int flip, double* lo,
                         double* hi) const {
        const uint32_t lo_face[3] = {o.x, o.y, o.z};
#if defined(__AVX2__)
        // Four lanes at a time, the same operations: plane_t is (plane - origin) * inv_dir where the
        // direction is not zero, std::max(a, b) is a < b ? b : a and std::min(a, b) b < a ? b : a.
        // Other lanes of a half get their own rays' numbers, which packet_node reads and masks out.
        unsigned entered = 0;
        const double inf_ = std::numeric_limits<double>::infinity();
        for (int h = 0; h < kMaxPacket / 4; ++h) {
            if (!((active >> (4 * h)) & 0xFu)) {   // every lane's piece is set: packet_node reads them all
                store4(lo + 4 * h, V4d{inf_, inf_, inf_, inf_}), store4(hi + 4 * h, -V4d{inf_, inf_, inf_, inf_});
                continue;
            }
            V4d t_in, t_out;
            load4(t_in, p.t0 + 4 * h), load4(t_out, p.t1 + 4 * h);
            for (int a = 0; a < 3; ++a) {
                const bool down = (flip >> (2 - a)) & 1;
                const double lower = double(lo_face[a]), upper = double(lo_face[a] + side);
                const double in_ = down ? upper : lower, out_ = down ? lower : upper;
                V4d O, I;
                load4(O, p.origin[a] + 4 * h), load4(I, p.inv_dir[a] + 4 * h);
                const V4d e = (V4d{in_, in_, in_, in_} - O) * I, x = (V4d{out_, out_, out_, out_} - O) * I;
                t_in = t_in < e ? e : t_in;
                t_out = x < t_out ? x : t_out;
            }
            store4(lo + 4 * h, t_in), store4(hi + 4 * h, t_out);
            entered |= unsigned(_mm256_movemask_pd(__m256d(t_out > t_in))) << (4 * h);
        }
        return entered & active;
#else
        std::fill(lo, lo + kMaxPacket, std::numeric_limits<double>::infinity());
        std::fill(hi, hi + kMaxPacket, -std::numeric_limits<double>::infinity());
        unsigned entered = 0;
        for (unsigned m = active; m; m &= m - 1) {
            const int k = std::countr_zero(m);
            const IndexRay& r = p.lane[k].ray;
            double t_in = p.t0[k], t_out = p.t1[k];
            for (int a = 0; a < 3; ++a) {
                const bool down = (flip >> (2 - a)) & 1;
                const double lower = double(lo_face[a]), upper = double(lo_face[a] + side);
                t_in = std::max(t_in, r.plane_t(a, down ? upper : lower));
                t_out = std::min(t_out, r.plane_t(a, down ? lower : upper));
            }
            lo[k] = t_in, hi[k] = t_out;
            if (t_out > t_in) entered |= 1u << k;
        }
        return entered;
#endif
    }

    /// The upper levels for a packet, culled by its Beam instead of each lane's pieces: a child is
    /// visited (in packet_node's order, front to back for every lane) where an isovalue lies in
    /// its range and Beam::may_enter; at depth beam_depth() (or at a scalar leaf above it) each
    /// lane's piece is computed directly (beam_pieces) and the lanes go on as packet_node would
    /// take them there. A lane's first hit is the one of packet_node: it tests the same cells on
    /// the same pieces, in its own front-to-back order. Returns the lanes of `active` that did not hit.
    unsigned beam_node(Packet& p, const Beam& beam, int d, uint32_t index, const Coord& o, unsigned active, int flip) const {
        const auto [n, first, half, live] = packet_at(p, d, index);
        if (!live) return active;
        for (unsigned m = in_visit_order(live, flip); m && active; m &= m - 1) {
            const unsigned c = unsigned(std::countr_zero(m) ^ flip);
            if (!LiveChildren<T>::holds(n, live, int(c), scene_.isovalues, scene_.iso_count)) continue;
            const Coord co = child_origin_of(o, int(c), half);
            if (!beam.may_enter(co, half, flip)) continue;
            const bool leaf = n.is_scalar_leaf(int(c));
            if (!leaf && d + 1 < beam_depth()) {
                active = beam_node(p, beam, d + 1, tree_.child_index_at(first, n, int(c)), co, active, flip);
                continue;
            }
            alignas(32) double c0[kMaxPacket], c1[kMaxPacket];
            const unsigned entered = beam_pieces(p, co, half, active, flip, c0, c1);
            if (entered) active &= ~lanes_into_child(p, n, d, first, c, co, half, entered, flip, c0, c1);
        }
        return active;
    }

    /// `mask` (bit c: child c) with bit c moved to bit c ^ flip, so that its set bits, lowest
    /// first, are packet_node's visiting order: each set bit of flip swaps the halves of the
    /// mask along that axis.
    static unsigned in_visit_order(unsigned mask, int flip) {
        if (flip & 4) mask = ((mask & 0x0Fu) << 4) | (mask >> 4);
        if (flip & 2) mask = ((mask & 0x33u) << 2) | ((mask >> 2) & 0x33u);
        if (flip & 1) mask = ((mask & 0x55u) << 1) | ((mask >> 1) & 0x55u);
        return mask;
    }

    /// Per cell of a cap (octant bits), the lattice blocks its corners lie in.
    static constexpr unsigned kCellBlocks[8] = {cap_blocks_of_octant(0), cap_blocks_of_octant(1), cap_blocks_of_octant(2), cap_blocks_of_octant(3),
                                                cap_blocks_of_octant(4), cap_blocks_of_octant(5), cap_blocks_of_octant(6), cap_blocks_of_octant(7)};
    /// Corner i + 2j + 4k of a cap's cell is lattice point (x + i, y + j, z + k): its offset from
    /// the cell's lower corner in CapBlocks::lattice (9 x + 3 y + z).
    static constexpr int kCellCorner[8] = {0, 9, 3, 12, 1, 10, 4, 13};

    /// The corner lattice of the cap at `co` from its cell (x, y, z) (0 or 1 each) on, with the
    /// blocks in `need` decoded first: corner i + 2j + 4k of the cell is at kCellCorner[i + 2j + 4k].
    OCTISO_ALWAYS_INLINE const double* cap_cell_lattice(CapBlocks& blocks, unsigned need, const CapRef<T>& ref, const Coord& co,
                                                        uint32_t x, uint32_t y, uint32_t z, const uint32_t* trace) const {
        if ((blocks.ready & need) != need) fill_cap_blocks(blocks, need & ~blocks.ready, ref, co, trace);
        return blocks.lattice + (9 * x + 3 * y + z);
    }

    /// Whether a cell lies beyond the last data cell (padding of the octree's cube): never tested.
    OCTISO_ALWAYS_INLINE bool past_last_cell(const int64_t cell[3]) const {
        const Dims dims = tree_.dims();
        return cell[0] > int64_t(dims.x) - 2 || cell[1] > int64_t(dims.y) - 2 || cell[2] > int64_t(dims.z) - 2;
    }

    /// Locates entry q of `beside`, the CapParent kept for the node at depth d that holds `co` (the
    /// cap parent at dmax-2, or a node whose coarse corners level of detail reads), from its
    /// trace: the depth-d node across the faces that q's bits name, or the scalar leaf above it
    /// that covers it.
    [[gnu::noinline]] void locate_neighbour_node(CapParent& beside, int q, const Coord& co, int d, const uint32_t* trace) const {
        const uint32_t side = 2 * tree_.child_bit(d), mask = ~(side - 1);
        const Coord dest{(co.x & mask) + ((q & 4) ? side : 0u), (co.y & mask) + ((q & 2) ? side : 0u),
                         (co.z & mask) + ((q & 1) ? side : 0u)};
        const auto at = tree_.node_at(co, dest, d, trace, d);
        if (at.is_leaf) {
            beside.is_leaf |= 1u << q;
            beside.leaf[q] = at.value;
        } else {
            const InteriorNode<T>& n = tree_.node(d, at.index);
            beside.node[q] = &n;
            beside.first[q] = tree_.first_child(d, at.index, n);
        }
        beside.ready |= 1u << q;
    }

    /// Child `oct` of entry q of `beside` (the CapParent kept for the node at depth d that holds co;
    /// the entry located on first use): the covering leaf's value, a scalar leaf's value, a cap
    /// (a stored child of an entry at the cap parents, d = dmax-2), or above them a stored child's
    /// scalar, the voxel at its lower corner (format 4). So voxel() of the result, its octant 0, is
    /// that child's lower corner voxel at every depth.
    OCTISO_ALWAYS_INLINE LeafRef<T> beside_child(CapParent& beside, int q, int oct, const Coord& co, int d,
                                                 const uint32_t* trace) const {
        if (!((beside.ready >> q) & 1u)) locate_neighbour_node(beside, q, co, d, trace);
        if ((beside.is_leaf >> q) & 1u) return {beside.leaf[q], false, {}, 0};
        const InteriorNode<T>& n = *beside.node[q];
        if (n.is_scalar_leaf(oct) || d != tree_.dmax() - 2) return {n.scalar[oct], false, {}, 0};
        return {T{}, true, tree_.cap_at(beside.first[q], n, oct), 0};
    }

    /// Puts the lattice voxels of the blocks in `missing` into `blocks` (CapBlocks). Block r of the
    /// cap at octant c of its parent is child c ^ r of parent entry c & r: on the axes of r where c
    /// is already on the upper side, the block lies across the parent's face.
    [[gnu::noinline]] void fill_cap_blocks(CapBlocks& blocks, unsigned missing, const CapRef<T>& ref, const Coord& co,
                                         const uint32_t* trace) const {
        CapParent& parent = blocks.parent;
        const int c = blocks.octant;
        for (unsigned m = missing; m; m &= m - 1) {
            const int r = std::countr_zero(m);
            const LeafRef<T> found =
                r == 0 ? LeafRef<T>{T{}, true, ref, 0} : beside_child(parent, c & r, c ^ r, co, tree_.dmax() - 2, trace);
            // The block's lattice voxels: 2 on the axes of r (its local 0), 0 or 1 on the others.
            for (int local = 0; local < 8; ++local) {
                if (local & r) continue;
                const int x = (r & 4) ? 2 : (local >> 2) & 1, y = (r & 2) ? 2 : (local >> 1) & 1, z = (r & 1) ? 2 : local & 1;
                blocks.lattice[9 * x + 3 * y + z] = found.in_cap ? double(found.cap.voxel(local)) : double(found.value);
            }
        }
        blocks.ready |= missing;
    }

    bool cap(RayState& w, const uint32_t* trace, const CapRef<T>& ref, const Coord& co, double t0, double t1,
             CapBlocks& blocks) const {
        const int parent_depth = tree_.dmax() - 2;
        if constexpr (Recorder::kOn) recorder_.enter_cap(parent_depth + 1, trace[parent_depth], co, t0, t1);
        // Sort-last (set_owned_cells): decided once per cap.
        const bool cap_on_ghost = restricted_ && ghost_ && co.x + 2 == owned_.hi[0];
        // Forced inline: once the packed caps' decode made it larger, GCC called it per cell
        // (perf, Marschner-Lobb 256^3: walk_units + the gather 40 % above the inlined walk).
        return walk_cap_cells(w, co, t0, t1, restricted_ && !inside_owned(co, 2), [&](Coord v, double corner[8]) OCTISO_LAMBDA_INLINE {
            if constexpr (!kOwnCorners) {
                corners_.gather(v, corner);
                return;
            }
            const uint32_t x = v.x - co.x, y = v.y - co.y, z = v.z - co.z;
            const bool on_ghost = cap_on_ghost && v.x + 1 == owned_.hi[0];
            // On the ghost plane the +x corners come from it, not from the blocks beyond the box.
            const unsigned need = kCellBlocks[(x << 2) | (y << 1) | z] & (on_ghost ? 0x0Fu : 0xFFu);
            const double* at = cap_cell_lattice(blocks, need, ref, co, x, y, z, trace);
            if (on_ghost) [[unlikely]] {
                for (int k = 0; k < 8; ++k) corner[k] = (k & 1) ? ghost_value(v, k) : at[kCellCorner[k]];
                return;
            }
            for (int k = 0; k < 8; ++k) corner[k] = at[kCellCorner[k]];
        });
    }

    bool scalar_leaf(RayState& w, const uint32_t* trace, int holder_depth, const Coord& co, uint32_t side, T value,
                     double t0, double t1) const {
        const double v = double(value);
        const bool leaf_on_ghost = restricted_ && ghost_ && co.x + side == owned_.hi[0];
        const bool partial = restricted_ && !inside_owned(co, side);   // cells outside the box skipped
        // The outer corners of the shell cells (beyond the leaf) come from the scalar leaf or cap
        // that held the last one read, while they lie in it: a shell cell's 4-7 outer corners and
        // the next cell's mostly lie in one neighbour, found by one descent instead of one each.
        // Only voxels of that neighbour are read from it, so every corner is the one a descent of
        // its own finds (RenderAgreement.BigLeavesBesideNoisyCapsReadEveryOuterCorner). aal @0.5,
        // where such shells are common: 0.970 / 0.979 x the trace at the minimum in two runs (9
        // and 11 pairs, build_ab_beyond_leaf_first.json, build_ab_beyond_leaf.json); ch2better,
        // ch2, plume and mixing 0.98-1.01 x. One memo shared by the lanes of a packet crossing the
        // leaf took 1.014-1.018 x the time of this per-ray one at the minimum (15 pairs,
        // build_ab_beyond_leaf_shared_by_lanes.json); keeping the last cap's parent as well,
        // 1.009-1.045 x (build_ab_beyond_leaf_cap_parent.json).
        struct {
            Coord o{~0u, ~0u, ~0u};
            uint32_t keep = 0;   // ~(side - 1) of the neighbour at o; 0: none yet
            LeafRef<T> ref{};
        } beyond;
        auto beyond_value = [&](Coord p, Coord dest) OCTISO_LAMBDA_INLINE {
            if ((dest.x & beyond.keep) != beyond.o.x || (dest.y & beyond.keep) != beyond.o.y ||
                (dest.z & beyond.keep) != beyond.o.z) {
                uint32_t found_side = 1;
                beyond.ref = tree_.neighbour_locate(p, dest, holder_depth, trace, &found_side);
                beyond.keep = ~(found_side - 1);
                beyond.o = {dest.x & beyond.keep, dest.y & beyond.keep, dest.z & beyond.keep};
            } else if (beyond.ref.in_cap) {
                beyond.ref.octant = octant_of(dest, 1u);
            }
            return double(beyond.ref.voxel());
        };
        auto gather = [&](Coord p, double corner[8]) {
            if constexpr (!kOwnCorners) {
                corners_.gather(p, corner);
                return;
            }
            const uint32_t ex = co.x + side, ey = co.y + side, ez = co.z + side;
            const bool on_ghost = leaf_on_ghost && p.x + 1 == owned_.hi[0];
            for (int k = 0; k < 8; ++k) {
                const Coord dest{p.x + (k & 1), p.y + ((k >> 1) & 1), p.z + ((k >> 2) & 1)};
                corner[k] = (dest.x < ex && dest.y < ey && dest.z < ez) ? v
                            : (on_ghost && (k & 1))                     ? ghost_value(p, k)
                                                                        : beyond_value(p, dest);
            }
        };
        bool iso_equals_value = false;
        for (int i = 0; i < scene_.iso_count; ++i) iso_equals_value |= scene_.isovalues[i] == v;
        if constexpr (Recorder::kOn) recorder_.scalar_leaf(holder_depth, co, side, v, t0, t1, iso_equals_value);
        if (iso_equals_value) return walk_cells(w, co, side, t0, t1, partial, gather);

        // Skip the inner cells [co, co + side - 1)^3: constant, never crossed by another iso.
        double ti0 = t0, ti1 = t1;
        inside_box(w.ray, co, side - 1, ti0, ti1);
        if (!(ti0 < ti1)) return walk_cells(w, co, side, t0, t1, partial, gather);
        if (ti0 > t0 && walk_cells(w, co, side, t0, ti0, partial, gather)) return true;
        return ti1 < t1 && walk_cells(w, co, side, ti1, t1, partial, gather);
    }

    /// Cuts [ti0, ti1) to where the ray is inside the box [lo, lo + extent]^3 (open at the upper
    /// faces); leaves ti0 >= ti1 where it never is. A scalar leaf's constant interior.
    static void inside_box(const IndexRay& r, const Coord& lo, uint32_t extent, double& ti0, double& ti1) {
        const uint32_t o[3] = {lo.x, lo.y, lo.z};
        for (int a = 0; a < 3; ++a) {
            const double p0 = double(o[a]), p1 = double(o[a] + extent);
            const double d = r.dir[a];
            if (d == 0) {
                if (r.origin[a] < p0 || r.origin[a] >= p1) ti1 = ti0 - 1;   // never inside
                continue;
            }
            const double ta = r.plane_t(a, d > 0 ? p0 : p1), tb = r.plane_t(a, d > 0 ? p1 : p0);
            ti0 = std::max(ti0, ta);
            ti1 = std::min(ti1, tb);
        }
    }

    /// The cells of the box [lo, lo + side)^3 that the ray crosses on [t0, t1), in order, by the
    /// one cell DDA (cell_dda.h). Each data cell gets the half-open piece [t_in, t_out) (closed at
    /// the data exit); `gather` fills its 8 corners. Cells of the box beyond the data (padding)
    /// are stepped over. Returns true at the first hit.
    template <class Gather>
    /// `partial`: the box reaches past the owned cells (set_owned_cells); those are skipped.
    bool walk_cells(RayState& w, const Coord& lo, uint32_t side, double t0, double t1, bool partial, Gather&& gather) const {
        const Dims dims = tree_.dims();
        const int64_t last_cell[3] = {int64_t(dims.x) - 2, int64_t(dims.y) - 2, int64_t(dims.z) - 2};
        const DdaBox box{{lo.x, lo.y, lo.z},
                         {int64_t(lo.x) + side, int64_t(lo.y) + side, int64_t(lo.z) + side},
                         {last_cell[0], last_cell[1], last_cell[2]},
                         scene_.box_hi};
        return walk_units(w.ray, UnitCells{}, box, t0, t1, w.t_exit,
                          [&](const int64_t cell[3], double t_in, double t_out, bool closed_end) OCTISO_LAMBDA_INLINE {
                              return visit_cell(w, cell, t_in, t_out, closed_end, partial, gather);
                          });
    }

    /// One cell of a walk (walk_cells, walk_cap_cells) on its piece [t_in, t_out): stepped over
    /// beyond the last data cell (padding) or outside the owned cells, else gathered and tested.
    template <class Gather>
    OCTISO_ALWAYS_INLINE bool visit_cell(RayState& w, const int64_t cell[3], double t_in, double t_out, bool closed_end,
                                         bool partial, Gather& gather) const {
        if (past_last_cell(cell)) return false;
        OCTISO_DCHECK(cell[0] >= 0 && cell[1] >= 0 && cell[2] >= 0, "cell below the data box");
        if (partial && !owns_cell(cell)) [[unlikely]] return false;
        const Coord v{uint32_t(cell[0]), uint32_t(cell[1]), uint32_t(cell[2])};
        double corner[8];
        gather(v, corner);
        return test_cell(w, v, corner, t_in, t_out, closed_end);
    }

    /// The cells of the cap [co, co + 2)^3 that the ray crosses on [t0, t1), in order, as
    /// walk_cells would hand them over, but split at the cap's mid-planes like a node's children
    /// (for_each_child_piece with children of side 1) instead of by the DDA: the same pieces bit
    /// for bit (each face time is plane_t of the same plane; a ray's side at t0 is decided by the
    /// same comparisons the DDA's first-cell settling makes; empty pieces are skipped by both, and
    /// no empty piece can end at the data exit inside a cap, so closed_end never differs).
    /// 0.93-0.96 x the frame time (min of 5 pairs, build_ab_cap_split_rerun.json; a first run on
    /// a noisier machine read 0.87-1.13, build_ab_cap_split.json).
    template <class Gather>
    bool walk_cap_cells(RayState& w, const Coord& co, double t0, double t1, bool partial, Gather&& gather) const {
        return for_each_child_piece(w.ray, co, 1, t0, t1, [&](int c, double t_in, double t_out) OCTISO_LAMBDA_INLINE {
            const Coord v = child_origin_of(co, c, 1);
            const int64_t cell[3] = {v.x, v.y, v.z};
            return visit_cell(w, cell, t_in, t_out, t_out == w.t_exit, partial, gather);
        });
    }

    /// Whether the cube [co, co + side]^3 of voxels lies inside the data: a coarse cell of side
    /// `side` there is whole, not cut at the last voxel.
    bool inside_data(const Coord& co, uint32_t side) const {
        const Dims dims = tree_.dims();
        return co.x + side < dims.x && co.y + side < dims.y && co.z + side < dims.z;
    }

    /// Level of detail: child c (origin co, side `side`) of node n at depth d, traced on lattice
    /// `unit` over [t0, t1). A child that is one whole coarse cell inside the data is tested at
    /// once, its corners the lower corner voxels of its siblings and of the node's neighbours'
    /// children (coarse_corners; `beside` holds the node and those neighbours): with the leaf-interior skip
    /// of coarse_cells, 1.07 x / 1.05 x faster frames at F = 2 / 4 on plume 1024^3 than walking it
    /// as a box of one unit (two builds alternated under load, no JSON: a direction, BENCHMARKS
    /// "Level of detail"). Everything else walks.
    bool coarse_child(RayState& w, const uint32_t* trace, int d, const InteriorNode<T>& n, int c, const Coord& co,
                      uint32_t side, uint32_t unit, double t0, double t1, CapParent& beside) const {
        if (!whole_coarse_child(co, side, unit))
            return coarse_cells(w, trace, d, co, side, unit, n.is_scalar_leaf(c), n.scalar[c], t0, t1);
        double corner[8];
        coarse_corners(beside, trace, d, c, co, corner);
        return coarse_whole_cell(w, co, side, corner, t0, t1);
    }
    /// Whether a child of side `side` at co is one whole coarse cell of lattice `unit` inside the
    /// data (coarse_child tests it at once).
    bool whole_coarse_child(const Coord& co, uint32_t side, uint32_t unit) const { return unit == side && inside_data(co, side); }

    /// The corners of such a child c of the node at depth d, the lattice voxels at its 8 vertices:
    /// corner k is the lower corner voxel of child c ^ r of entry c & r of `beside` (r the octant
    /// bits of k; entry 0 is the node itself, the others its forward neighbours at depth d,
    /// located at most once per visit of the node, for all its children and a packet's lanes).
    /// That voxel is a stored child's scalar above the cap parents (format 4), a cap's voxel 0 at
    /// them, a scalar leaf's value anywhere: what a descent by lattice_value returns, bit for bit.
    /// Against a DDA walk of the one cell with a descent per corner, per lane (the path before):
    /// a cut at the caps 0.79-0.80 x the LOD F = 1 trace on plume and mixing 1024^3, 0.93-0.95 x
    /// at 512^3 (build_ab_lod_cap_corners.json); above them, the corners once for a packet's lanes
    /// 0.94-0.97 x at 1024^3 (build_ab_lod_shared_corners.json) and the neighbours once per node
    /// 0.956-0.967 x on plume and mixing 2048^3, where 84-96 % of the hits stop at unit 4
    /// (build_ab_lod_node_neighbours.json); every pixel the same.
    void coarse_corners(CapParent& beside, const uint32_t* trace, int d, int c, const Coord& co, double corner[8]) const {
        for (int k = 0; k < 8; ++k) {
            const int r = ((k & 1) << 2) | (k & 2) | ((k >> 2) & 1);   // corner k (x = bit 0) as octant bits (x = 4)
            corner[k] = double(beside_child(beside, c & r, c ^ r, co, d, trace).voxel());
        }
    }
    /// The whole coarse cell of side `side` at co with `corner` on the ray's piece [t0, t1).
    bool coarse_whole_cell(RayState& w, const Coord& co, uint32_t side, const double corner[8], double t0, double t1) const {
        const bool closed_end = t1 == w.t_exit;
        if (!(t1 > t0 || closed_end)) return false;
        const uint32_t extent[3] = {side, side, side};
        if (!intersect_coarse_cell<Finder, kDeferRoots, CornerKind>(finder_, scene_, w, co, extent, corner, t0, t1,
                                                                    closed_end))
            return false;
        w.hit.cell_log2 = std::countr_zero(side);
        return true;
    }
    /// coarse_child for the lanes `entered` of a packet, each on its piece [c0[k], c1[k]): a whole
    /// coarse cell has its corners read once for all of them. Returns the lanes that hit.
    unsigned coarse_lanes(Packet& p, CapParent& beside, const InteriorNode<T>& n, int d, int c, const Coord& co, uint32_t half,
                          uint32_t unit, unsigned entered, const double* c0, const double* c1) const {
        unsigned hit = 0;
        if (whole_coarse_child(co, half, unit)) {
            double corner[8];
            coarse_corners(beside, p.trace, d, c, co, corner);
            for (unsigned m = entered; m; m &= m - 1) {
                const int k = std::countr_zero(m);
                if (coarse_whole_cell(p.lane[k], co, half, corner, c0[k], c1[k])) hit |= 1u << k;
            }
            return hit;
        }
        for (unsigned m = entered; m; m &= m - 1) {
            const int k = std::countr_zero(m);
            if (coarse_cells(p.lane[k], p.trace, d, co, half, unit, n.is_scalar_leaf(c), n.scalar[c], c0[k], c1[k])) hit |= 1u << k;
        }
        return hit;
    }

    /// Level of detail: the cells of lattice `unit` (a power of two >= 2) inside the child cube
    /// [co, co + side)^3 of the node at depth d (w.trace down to d) that the ray crosses on
    /// [t0, t1), by the one DDA in units of `unit` (planes at multiples of it: the node's own
    /// mid-planes, so pieces abut exactly). A cell's corners are the lattice voxels at its
    /// vertices (Octree::lattice_value); on the upper data border the cell is cut to the last
    /// voxel, whose corners are then voxels off the lattice, read at the finest unit that divides
    /// them. Inside a scalar leaf every corner in its cube is its value.
    bool coarse_cells(RayState& w, const uint32_t* trace, int d, const Coord& co, uint32_t side, uint32_t unit, bool is_leaf, T leaf_value,
                      double t0, double t1) const {
        const Dims dims = tree_.dims();
        const uint32_t n[3] = {dims.x, dims.y, dims.z};
        const int shift = std::countr_zero(unit);
        const uint32_t o[3] = {co.x, co.y, co.z};
        DdaBox box;
        for (int a = 0; a < 3; ++a) {
            box.lo[a] = int64_t(o[a] >> shift);
            box.hi[a] = int64_t((uint64_t(o[a]) + side) >> shift);
            box.top_unit[a] = int64_t((n[a] - 2) >> shift);   // the unit holding the last data cell
        }
        box.box_hi = scene_.box_hi;
        const double leaf = double(leaf_value);
        auto walk = [&](double ta, double tb) {
            return walk_units(w.ray, ScaledCells{double(unit)}, box, ta, tb, w.t_exit,
                          [&](const int64_t cell[3], double t_in, double t_out, bool closed_end) {
                              uint32_t q[3], e[3];
                              for (int a = 0; a < 3; ++a) {
                                  q[a] = uint32_t(cell[a]) << shift;
                                  if (q[a] > n[a] - 2) return false;   // beyond the last data cell
                                  e[a] = std::min(unit, n[a] - 1 - q[a]);
                              }
                              double corner[8];
                              for (int k = 0; k < 8; ++k) {
                                  const Coord p{q[0] + ((k & 1) ? e[0] : 0u), q[1] + ((k & 2) ? e[1] : 0u),
                                                q[2] + ((k & 4) ? e[2] : 0u)};
                                  if (is_leaf && p.x - co.x < side && p.y - co.y < side && p.z - co.z < side) {
                                      corner[k] = leaf;
                                      continue;
                                  }
                                  const uint32_t bits = p.x | p.y | p.z;
                                  const uint32_t at = bits == 0 ? unit : std::min(unit, bits & (0u - bits));
                                  corner[k] = double(tree_.lattice_value(co, p, at, d, trace));
                              }
                              const Coord v{q[0], q[1], q[2]};
                              if (!intersect_coarse_cell<Finder, kDeferRoots, CornerKind>(finder_, scene_, w, v, e, corner,
                                                                                          t_in, t_out, closed_end))
                                  return false;
                              w.hit.cell_log2 = shift;
                              return true;
                          });
        };
        bool iso_equals_leaf = false;
        for (int i = 0; i < scene_.iso_count; ++i) iso_equals_leaf |= scene_.isovalues[i] == leaf;
        if (!is_leaf || iso_equals_leaf) return walk(t0, t1);
        // As scalar_leaf does at full resolution: the coarse cells with all 8 corners in the
        // leaf, [co, co + side - unit)^3, are constant and never crossed by another isovalue.
        double ti0 = t0, ti1 = t1;
        inside_box(w.ray, co, side - unit, ti0, ti1);
        if (!(ti0 < ti1)) return walk(t0, t1);
        if (ti0 > t0 && walk(t0, ti0)) return true;
        return ti1 < t1 && walk(ti1, t1);
    }

    bool test_cell(RayState& w, Coord v, const double corner[8], double t_in, double t_out, bool closed_end) const {
        if constexpr (Recorder::kOn) {
            double lo, hi;
            corner_range(corner, lo, hi);
            recorder_.cell(v, t_in, t_out, closed_end, lo, hi);
            const bool hit = intersect_cell(finder_, scene_, w, v, corner, t_in, t_out, closed_end);
            if (hit) recorder_.root(w.hit.t, w.hit.iso_index);
            return hit;
        }
        return intersect_cell<Finder, kDeferRoots, CornerKind>(finder_, scene_, w, v, corner, t_in, t_out, closed_end);
    }

    const Octree<T> tree_;   // a view: cheap to copy, and no dangling reference to a temporary
    const CellWalkScene scene_;
    const LiveChildren<T> live_;   ///< the per-node cull of all 8 children (1-byte scalars)
    const Finder finder_;
    int min_packet_lanes_ = kDefaultMinPacketLanes;
    mutable LodCut lod_;   ///< set_lod(): per frame, between frames
    static constexpr bool restricted_ = kOwned;
    CellBox owned_;
    const double* ghost_ = nullptr;   ///< the plane x = owned_.hi[0], or null
    [[no_unique_address]] const Corners corners_;
    [[no_unique_address]] const Recorder recorder_;
};

OCTISO_ISA_END
}  // namespace octiso
