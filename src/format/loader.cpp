// OctFile: maps a .oct file read-only, validates header and section table at open (cheap, all of
// it, without touching any step's bytes), and each step's sections on first use (padding,
// checksums, then every index; validate.cpp), so a mapped series only becomes resident for the
// steps used. Steps are handed out as zero-copy Octree<T> views into the mapping. Verify::Touched
// leaves the nodes to format::TouchValidator, which checks each block when it is first read.
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <mutex>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "format/oct_layout.h"
#include "format/touch_validation.h"
#include "format/validate.h"
#include "util/mapping_guard.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"

namespace octiso {

using format::FileHeader;
using format::SectionEntry;

namespace {

struct StepState {
    std::once_flag once;
    StepSizes sizes;   // written once inside call_once, read-only afterwards
    std::once_flag full_once;   // Verify::Touched: step_sizes() counts every node once
    StepSizes full_sizes;
};

std::string num(uint64_t v) { return std::to_string(v); }
std::string g17(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.17g", v);
    return b;
}

bool all_zero(const std::byte* p, uint64_t n) {
    for (uint64_t i = 0; i < n; ++i)
        if (p[i] != std::byte{0}) return false;
    return true;
}

}  // namespace

struct OctFile::Impl {
    std::string path;
    Verify verify = Verify::Full;
    const std::byte* base = nullptr;   // the whole file, mapped read-only
    uint64_t bytes = 0;
    int fd = -1;         // kept open: holds the shared flock, and the fault handler fstats it
    int guard_slot = -1; // io::register_mapping slot (mapping_guard.h)
    struct stat opened {};   // fstat at open, for check_unchanged()
    OctInfo info;
    const SectionEntry* table = nullptr;   // step_count * dmax entries, (step, depth) order
    std::unique_ptr<StepState[]> steps;
    std::unique_ptr<format::TouchValidator> touch;   // Verify::Touched only

    ~Impl() {
        touch.reset();   // clears its fault resolver before the slot and the mapping go
        io::unregister_mapping(guard_slot);
        if (base) ::munmap(const_cast<std::byte*>(base), size_t(bytes));
        if (fd >= 0) ::close(fd);
    }

    [[noreturn]] void fail(const std::string& problem) const { throw Error(path, problem); }

    const SectionEntry& section(uint32_t step, int depth) const {
        return table[uint64_t(step) * uint64_t(info.dmax) + uint64_t(depth)];
    }

    void map_file();
    void check_header();
    void check_table();
    void check_step_padding(uint32_t k) const;

    template <typename T> OctreeArrays<T> arrays(uint32_t k) const {
        OctreeArrays<T> a;
        a.dims = info.dims;
        a.dmax = info.dmax;
        for (int d = 0; d + 1 < info.dmax; ++d) {
            const SectionEntry& s = section(k, d);
            a.nodes[size_t(d)] = reinterpret_cast<const InteriorNode<T>*>(base + s.offset);
            a.node_count[size_t(d)] = s.count;
            a.group_base[size_t(d)] = reinterpret_cast<const uint64_t*>(
                base + s.offset + format::group_bases_offset(s.count, scalar_type_bytes(info.type)));
        }
        const SectionEntry& c = section(k, info.dmax - 1);   // count >= kCapReadSlack (check_table)
        a.caps = reinterpret_cast<const uint8_t*>(base + c.offset);
        a.cap_bytes = c.count - kCapReadSlack;
        a.cap_count = 0;   // counted by validate_tree from the cap parents
        return a;
    }

    /// Validates step k exactly once (std::call_once: concurrent first callers wait; a failed
    /// validation throws to every caller and is retried by the next one).
    const StepSizes& ensure_valid(uint32_t k) const {
        if (k >= info.step_count)
            fail("step " + num(k) + " does not exist (expected 0 .. " + num(info.step_count - 1) + ")");
        StepState& st = steps[k];
        std::call_once(st.once, [&] {
            if (touch)
                if (const auto problem = touch->failure()) fail(*problem);   // a zeroed block may hold the table
            check_step_padding(k);
            if (verify == Verify::Full)
                for (int d = 0; d < info.dmax; ++d) format::verify_section_checksum(path, base, section(k, d));
            st.sizes = dispatch_scalar_type(info.type, [&](auto t) {
                using T = decltype(t);
                // Touched: the counts now, each node when a block of them is first read.
                return verify == Verify::Touched ? format::validate_counts<T>(path, arrays<T>(k), k)
                                                 : format::validate_tree<T>(path, arrays<T>(k), k);
            });
        });
        return st.sizes;
    }

