// Format detection (extension first, then magic bytes) and open_volume(): the one entry point the
// converter uses to turn a path and the raw/placement flags of CONVENTIONS 3 into a checked
// LoadedVolume. The readers themselves live in raw_reader.cpp and vtk_reader.cpp; LoadedVolume's
// constructor and the format names live in the core (src/volume/loaded_volume.cpp).
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <new>
#include <vector>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/input_file.h"
#include "io/nifti_header.h"
#include "io/volume_stream.h"
#include "octiso/reader.h"

namespace octiso {

namespace io {

uint64_t check_input_file(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) {
        if (errno == ENOENT || errno == ENOTDIR) throw Error(path, "no such file");
        throw Error(path, std::string("cannot access: ") + std::strerror(errno));
    }
    if (S_ISDIR(st.st_mode)) throw Error(path, "is a directory, not a volume file");
    if (!S_ISREG(st.st_mode)) throw Error(path, "is not a regular file");
    if (::access(path.c_str(), R_OK) != 0) throw Error(path, std::string("not readable: ") + std::strerror(errno));
    return uint64_t(st.st_size);
}

}  // namespace io

namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

bool ends_with(const std::string& s, std::string_view suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::optional<VolumeFormat> format_from_extension(const std::string& path) {
    const std::string p = lower(path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1));
    if (ends_with(p, ".nii") || ends_with(p, ".nii.gz")) return VolumeFormat::nifti;
    if (ends_with(p, ".vti")) return VolumeFormat::vti;
    if (ends_with(p, ".vtk")) return VolumeFormat::legacy_vtk;
    if (ends_with(p, ".mhd") || ends_with(p, ".mha")) return VolumeFormat::meta_image;
    if (ends_with(p, ".nrrd") || ends_with(p, ".nhdr")) return VolumeFormat::nrrd;
    return std::nullopt;
}

// Magic bytes. NIfTI is recognised only to say that it needs its extension (the name decides
// gzip and the .nii form, as for every NIfTI tool).
std::optional<VolumeFormat> format_from_magic(const std::string& path) {
    char head[512] = {};
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) return std::nullopt;
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        ::close(fd);
        return std::nullopt;
    }
    const ssize_t n = ::read(fd, head, sizeof head - 1);
    ::close(fd);
    if (n <= 0) return std::nullopt;
    const std::string_view text(head, size_t(n));
    if (text.starts_with("NRRD000")) return VolumeFormat::nrrd;
    if (text.starts_with("# vtk DataFile")) return VolumeFormat::legacy_vtk;
    if ((text.starts_with("<?xml") || text.starts_with("<VTKFile")) && text.find("<VTKFile") != text.npos &&
        text.find("\"ImageData\"") != text.npos)
        return VolumeFormat::vti;
    if (text.starts_with("ObjectType = Image")) return VolumeFormat::meta_image;
    // NIfTI-1: sizeof_hdr 348 at byte 0, magic "n+1" at 344; NIfTI-2: 540 and "n+2" at 4.
    if (n >= 348 && text.substr(344, 4) == std::string_view("n+1\0", 4)) return VolumeFormat::nifti;
    if (n >= 8 && text.substr(4, 4) == std::string_view("n+2\0", 4)) return VolumeFormat::nifti;
    return std::nullopt;
}

}  // namespace

VolumeFormat detect_volume_format(const std::string& path) {
    if (auto f = format_from_extension(path)) return *f;
    if (auto f = format_from_magic(path)) return *f;
    return VolumeFormat::raw;
}

