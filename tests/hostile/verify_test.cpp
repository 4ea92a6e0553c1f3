// Issue 18, class 9: derived metadata that lies under valid checksums. verify_octree (and
// octiso-info --verify) recomputes every min/max and scalar from the leaves: files octiso writes
// pass, across types, iso-ranges, tolerances and series; a forged range is reported, naming the
// step, depth, node and child, with exit 2.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "format/oct_test_util.h"
#include "octiso/error.h"
#include "octiso/verify.h"
#include "test_util/run_shell.h"

namespace octiso::test {
namespace {

const std::string kTools = OCTISO_TOOLS_DIR;

TEST(HostileVerify, FilesOctisoWritesVerify) {
    ScratchDir dir;
    const char* specs[] = {"--synthetic sphere:20 --type u8", "--synthetic noise:33 --type f32",
                           "--synthetic marschner-lobb:24 --type i16", "--synthetic plume-series:16,3",
                           "--synthetic sponge:27 --type f64 --iso-range 10,90", "--synthetic mixing:20 --tolerance 2",
                           "--synthetic sphere:5,9,3 --type u32"};
    for (const char* spec : specs) {
        SCOPED_TRACE(spec);
        const std::string out = dir.file("v.oct");
        ASSERT_EQ(run_shell("'" + kTools + "/octiso-convert' " + spec + " -o '" + out + "' 2>/dev/null"), 0);
        const OctFile f = OctFile::open(out);
        VerifyStats s;
        ASSERT_NO_THROW(s = verify_octree(f));
        EXPECT_GT(s.nodes, 0u);
        EXPECT_EQ(run_shell("'" + kTools + "/octiso-info' '" + out + "' --verify >/dev/null 2>&1"), 0);
    }
}

/// The forgery: min > max in every node, checksums recomputed, so the loader accepts it.
TEST(HostileVerify, InvertedRangesInEveryNodeAreReported) {
    ScratchDir dir;
    dir.allow_lying_metadata();   // the forgeries are the point
    const std::string good = dir.file("good.oct"), bad = dir.file("bad.oct");
    ASSERT_EQ(run_shell("'" + kTools + "/octiso-convert' --synthetic sphere:24 --type u8 -o '" + good + "' 2>/dev/null"), 0);
    OctBytes b(good);
    const int dmax = b.header().dmax;
    for (int d = 0; d + 1 < dmax; ++d)
        for (uint64_t i = 0; i < b.entry(b.entry_index(0, d)).count; ++i) {
            InteriorNode<uint8_t> n = b.node<uint8_t>(0, d, i);
            for (int c = 0; c < 8; ++c) n.bounds.min[c] = 255, n.bounds.max[c] = 0;
            b.set_node(0, d, i, n);
        }
    b.rechecksum();
    b.save(bad);
    const OctFile f = OctFile::open(bad);   // checksums and indices are fine
    try {
        verify_octree(f);
        FAIL() << "the lie was not found";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("bad.oct: step 0, depth 0, node 0, child"), std::string::npos) << e.what();
    }
    std::string out;
    const int status = run_shell("'" + kTools + "/octiso-info' '" + bad + "' --verify 2>&1 >/dev/null", &out);
    EXPECT_EQ(status, 2);
    EXPECT_NE(out.find("bad.oct: step 0"), std::string::npos) << out;
    EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
}

/// Subtler lies: one deep range narrowed by one, and one interior child's scalar moved out of range.
TEST(HostileVerify, OneNarrowedRangeOrMisplacedScalarIsReported) {
    ScratchDir dir;
    dir.allow_lying_metadata();   // the forgeries are the point
    const std::string good = dir.file("good.oct");
    ASSERT_EQ(run_shell("'" + kTools + "/octiso-convert' --synthetic noise:32 --type u8 -o '" + good + "' 2>/dev/null"), 0);
    const OctBytes original(good);
    const int d = original.header().dmax - 2;   // the deepest interior level
    const int above = d - 1;                    // its children are nodes: their scalar is their corner voxel
    bool narrowed = false, moved = false;
    for (uint64_t i = 0; i < original.entry(original.entry_index(0, d)).count && !narrowed; ++i)
        for (int c = 0; c < 8; ++c) {
            InteriorNode<uint8_t> n = original.node<uint8_t>(0, d, i);
            if (!narrowed && n.bounds.min[c] < n.bounds.max[c]) {
                OctBytes b = original;
                ++n.bounds.min[c];
                b.set_node(0, d, i, n);
                b.rechecksum();
                b.save(dir.file("narrow.oct"));
                EXPECT_THROW(verify_octree(OctFile::open(dir.file("narrow.oct"))), Error);
                narrowed = true;
            }
        }
    for (uint64_t i = 0; i < original.entry(original.entry_index(0, above)).count && !moved; ++i)
        for (int c = 0; c < 8; ++c) {
            InteriorNode<uint8_t> n = original.node<uint8_t>(0, above, i);
            if (!moved && !n.is_scalar_leaf(c) && n.bounds.max[c] < 255) {
                OctBytes b = original;
                n.scalar[c] = uint8_t(n.bounds.max[c] + 1);
                b.set_node(0, above, i, n);
                b.rechecksum();
                b.save(dir.file("scalar.oct"));
                EXPECT_THROW(verify_octree(OctFile::open(dir.file("scalar.oct"))), Error);
                moved = true;
            }
        }
    EXPECT_TRUE(narrowed && moved);
}

}  // namespace
}  // namespace octiso::test
