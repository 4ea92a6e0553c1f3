// Damaged and hostile .oct files must give an octiso::Error, never a crash or a read outside the
// mapping: every truncation, single bit flips (Verify::Full: always an Error; IndicesOnly: an Error
// or a view that is safe to walk), index corruption with all checksums recomputed, hostile
// section tables (offset + size wrapping around), and bad header fields.
#include <cmath>
#include <functional>
#include <limits>
#include <random>

#include "format/oct_test_util.h"
#include "octiso/any_octree.h"
#include "octiso/decode.h"
#include "octiso/error.h"

namespace octiso::test {
namespace {

using format::FileHeader;
using format::SectionEntry;

/// Opens `path` and validates every step. Returns normally only if the whole file is valid;
/// an octiso::Error propagates, anything else fails the test through gtest.
void load_everything(const std::string& path, Verify verify) {
    const OctFile f = OctFile::open(path, verify);
    dispatch_scalar_type(f.info().type, [&](auto t) {
        using T = decltype(t);
        for (uint32_t k = 0; k < f.info().step_count; ++k) {
            const Octree<T> tree = f.step<T>(k);
            // Walk everything the renderer could reach: with ASan this proves the view is safe.
            std::vector<T> out(size_t(tree.dims().voxels()));
            decode_to_dense(tree, out.data());
            const Dims d = tree.dims();
            for (uint32_t z = 0; z < d.z; ++z)
                for (uint32_t y = 0; y < d.y; ++y)
                    for (uint32_t x = 0; x < d.x; ++x)
                        if (!(tree.point_locate({x, y, z}) == out[x + uint64_t(d.x) * (y + uint64_t(d.y) * z)]) &&
                            !std::isnan(double(out[x + uint64_t(d.x) * (y + uint64_t(d.y) * z)])))
                            FAIL() << "decode and point location disagree at " << x << "," << y << "," << z;
            for_each_node<T>(tree, [&](int, uint32_t, Coord) {});
        }
    });
}

bool rejected(const std::string& path, Verify verify) {
    try {
        load_everything(path, verify);
        return false;
    } catch (const Error& e) {
        EXPECT_EQ(e.subject(), path) << e.what();   // every message names the file
        return true;
    }
}

/// A small valid file of two steps of u8 (dmax 4): the first of pattern `p`, the second random.
struct Fixture {
    ScratchDir dir;
    std::string good = dir.file("good.oct");
    std::string bad = dir.file("bad.oct");
    Fixture(Pattern p = Pattern::Sparse) {
        const auto v0 = make_volume<uint8_t>({9, 6, 5}, p, 11);
        const auto v1 = make_volume<uint8_t>({9, 6, 5}, Pattern::Random, 12);
        const auto b0 = build_octree(v0.view(), {});
        const auto b1 = build_octree(v1.view(), {});
        write_oct<uint8_t>(good, info_for(ScalarType::u8, v0.dims), {b0.view(), b1.view()});
    }
    /// Applies `edit` to a copy of the good file, re-checksums unless told not to, and says
    /// whether the loader (both modes) rejects it.
    void expect_rejected(const std::function<void(OctBytes&)>& edit, const char* what, bool rechecksum = true) {
        OctBytes b(good);
        edit(b);
        if (rechecksum) b.rechecksum();
        b.save(bad);
        EXPECT_TRUE(rejected(bad, Verify::Full)) << what;
        EXPECT_TRUE(rejected(bad, Verify::IndicesOnly)) << what;
    }
};

TEST(OctReject, TheEditorItselfKeepsAGoodFileGood) {
    Fixture fx;
    OctBytes b(fx.good);
    b.rechecksum();
    b.save(fx.bad);
    EXPECT_FALSE(rejected(fx.bad, Verify::Full));
    EXPECT_EQ(read_bytes(fx.bad), read_bytes(fx.good));
}

TEST(OctReject, EveryTruncationIsAnError) {
    Fixture fx;
    const std::vector<char> bytes = read_bytes(fx.good);
    ASSERT_GT(bytes.size(), 1000u);
    for (size_t n = 0; n < bytes.size(); ++n) {
        write_bytes(fx.bad, bytes.data(), n);
        ASSERT_TRUE(rejected(fx.bad, Verify::IndicesOnly)) << "prefix of " << n << " bytes";
    }
    // And one byte too many.
    std::vector<char> longer = bytes;
    longer.push_back(0);
    write_bytes(fx.bad, longer.data(), longer.size());
    EXPECT_TRUE(rejected(fx.bad, Verify::Full));
}

TEST(OctReject, EverySingleBitFlipIsAnErrorWithFullVerification) {
    Fixture fx;
    std::vector<char> bytes = read_bytes(fx.good);
    ASSERT_LT(bytes.size(), 8000u);   // keep the exhaustive loop small
    for (size_t bit = 0; bit < bytes.size() * 8; ++bit) {
        bytes[bit / 8] = char(bytes[bit / 8] ^ (1 << (bit % 8)));
        write_bytes(fx.bad, bytes.data(), bytes.size());
        ASSERT_TRUE(rejected(fx.bad, Verify::Full)) << "bit " << bit % 8 << " of byte " << bit / 8;
        bytes[bit / 8] = char(bytes[bit / 8] ^ (1 << (bit % 8)));
    }
}

TEST(OctReject, BitFlipsWithoutChecksumsGiveAnErrorOrASafeView) {
    // The flips land in node data with the checksums recomputed, so only the index checks stand
    // between a flip and the traversal. Each outcome must be an Error or a walkable tree.
    for (Pattern p : {Pattern::Sparse, Pattern::Random}) {
        Fixture fx(p);
        OctBytes good(fx.good);
        const FileHeader h = good.header();
        const uint64_t data_begin = good.entry(0).offset, data_end = h.section_table_offset;
        std::mt19937_64 rng(77);
        int n_rejected = 0, n_valid = 0;
        for (int trial = 0; trial < 3000; ++trial) {
            OctBytes b = good;
            const uint64_t byte = data_begin + rng() % (data_end - data_begin);
            b.bytes[byte] = char(b.bytes[byte] ^ (1 << (rng() % 8)));
            b.rechecksum();
            b.save(fx.bad);
            try {
                load_everything(fx.bad, Verify::IndicesOnly);
                ++n_valid;
            } catch (const Error&) {
                ++n_rejected;
            }
            if (::testing::Test::HasFatalFailure()) return;
        }
        // Both outcomes occur: flips in min/max stay valid, flips in masks and starts do not.
        EXPECT_GT(n_rejected, 0);
        EXPECT_GT(n_valid, 0);
    }
}

// ---- index corruption, checksums recomputed: only the structural checks can catch these ----

/// Index of the last node at `depth` of step 0 that has children.
uint64_t last_parent(const OctBytes& b, int depth) {
    const SectionEntry s = b.entry(b.entry_index(0, depth));
    for (uint64_t i = s.count; i-- > 0;)
        if (b.node<uint8_t>(0, depth, i).child_mask != 0) return i;
    ADD_FAILURE() << "no node with children at depth " << depth;
    return 0;
}

TEST(OctReject, ChildIndicesOutOfRangeOrOverlappingAreErrors) {
    Fixture fx;
    const int dmax = OctBytes(fx.good).header().dmax;
    ASSERT_EQ(dmax, 4);
    for (int d = 0; d <= dmax - 2; ++d) {
        SCOPED_TRACE(d);
        fx.expect_rejected([&](OctBytes& b) {
            const uint64_t i = last_parent(b, d);
            auto n = b.node<uint8_t>(0, d, i);
            n.child_offset += 1;   // past the end of the next level
            b.set_node(0, d, i, n);
        }, "child_offset one too large");
        fx.expect_rejected([&](OctBytes& b) {
            const uint64_t i = last_parent(b, d);
            b.set_group_base(0, d, i >> kNodeGroupShift, std::numeric_limits<uint32_t>::max());   // 32-bit wrap if added in 32 bits
        }, "group base at the 32-bit limit");
        fx.expect_rejected([&](OctBytes& b) {
            const uint64_t i = last_parent(b, d);
            b.set_group_base(0, d, i >> kNodeGroupShift, std::numeric_limits<uint64_t>::max());   // wraps if added
        }, "group base at the 64-bit limit");
        fx.expect_rejected([&](OctBytes& b) {
            b.set_group_base(0, d, 0, b.group_base(0, d, 0) + 1);   // a gap before the level's first child
        }, "group base one too large");
        fx.expect_rejected([&](OctBytes& b) {
            const uint64_t i = last_parent(b, d);
            auto n = b.node<uint8_t>(0, d, i);
            ASSERT_NE(n.child_mask, 0xff) << "fixture needs a node with a leaf child";
            n.child_mask = uint8_t(n.child_mask | (n.child_mask + 1));   // one more child bit
            b.set_node(0, d, i, n);
        }, "child_mask with too many bits");
        fx.expect_rejected([&](OctBytes& b) {
            const uint64_t i = last_parent(b, d);
            auto n = b.node<uint8_t>(0, d, i);
            n.child_mask = uint8_t(n.child_mask & (n.child_mask - 1));   // one child bit fewer
            b.set_node(0, d, i, n);
        }, "child_mask with too few bits (a node below loses its parent)");
        if (d < dmax - 2) {
            fx.expect_rejected([&](OctBytes& b) {
                auto n = b.node<uint8_t>(0, d, 0);
                n.cap_bits = 1;
                b.set_node(0, d, 0, n);
            }, "cap_bits above the cap parents");

        } else {
            fx.expect_rejected([&](OctBytes& b) {
                const uint64_t i = last_parent(b, d);
                auto n = b.node<uint8_t>(0, d, i);
                n.cap_bits = uint8_t(n.cap_bits + 1);   // its caps now run past the level
                b.set_node(0, d, i, n);
            }, "cap_bits one too large");
            fx.expect_rejected([&](OctBytes& b) {
                const uint64_t g = last_parent(b, d) >> kNodeGroupShift;
                b.set_group_base(0, d, g, b.group_base(0, d, g) + (uint64_t(1) << 32));   // 2^32 bytes on
            }, "cap offset past the level in its group base's high bits");
        }
    }
}

/// `good` edited by `edit` and checksummed again, saved as `bad`: every load of it, with full and
/// with index-only verification, must fail naming `bad` and saying `words`.
void expect_edit_refused(const std::string& good, const std::string& bad, const std::function<void(OctBytes&)>& edit,
                         const std::string& words) {
    OctBytes b(good);
    edit(b);
    b.rechecksum();
    b.save(bad);
    for (Verify verify : {Verify::Full, Verify::IndicesOnly}) {
        try {
            load_everything(bad, verify);
            ADD_FAILURE() << words << ": accepted";
        } catch (const Error& e) {
            EXPECT_EQ(e.subject(), bad);
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
    }
}

/// Format 3's own fields (issue 19), on a u16 file (quantized bounds, caps up to 16 bits):
/// each check names what it found.
TEST(OctReject, CompactNodeFieldsAreValidated) {
    ScratchDir dir;
    const std::string good = dir.file("good.oct"), bad = dir.file("bad.oct");
    const auto v = make_volume<uint16_t>({9, 6, 5}, Pattern::Random, 3);
    write_oct<uint16_t>(good, info_for(ScalarType::u16, v.dims), {build_octree(v.view(), {}).view()});
    const int dmax = OctBytes(good).header().dmax;
    auto expect = [&](const std::function<void(OctBytes&)>& edit, const std::string& words) {
        expect_edit_refused(good, bad, edit, words);
    };
    expect([&](OctBytes& b) {
        auto n = b.node<uint16_t>(0, dmax - 2, 0);
        n.cap_bits = 17;   // neither a packed width (<= 15) nor whole (16)
        b.set_node(0, dmax - 2, 0, n);
    }, "cap_bits out of range (expected 0 .. 15 or 16, found 17)");
    expect([&](OctBytes& b) {
        auto n = b.node<uint16_t>(0, 0, 0);
        std::swap(n.bounds.lo, n.bounds.hi);
        if (n.bounds.lo == n.bounds.hi) n.bounds.lo = uint16_t(n.bounds.hi + 1);
        b.set_node(0, 0, 0, n);
    }, "bounds range is not finite and ordered");
    expect([&](OctBytes& b) {
        // Format 4: the root's stored child 0 keeps the voxel at (0, 0, 0), inside its range.
        auto n = b.node<uint16_t>(0, 0, 0);
        ASSERT_TRUE(n.child_mask & 1u);
        n.scalar[0] = n.bounds.upper(0) < 65535 ? uint16_t(n.bounds.upper(0) + 1) : uint16_t(n.bounds.lower(0) - 1);
        b.set_node(0, 0, 0, n);
    }, "child 0: its lattice sample (scalar) lies outside its range");
    expect([&](OctBytes& b) {
        const SectionEntry s = b.entry(b.entry_index(0, dmax - 1));
        b.bytes[s.offset + s.bytes - 1] = 1;   // the read slack after the last cap
    }, "bytes after the last cap are not zero");
    expect([&](OctBytes& b) {
        // Format 5: a group's first node starts at its base; the offset moves into the base.
        auto n = b.node<uint16_t>(0, dmax - 2, 0);
        n.child_offset = 1;
        b.set_node(0, dmax - 2, 0, n);
    }, "the first node of a group must have child_offset 0 (found 1)");
    expect([&](OctBytes& b) {
        // A cap level shorter than its read slack: the table says 7 bytes.
        const uint64_t i = b.entry_index(0, dmax - 1);
        SectionEntry s = b.entry(i);
        s.count = s.bytes = 7;
        b.set_entry(i, s);
    }, "the cap level must end with 8 zero bytes");
}

/// Format 6's 1-byte cap field (CapAnchor, octree.h): a width of 1 .. 8 below the anchor bit, 0
/// only in a cap parent without stored children. Each refusal names the field and the value.
TEST(OctReject, OneByteCapWidthsAreValidated) {
    ScratchDir dir;
    const std::string good = dir.file("good.oct"), bad = dir.file("bad.oct");
    const auto v = make_volume<uint8_t>({9, 6, 5}, Pattern::Random, 5);
    write_oct<uint8_t>(good, info_for(ScalarType::u8, v.dims), {build_octree(v.view(), {}).view()});
    const int dmax = OctBytes(good).header().dmax;
    ASSERT_NE(OctBytes(good).node<uint8_t>(0, dmax - 2, 0).child_mask, 0) << "fixture needs a cap parent with caps";
    auto expect = [&](uint8_t cap_bits, const std::string& words) {
        expect_edit_refused(good, bad, [&](OctBytes& b) {
            auto n = b.node<uint8_t>(0, dmax - 2, 0);
            n.cap_bits = cap_bits;
            b.set_node(0, dmax - 2, 0, n);
        }, words);
    };
    const auto stored = std::to_string(OctBytes(good).node<uint8_t>(0, dmax - 2, 0).child_mask);
    expect(9, "cap_bits out of range (expected a width of 1 .. 8 in bits 0-6 and the anchor in bit 7, or 0 without "
              "stored children; found 9 with child_mask " + stored + ")");
    expect(0x80 | 9, "found 137 with child_mask " + stored);
    expect(0, "found 0 with child_mask " + stored);   // no width, yet caps to read
    expect(0x80, "found 128 with child_mask " + stored);
}

/// Format 5 (issue 19): the zero bytes between an interior level's records and its group bases
/// (u8 records are 28 bytes, so a level of one node has 4), and the zero tail of a double record.
TEST(OctReject, GroupPaddingAndRecordTailMustBeZero) {
    {
        Fixture fx;
        fx.expect_rejected([&](OctBytes& b) {
            const SectionEntry s = b.entry(b.entry_index(0, 0));
            ASSERT_EQ(s.count, 1u);
            ASSERT_EQ(format::group_bases_offset(1, 1), 32u);
            b.bytes[s.offset + 31] = 1;   // the root's record is 28 bytes, its base at 32
        }, "padding before the group bases");
    }
    ScratchDir dir;
    const std::string good = dir.file("good.oct"), bad = dir.file("bad.oct");
    const auto v = make_volume<double>({9, 6, 5}, Pattern::Random, 3);
    write_oct<double>(good, info_for(ScalarType::f64, v.dims), {build_octree(v.view(), {}).view()});
    OctBytes b(good);
    auto n = b.node<double>(0, 0, 0);
    ASSERT_EQ(n.tail.zero, 0u);
    n.tail.zero = 7;
    b.set_node(0, 0, 0, n);
    b.rechecksum();
    b.save(bad);
    try {
        load_everything(bad, Verify::Full);
        ADD_FAILURE() << "a non-zero record tail was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("the record's last 4 bytes must be zero (found 7)"), std::string::npos) << e.what();
    }
}

TEST(OctReject, MessagesNameFileStepDepthNodeAndNumbers) {
    Fixture fx;
    OctBytes b(fx.good);
    const uint64_t below = b.entry(b.entry_index(1, 1)).count;
    b.set_group_base(1, 0, 0, below);   // every child of the root past the end of depth 1
    b.rechecksum();
    b.save(fx.bad);
    const OctFile f = OctFile::open(fx.bad, Verify::IndicesOnly);
    EXPECT_NO_THROW(f.step<uint8_t>(0));   // the other step is fine
    try {
        f.step<uint8_t>(1);
        FAIL() << "corrupt step accepted";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find(fx.bad), std::string::npos) << m;
        EXPECT_NE(m.find("step 1, depth 0"), std::string::npos) << m;
        EXPECT_NE(m.find("node 0"), std::string::npos) << m;
        EXPECT_NE(m.find("expected <= " + std::to_string(below)), std::string::npos) << m;
    }
    // A failed step stays failed on the next request.
    EXPECT_THROW(f.step<uint8_t>(1), Error);
}

TEST(OctReject, OverlappingChildrenAreErrors) {
    Fixture fx(Pattern::Random);
    fx.expect_rejected([&](OctBytes& b) {
        // Two parents at depth 1 pointing at the same children: overlap.
        const SectionEntry s = b.entry(b.entry_index(0, 1));
        std::vector<uint64_t> parents;
        for (uint64_t i = 0; i < s.count; ++i)
            if (b.node<uint8_t>(0, 1, i).child_mask) parents.push_back(i);
        ASSERT_GE(parents.size(), 2u);
        auto n = b.node<uint8_t>(0, 1, parents[1]);
        ASSERT_EQ(parents[1] >> kNodeGroupShift, parents[0] >> kNodeGroupShift);
        n.child_offset = b.node<uint8_t>(0, 1, parents[0]).child_offset;
        b.set_node(0, 1, parents[1], n);
    }, "overlapping children");
}

TEST(OctReject, BadCountsAreErrors) {
    Fixture fx;
    fx.expect_rejected([](OctBytes& b) {
        SectionEntry s = b.entry(b.entry_index(1, 3));
        s.count -= 1;   // bytes no longer count * record size
        b.set_entry(b.entry_index(1, 3), s);
    }, "count without bytes");
    fx.expect_rejected([](OctBytes& b) {
        // Shrink the last cap section consistently and move the table: the parents now point
        // past the end of the caps.
        const uint64_t last = b.section_count() - 1;
        SectionEntry s = b.entry(last);
        ASSERT_GE(s.count, 2u);
        FileHeader h = b.header();
        std::vector<char> table(b.bytes.begin() + long(h.section_table_offset), b.bytes.end());
        s.count -= 1;
        s.bytes -= s.record_bytes;
        std::memcpy(table.data() + last * sizeof s, &s, sizeof s);
        const uint64_t new_table = format::align_up(s.offset + s.bytes);
        b.bytes.resize(new_table);
        std::fill(b.bytes.begin() + long(s.offset + s.bytes), b.bytes.end(), 0);
        b.bytes.insert(b.bytes.end(), table.begin(), table.end());
        h.section_table_offset = new_table;
        h.file_bytes = b.bytes.size();
        b.set_header(h);
    }, "one cap fewer than the parents need");
    fx.expect_rejected([](OctBytes& b) {
        SectionEntry s = b.entry(0);
        s.count = 2;
        s.bytes = 2 * uint64_t(s.record_bytes);
        b.set_entry(0, s);
    }, "two roots");
    fx.expect_rejected([](OctBytes& b) {
        SectionEntry s = b.entry(0);
        s.count = 0;
        s.bytes = 0;
        b.set_entry(0, s);
    }, "no root");
}

TEST(OctReject, HostileSectionTablesAreErrors) {
    Fixture fx;
    const uint64_t kMax = std::numeric_limits<uint64_t>::max();
    for (uint64_t i : {uint64_t(0), uint64_t(2), uint64_t(7)}) {
        SCOPED_TRACE(i);
        fx.expect_rejected([&](OctBytes& b) {
            SectionEntry s = b.entry(i);
            s.offset = kMax - 5;   // offset + bytes wraps around to a small number
            b.set_entry(i, s);
        }, "offset near 2^64");
        fx.expect_rejected([&](OctBytes& b) {
            SectionEntry s = b.entry(i);
            s.bytes = kMax - s.offset + 1 + 64;   // wraps to 64
            b.set_entry(i, s);
        }, "bytes that wrap");
        fx.expect_rejected([&](OctBytes& b) {
            SectionEntry s = b.entry(i);
            // count * record wraps around to the real byte size. The cap level is a byte array
            // (record size 1, format 3): nothing wraps there, so a count far past its bytes.
            if (s.record_bytes == 1) s.count += uint64_t(1) << 63;
            else s.count = s.count + (uint64_t(1) << 63) / (s.record_bytes & -s.record_bytes) * 2;
            b.set_entry(i, s);
        }, "count * record size that wraps");
        fx.expect_rejected([&](OctBytes& b) {
            SectionEntry s = b.entry(i);
            s.offset += 64;
            b.set_entry(i, s);
        }, "section moved off its canonical offset");
        fx.expect_rejected([&](OctBytes& b) {
            SectionEntry s = b.entry(i);
            s.depth ^= 1;
            b.set_entry(i, s);
        }, "duplicate (step, depth)");
        fx.expect_rejected([&](OctBytes& b) {
            SectionEntry s = b.entry(i);
            s.kind = s.kind == 1 ? 2 : 1;
            b.set_entry(i, s);
        }, "wrong kind");
        fx.expect_rejected([&](OctBytes& b) {
            SectionEntry s = b.entry(i);
            s.record_bytes += 1;
            b.set_entry(i, s);
        }, "wrong record size");
    }
    fx.expect_rejected([&](OctBytes& b) {
        FileHeader h = b.header();
        h.section_table_offset = kMax - 10;
        b.set_header(h);
    }, "table offset near 2^64");
    fx.expect_rejected([&](OctBytes& b) {
        FileHeader h = b.header();
        h.section_count = kMax / sizeof(SectionEntry) + 2;   // count * 48 wraps
        b.set_header(h);
    }, "table size that wraps");
    fx.expect_rejected([&](OctBytes& b) {
        // Nonzero padding between sections would escape every checksum.
        for (uint64_t i = 1; i < b.section_count(); ++i)
            if (b.entry(i - 1).offset + b.entry(i - 1).bytes < b.entry(i).offset) {
                b.bytes[b.entry(i).offset - 1] = 1;
                return;
            }
        FAIL() << "fixture has no padding between sections";
    }, "padding not zero");
}

TEST(OctReject, BadHeaderFieldsAreErrors) {
    Fixture fx;
    auto header_edit = [&](const char* what, const std::function<void(FileHeader&)>& f, bool rechecksum = true) {
        fx.expect_rejected([&](OctBytes& b) {
            FileHeader h = b.header();
            f(h);
            b.set_header(h);
        }, what, rechecksum);
    };
    header_edit("magic", [](FileHeader& h) { h.magic[0] = 'X'; });
    header_edit("version", [](FileHeader& h) { h.version = format::kFormatVersion + 1; });
    header_edit("header size", [](FileHeader& h) { h.header_bytes = 128; });
    header_edit("endianness", [](FileHeader& h) { h.endian_tag = __builtin_bswap32(format::kEndianTag); });
    header_edit("header checksum", [](FileHeader& h) { h.tolerance = 1.0; }, false);
    header_edit("scalar type code", [](FileHeader& h) { h.scalar_type = 8; });
    header_edit("wider scalar type", [](FileHeader& h) { h.scalar_type = uint8_t(ScalarType::u16); h.scalar_bytes = 2; });
    header_edit("scalar size", [](FileHeader& h) { h.scalar_bytes = 2; });
    header_edit("zero extent", [](FileHeader& h) { h.dims[1] = 0; });
    header_edit("huge extent", [](FileHeader& h) { h.dims[2] = Dims::kMaxExtent + 1; });
    header_edit("dims not matching dmax", [](FileHeader& h) { h.dims[0] = 100; });
    header_edit("dmax", [](FileHeader& h) { h.dmax = 5; });
    header_edit("no steps", [](FileHeader& h) { h.step_count = 0; });
    header_edit("more steps than sections", [](FileHeader& h) { h.step_count = 3; });
    header_edit("fewer steps than sections", [](FileHeader& h) { h.step_count = 1; });
    header_edit("iso-range flag", [](FileHeader& h) { h.has_iso_range = 2; });
    header_edit("iso-range order", [](FileHeader& h) { std::swap(h.iso_range[0], h.iso_range[1]); });
    header_edit("spacing NaN", [](FileHeader& h) { h.spacing[0] = std::nan(""); });
    header_edit("spacing zero", [](FileHeader& h) { h.spacing[2] = 0.0; });
    header_edit("origin inf", [](FileHeader& h) { h.origin[1] = INFINITY; });
    header_edit("tolerance negative", [](FileHeader& h) { h.tolerance = -1.0; });
    header_edit("file size", [](FileHeader& h) { h.file_bytes += 64; });
    header_edit("entry size", [](FileHeader& h) { h.section_entry_bytes = 64; });
    header_edit("reserved", [](FileHeader& h) { h.reserved[40] = 1; });
    header_edit("value slope zero", [](FileHeader& h) { h.value_slope = 0.0; });
    header_edit("value slope NaN", [](FileHeader& h) { h.value_slope = std::nan(""); });
    header_edit("value intercept inf", [](FileHeader& h) { h.value_inter = -INFINITY; });
    header_edit("flipped-axes mask", [](FileHeader& h) { h.flipped_axes = 8; });
}

/// f32 bounds must be finite: a NaN range would decode to bounds no isovalue compares with.
TEST(OctReject, NonFiniteFloatBoundsAreErrors) {
    ScratchDir dir;
    const std::string good = dir.file("good.oct"), bad = dir.file("bad.oct");
    const auto v = make_volume<float>({9, 6, 5}, Pattern::Random, 5);
    write_oct<float>(good, info_for(ScalarType::f32, v.dims), {build_octree(v.view(), {}).view()});
    for (const float lo : {std::numeric_limits<float>::quiet_NaN(), -std::numeric_limits<float>::infinity()}) {
        OctBytes b(good);
        auto n = b.node<float>(0, 0, 0);
        n.bounds.lo = lo;
        b.set_node(0, 0, 0, n);
        b.rechecksum();
        b.save(bad);
        for (Verify verify : {Verify::Full, Verify::IndicesOnly}) {
            try {
                load_everything(bad, verify);
                ADD_FAILURE() << "bounds lo " << lo << " accepted";
            } catch (const Error& e) {
                EXPECT_NE(std::string(e.what()).find("bounds range is not finite and ordered"), std::string::npos) << e.what();
            }
        }
    }
}

/// A valid small file relabelled as format `version` must be refused with exit status 2, naming
/// the version and saying how to get a file this build reads.
void expect_version_refused(uint32_t version) {
    ScratchDir dir;
    const std::string path = dir.file("old.oct");
    const std::vector<uint8_t> v(4 * 4 * 4, 7);
    AnyOctree::build(VolumeView<uint8_t>{reinterpret_cast<const std::byte*>(v.data()), Dims{4, 4, 4}, false}, Placement{}, {})
        .save(path);
    OctBytes b(path);
    FileHeader h = b.header();
    h.version = version;
    b.set_header(h);
    b.rechecksum();
    b.save(path);
    try {
        OctFile::open(path);
        ADD_FAILURE() << "a version " << version << " file was opened";
    } catch (const Error& e) {
        EXPECT_EQ(e.exit_status(), 2);
        EXPECT_NE(std::string(e.what()).find("format version " + std::to_string(version)), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("convert the source again with octiso-convert"), std::string::npos) << e.what();
    }
}

TEST(OctReject, VersionOneFilesAskToBeConvertedAgain) {
    // Version 1 never recorded NIfTI value scaling or flipped axes, so its values may be stored
    // unscaled: the loader says how to get a file it can trust instead of reading it.
    expect_version_refused(1);
}

TEST(OctReject, VersionTwoFilesAskToBeConvertedAgain) {
    // Version 2 stored wide nodes and whole caps: nothing in it reads as format 3.
    expect_version_refused(2);
}

TEST(OctReject, VersionThreeFilesAskToBeConvertedAgain) {
    // Version 3 has this layout but midpoints where level of detail reads corner voxels: read as
    // format 4 it would render a wrong coarse surface without any error.
    expect_version_refused(3);
}

TEST(OctReject, VersionFourFilesAskToBeConvertedAgain) {
    // Version 4 kept a 48-bit first child in every node: its records are not format 5's (issue 19).
    expect_version_refused(4);
}

TEST(OctReject, VersionFiveFilesAskToBeConvertedAgain) {
    // Version 5's 1-byte caps kept their base in the slot: format 6 reads the slot as the first
    // byte of the deltas and takes the base from a bound (issue 19), so it would decode wrong voxels.
    expect_version_refused(5);
}

TEST(OctReject, NonFilesAndEmptyFilesAreErrors) {
    ScratchDir dir;
    EXPECT_THROW(OctFile::open(dir.file("missing.oct")), Error);
    EXPECT_THROW(OctFile::open(dir.file("")), Error);   // the directory itself
    write_bytes(dir.file("empty.oct"), "", 0);
    EXPECT_THROW(OctFile::open(dir.file("empty.oct")), Error);
}

}  // namespace
}  // namespace octiso::test
