// The text headers of NRRD and MetaImage split into fields, for the two users that must agree on
// them: header_check.cpp (bound the declared size before VTK allocates it) and text_layout.cpp
// (where the voxels lie, so that the out-of-core converter can stream them). Only the first
// 64 KiB of a file are read; no voxel is touched here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "octiso/volume.h"

namespace octiso::io {

/// Header bytes read at most: the first 64 KiB of the file.
constexpr size_t kTextHeaderLimit = 1 << 16;
/// The first min(file size, kTextHeaderLimit) bytes of `path` (empty if it cannot be read).
std::string header_bytes(const std::string& path);

/// The fields of one header: keys as the format spells them after the rules below, values trimmed.
/// `data_offset` is where attached voxel data starts in the header's own file (NRRD: after the
/// blank line; MetaImage: after the ElementDataFile line); nullopt where the header never ends
/// inside the bytes read.
struct TextHeader {
    std::map<std::string, std::string> field;
    std::optional<uint64_t> data_offset;
    bool has(const std::string& key) const { return field.count(key) != 0; }
    std::string get(const std::string& key) const {
        const auto it = field.find(key);
        return it == field.end() ? std::string() : it->second;
    }
};

/// NRRD: "key: value" lines up to the first blank line (LF or CRLF); keys lower-cased with spaces
/// removed ("data file" -> "datafile"), comments and "key:=value" pairs skipped.
TextHeader parse_nrrd_header(const std::string& path);
/// MetaImage: "Key = Value" lines up to and including ElementDataFile; keys as written.
TextHeader parse_meta_image_header(const std::string& path);

/// Element bytes of a NRRD "type" (1, 2, 4, 8), 0 when unknown; the scalar type where octiso
/// stores it (nullopt for 64-bit integers and unknown names).
int nrrd_type_bytes(const std::string& type);
std::optional<ScalarType> nrrd_scalar_type(const std::string& type);
/// The same for a MetaImage ElementType (MET_UCHAR ...).
int meta_image_type_bytes(const std::string& type);
std::optional<ScalarType> meta_image_scalar_type(const std::string& type);

/// A whitespace-separated list of extents, each a decimal integer of at most 18 digits (so that
/// the product cannot be fooled by an overflowing parse); `what` names the field in the error.
std::vector<uint64_t> parse_sizes(const std::string& text, const std::string& what, const std::string& path);
/// element_bytes x every size, with zero axes and 64-bit overflow refused.
uint64_t checked_product(const std::vector<uint64_t>& sizes, uint64_t element_bytes, const std::string& path);

/// A detached data file named in a header, resolved against the header's folder; nullopt for a
/// list ("LIST"), a pattern (with '%') or a name with spaces (also a pattern's form).
std::optional<std::string> single_data_file(const std::string& header_path, const std::string& name);

std::string lower_case(std::string s);
std::string trimmed(std::string s);
uint64_t regular_file_size(const std::string& path);   ///< 0 if not a regular file

}  // namespace octiso::io
