// The streamed build of one step (stream_build.h). Steps per step:
//  1. slabs in z order: read the new layers (the halo of the last slab is kept, so every byte of
//     the input is read once), condition them (prepare.h, on the slab), build the slab's pieces in
//     parallel (piece_builder.h) and append their arrays, per depth, to the spill files;
//  2. the top: the nodes above the pieces' depth k, from their root summaries in depth-first order;
//  3. sections: depth by depth, the pieces' chunks read back in depth-first order, their children
//     placed as they pass (child_groups.h), checked (the next depth covered exactly, 32-bit) and
//     streamed into the writer with the group bases after them; it checksums them as they pass.
#include "convert/stream_build.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include <malloc.h>

#include <tbb/parallel_for.h>

#include "convert/spill_file.h"
#include "octiso/error.h"
#include "octree/child_groups.h"
#include "octree/piece_builder.h"
#include "octree/prepare.h"
#include "util/check.h"

namespace octiso::convert_detail {

namespace {

using detail::Builder;
using detail::Sink;
using detail::Summary;

constexpr uint32_t kMaxPieceSide = 64;   // 2048^2 layers: 1024 pieces a slab for 2 threads, halo 1/64
constexpr uint32_t kMinPieceSide = 4;    // a node at depth dmax-2, the smallest the builder cuts at

uint64_t ceil_div(uint64_t a, uint64_t b) { return (a + b - 1) / b; }

struct Halo {
    uint32_t below, above;
};
Halo halo_of(const BuildOptions& options) { return options.iso_range ? Halo{1, 2} : Halo{0, 1}; }

// The estimates are doubles: a hostile grid (2^30 x 2^30 layers) must compare as too large, not
// wrap around 2^64 and pass.
double slab_need(Dims dims, double b, const BuildOptions& options, uint32_t s, bool is_float) {
    const Halo h = halo_of(options);
    const double layer = double(dims.x) * dims.y;
    const double region = layer * double(std::min<uint64_t>(uint64_t(s) + h.below + h.above, dims.z));
    double need = region * b;                                        // the layers themselves
    if (options.nan_as && is_float) need += region * b;              // the --nan-as copy
    if (options.iso_range) need += region * b + region;              // clamped copy + flags
    const uint64_t s_data = std::min<uint64_t>(s, dims.z);
    const double caps = double(ceil_div(dims.x, 2)) * double(ceil_div(dims.y, 2)) * double(ceil_div(s_data, 2)) * 8 * b;
    // Nodes at format 2's record size, 24 b + 8 bytes: an upper bound of the record sizes of formats 3-5 (octree.h).
    const double nodes =
        double(ceil_div(dims.x, 4)) * double(ceil_div(dims.y, 4)) * double(ceil_div(s_data, 4)) * (24 * b + 8) * 8 / 7;
    need += 2 * (caps + nodes);                                      // the pieces' vectors, growth slack
    return need;
}

double fixed_need(Dims dims, double b, uint32_t s) {
    const int dmax = dmax_for(dims);
    const double pieces = double(ceil_div(dims.x, s)) * double(ceil_div(dims.y, s)) * double(ceil_div(dims.z, s));
    const double levels = double(std::countr_zero(s));
    const double per_piece = levels * 4 + 48 + 4 + 8;                // counts, Summary<T>, order, chunk offset
    const double cube = double(s) * s * s;
    const double staging = cube * b + cube / 8 * (24 * b + 8);
    return pieces * per_piece + staging + double(dmax) * 4096;
}

std::string mib_text(double b) {
    char text[64];
    std::snprintf(text, sizeof text, "%.0f MiB", std::ceil(b / 1048576.0));
    return text;
}

template <typename T> class StepBuilder {
public:
    StepBuilder(VolumeStream& stream, const BuildOptions& options, const StreamPlan& plan, OctWriter& writer,
                const std::string& output)
        : stream_(stream), options_(options), writer_(writer), dims_(stream.dims()), dmax_(dmax_for(dims_)),
          side_(plan.piece_side), k_(dmax_ - std::countr_zero(plan.piece_side)), levels_(dmax_ - k_),
          npx_(uint32_t(ceil_div(dims_.x, side_))), npy_(uint32_t(ceil_div(dims_.y, side_))),
          npz_(uint32_t(ceil_div(dims_.z, side_))), allowance_{plan.spill_memory} {
        OCTISO_CHECK(k_ >= 0 && k_ <= dmax_ - 2, "piece side ", side_, " does not fit dmax ", dmax_);
        n_pieces_ = uint64_t(npx_) * npy_ * npz_;
        counts_.assign(size_t(levels_), std::vector<uint32_t>(n_pieces_, 0));
        roots_.resize(n_pieces_);
        leaves_.assign(size_t(dmax_), 0);
        for (int l = 0; l < levels_; ++l)
            spill_.push_back(std::make_unique<SpillFile>(output + ".spill-d" + std::to_string(k_ + l), allowance_));
    }

    StreamStepResult run(const std::function<void(uint32_t)>& on_layers) {
        const auto t0 = std::chrono::steady_clock::now();
        const auto since = [](std::chrono::steady_clock::time_point t) {
            return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
        };
        StreamStepResult r;
        build_slabs(on_layers);
        r.slabs_seconds = since(t0);
        const auto t_top = std::chrono::steady_clock::now();
        Sink<T> top(dmax_);
        const std::vector<uint64_t> order = build_top(top);
        r.top_seconds = since(t_top);
        const auto t_sections = std::chrono::steady_clock::now();
        r.sizes = write_sections(top, order);
        r.sections_seconds = since(t_sections);
        for (const auto& s : spill_) r.spilled_bytes += s->disk_bytes();
        r.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        return r;
    }

private:
    uint64_t piece_id(Coord o) const { return uint64_t(o.x / side_) + npx_ * (uint64_t(o.y / side_) + uint64_t(npy_) * (o.z / side_)); }

    // 1. Slabs of side_ layers, each with its halo; the overlap with the previous slab is kept.
    void build_slabs(const std::function<void(uint32_t)>& on_layers) {
        const Halo h = halo_of(options_);
        const uint64_t layer = uint64_t(dims_.x) * dims_.y;
        std::vector<T> buf(size_t(layer * std::min<uint64_t>(uint64_t(side_) + h.below + h.above, dims_.z)));
        uint32_t have_b = 0, have_e = 0;   // layers [have_b, have_e) sit at the start of buf
        for (uint32_t pz = 0; pz < npz_; ++pz) {
            const uint32_t z0 = pz * side_;
            const uint32_t zb = z0 >= h.below ? z0 - h.below : 0;
            const uint32_t ze = uint32_t(std::min<uint64_t>(dims_.z, uint64_t(z0) + side_ + h.above));
            OCTISO_CHECK(have_e >= zb || have_e == 0, "slab ", pz, " starts past the layers read");
            if (have_e > zb) std::memmove(buf.data(), buf.data() + (zb - have_b) * layer, (have_e - zb) * layer * sizeof(T));
            else have_e = zb;
            have_b = zb;
            stream_.read_layers(ze - have_e, reinterpret_cast<std::byte*>(buf.data() + (have_e - zb) * layer));
            have_e = ze;
            if (on_layers) on_layers(ze);

            const VolumeView<T> slab{reinterpret_cast<const std::byte*>(buf.data()), Dims{dims_.x, dims_.y, ze - zb}, false};
            const detail::PreparedVolume<T> prepared = detail::prepare_volume(slab, options_, zb);
            const Builder<T> builder(prepared.view, dims_, dmax_, options_.tolerance, zb);
            const uint32_t n_slab = npx_ * npy_;
            std::vector<Sink<T>> sinks;
            sinks.reserve(n_slab);
            for (uint32_t i = 0; i < n_slab; ++i) sinks.emplace_back(dmax_);
            const uint64_t first = uint64_t(pz) * n_slab;
            tbb::parallel_for(uint32_t(0), n_slab, [&](uint32_t i) {
                const Coord o{(i % npx_) * side_, (i / npx_) * side_, z0};
                roots_[first + i] = builder.build(k_, o, sinks[i]);
            });
            for (uint32_t i = 0; i < n_slab; ++i) {
                Sink<T>& s = sinks[i];
                for (int l = 0; l < levels_; ++l) {
                    const int d = k_ + l;
                    const bool caps = d == dmax_ - 1;
                    const uint64_t n = caps ? s.caps.size() : s.nodes[size_t(d)].size();   // caps: bytes
                    OCTISO_CHECK(n <= UINT32_MAX, "piece of ", n, " records at depth ", d);
                    counts_[size_t(l)][first + i] = uint32_t(n);
                    if (caps) {
                        spill_[size_t(l)]->append(s.caps.data(), n);
                        cap_count_ += s.cap_count;
                    }
                    else spill_[size_t(l)]->append(s.nodes[size_t(d)].data(), n * sizeof(InteriorNode<T>));
                    leaves_[size_t(d)] += s.leaves[size_t(d)];
                }
                s = Sink<T>(0);   // free this piece's arrays as soon as they are appended
            }
            // Deviation from build.cpp: no malloc_trim per slab. The next slab reuses the freed
            // heap at once; handing it back made every slab fault in and zero fresh pages (15 %
            // of a 1024^3 conversion in perf). The slab estimate of plan_stream() covers it.
            sinks = {};
        }
        ::malloc_trim(0);
    }

    // 2. The nodes above depth k, in the same descent as build.cpp's top; `order` lists the
    //    pieces in depth-first order, the order of every depth >= k in the file.
    std::vector<uint64_t> build_top(Sink<T>& top) {
        const Builder<T> builder(VolumeView<T>{}, dims_, dmax_, options_.tolerance);
        std::vector<uint64_t> order;
        order.reserve(n_pieces_);
        auto descend = [&](auto&& self, int d, Coord o) -> Summary<T> {
            if (builder.outside(o)) return Summary<T>::padding();
            if (d == k_) {
                const uint64_t id = piece_id(o);
                order.push_back(id);
                return roots_[id];
            }
            Summary<T> ch[8];
            for (int c = 0; c < 8; ++c) ch[c] = self(self, d + 1, detail::child_origin(o, c, builder.child_bit(d)));
            return builder.combine(d, ch, top);
        };
        if (k_ > 0) descend(descend, 0, Coord{});
        else order.push_back(0);
        OCTISO_CHECK(order.size() == n_pieces_, order.size(), " of ", n_pieces_, " pieces reached");
        return order;
    }

    uint64_t count_at(int d, const Sink<T>& top) const {
        if (d < k_) return top.nodes[size_t(d)].size();
        uint64_t n = 0;
        for (uint32_t c : counts_[size_t(d - k_)]) n += c;
        return n;
    }

    // Places the children of section d's nodes as they pass (child_groups.h) and checks what
    // validate_tree() checks at load: the children cover depth d+1 exactly, within 32-bit node
    // indices (or 48-bit cap offsets).
    void check_children(const detail::GroupPlacer& placer, uint64_t next_count, int d) const {
        const bool caps_below = d + 1 == dmax_ - 1;   // then counts are bytes
        if (next_count > (caps_below ? kMaxCapByteOffset : uint64_t(1) << 32))
            throw Error(options_.source_name, caps_below ? "octree too large: more than 2^48 bytes of caps"
                                                         : "octree too large: more than 2^32 nodes at depth " +
                                                               std::to_string(d + 1) + " (32-bit child indices)");
        OCTISO_CHECK(placer.children() == next_count, "depth ", d, " has children for ", placer.children(), " of ",
                     next_count, " at depth ", d + 1);
    }
    // A section's group bases after its records (oct_layout.h): zero bytes to a multiple of 8, then the bases.
    void append_group_bases(uint64_t count, const detail::GroupPlacer& placer) {
        static constexpr uint8_t kZero[8] = {};
        const uint64_t records = count * sizeof(InteriorNode<T>);
        writer_.append_records(kZero, group_bases_at(records) - records);
        OCTISO_CHECK(placer.bases().size() == node_groups(count), placer.bases().size(), " group bases for ", count, " nodes");
        writer_.append_records(placer.bases().data(), placer.bases().size() * sizeof(uint64_t));
    }

    // 3. Sections in depth order.
    StepSizes write_sections(Sink<T>& top, const std::vector<uint64_t>& order) {
        StepSizes sizes;
        std::vector<uint64_t> total(static_cast<size_t>(dmax_));
        for (int d = 0; d < dmax_; ++d) total[size_t(d)] = count_at(d, top);
        OCTISO_CHECK(total[0] == 1, "the root level holds ", total[0], " nodes");
        for (int d = 0; d < k_; ++d) {
            detail::GroupPlacer placer(d + 1 == dmax_ - 1);
            for (auto& n : top.nodes[size_t(d)]) placer.place(n);
            check_children(placer, total[size_t(d + 1)], d);
            writer_.begin_section(d, total[size_t(d)]);
            writer_.append_records(top.nodes[size_t(d)].data(), total[size_t(d)] * sizeof(InteriorNode<T>));
            append_group_bases(total[size_t(d)], placer);
            writer_.end_section();
            sizes.scalar_leaves_per_depth.push_back(top.leaves[size_t(d)]);
        }
        std::vector<InteriorNode<T>> nodes;
        std::vector<uint8_t> caps;
        std::vector<uint64_t> at(n_pieces_);   // record offset of each piece's chunk in its spill file
        for (int l = 0; l < levels_; ++l) {
            const int d = k_ + l;
            const bool is_caps = d == dmax_ - 1;
            const size_t record = is_caps ? 1 : sizeof(InteriorNode<T>);   // the cap level counts bytes
            uint64_t acc = 0;
            for (uint64_t id = 0; id < n_pieces_; ++id) at[id] = acc, acc += counts_[size_t(l)][id];
            writer_.begin_section(d, total[size_t(d)] + (is_caps ? kCapReadSlack : 0));
            detail::GroupPlacer placer(d + 1 == dmax_ - 1);
            for (const uint64_t id : order) {
                const uint64_t n = counts_[size_t(l)][id];
                if (is_caps) {
                    caps.resize(n);
                    spill_[size_t(l)]->read(at[id] * record, n * record, caps.data());
                    writer_.append_records(caps.data(), n * record);
                } else {
                    nodes.resize(n);
                    spill_[size_t(l)]->read(at[id] * record, n * record, nodes.data());
                    for (auto& node : nodes) placer.place(node);
                    writer_.append_records(nodes.data(), n * record);
                }
            }
            if (!is_caps) {
                check_children(placer, total[size_t(d + 1)], d);
                append_group_bases(total[size_t(d)], placer);
            } else {
                static constexpr uint8_t kSlack[kCapReadSlack] = {};
                writer_.append_records(kSlack, kCapReadSlack);
            }
            writer_.end_section();
            sizes.scalar_leaves_per_depth.push_back(leaves_[size_t(d)]);
        }
        sizes.nodes_per_depth = total;
        for (int d = 0; d + 1 < dmax_; ++d) {
            sizes.interior_bytes += interior_level_bytes<T>(total[size_t(d)]);
            sizes.minmax_bytes += total[size_t(d)] * sizeof(ChildBounds<T>);
        }
        sizes.cap_bytes = total[size_t(dmax_ - 1)];
        sizes.nodes_per_depth[size_t(dmax_ - 1)] = cap_count_;
        return sizes;
    }

    VolumeStream& stream_;
    const BuildOptions& options_;
    OctWriter& writer_;
    const Dims dims_;
    const int dmax_;
    const uint32_t side_;
    const int k_;        // depth of the pieces' roots
    const int levels_;   // depths k .. dmax-1 held per piece
    const uint32_t npx_, npy_, npz_;
    uint64_t n_pieces_ = 0;
    std::vector<std::vector<uint32_t>> counts_;   // [depth - k][piece id]: records of each piece
    std::vector<Summary<T>> roots_;               // [piece id]
    std::vector<uint64_t> leaves_;                // scalar leaves per depth, pieces' depths only
    uint64_t cap_count_ = 0;                      // caps (counts_ holds their bytes)
    SpillAllowance allowance_;
    std::vector<std::unique_ptr<SpillFile>> spill_;   // [depth - k]
};

}  // namespace

StreamPlan plan_stream(Dims dims, ScalarType type, const BuildOptions& options, uint64_t budget, uint32_t forced_side,
                       const std::string& subject) {
    const double b = double(scalar_type_bytes(type));
    const bool is_float = type == ScalarType::f32 || type == ScalarType::f64;
    const uint32_t top_side = 1u << dmax_for(dims);
    auto need = [&](uint32_t s) { return slab_need(dims, b, options, s, is_float) + fixed_need(dims, b, s); };
    StreamPlan p;
    if (forced_side) {
        if (!std::has_single_bit(forced_side) || forced_side < kMinPieceSide)
            throw Error("--piece-side", "must be a power of two >= 4, found " + std::to_string(forced_side));
        p.piece_side = std::min(forced_side, top_side);
    } else {
        // The largest side whose need leaves half the budget to the spill store; if none does,
        // the side that needs least (smaller pieces shrink the slab but add per-piece
        // summaries for the whole volume: at 3072^2 layers 16^3 needs 1.1 GiB, 4^3 30 GiB).
        const uint32_t largest = std::min(kMaxPieceSide, top_side);
        p.piece_side = 0;
        uint32_t cheapest = largest;
        for (uint32_t s = largest; s >= kMinPieceSide; s /= 2) {
            if (need(s) < need(cheapest)) cheapest = s;
            if (!p.piece_side && need(s) <= double(budget) / 2) p.piece_side = s;
        }
        if (!p.piece_side) p.piece_side = cheapest;
    }
    const double total = slab_need(dims, b, options, p.piece_side, is_float) + fixed_need(dims, b, p.piece_side);
    if (total > double(budget))
        throw Error(subject, "out of memory: one slab of " + std::to_string(p.piece_side) + " layers of " +
                                 std::to_string(dims.x) + "x" + std::to_string(dims.y) + " " +
                                 std::string(scalar_type_name(type)) + " needs " + mib_text(total) +
                                 ", more than the memory budget of " + mib_text(double(budget)) + " (--memory)");
    p.slab_bytes = uint64_t(std::ceil(slab_need(dims, b, options, p.piece_side, is_float)));
    p.fixed_bytes = uint64_t(std::ceil(fixed_need(dims, b, p.piece_side)));
    p.spill_memory = budget - std::min(budget, p.slab_bytes + p.fixed_bytes);
    return p;
}

StreamStepResult stream_build_step(VolumeStream& stream, const BuildOptions& options, const StreamPlan& plan,
                                   OctWriter& writer, const std::string& output,
                                   const std::function<void(uint32_t)>& on_layers) {
    try {
        return dispatch_scalar_type(stream.type(), [&](auto tag) {
            using T = decltype(tag);
            StepBuilder<T> b(stream, options, plan, writer, output);
            return b.run(on_layers);
        });
    } catch (const std::bad_alloc&) {
        const Dims d = stream.dims();
        throw Error(options.source_name, "out of memory streaming the octree of this " + std::to_string(d.x) + "x" +
                                             std::to_string(d.y) + "x" + std::to_string(d.z) + " volume (try a smaller --memory)");
    }
}

}  // namespace octiso::convert_detail
