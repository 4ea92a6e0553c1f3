// Where the voxels of a NRRD or MetaImage file lie (issue 13, item 2: stream them instead of
// loading them whole through VTK): the data file, the byte where they start, the encoding, the
// byte order, the grid and the type, all from the header. The placement is not parsed here: the
// stream takes spacing and origin from VTK's own reading of the header (CONVENTIONS 2b, last item: "as
// VTK's readers report them"), so the two converter paths cannot disagree on it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "octiso/loaded_volume.h"
#include "octiso/volume.h"

namespace octiso::io {

/// deflate: gzip or zlib framing, found from its header; ascii: NRRD's whitespace-separated numbers.
enum class DataEncoding { raw, deflate, ascii };

struct DataLayout {
    std::string data_path;        ///< the header's own file for attached data
    uint64_t offset = 0;          ///< first byte of the (compressed) data in data_path
    DataEncoding encoding = DataEncoding::raw;
    bool big_endian = false;
    ScalarType type = ScalarType::u8;
    Dims dims{1, 1, 1};           ///< a 1-D or 2-D file padded with extents of 1
};

/// The layout, or why the file is read whole by VTK instead: an encoding other than raw,
/// gzip/zlib and NRRD ascii (hex, bzip2, MetaImage's ASCII), a list or pattern of data files, NRRD line and byte skips
/// (VTK refuses those too), more than three
/// axes or more than one component, a type octiso does not store. Malformed values in fields the
/// stream relies on (sizes past Dims::kMaxExtent, a byte skip past the file) throw Error(path, ...).
struct LayoutOrReason {
    std::optional<DataLayout> layout;
    std::string why_not;
};
LayoutOrReason text_data_layout(const std::string& path, VolumeFormat format);   ///< nrrd or meta_image

}  // namespace octiso::io
