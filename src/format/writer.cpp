// OctWriter: streams a .oct file step by step into an AtomicOutput temporary (nothing but the
// current step's arrays is ever held), then appends the section table, rewrites the header at
// offset 0, syncs and renames. The layout it produces is drawn in oct_layout.h.
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include <unistd.h>

#include "format/oct_layout.h"
#include "format/validate.h"
#include "util/atomic_output.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"

namespace octiso {

using format::FileHeader;
using format::SectionEntry;

struct OctWriter::Impl {
    OctInfo info;
    AtomicOutput out;
    std::FILE* file = nullptr;
    uint64_t pos = 0;                  // bytes written so far (the file position)
    std::vector<SectionEntry> table;
    bool broken = false;               // a write failed: finish() must not publish the file
    bool finished = false;
    // The section being streamed (begin_section .. end_section); open_depth < 0 when none.
    int open_depth = -1;
    int next_depth = 0;                // the depth the next streamed section must have
    SectionEntry open_entry{};
    uint64_t open_written = 0;
    format::ChecksumStream open_checksum;

    Impl(std::string path, const OctInfo& i) : info(i), out(std::move(path)) {}
    ~Impl() {
        if (file) std::fclose(file);   // before AtomicOutput's destructor removes the temporary
    }

    [[noreturn]] void fail_io(const std::string& what) {
        broken = true;
        throw Error(out.path(), what + ": " + std::strerror(errno), ErrorKind::Other);
    }
    void write(const void* data, uint64_t n) {
        if (n != 0 && std::fwrite(data, 1, size_t(n), file) != size_t(n)) fail_io("write failed");
        pos += n;
    }
    void pad_to_alignment() {
        static constexpr std::byte kZeros[format::kSectionAlign] = {};
        write(kZeros, format::align_up(pos) - pos);
    }
    /// A section from memory: `count` records, and for an interior level its group bases after
    /// them (oct_layout.h); the checksum runs over the bytes as they are written.
    void add_section(format::SectionKind kind, uint32_t step, int depth, uint32_t record_bytes, const void* data,
                     uint64_t count, const uint64_t* group_bases = nullptr) {
        pad_to_alignment();
        SectionEntry s{};
        s.kind = uint32_t(kind);
        s.step = step;
        s.depth = uint32_t(depth);
        s.record_bytes = record_bytes;
        s.offset = pos;
        s.count = count;
        const uint64_t records = count * record_bytes;   // the arrays exist in memory, so this cannot overflow
        format::ChecksumStream sum;
        sum.update(data, size_t(records));
        write(data, records);
        if (kind == format::SectionKind::Interior) {
            static constexpr uint8_t kZero[8] = {};
            const uint64_t pad = group_bases_at(records) - records, bases = 8 * node_groups(count);
            sum.update(kZero, size_t(pad));
            write(kZero, pad);
            sum.update(group_bases, size_t(bases));
            write(group_bases, bases);
        }
        s.bytes = pos - s.offset;
        s.checksum = sum.digest();
        table.push_back(s);
    }
};

OctWriter::OctWriter(std::string path, const OctInfo& info) : impl_(std::make_unique<Impl>(std::move(path), info)) {
    Impl& m = *impl_;
    const std::string& p = m.out.path();
    // The header must pass the loader's checks later, so refuse what it would refuse now.
    for (uint32_t e : {info.dims.x, info.dims.y, info.dims.z})
        if (e < 1 || e > Dims::kMaxExtent)
            throw Error(p, "grid extent out of range (expected 1 .. " + std::to_string(Dims::kMaxExtent) + ", found " +
                               std::to_string(e) + ")");
    if (info.dmax != 0 && info.dmax != dmax_for(info.dims))
        throw Error(p, "dmax does not match the grid (expected " + std::to_string(dmax_for(info.dims)) + ", found " +
                           std::to_string(info.dmax) + ")");
    m.info.dmax = dmax_for(info.dims);
    m.info.step_count = 0;
    check_placement(info.placement, info.dims, p);
    if (info.iso_range && !((*info.iso_range)[0] < (*info.iso_range)[1] && std::isfinite((*info.iso_range)[0]) &&
                            std::isfinite((*info.iso_range)[1])))
        throw Error(p, "iso-range must be finite with LO < HI");
    if (!std::isfinite(info.tolerance) || !(info.tolerance >= 0)) throw Error(p, "tolerance must be finite and >= 0");
    if (!std::isfinite(info.value_scale.slope) || info.value_scale.slope == 0 || !std::isfinite(info.value_scale.inter))
        throw Error(p, "value scale must have a finite, non-zero slope and a finite intercept");
    if (info.flipped_axes > kAllAxesFlipped) throw Error(p, "flipped axes must be a mask of x, y, z");

    m.file = std::fopen(m.out.temp_path().c_str(), "wb");
    if (!m.file) throw Error(m.out.temp_path(), std::string("cannot create: ") + std::strerror(errno), ErrorKind::Other);
    // Placeholder header; the real one is written at finish(), when the table is known.
    const FileHeader zero{};
    m.write(&zero, sizeof zero);
}

OctWriter::~OctWriter() = default;

template <typename T> void OctWriter::add_step(const Octree<T>& octree) {
    Impl& m = *impl_;
    const std::string& p = m.out.path();
    if (m.finished) throw Error(p, "add_step() after finish()", ErrorKind::Other);
    if (m.broken) throw Error(p, "an earlier write failed", ErrorKind::Other);
    if (m.open_depth >= 0 || m.next_depth != 0) throw Error(p, "add_step() inside a streamed step", ErrorKind::Other);
    if (scalar_type_of<T>() != m.info.type)
        throw Error(p, "step of type " + std::string(scalar_type_name(scalar_type_of<T>())) + " added to a file of type " +
                           std::string(scalar_type_name(m.info.type)), ErrorKind::Other);
    if (octree.dims() != m.info.dims || octree.dmax() != m.info.dmax)
        throw Error(p, "step grid does not match the file (expected dmax " + std::to_string(m.info.dmax) + ", found " +
                           std::to_string(octree.dmax()) + ", or other extents)", ErrorKind::Other);
    const uint32_t step = m.info.step_count;
    if (step == UINT32_MAX) throw Error(p, "too many time steps", ErrorKind::Other);
    // The loader would reject a file with a bad tree; refuse to write one in the first place.
    try {
        format::validate_tree<T>(p, octree.arrays(), step);
    } catch (const Error& e) {
        throw Error(p, "refusing to write an inconsistent octree: " + e.problem(), ErrorKind::Other);
    }
    const OctreeArrays<T>& a = octree.arrays();
    for (int d = 0; d + 1 < a.dmax; ++d)
        m.add_section(format::SectionKind::Interior, step, d, uint32_t(sizeof(InteriorNode<T>)), a.nodes[size_t(d)],
                      a.node_count[size_t(d)], a.group_base[size_t(d)]);
    m.add_section(format::SectionKind::Caps, step, a.dmax - 1, 1, a.caps, a.cap_bytes + kCapReadSlack);
    m.info.step_count = step + 1;
}

void OctWriter::begin_section(int depth, uint64_t count) {
    Impl& m = *impl_;
    const std::string& p = m.out.path();
    if (m.finished) throw Error(p, "begin_section() after finish()", ErrorKind::Other);
    if (m.broken) throw Error(p, "an earlier write failed", ErrorKind::Other);
    if (m.open_depth >= 0 || depth != m.next_depth || depth >= m.info.dmax)
        throw Error(p, "streamed section out of order (expected depth " + std::to_string(m.next_depth) + ", found " +
                           std::to_string(depth) + ")", ErrorKind::Other);
    if (depth == 0 && m.info.step_count == UINT32_MAX) throw Error(p, "too many time steps", ErrorKind::Other);
    const bool caps = depth == m.info.dmax - 1;
    const uint64_t scalar = scalar_type_bytes(m.info.type);
    const uint64_t record = caps ? format::cap_record_bytes(scalar) : format::interior_record_bytes(scalar);
    if (count > (uint64_t(1) << 40))   // far beyond 2^32 nodes a depth, so count * record cannot wrap
        throw Error(p, "section of " + std::to_string(count) + " records is too large", ErrorKind::Other);
    m.pad_to_alignment();
    SectionEntry& e = m.open_entry;
    e = SectionEntry{};
    e.kind = uint32_t(caps ? format::SectionKind::Caps : format::SectionKind::Interior);
    e.step = m.info.step_count;
    e.depth = uint32_t(depth);
    e.record_bytes = uint32_t(record);
    e.offset = m.pos;
    e.count = count;
    e.bytes = caps ? count * record : format::interior_section_bytes(count, scalar);   // records, then group bases
    m.open_written = 0;
    m.open_checksum.reset();
    m.open_depth = depth;
}

void OctWriter::append_records(const void* data, uint64_t bytes) {
    Impl& m = *impl_;
    if (m.open_depth < 0) throw Error(m.out.path(), "append_records() outside a section", ErrorKind::Other);
    if (bytes > m.open_entry.bytes - m.open_written)
        throw Error(m.out.path(), "streamed section overruns its count at depth " + std::to_string(m.open_depth),
                    ErrorKind::Other);
    m.open_checksum.update(data, size_t(bytes));
    m.write(data, bytes);
    m.open_written += bytes;
}

void OctWriter::end_section() {
    Impl& m = *impl_;
    const std::string& p = m.out.path();
    if (m.open_depth < 0) throw Error(p, "end_section() outside a section", ErrorKind::Other);
    if (m.open_written != m.open_entry.bytes)
        throw Error(p, "streamed section at depth " + std::to_string(m.open_depth) + " holds " +
                           std::to_string(m.open_written) + " bytes (expected " + std::to_string(m.open_entry.bytes) + ")",
                    ErrorKind::Other);
    m.open_entry.checksum = m.open_checksum.digest();
    m.table.push_back(m.open_entry);
    const bool caps = m.open_depth == m.info.dmax - 1;
    m.open_depth = -1;
    m.next_depth = caps ? 0 : m.next_depth + 1;
    if (caps) m.info.step_count += 1;
}

void OctWriter::finish() {
    Impl& m = *impl_;
    const std::string& p = m.out.path();
    if (m.finished) throw Error(p, "finish() called twice", ErrorKind::Other);
    if (m.broken) throw Error(p, "an earlier write failed", ErrorKind::Other);
    if (m.info.step_count == 0) throw Error(p, "no time steps were added", ErrorKind::Other);
    if (m.open_depth >= 0 || m.next_depth != 0) throw Error(p, "a streamed step is unfinished", ErrorKind::Other);

    m.pad_to_alignment();
    FileHeader h{};
    std::memcpy(h.magic, format::kMagic, sizeof h.magic);
    h.version = format::kFormatVersion;
    h.header_bytes = sizeof(FileHeader);
    h.endian_tag = format::kEndianTag;
    h.scalar_type = uint8_t(m.info.type);
    h.scalar_bytes = uint8_t(scalar_type_bytes(m.info.type));
    h.has_iso_range = m.info.iso_range ? 1 : 0;
    h.dmax = uint8_t(m.info.dmax);
    h.dims[0] = m.info.dims.x;
    h.dims[1] = m.info.dims.y;
    h.dims[2] = m.info.dims.z;
    h.step_count = m.info.step_count;
    for (int i = 0; i < 3; ++i) {
        h.spacing[i] = m.info.placement.spacing[size_t(i)];
        h.origin[i] = m.info.placement.origin[size_t(i)];
    }
    if (m.info.iso_range) {
        h.iso_range[0] = (*m.info.iso_range)[0];
        h.iso_range[1] = (*m.info.iso_range)[1];
    }
    h.tolerance = m.info.tolerance;
    h.value_slope = m.info.value_scale.slope;
    h.value_inter = m.info.value_scale.inter;
    h.flipped_axes = m.info.flipped_axes;
    h.section_table_offset = m.pos;
    h.section_count = m.table.size();
    h.section_entry_bytes = sizeof(SectionEntry);
    const uint64_t table_bytes = m.table.size() * sizeof(SectionEntry);
    h.section_table_checksum = format::checksum(m.table.data(), size_t(table_bytes));
    m.write(m.table.data(), table_bytes);
    h.file_bytes = m.pos;
    h.header_checksum = format::checksum(&h, format::kHeaderChecksummedBytes);

    if (std::fseek(m.file, 0, SEEK_SET) != 0) m.fail_io("seek failed");
    if (std::fwrite(&h, 1, sizeof h, m.file) != sizeof h) m.fail_io("write failed");
    if (std::fflush(m.file) != 0) m.fail_io("write failed");
    if (::fsync(::fileno(m.file)) != 0) m.fail_io("sync failed");
    const int rc = std::fclose(m.file);
    m.file = nullptr;
    if (rc != 0) m.fail_io("close failed");
    m.out.commit(int64_t(m.pos));
    m.finished = true;
}

uint64_t OctWriter::bytes_written() const { return impl_->pos; }

#define OCTISO_INSTANTIATE(T) template void OctWriter::add_step<T>(const Octree<T>&);
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)
#undef OCTISO_INSTANTIATE

}  // namespace octiso
