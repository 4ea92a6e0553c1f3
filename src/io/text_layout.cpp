// text_data_layout(): the NRRD (teem's format description, "data file", "byte skip", "encoding")
// and MetaImage (MetaIO's ElementDataFile, HeaderSize, CompressedData) rules for where the
// voxels are, as far as a stream needs them. Anything these rules do not cover is left to VTK.
#include "io/text_layout.h"

#include "io/text_header.h"
#include "octiso/error.h"

namespace octiso::io {

namespace {

LayoutOrReason whole(std::string why) { return {std::nullopt, std::move(why)}; }

/// sizes -> dims, one to three axes, each within Dims::kMaxExtent; nullopt (and a reason) beyond three.
std::optional<Dims> dims_of(const std::vector<uint64_t>& sizes, const std::string& what, const std::string& path) {
    if (sizes.size() > 3) return std::nullopt;
    uint32_t d[3] = {1, 1, 1};
    for (size_t a = 0; a < sizes.size(); ++a) {
        if (sizes[a] == 0 || sizes[a] > Dims::kMaxExtent)
            throw Error(path, what + " " + std::to_string(sizes[a]) + " is outside 1.." + std::to_string(Dims::kMaxExtent));
        d[a] = uint32_t(sizes[a]);
    }
    return Dims{d[0], d[1], d[2]};
}

/// A byte count from a header field: decimal digits only, at most 18 of them.
uint64_t byte_count(const std::string& text, const std::string& what, const std::string& path) {
    const std::vector<uint64_t> v = parse_sizes(text, what, path);
    if (v.size() != 1) throw Error(path, what + " '" + text + "' is not one number");
    return v[0];
}

/// `skip` bytes in front of `bytes` voxel bytes, all inside a file of `file_bytes` from `base`.
void check_fits(uint64_t base, uint64_t skip, uint64_t bytes, uint64_t file_bytes, const std::string& what,
                const std::string& path) {
    if (base > file_bytes || skip > file_bytes - base || bytes > file_bytes - base - skip)
        throw Error(path, what + ": " + std::to_string(bytes) + " voxel bytes after " + std::to_string(base + skip) +
                              " do not fit in the " + std::to_string(file_bytes) + "-byte data file");
}

LayoutOrReason nrrd_layout(const std::string& path) {
    if (!header_bytes(path).starts_with("NRRD000")) return whole("no NRRD000 magic");
    TextHeader h = parse_nrrd_header(path);
    if (!h.has("sizes") || !h.has("type")) return whole("the header lacks sizes or type");
    DataLayout l;
    const std::optional<ScalarType> type = nrrd_scalar_type(h.get("type"));
    if (!type) return whole("type '" + h.get("type") + "' is not one octiso streams");
    l.type = *type;
    const std::vector<uint64_t> sizes = parse_sizes(h.get("sizes"), "NRRD sizes", path);
    if (h.has("dimension") && h.get("dimension") != std::to_string(sizes.size()))
        return whole("dimension does not match the number of sizes");
    const std::optional<Dims> dims = dims_of(sizes, "NRRD size", path);
    if (!dims) return whole("more than three axes");
    l.dims = *dims;
    const uint64_t bytes = checked_volume_bytes(l.dims, l.type, path);

    const std::string enc = lower_case(h.has("encoding") ? h.get("encoding") : "raw");
    if (enc == "gzip" || enc == "gz") l.encoding = DataEncoding::deflate;
    // ascii is read here, not by VTK: VTK 9.1's NRRD reader turns ascii data into zeros (and
    // reads uchar digits as characters), silently (text_stream_test.cpp).
    else if (enc == "ascii" || enc == "text" || enc == "txt") l.encoding = DataEncoding::ascii;
    else if (enc != "raw") return whole("encoding '" + enc + "'");
    if (scalar_type_bytes(l.type) > 1 && l.encoding != DataEncoding::ascii) {
        const std::string endian = lower_case(h.get("endian"));
        if (endian != "little" && endian != "big") return whole("no endian field for a multi-byte type");
        l.big_endian = endian == "big";
    }
    if (h.has("lineskip") && h.get("lineskip") != "0") return whole("line skip");

    if (h.has("datafile")) {
        const std::optional<std::string> single = single_data_file(path, h.get("datafile"));
        if (!single) return whole("a list or pattern of data files");
        l.data_path = *single;
        l.offset = 0;
    } else {
        if (!h.data_offset) return whole("no blank line ends the header");
        l.data_path = path;
        l.offset = *h.data_offset;
    }
    const uint64_t file_bytes = regular_file_size(l.data_path);
    if (file_bytes == 0 && bytes > 0) throw Error(path, "NRRD data file '" + l.data_path + "' is missing or empty");
    // Byte skips: VTK's NRRD reader refuses them, so the whole-file path could not give the
    // bytes to compare with; both paths leave the file to VTK and its message.
    if (h.has("byteskip") && h.get("byteskip") != "0") return whole("byte skip (VTK's NRRD reader refuses it too)");
    if (l.encoding == DataEncoding::raw) check_fits(l.offset, 0, bytes, file_bytes, "NRRD", path);
    return {l, {}};
}

LayoutOrReason meta_image_layout(const std::string& path) {
    TextHeader h = parse_meta_image_header(path);
    if (!h.data_offset || !h.has("DimSize") || !h.has("ElementType")) return whole("the header lacks DimSize, ElementType or ElementDataFile");
    DataLayout l;
    const std::optional<ScalarType> type = meta_image_scalar_type(h.get("ElementType"));
    if (!type) return whole("ElementType '" + h.get("ElementType") + "' is not one octiso streams");
    l.type = *type;
    if (h.has("ElementNumberOfChannels") && h.get("ElementNumberOfChannels") != "1") return whole("more than one channel");
    if (lower_case(h.get("BinaryData")) == "false") return whole("ASCII data");
    const std::vector<uint64_t> sizes = parse_sizes(h.get("DimSize"), "MetaImage DimSize", path);
    if (h.has("NDims") && h.get("NDims") != std::to_string(sizes.size())) return whole("NDims does not match DimSize");
    const std::optional<Dims> dims = dims_of(sizes, "MetaImage DimSize", path);
    if (!dims) return whole("more than three axes");
    l.dims = *dims;
    const uint64_t bytes = checked_volume_bytes(l.dims, l.type, path);
    const std::string msb = lower_case(h.has("ElementByteOrderMSB") ? h.get("ElementByteOrderMSB") : h.get("BinaryDataByteOrderMSB"));
    l.big_endian = msb == "true";
    if (lower_case(h.get("CompressedData")) == "true") l.encoding = DataEncoding::deflate;

    const std::string file = h.get("ElementDataFile");
    if (lower_case(file) == "local") {
        l.data_path = path;
        l.offset = *h.data_offset;
    } else {
        const std::optional<std::string> single = single_data_file(path, file);
        if (!single) return whole("a list or pattern of data files");
        l.data_path = *single;
    }
    const uint64_t file_bytes = regular_file_size(l.data_path);
    if (file_bytes == 0 && bytes > 0) throw Error(path, "MetaImage data file '" + l.data_path + "' is missing or empty");
    if (h.has("HeaderSize")) {
        if (l.encoding != DataEncoding::raw) return whole("HeaderSize with compressed data");
        const std::string skip = h.get("HeaderSize");
        if (skip == "-1") {
            check_fits(0, 0, bytes, file_bytes, "MetaImage", path);
            l.offset = file_bytes - bytes;   // the voxels are the file's last bytes
        } else {
            const uint64_t n = byte_count(skip, "MetaImage HeaderSize", path);
            check_fits(l.offset, n, bytes, file_bytes, "MetaImage", path);
            l.offset += n;
        }
    } else if (l.encoding == DataEncoding::raw) {
        check_fits(l.offset, 0, bytes, file_bytes, "MetaImage", path);
    }
    return {l, {}};
}

}  // namespace

LayoutOrReason text_data_layout(const std::string& path, VolumeFormat format) {
    if (format == VolumeFormat::nrrd) return nrrd_layout(path);
    if (format == VolumeFormat::meta_image) return meta_image_layout(path);
    return whole("not a NRRD or MetaImage header");
}

}  // namespace octiso::io