    /// The sizes of every level (Verify::Touched counted no node at first use; this does, once).
    const StepSizes& full_sizes(uint32_t k) const {
        const StepSizes& sizes = ensure_valid(k);
        if (verify != Verify::Touched) return sizes;
        StepState& st = steps[k];
        std::call_once(st.full_once, [&] {
            try {
                st.full_sizes = dispatch_scalar_type(info.type, [&](auto t) {
                    using T = decltype(t);
                    return format::validate_tree<T>(path, arrays<T>(k), k);
                });
            } catch (const Error&) {
                // A block zeroed for a bad node breaks the rules across nodes too: name the node.
                if (const auto problem = touch->failure()) fail(*problem);
                throw;
            }
        });
        return st.full_sizes;
    }
};

// 1. Map: the file is never read through anything but this read-only mapping. The descriptor
//    stays open with a shared flock for the mapping's lifetime (policy in util/mapping_guard.h).
void OctFile::Impl::map_file() {
    // O_NONBLOCK: opening a FIFO for reading blocks until a writer appears (issue 18: a hang);
    // non-blocking it returns at once, and fstat below refuses anything but a regular file.
    fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) {
        if (errno == ENOENT || errno == ENOTDIR) fail("no such file");
        throw Error(path, std::string("cannot open: ") + std::strerror(errno));
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0) throw Error(path, std::string("cannot stat: ") + std::strerror(errno));
    if (!S_ISREG(st.st_mode))
        fail(S_ISDIR(st.st_mode) ? "is a directory, not a .oct file" : "is not a regular file (a FIFO, socket or device)");
    io::lock_shared_or_refuse(fd, path);
    opened = st;
    bytes = uint64_t(st.st_size);
    if (bytes < sizeof(FileHeader))
        fail("too short to be a .oct file (expected at least " + num(sizeof(FileHeader)) + " bytes, found " + num(bytes) + ")");
    void* p = ::mmap(nullptr, size_t(bytes), PROT_READ, MAP_PRIVATE, fd, 0);
    if (p == MAP_FAILED) throw Error(path, std::string("cannot map: ") + std::strerror(errno), ErrorKind::Other);
    base = static_cast<const std::byte*>(p);
    guard_slot = io::register_mapping(base, bytes, fd, path);
}

