// Verify::Touched (issue 13, format/touch_validation.h): a good file reads as under Verify::Full
// and checks only the blocks that are read; every node defect that Full finds at open is found
// when its block is read, reported by check_unchanged() with Full's words, and the walk that
// read it stays inside the file (ASan proves it in the sanitizer pass); the rules across nodes
// that Touched does not check are shown not to be checked, and still safe to walk.
#include <random>

#include "format/oct_test_util.h"
#include "octiso/decode.h"
#include "octiso/error.h"

namespace octiso::test {
namespace {

/// A u8 file of several blocks: random data, so every level is full (160x150x140: ~5 MiB).
struct BigFile {
    ScratchDir dir{"octiso_touch"};
    std::string good = dir.file("good.oct");
    std::string bad = dir.file("bad.oct");
    explicit BigFile(Dims dims = {160, 150, 140}) {
        const auto v = make_volume<uint8_t>(dims, Pattern::Random, 5);
        const auto b = build_octree(v.view(), {});
        write_oct<uint8_t>(good, info_for(ScalarType::u8, v.dims), {b.view()});
    }
};

/// Decodes every voxel and visits every node: all that a renderer could reach.
std::vector<uint8_t> walk(const Octree<uint8_t>& tree) {
    std::vector<uint8_t> out(size_t(tree.dims().voxels()));
    decode_to_dense(tree, out.data());
    for_each_node<uint8_t>(tree, [](int, uint32_t, Coord) {});
    return out;
}

/// Full's message for `path`, without the file name in front (Error::what() is "FILE: ...").
std::string full_problem(const std::string& path) {
    try {
        const OctFile f = OctFile::open(path, Verify::Full);
        walk(f.step<uint8_t>(0));
    } catch (const Error& e) {
        return e.problem();
    }
    return {};
}

TEST(TouchValidation, AGoodFileReadsAsUnderFullAndChecksOnlyWhatIsRead) {
    BigFile fx({256, 256, 200});   // ~20 MiB: blocks without a section start, left until read
    const OctFile full = OctFile::open(fx.good, Verify::Full);
    const std::vector<uint8_t> expected = walk(full.step<uint8_t>(0));

    const OctFile f = OctFile::open(fx.good, Verify::Touched);
    ASSERT_EQ(f.verify(), Verify::Touched);
    const Octree<uint8_t> tree = f.step<uint8_t>(0);
    const TouchStats opened = *f.touch_stats();
    ASSERT_GE(opened.blocks, 3u) << "the fixture must span several blocks";
    // One voxel reads one path from the root: fewer blocks than the whole tree.
    (void)tree.point_locate({3, 4, 5});
    const uint64_t after_one = f.touch_stats()->checked;
    EXPECT_EQ(walk(tree), expected);
    const uint64_t after_all = f.touch_stats()->checked;
    EXPECT_LT(after_one, after_all);
    EXPECT_LE(after_all, opened.blocks);
    EXPECT_NO_THROW(f.check_unchanged());
    // step_sizes() counts every node, as under Full.
    EXPECT_EQ(f.step_sizes(0).nodes_per_depth, full.step_sizes(0).nodes_per_depth);
    EXPECT_EQ(f.step_sizes(0).scalar_leaves_per_depth, full.step_sizes(0).scalar_leaves_per_depth);
}

TEST(TouchValidation, NodeDefectsAreFoundWhenReadWithFullsMessage) {
    BigFile fx;
    const OctBytes good(fx.good);
    const int dmax = good.header().dmax;
    struct Edit {
        const char* what;
        int depth;   // -1: the cap parents
        void (*apply)(InteriorNode<uint8_t>&);   // or, when null, to its group base
        uint64_t (*base)(uint64_t);
    };
    const Edit edits[] = {
        {"group base at the 32-bit limit", 1, nullptr, [](uint64_t) { return uint64_t(0xffffffffu); }},
        {"group base past the level", 2, nullptr, [](uint64_t v) { return v + (uint64_t(1) << 30); }},
        {"cap offset past the level", -1, nullptr, [](uint64_t v) { return v + (uint64_t(7) << 32); }},
        {"cap width out of range", -1, [](InteriorNode<uint8_t>& n) { n.cap_bits = 9; }, nullptr},
        {"cap width above the cap parents", 1, [](InteriorNode<uint8_t>& n) { n.cap_bits = 3; }, nullptr},
    };
    for (const Edit& e : edits) {
        SCOPED_TRACE(e.what);
        const int d = e.depth < 0 ? dmax - 2 : e.depth;
        OctBytes b = good;
        const uint64_t count = b.entry(b.entry_index(0, d)).count;
        // Somewhere past the first block of a big level, a group's first node (the first a bad
        // group base makes bad).
        const uint64_t i = (count - 1 - count / 3) & ~(kNodeGroup - 1);
        auto n = b.node<uint8_t>(0, d, i);
        ASSERT_NE(n.child_mask, 0) << "random data: every node has children";
        if (e.apply) e.apply(n);
        else b.set_group_base(0, d, i >> kNodeGroupShift, e.base(b.group_base(0, d, i >> kNodeGroupShift)));
        b.set_node(0, d, i, n);
        b.rechecksum();
        b.save(fx.bad);
        const std::string expected = full_problem(fx.bad);
        ASSERT_NE(expected.find("node " + std::to_string(i) + ":"), std::string::npos) << expected;

        const OctFile f = OctFile::open(fx.bad, Verify::Touched);
        walk(f.step<uint8_t>(0));   // reads the bad block: zeroed, and the walk stays in the file
        try {
            f.check_unchanged();
            ADD_FAILURE() << "not reported";
        } catch (const Error& err) {
            EXPECT_EQ(err.subject(), fx.bad);
            EXPECT_EQ(err.problem().rfind(expected, 0), 0u) << err.problem() << "\nexpected: " << expected;
        }
    }
}

TEST(TouchValidation, ADefectInABlockNeverReadIsNotReported) {
    // ~20 MiB: the cap parents span blocks that hold no section boundary (the step's first use
    // reads the padding at every section start, so those blocks are checked at once).
    BigFile fx({256, 256, 200});
    OctBytes b(fx.good);
    const int d = b.header().dmax - 2;
    const uint64_t middle = b.entry(b.entry_index(0, d)).count / 2;
    const uint64_t g = middle >> kNodeGroupShift;
    b.set_group_base(0, d, g, b.group_base(0, d, g) + (uint64_t(7) << 32));   // the caps of the middle group, far past the level
    b.rechecksum();
    b.save(fx.bad);
    const OctFile f = OctFile::open(fx.bad, Verify::Touched);
    const Octree<uint8_t> tree = f.step<uint8_t>(0);
    (void)tree.point_locate({0, 0, 0});   // the first path, blocks away from the last cap parent
    EXPECT_NO_THROW(f.check_unchanged());
    walk(tree);
    EXPECT_THROW(f.check_unchanged(), Error);
}

TEST(TouchValidation, RulesAcrossNodesAreLeftToFullAndStaySafe) {
    // Two neighbours pointing at the same children: Full refuses it, Touched does not look
    // across nodes (no read outside the file follows from it), and the walk stays safe.
    BigFile fx;
    OctBytes b(fx.good);
    auto first = b.node<uint8_t>(0, 1, 0), second = b.node<uint8_t>(0, 1, 1);
    second.child_offset = first.child_offset;
    second.child_mask = first.child_mask;
    b.set_node(0, 1, 1, second);
    b.rechecksum();
    b.save(fx.bad);
    EXPECT_NE(full_problem(fx.bad).find("overlap"), std::string::npos);
    const OctFile f = OctFile::open(fx.bad, Verify::Touched);
    walk(f.step<uint8_t>(0));
    EXPECT_NO_THROW(f.check_unchanged());
}

TEST(TouchValidation, RandomFlipsGiveAReportOrASafeWalk) {
    BigFile fx;
    const OctBytes good(fx.good);
    const uint64_t begin = good.entry(0).offset, end = good.header().section_table_offset;
    std::mt19937_64 rng(91);
    int reported = 0;   // flips in min/max that keep every range ordered load clean under both modes
    for (int trial = 0; trial < 60; ++trial) {
        OctBytes b = good;
        for (int k = 0; k < 64; ++k) {
            const uint64_t byte = begin + rng() % (end - begin);
            b.bytes[byte] = char(b.bytes[byte] ^ (1 << (rng() % 8)));
        }
        b.rechecksum();
        b.save(fx.bad);
        const OctFile f = OctFile::open(fx.bad, Verify::Touched);
        try {
            walk(f.step<uint8_t>(0));
            f.check_unchanged();
        } catch (const Error& e) {
            EXPECT_EQ(e.subject(), fx.bad);
            // Touched checks a subset of Full's rules: what it refuses, Full refuses too.
            EXPECT_FALSE(full_problem(fx.bad).empty()) << e.what();
            ++reported;
        }
    }
    EXPECT_GT(reported, 0);
}

}  // namespace
}  // namespace octiso::test