namespace {

// The format of `path` under `options`, with the flag checks every reader shares:
// 1. An extension names the format outright; raw-only flags then mean a confused command line.
// 2. Magic bytes claim an extension-less file, unless --dims/--type say it is raw.
// 3. Anything else is raw (CONVENTIONS 3), and needs --dims and --type.
VolumeFormat choose_format(const std::string& path, const RawOptions& options) {
    io::check_input_file(path);
    const bool raw_flags = options.dims || options.type;
    VolumeFormat format = VolumeFormat::raw;
    if (auto f = format_from_extension(path)) {
        format = *f;
        const char* flag = options.dims ? "--dims" : options.type ? "--type" : options.endian ? "--endian"
                         : options.offset ? "--offset" : nullptr;
        if (flag)
            throw Error(flag, "applies only to raw input, and '" + path + "' is read as " +
                                  std::string(volume_format_name(format)));
    } else if (!raw_flags) {
        if (auto m = format_from_magic(path)) format = *m;
        if (format == VolumeFormat::nifti)
            throw Error(path, "looks like NIfTI: name it .nii or .nii.gz to read it as NIfTI "
                              "(or give --dims and --type to read it as raw)");
    }
    if (format == VolumeFormat::raw) {
        if (!options.dims)
            throw Error("--dims", "raw input '" + path + "' needs --dims NX,NY,NZ (no other format claims the file)");
        if (!options.type)
            throw Error("--type", "raw input '" + path + "' needs --type u8|i8|u16|i16|u32|i32|f32|f64");
    }
    if (options.array && (format == VolumeFormat::raw || format == VolumeFormat::nifti))
        throw Error("--array", "picks an array of a VTK file (.vti .vtk), and '" + path + "' is read as " +
                                   std::string(volume_format_name(format)) + ", which holds one");
    if (format != VolumeFormat::raw && (options.endian || options.offset)) {
        throw Error(options.endian ? "--endian" : "--offset",
                    "applies only to raw input, and '" + path + "' is read as " + std::string(volume_format_name(format)));
    }
    return format;
}

// --spacing / --origin over what the file says, then the placement limits.
Placement overridden_placement(Placement placement, Dims dims, const std::string& path, const RawOptions& options) {
    if (options.spacing) placement.spacing = *options.spacing;
    if (options.origin) placement.origin = *options.origin;
    check_placement(placement, dims, path, "; override it with --spacing/--origin");
    return placement;
}

}  // namespace

LoadedVolume read_stream_whole(VolumeStream& s) {
    auto buffer = std::make_shared<std::vector<std::byte>>();
    try {
        buffer->resize(size_t(s.bytes()));
    } catch (const std::bad_alloc&) {
        throw Error(s.source(), "out of memory reading the " + std::to_string(s.bytes()) + " voxel bytes the header declares");
    }
    s.read_layers(s.dims().z, buffer->data());
    const std::byte* data = buffer->data();
    LoadedVolume v(std::move(buffer), data, s.type(), s.dims(), s.placement(), false, s.source(), s.format());
    v.set_source_order(s.value_scale(), s.flipped_axes());
    v.set_warning(s.warning());
    return v;
}

LoadedVolume open_volume(const std::string& path, const RawOptions& options) {
    const VolumeFormat format = choose_format(path, options);
    // NIfTI goes through the same reader as the out-of-core path (nifti_stream.cpp), not VTK's:
    // VTK applies neither scl_slope nor the sform's flips, and reverses the slices of qfac -1
    // files, so one reader for both paths is what keeps their .oct bytes equal (CONVENTIONS 2b).
    // NRRD and MetaImage likewise wherever the stream reads them (text_stream.cpp): VTK 9.1's
    // NRRD reader leaves big-endian gzip data unswapped and reads ascii data as zeros
    // (text_stream_test.cpp shows both); VTK still gives the placement. The layouts the stream
    // leaves alone are VTK's.
    std::unique_ptr<VolumeStream> text;
    if ((format == VolumeFormat::nrrd || format == VolumeFormat::meta_image) && !options.array)
        text = try_open_text_stream(path, format);
    LoadedVolume volume = format == VolumeFormat::raw
                              ? read_raw(path, *options.dims, *options.type, options.endian.value_or(Endian::little),
                                         options.offset.value_or(0))
                          : format == VolumeFormat::nifti ? read_nifti(path)
                          : text                          ? read_stream_whole(*text)
                                                          : read_vtk(path, format, options.array);
    volume.set_placement(overridden_placement(volume.placement(), volume.dims(), path, options));
    return volume;
}

bool is_streamable(const std::string& path, const RawOptions& options) {
    const VolumeFormat f = choose_format(path, options);
    if (f == VolumeFormat::nrrd || f == VolumeFormat::meta_image) return !options.array && !text_stream_refusal(path, f);
    return f == VolumeFormat::raw || f == VolumeFormat::nifti;
}

std::unique_ptr<VolumeStream> open_volume_stream(const std::string& path, const RawOptions& options) {
    const VolumeFormat format = choose_format(path, options);
    std::unique_ptr<VolumeStream> s;
    if (format == VolumeFormat::raw)
        s = open_raw_stream(path, *options.dims, *options.type, options.endian.value_or(Endian::little),
                            options.offset.value_or(0));
    else if (format == VolumeFormat::nifti)
        s = open_nifti_stream(path);
    else if (format == VolumeFormat::nrrd || format == VolumeFormat::meta_image)
        s = open_text_stream(path, format);
    else
        throw Error(path, std::string(volume_format_name(format)) + " input is read whole, not streamed", ErrorKind::Other);
    s->set_placement(overridden_placement(s->placement(), s->dims(), path, options));
    return s;
}

}  // namespace octiso