// 2. Header: identity first (magic, endianness, version, size), then its checksum, then fields.
void OctFile::Impl::check_header() {
    FileHeader h;
    std::memcpy(&h, base, sizeof h);
    if (std::memcmp(h.magic, format::kMagic, sizeof h.magic) != 0) fail("not a .oct file (bad magic bytes)");
    if (h.endian_tag != format::kEndianTag)
        fail("byte order tag mismatch (expected 0x01020304, found 0x" + [&] {
            char b[9];
            std::snprintf(b, sizeof b, "%08x", h.endian_tag);
            return std::string(b);
        }() + "): written on a big-endian machine or damaged");
    if (h.version == 1)
        fail("is .oct format version 1, written before value scaling and flipped axes were recorded (a NIfTI "
             "source may be stored unscaled): convert the source again with octiso-convert");
    if (h.version == 2)
        fail("is .oct format version 2, the node layout before compact nodes and packed caps (format 3): convert "
             "the source again with octiso-convert");
    if (h.version == 3)
        fail("is .oct format version 3, whose stored children hold the midpoint of their range, not the corner "
             "voxel level of detail samples (format 4): convert the source again with octiso-convert");
    if (h.version == 4)
        fail("is .oct format version 4, the node layout before child groups (format 5): convert "
             "the source again with octiso-convert");
    if (h.version == 5)
        fail("is .oct format version 5, the cap layout before bound-anchored caps (format 6): convert "
             "the source again with octiso-convert");
    if (h.version != format::kFormatVersion)
        fail("unsupported format version (expected " + num(format::kFormatVersion) + ", found " + num(h.version) + ")");
    if (h.header_bytes != sizeof(FileHeader))
        fail("bad header size (expected " + num(sizeof(FileHeader)) + ", found " + num(h.header_bytes) + ")");
    if (format::checksum(base, format::kHeaderChecksummedBytes) != h.header_checksum) fail("header checksum mismatch");
    if (h.file_bytes != bytes)
        fail(std::string(bytes < h.file_bytes ? "truncated" : "has trailing bytes") + " (expected " + num(h.file_bytes) +
             " bytes, found " + num(bytes) + ")");
    if (h.scalar_type >= kScalarTypeCount)
        fail("unknown scalar type code (expected 0 .. " + num(kScalarTypeCount - 1) + ", found " + num(h.scalar_type) + ")");
    info.type = ScalarType(h.scalar_type);
    if (h.scalar_bytes != scalar_type_bytes(info.type))
        fail("scalar size does not match type " + std::string(scalar_type_name(info.type)) + " (expected " +
             num(scalar_type_bytes(info.type)) + ", found " + num(h.scalar_bytes) + ")");
    for (int i = 0; i < 3; ++i)
        if (h.dims[i] < 1 || h.dims[i] > Dims::kMaxExtent)
            fail("grid extent " + std::string(1, "xyz"[i]) + " out of range (expected 1 .. " + num(Dims::kMaxExtent) +
                 ", found " + num(h.dims[i]) + ")");
    info.dims = Dims{h.dims[0], h.dims[1], h.dims[2]};
    info.dmax = dmax_for(info.dims);
    if (h.dmax != info.dmax)
        fail("dmax does not match the grid " + num(h.dims[0]) + "x" + num(h.dims[1]) + "x" + num(h.dims[2]) +
             " (expected " + num(info.dmax) + ", found " + num(h.dmax) + ")");
    for (int i = 0; i < 3; ++i) {
        info.placement.spacing[size_t(i)] = h.spacing[i];
        info.placement.origin[size_t(i)] = h.origin[i];
    }
    check_placement(info.placement, info.dims, path);   // finite, in range, a finite world box
    if (h.has_iso_range > 1) fail("bad iso-range flag (expected 0 or 1, found " + num(h.has_iso_range) + ")");
    if (h.has_iso_range) {
        if (!std::isfinite(h.iso_range[0]) || !std::isfinite(h.iso_range[1]) || !(h.iso_range[0] < h.iso_range[1]))
            fail("iso-range must be finite with LO < HI");
        info.iso_range = std::array<double, 2>{h.iso_range[0], h.iso_range[1]};
    } else if (h.iso_range[0] != 0 || h.iso_range[1] != 0) {
        fail("iso-range values present without the iso-range flag");
    }
    if (!std::isfinite(h.tolerance) || !(h.tolerance >= 0)) fail("tolerance must be finite and >= 0");
    info.tolerance = h.tolerance;
    if (!std::isfinite(h.value_slope) || h.value_slope == 0 || !std::isfinite(h.value_inter))
        fail("value scale must have a finite, non-zero slope and a finite intercept (found slope " + g17(h.value_slope) +
             ", intercept " + g17(h.value_inter) + ")");
    info.value_scale = ValueScale{h.value_slope, h.value_inter};
    if (h.flipped_axes > kAllAxesFlipped)
        fail("bad flipped-axes mask (expected 0 .. " + num(kAllAxesFlipped) + ", found " + num(h.flipped_axes) + ")");
    info.flipped_axes = h.flipped_axes;
    if (h.step_count == 0) fail("holds no time steps");
    info.step_count = h.step_count;
    if (h.reserved0 != 0 || !all_zero(reinterpret_cast<const std::byte*>(h.reserved), sizeof h.reserved))
        fail("reserved header bytes are not zero");
}

