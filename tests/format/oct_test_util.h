// Helpers for the .oct suites (scratch directories come from test_util/scratch_dir.h): writing a built octree to a file, and
// OctBytes, an in-memory copy of a .oct file that tests corrupt field by field and re-checksum so
// that the loader's structural checks (not only its checksums) are what rejects the result.
#pragma once

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "format/oct_layout.h"
#include "octiso/build.h"
#include "octiso/oct_file.h"
#include "octree/octree_test_util.h"
#include "test_util/scratch_dir.h"

namespace octiso::test {

inline OctInfo info_for(ScalarType type, Dims dims) {
    OctInfo info;
    info.type = type;
    info.dims = dims;
    info.placement.spacing = {0.5, 1.0, 2.5};
    info.placement.origin = {-3.0, 0.25, 100.0};
    info.iso_range = std::array<double, 2>{-1.5, 7.0};
    info.tolerance = 0.0;
    return info;
}

template <typename T> void write_oct(const std::string& path, const OctInfo& info, const std::vector<Octree<T>>& steps) {
    OctWriter w(path, info);
    for (const Octree<T>& s : steps) w.add_step(s);
    w.finish();
}

inline std::vector<char> read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<char>(std::istreambuf_iterator<char>(in), {});
}
inline void write_bytes(const std::string& path, const char* data, size_t n) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(data, std::streamsize(n));
}

/// A .oct file as bytes: typed access to header, table and node records, and re-checksumming.
struct OctBytes {
    std::vector<char> bytes;

    explicit OctBytes(const std::string& path) : bytes(read_bytes(path)) {}

    format::FileHeader header() const {
        format::FileHeader h;
        std::memcpy(&h, bytes.data(), sizeof h);
        return h;
    }
    void set_header(const format::FileHeader& h) { std::memcpy(bytes.data(), &h, sizeof h); }
    format::SectionEntry entry(uint64_t i) const {
        format::SectionEntry s;
        std::memcpy(&s, bytes.data() + header().section_table_offset + i * sizeof s, sizeof s);
        return s;
    }
    void set_entry(uint64_t i, const format::SectionEntry& s) {
        std::memcpy(bytes.data() + header().section_table_offset + i * sizeof s, &s, sizeof s);
    }
    uint64_t section_count() const { return header().section_count; }
    uint64_t entry_index(uint32_t step, int depth) const { return uint64_t(step) * header().dmax + uint64_t(depth); }

    template <typename T> InteriorNode<T> node(uint32_t step, int depth, uint64_t i) const {
        InteriorNode<T> n;
        std::memcpy(&n, bytes.data() + entry(entry_index(step, depth)).offset + i * sizeof n, sizeof n);
        return n;
    }
    template <typename T> void set_node(uint32_t step, int depth, uint64_t i, const InteriorNode<T>& n) {
        std::memcpy(bytes.data() + entry(entry_index(step, depth)).offset + i * sizeof n, &n, sizeof n);
    }
    /// Group base g of the interior section (step, depth): after its records (oct_layout.h).
    uint64_t group_base(uint32_t step, int depth, uint64_t g) const {
        uint64_t v;
        std::memcpy(&v, bytes.data() + group_base_at(step, depth, g), sizeof v);
        return v;
    }
    void set_group_base(uint32_t step, int depth, uint64_t g, uint64_t v) {
        std::memcpy(bytes.data() + group_base_at(step, depth, g), &v, sizeof v);
    }
    uint64_t group_base_at(uint32_t step, int depth, uint64_t g) const {
        const format::SectionEntry s = entry(entry_index(step, depth));
        return s.offset + format::group_bases_offset(s.count, header().scalar_bytes) + 8 * g;
    }

    /// Recomputes every section checksum (sections whose bounds are sane), the table checksum and
    /// the header checksum, in that order.
    void rechecksum() {
        format::FileHeader h = header();
        const uint64_t size = bytes.size();
        if (h.section_table_offset <= size && h.section_count <= (size - h.section_table_offset) / sizeof(format::SectionEntry)) {
            for (uint64_t i = 0; i < h.section_count; ++i) {
                format::SectionEntry s = entry(i);
                if (s.bytes <= size && s.offset <= size - s.bytes) {
                    s.checksum = format::checksum(bytes.data() + s.offset, size_t(s.bytes));
                    set_entry(i, s);
                }
            }
            h.section_table_checksum = format::checksum(bytes.data() + h.section_table_offset,
                                                        size_t(h.section_count * sizeof(format::SectionEntry)));
        }
        h.header_checksum = format::checksum(&h, format::kHeaderChecksummedBytes);
        set_header(h);
    }
    void save(const std::string& path) const { write_bytes(path, bytes.data(), bytes.size()); }
};

}  // namespace octiso::test
