// The header parsers behind header_check.h. They read at most the first 64 KiB of a file (the
// header) and stat any detached data file; no voxel is read here.
#include "io/header_check.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include <sys/stat.h>
#include <zlib.h>

#include "io/text_header.h"
#include "octiso/error.h"

namespace octiso::io {

namespace {

constexpr uint64_t kDeflateMaxRatio = 1032;
std::string num(uint64_t v) { return std::to_string(v); }

[[noreturn]] void too_big(const std::string& path, const std::string& what, uint64_t declared, uint64_t held,
                          bool compressed) {
    throw Error(path, what + " declares " + num(declared) + " bytes of voxels but the file holds " +
                          (compressed ? "at most " + num(held) + " (compressed data, 1032:1 at best)" : num(held)));
}

void check_bound(const std::string& path, const std::string& what, uint64_t declared, uint64_t available, bool compressed) {
    const uint64_t bound = compressed ? (available > UINT64_MAX / kDeflateMaxRatio ? UINT64_MAX : available * kDeflateMaxRatio)
                                      : available;
    if (declared > bound) too_big(path, what, declared, bound, compressed);
}

// ---- NIfTI ---------------------------------------------------------------------------------

template <typename V> V load(const unsigned char* p, bool swap) {
    unsigned char b[sizeof(V)];
    std::memcpy(b, p, sizeof b);
    if (swap) std::reverse(b, b + sizeof b);
    V v;
    std::memcpy(&v, b, sizeof v);
    return v;
}

int nifti_type_bytes(int datatype) {
    switch (datatype) {
        case 2: case 256: return 1;      // u8, i8
        case 4: case 512: return 2;      // i16, u16
        case 8: case 768: case 16: return 4;   // i32, u32, f32
        case 64: return 8;               // f64
        default: return 0;
    }
}

uint64_t check_nifti(const std::string& path) {
    const bool gz = lower_case(path).size() >= 3 && lower_case(path).substr(path.size() - 3) == ".gz";
    unsigned char h[540] = {};
    size_t n = 0;
    if (gz) {
        gzFile f = ::gzopen(path.c_str(), "rb");
        if (!f) throw Error(path, "cannot open as gzip");
        const int r = ::gzread(f, h, sizeof h);
        ::gzclose(f);
        if (r < 0) throw Error(path, "not a readable gzip stream");
        n = size_t(r);
    } else {
        std::ifstream f(path, std::ios::binary);
        f.read(reinterpret_cast<char*>(h), sizeof h);
        n = size_t(f.gcount());
    }
    const uint64_t bytes = regular_file_size(path);
    check_nifti_header(h, n, gz ? (bytes > UINT64_MAX / kDeflateMaxRatio ? UINT64_MAX : bytes * kDeflateMaxRatio) : bytes,
                       !gz, path);
    return 0;   // NIfTI is streamed (nifti_stream.cpp); its size is the parsed header's business
}

// ---- NRRD ----------------------------------------------------------------------------------

uint64_t check_nrrd(const std::string& path) {
    TextHeader header = parse_nrrd_header(path);
    auto& field = header.field;
    if (!field.count("sizes") || !field.count("type")) return 0;   // VTK will say what is missing
    const int tb = nrrd_type_bytes(field["type"]);
    if (tb == 0) throw Error(path, "NRRD type '" + field["type"] + "' is not supported");
    const std::vector<uint64_t> sizes = parse_sizes(field["sizes"], "NRRD sizes", path);
    const uint64_t declared = checked_product(sizes, uint64_t(tb), path);
    const std::string enc = lower_case(field.count("encoding") ? field["encoding"] : "raw");
    uint64_t available = 0;
    std::string data = field.count("datafile") ? field["datafile"] : "";
    if (data.empty()) {
        if (!header.data_offset) {
            if (regular_file_size(path) < kTextHeaderLimit) throw Error(path, "NRRD header has no blank line before the data");
            return 0;
        }
        available = regular_file_size(path) - *header.data_offset;
    } else {
        const std::optional<std::string> single = single_data_file(path, data);
        if (!single) return 0;   // a list or pattern of files: left to VTK
        data = *single;
        struct stat st {};
        if (::stat(data.c_str(), &st) != 0) throw Error(path, "NRRD data file '" + data + "' does not exist");
        available = uint64_t(st.st_size);
    }
    if (field.count("byteskip") && field["byteskip"] != "-1") {
        const uint64_t b = std::strtoull(field["byteskip"].c_str(), nullptr, 10);
        available = b > available ? 0 : available - b;
    }
    if (enc == "raw") check_bound(path, "NRRD header", declared, available, false);
    else if (enc == "gzip" || enc == "gz") check_bound(path, "NRRD header", declared, available, true);
    else if (enc == "hex") check_bound(path, "NRRD header", declared * 2, available, false);
    else if (enc == "ascii" || enc == "text" || enc == "txt")
        check_bound(path, "NRRD header", declared / uint64_t(tb) * 2 - 1, available, false);
    return declared;
}

// ---- legacy VTK ----------------------------------------------------------------------------

int vtk_type_bytes(const std::string& t) {
    static const std::map<std::string, int> types = {
        {"unsigned_char", 1}, {"char", 1}, {"signed_char", 1}, {"unsigned_short", 2}, {"short", 2}, {"unsigned_int", 4},
        {"int", 4}, {"unsigned_long", 8}, {"long", 8}, {"float", 4}, {"double", 8}, {"vtktypeint64", 8}, {"vtktypeuint64", 8}};
    const auto it = types.find(lower_case(t));
    return it == types.end() ? 0 : it->second;
}

uint64_t check_legacy_vtk(const std::string& path) {
    const std::string head = header_bytes(path);
    std::istringstream in(head);
    std::string line;
    bool binary = false;
    uint64_t point_data = 0, components = 1;
    int tb = 0;
    std::vector<uint64_t> dims;
    for (int lineno = 0; std::getline(in, line); ++lineno) {
        if (lineno == 2) binary = lower_case(trimmed(line)) == "binary";
        if (lineno < 3) continue;
        std::istringstream w(line);
        std::string key;
        w >> key;
        key = lower_case(key);
        if (key == "dimensions") {
            uint64_t v;
            while (w >> v) dims.push_back(v);
        } else if (key == "point_data") {
            w >> point_data;
        } else if (key == "cell_data" && point_data == 0) {
            return 0;   // cell data first: rare; VTK and the later checks handle it
        } else if (key == "scalars" && point_data > 0) {
            std::string name, type;
            w >> name >> type;
            if (!(w >> components)) components = 1;
            tb = vtk_type_bytes(type);
            if (tb == 0) throw Error(path, "legacy VTK scalar type '" + type + "' is not supported");
        } else if (key == "lookup_table" && tb > 0) {
            if (dims.size() == 3) {
                const uint64_t n = checked_product(dims, 1, path);
                if (n != point_data)
                    throw Error(path, "legacy VTK header: DIMENSIONS give " + num(n) + " points but POINT_DATA says " + num(point_data));
            }
            const std::streamoff at = in.tellg();
            if (at < 0) return 0;
            const uint64_t declared = checked_product({point_data, components}, uint64_t(tb), path);
            const uint64_t available = regular_file_size(path) - uint64_t(at);
            if (binary) check_bound(path, "legacy VTK header", declared, available, false);
            else check_bound(path, "legacy VTK header", declared / uint64_t(tb) * 2 - 1, available, false);
            return declared;
        }
    }
    return 0;
}

// ---- MetaImage -----------------------------------------------------------------------------

uint64_t check_meta_image(const std::string& path) {
    TextHeader header = parse_meta_image_header(path);
    auto& field = header.field;
    if (!header.data_offset || !field.count("DimSize") || !field.count("ElementType")) return 0;   // VTK reports it
    const int tb = meta_image_type_bytes(field["ElementType"]);
    if (tb == 0) throw Error(path, "MetaImage ElementType '" + field["ElementType"] + "' is not supported");
    std::vector<uint64_t> sizes = parse_sizes(field["DimSize"], "MetaImage DimSize", path);
    if (field.count("ElementNumberOfChannels")) sizes.push_back(std::strtoull(field["ElementNumberOfChannels"].c_str(), nullptr, 10));
    const uint64_t declared = checked_product(sizes, uint64_t(tb), path);
    const bool compressed = lower_case(field["CompressedData"]) == "true";
    std::string data = field["ElementDataFile"];
    uint64_t available = 0;
    if (data == "LOCAL" || data == "Local" || data == "local") {
        available = regular_file_size(path) - *header.data_offset;
    } else {
        const std::optional<std::string> single = single_data_file(path, data);
        if (!single) return 0;
        data = *single;
        struct stat st {};
        if (::stat(data.c_str(), &st) != 0) throw Error(path, "MetaImage data file '" + data + "' does not exist");
        available = uint64_t(st.st_size);
    }
    if (field.count("HeaderSize") && field["HeaderSize"] != "-1") {
        const uint64_t b = std::strtoull(field["HeaderSize"].c_str(), nullptr, 10);
        available = b > available ? 0 : available - b;
    }
    check_bound(path, "MetaImage header", declared, available, compressed);
    return declared;
}

}  // namespace

void check_nifti_header(const unsigned char* h, size_t n, uint64_t bound, bool exact, const std::string& path) {
    // 1. Version and byte order from sizeof_hdr (348: NIfTI-1, 540: NIfTI-2).
    if (n < 348) throw Error(path, "NIfTI header is truncated (" + num(n) + " of 348 bytes)");
    const int32_t raw = load<int32_t>(h, false), swapped = load<int32_t>(h, true);
    const bool swap = raw != 348 && raw != 540;
    const int32_t sizeof_hdr = swap ? swapped : raw;
    if (sizeof_hdr != 348 && sizeof_hdr != 540) throw Error(path, "not a NIfTI file (sizeof_hdr is " + num(uint32_t(raw)) + ")");
    const bool v2 = sizeof_hdr == 540;
    if (v2 && n < 540) throw Error(path, "NIfTI-2 header is truncated (" + num(n) + " of 540 bytes)");
    if (!v2 && std::memcmp(h + 344, "n+1", 4) != 0)
        throw Error(path, "NIfTI-1 magic is not \"n+1\" (a .hdr/.img pair or a damaged header)");
    if (v2 && std::memcmp(h + 4, "n+2", 4) != 0) throw Error(path, "NIfTI-2 magic is not \"n+2\"");
    // 2. Dimensions: dim[0] in 1..7, every used extent >= 1.
    int64_t dim[8];
    for (int i = 0; i < 8; ++i) dim[i] = v2 ? load<int64_t>(h + 16 + 8 * i, swap) : load<int16_t>(h + 40 + 2 * i, swap);
    if (dim[0] < 1 || dim[0] > 7) throw Error(path, "NIfTI dim[0] must be 1..7 (found " + std::to_string(dim[0]) + ")");
    std::vector<uint64_t> sizes;
    for (int i = 1; i <= dim[0]; ++i) {
        if (dim[i] < 1) throw Error(path, "NIfTI dim[" + num(uint64_t(i)) + "] must be >= 1 (found " + std::to_string(dim[i]) + ")");
        sizes.push_back(uint64_t(dim[i]));
    }
    // 3. Datatype and bitpix: only the scalar types octiso stores.
    const int datatype = v2 ? load<int16_t>(h + 12, swap) : load<int16_t>(h + 70, swap);
    const int bitpix = v2 ? load<int16_t>(h + 14, swap) : load<int16_t>(h + 72, swap);
    const int tb = nifti_type_bytes(datatype);
    if (tb == 0)
        throw Error(path, "NIfTI datatype " + std::to_string(datatype) +
                              " is not supported (expected 2 u8, 256 i8, 4 i16, 512 u16, 8 i32, 768 u32, 16 f32 or 64 f64)");
    if (bitpix != 8 * tb)
        throw Error(path, "NIfTI bitpix " + std::to_string(bitpix) + " does not match datatype " + std::to_string(datatype) +
                              " (expected " + num(uint64_t(8 * tb)) + ")");
    // 4. vox_offset: a whole number of bytes past the header, inside the file.
    double vox = v2 ? double(load<int64_t>(h + 168, swap)) : double(load<float>(h + 108, swap));
    if (!std::isfinite(vox) || vox < double(sizeof_hdr) || vox != std::floor(vox) || vox > 9e18)
        throw Error(path, "NIfTI vox_offset " + std::to_string(vox) + " is not a whole byte offset past the header");
    const uint64_t offset = uint64_t(vox);
    // 5. The declared voxels fit in what follows vox_offset.
    const uint64_t declared = checked_product(sizes, uint64_t(tb), path);
    const uint64_t available = offset > bound ? 0 : bound - offset;
    if (declared > available) too_big(path, "NIfTI header", declared, available, !exact);
}

uint64_t check_declared_size(const std::string& path, VolumeFormat format) {
    switch (format) {
        case VolumeFormat::nifti: return check_nifti(path);
        case VolumeFormat::nrrd: return check_nrrd(path);
        case VolumeFormat::legacy_vtk: return check_legacy_vtk(path);
        case VolumeFormat::meta_image: return check_meta_image(path);
        default: return 0;
    }
}

}  // namespace octiso::io