// 3. Section table: bounds without overflow, its checksum, then every entry.
void OctFile::Impl::check_table() {
    FileHeader h;
    std::memcpy(&h, base, sizeof h);
    if (h.section_entry_bytes != sizeof(SectionEntry))
        fail("bad section entry size (expected " + num(sizeof(SectionEntry)) + ", found " + num(h.section_entry_bytes) + ")");
    const uint64_t dmax = uint64_t(info.dmax);
    const uint64_t expected_count = uint64_t(info.step_count) * dmax;   // < 2^32 * 31: no overflow
    if (h.section_count != expected_count)
        fail("section count does not match " + num(info.step_count) + " steps of dmax " + num(dmax) + " (expected " +
             num(expected_count) + ", found " + num(h.section_count) + ")");
    const uint64_t table_bytes = expected_count * sizeof(SectionEntry);
    // A hostile header can make offset + bytes wrap around, so compare without adding.
    if (table_bytes > bytes || h.section_table_offset > bytes - table_bytes)
        fail("section table runs past end of file (" + num(table_bytes) + " bytes at offset " +
             num(h.section_table_offset) + ", file " + num(bytes) + " bytes)");
    if (h.section_table_offset % format::kSectionAlign != 0)
        fail("section table offset not 64-byte aligned (found " + num(h.section_table_offset) + ")");
    if (format::checksum(base + h.section_table_offset, size_t(table_bytes)) != h.section_table_checksum)
        fail("section table checksum mismatch");
    table = reinterpret_cast<const SectionEntry*>(base + h.section_table_offset);

    const uint64_t interior_rec = format::interior_record_bytes(scalar_type_bytes(info.type));
    const uint64_t cap_rec = format::cap_record_bytes(scalar_type_bytes(info.type));
    uint64_t end = sizeof(FileHeader);   // end of the previous region (header, then sections)
    for (uint64_t i = 0; i < expected_count; ++i) {
        const SectionEntry& s = table[i];
        const uint64_t step = i / dmax, depth = i % dmax;
        const std::string name = "section " + num(i) + " (step " + num(step) + ", depth " + num(depth) + ")";
        if (s.step != step || s.depth != depth)
            fail(name + ": sections must be listed in (step, depth) order (expected step " + num(step) + ", depth " +
                 num(depth) + ", found step " + num(s.step) + ", depth " + num(s.depth) + ")");
        const bool is_caps = depth == dmax - 1;
        const uint32_t kind = uint32_t(is_caps ? format::SectionKind::Caps : format::SectionKind::Interior);
        if (s.kind != kind) fail(name + ": wrong section kind (expected " + num(kind) + ", found " + num(s.kind) + ")");
        const uint64_t rec = is_caps ? cap_rec : interior_rec;
        if (s.record_bytes != rec)
            fail(name + ": record size does not match type " + std::string(scalar_type_name(info.type)) + " (expected " +
                 num(rec) + ", found " + num(s.record_bytes) + ")");
        if (s.bytes > bytes || s.offset > bytes - s.bytes)
            fail(name + ": runs past end of file (" + num(s.bytes) + " bytes at offset " + num(s.offset) + ", file " +
                 num(bytes) + " bytes)");
        // Interior sections hold their group bases after the records (oct_layout.h).
        const uint64_t scalar = scalar_type_bytes(info.type);
        if (s.count > s.bytes / rec ||
            (is_caps ? s.count * rec : format::interior_section_bytes(s.count, scalar)) != s.bytes)
            fail(name + ": byte size does not match the record count (expected " +
                 (is_caps ? num(s.count) + " x " + num(rec) + " bytes"
                          : num(format::interior_section_bytes(s.count, scalar)) + " bytes for " + num(s.count) +
                                " records of " + num(rec) + " and their group bases") +
                 ", found " + num(s.bytes) + ")");
        if (depth == 0 && s.count != 1)
            fail(name + ": the root level must hold exactly one node (expected 1, found " + num(s.count) + ")");
        if (is_caps && s.count < kCapReadSlack)
            fail(name + ": the cap level must end with " + num(kCapReadSlack) + " zero bytes (found " + num(s.count) +
                 " bytes in all)");
        // Canonical placement: right after the previous region, at the next multiple of 64,
        // with zero padding in between (so no byte of the file escapes every check).
        const uint64_t at = format::align_up(end);
        if (s.offset != at)
            fail(name + ": not at its canonical offset (expected " + num(at) + ", found " + num(s.offset) + ")");
        // The zero padding before each section is checked with its step (check_step_padding):
        // reading it here would fault in a page of every step at open, and a mapped series
        // should only become resident for the steps that are used (issue 6).
        end = s.offset + s.bytes;   // <= bytes, checked above
    }
    const uint64_t at = format::align_up(end);
    if (h.section_table_offset != at)
        fail("section table not at its canonical offset (expected " + num(at) + ", found " + num(h.section_table_offset) + ")");
    if (!all_zero(base + end, at - end)) fail("padding before the section table is not zero");
    if (h.section_table_offset + table_bytes != bytes)
        fail("bytes after the section table (expected the file to end at " + num(h.section_table_offset + table_bytes) +
             ", found " + num(bytes) + " bytes)");
}

