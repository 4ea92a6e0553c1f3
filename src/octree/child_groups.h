// Child groups (format 5, issue 19; octree.h): a level's children lie in node order, each node's
// right after the previous node's, so the first child of node i is the sum of the spans of the
// nodes before it. It is kept as a 64-bit base per group of kNodeGroup nodes (the first child of
// the group's first node) and a 16-bit child_offset in every node, relative to that base. Every
// writer of a level places children here: the in-memory builders over whole arrays, the
// streaming converter node by node as its records pass.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include <tbb/parallel_for.h>

#include "octiso/octree.h"
#include "util/check.h"

namespace octiso::detail {

/// Places the children of a level's nodes one node at a time, in level order, from node
/// `first_node` (a group's first) whose first child is `first_child`.
class GroupPlacer {
public:
    explicit GroupPlacer(bool caps_below, uint64_t first_node = 0, uint64_t first_child = 0)
        : caps_below_(caps_below), placed_(first_node), next_(first_child) {
        OCTISO_DCHECK((first_node & (kNodeGroup - 1)) == 0, "placing from node ", first_node, ", inside a group");
    }

    template <typename T> void place(InteriorNode<T>& n) {
        if ((placed_ & (kNodeGroup - 1)) == 0) bases_.push_back(next_);
        const uint64_t offset = next_ - bases_.back();
        OCTISO_DCHECK(offset <= UINT16_MAX, "child offset ", offset, " past 16 bits");
        n.child_offset = uint16_t(offset);
        next_ += n.children_span(caps_below_);
        ++placed_;
    }
    /// Where the next node's children start: what the nodes placed so far take in the level
    /// below (nodes, or bytes of caps), from first_child on.
    uint64_t children() const { return next_; }
    /// The bases of the groups begun so far.
    const std::vector<uint64_t>& bases() const { return bases_; }

private:
    bool caps_below_;
    uint64_t placed_, next_;
    std::vector<uint64_t> bases_;
};

/// Places the children of all `count` nodes of a level (node_groups(count) bases into `bases`),
/// in parallel over runs of groups: the spans of each run, a prefix sum over the runs, then each
/// run by its own GroupPlacer. Returns what the level's nodes take below (nodes, or bytes of caps).
template <typename T> uint64_t place_children(InteriorNode<T>* nodes, uint64_t count, bool caps_below, uint64_t* bases) {
    constexpr uint64_t kRun = kNodeGroup * 256;
    const uint64_t runs = (count + kRun - 1) / kRun;
    std::vector<uint64_t> run_start(runs + 1, 0);
    tbb::parallel_for(uint64_t(0), runs, [&](uint64_t r) {
        uint64_t span = 0;
        for (uint64_t i = r * kRun, e = std::min(count, i + kRun); i < e; ++i) span += nodes[i].children_span(caps_below);
        run_start[r + 1] = span;
    });
    for (uint64_t r = 0; r < runs; ++r) run_start[r + 1] += run_start[r];
    tbb::parallel_for(uint64_t(0), runs, [&](uint64_t r) {
        GroupPlacer placer(caps_below, r * kRun, run_start[r]);
        for (uint64_t i = r * kRun, e = std::min(count, i + kRun); i < e; ++i) placer.place(nodes[i]);
        std::copy(placer.bases().begin(), placer.bases().end(), bases + (r * kRun >> kNodeGroupShift));
    });
    return run_start[runs];
}

}  // namespace octiso::detail