// 4. Per step, at first use: the zero padding in front of each of its sections (canonical
//    offsets were checked at open, so each gap is [end of the previous region, offset), < 64 bytes).
void OctFile::Impl::check_step_padding(uint32_t k) const {
    for (int d = 0; d < info.dmax; ++d) {
        const uint64_t i = uint64_t(k) * uint64_t(info.dmax) + uint64_t(d);
        const uint64_t end = i == 0 ? sizeof(FileHeader) : table[i - 1].offset + table[i - 1].bytes;
        const SectionEntry& s = table[i];
        if (!all_zero(base + end, s.offset - end))
            fail("section " + num(i) + " (step " + num(k) + ", depth " + num(d) + "): padding before the section is not zero");
        if (d + 1 == info.dmax) continue;
        const uint64_t scalar = scalar_type_bytes(info.type);
        const uint64_t records = s.count * format::interior_record_bytes(scalar);
        if (!all_zero(base + s.offset + records, format::group_bases_offset(s.count, scalar) - records))
            fail("section " + num(i) + " (step " + num(k) + ", depth " + num(d) +
                 "): padding before the group bases is not zero");
    }
}

OctFile::OctFile() : impl_(std::make_unique<Impl>()) {}
OctFile::OctFile(OctFile&&) noexcept = default;
OctFile& OctFile::operator=(OctFile&&) noexcept = default;
OctFile::~OctFile() = default;

OctFile OctFile::open(const std::string& path, Verify verify) {
    OctFile f;
    Impl& m = *f.impl_;
    m.path = path;
    m.verify = verify;
    m.map_file();
    m.check_header();
    m.check_table();
    m.steps = std::make_unique<StepState[]>(m.info.step_count);
    if (verify == Verify::Touched) {
        if (m.guard_slot < 0) {
            m.verify = Verify::Full;   // no fault handler slot left: check everything at first use
        } else {
            FileHeader h;
            std::memcpy(&h, m.base, sizeof h);
            m.touch = std::make_unique<format::TouchValidator>(path, m.fd, m.base, m.bytes, m.info, h.section_table_offset,
                                                               m.guard_slot);
        }
    }
    return f;
}

const OctInfo& OctFile::info() const { return impl_->info; }
const std::string& OctFile::path() const { return impl_->path; }
uint64_t OctFile::file_bytes() const { return impl_->bytes; }

template <typename T> Octree<T> OctFile::step(uint32_t k) const {
    if (scalar_type_of<T>() != impl_->info.type)
        impl_->fail("holds " + std::string(scalar_type_name(impl_->info.type)) + " data, requested as " +
                    std::string(scalar_type_name(scalar_type_of<T>())));
    const StepSizes& sizes = impl_->ensure_valid(k);
    OctreeArrays<T> a = impl_->arrays<T>(k);
    a.cap_count = sizes.nodes_per_depth[size_t(a.dmax - 1)];
    return Octree<T>(a);
}

StepSizes OctFile::step_sizes(uint32_t k) const { return impl_->full_sizes(k); }

Verify OctFile::verify() const { return impl_->verify; }

std::optional<TouchStats> OctFile::touch_stats() const {
    if (!impl_->touch) return std::nullopt;
    return TouchStats{impl_->touch->blocks(), impl_->touch->blocks_checked(), impl_->touch->block_bytes()};
}

void OctFile::release_resident_pages() const {
    // Read-only and never written: dropping the pages loses nothing; a failure only costs memory.
    ::madvise(const_cast<std::byte*>(impl_->base), size_t(impl_->bytes), MADV_DONTNEED);
}

void OctFile::check_unchanged() const {
    struct stat st {};
    const Impl& m = *impl_;
    if (::fstat(m.fd, &st) != 0 || st.st_size != m.opened.st_size || st.st_mtim.tv_sec != m.opened.st_mtim.tv_sec ||
        st.st_mtim.tv_nsec != m.opened.st_mtim.tv_nsec)
        m.fail("the file changed while it was being read (rewritten in place by another program); nothing was written");
    if (m.touch)
        if (const auto problem = m.touch->failure()) m.fail(*problem + "; nothing was written");
}

#define OCTISO_INSTANTIATE(T) template Octree<T> OctFile::step<T>(uint32_t) const;
OCTISO_FOR_EACH_SCALAR_TYPE(OCTISO_INSTANTIATE)
#undef OCTISO_INSTANTIATE

}  // namespace octiso
