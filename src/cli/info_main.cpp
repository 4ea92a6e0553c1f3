// octiso-info: what a .oct file holds (header, sizes per step, counts per depth) and, with
// --extract-raw, the data of one step back as a raw array (CONVENTIONS 3). Every step is fully
// validated (checksums and indices) before it is reported. The value figures (range, exact
// percentiles, histogram) come from the tree (value_stats.h), so a wrong --type or --endian at
// conversion shows at once.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <unistd.h>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <vector>

#include "cli/common/cli.h"
#include "cli/common/flags.h"
#include "cli/common/json.h"
#include "cli/common/output_path.h"
#include "cli/common/report.h"
#include "format/oct_layout.h"
#include "io/volume_stream.h"
#include "util/atomic_output.h"
#include "octiso/any_octree.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/output_guard.h"
#include "octiso/value_stats.h"
#include "octiso/volume_writer.h"
#include "octiso/verify.h"

namespace {

using namespace octiso;

constexpr const char* kUsage =
    "usage: octiso-info FILE.oct [options]\n"
    "\n"
    "What a .oct file holds: type, dims, placement (world box of the voxel positions and its centre),\n"
    "the data range (exact, the root's min/max: the isovalues octiso-render accepts), sizes, and per\n"
    "step the nodes and scalar leaves per depth, the exact voxel min/max, percentiles and a histogram\n"
    "(read from the tree, no dense array). Every step is validated (checksums and indices) first.\n"
    "\n"
    "  --json                    one JSON object on stdout; the text report goes to stderr\n"
    "  --bins N                  histogram bins, 1..4096 (default 16)\n"
    "  --verify                  recompute every min/max and scalar from the leaves (exit 2 on a lie)\n"
    "  --extract-raw OUT.raw     write one step back as a raw x-fastest array, byte for byte (stored\n"
    "                            values, in the source file's axis order)\n"
    "  --extract OUT.vti|.nrrd|.nii|.nii.gz|.raw   the same with a header VTK, ParaView, 3D Slicer,\n"
    "                            nibabel read (type, dims, spacing, origin; .nii also the sform and\n"
    "                            scl_slope/scl_inter, in the source's axis order); .raw as --extract-raw\n"
    "  --step K                  the step --extract(-raw) writes (default 0)\n"
    "  --endian little|big       byte order of raw output (default little)\n"
    "  --version, -h/--help\n";

struct Extract {
    std::string path;
    bool with_header = false;   ///< --extract OUT.vti/.nrrd: a format that carries dims and placement
    uint32_t step = 0;
    bool big_endian = false;
    uint64_t bytes = 0;
};

/// Raw output goes out in slabs of layers of at most this many bytes, so a step larger than
/// memory extracts too (issue 13: the 27 GiB volume comes back byte for byte).
constexpr uint64_t kExtractSlabBytes = uint64_t(256) << 20;

/// kExtractSlabBytes, or OCTISO_EXTRACT_SLAB_BYTES where set (tests: slabs of a few layers, so
/// that a small file crosses slab seams).
uint64_t extract_slab_bytes() {
    const char* env = std::getenv("OCTISO_EXTRACT_SLAB_BYTES");
    if (!env || !*env) return kExtractSlabBytes;
    char* end = nullptr;
    const unsigned long long v = std::strtoull(env, &end, 10);
    return end && *end == '\0' && v > 0 ? uint64_t(v) : kExtractSlabBytes;
}

/// Decodes step `ex.step` and writes it x-fastest through AtomicOutput, byte-swapped if asked:
/// raw in slabs (kExtractSlabBytes); the formats with a header through VTK's writers, from one
/// dense array.
void extract_raw(const std::shared_ptr<const OctFile>& file, Extract& ex) {
    const OctInfo& info = file->info();
    ex.bytes = checked_volume_bytes(info.dims, info.type, file->path());
    // A dense array is decoded in memory: refuse up front, naming the size, rather than fail on
    // allocation (a sparse 16384^3 octree is 98 KB on disk and 16 TiB as an array), and before
    // the step is validated (that reads the whole file).
    const uint64_t memory = uint64_t(::sysconf(_SC_PHYS_PAGES)) * uint64_t(::sysconf(_SC_PAGESIZE));
    if (ex.with_header && ex.bytes > memory)
        throw Error("--extract", "step " + std::to_string(ex.step) + " of " + file->path() + " is " + std::to_string(ex.bytes) +
                                     " bytes as a dense array, more than this machine's " + std::to_string(memory) +
                                     " bytes of memory (--extract-raw writes it slab by slab)");
    const AnyOctree step = AnyOctree::step(file, ex.step);
    if (ex.with_header) {   // the formats' own byte order declaration: native
        std::vector<std::byte> data(size_t(ex.bytes));
        step.decode(data, std::endian::native);
        file->check_unchanged();
        write_volume_file(ex.path, info.type, info.dims, info.placement, data, info.value_scale, info.flipped_axes);
        return;
    }
    // Raw is the source's bytes back: axes reversed at conversion turned round again (.raw
    // through --extract does the same); reversing moves whole values, so the byte order stays.
    // A reversed z hands the stored layers out from the top: source slab [k0, k1) is stored
    // layers [nz - k1, nz - k0), reversed within the slab.
    const Dims d = info.dims;
    const uint64_t layer = uint64_t(d.x) * d.y * scalar_type_bytes(info.type);
    const uint32_t per_slab = uint32_t(std::clamp<uint64_t>(extract_slab_bytes() / layer, 1, d.z));
    std::vector<std::byte> slab(size_t(layer * per_slab));
    const std::endian order = ex.big_endian ? std::endian::big : std::endian::little;
    const bool z_reversed = info.flipped_axes & 4;
    AtomicFileWriter out(ex.path);
    for (uint32_t k0 = 0; k0 < d.z; k0 += per_slab) {
        const uint32_t k1 = std::min(d.z, k0 + per_slab), n = k1 - k0;
        const std::span<std::byte> part(slab.data(), size_t(layer * n));
        if (z_reversed) step.decode_layers(d.z - k1, d.z - k0, part, order);
        else step.decode_layers(k0, k1, part, order);
        file->check_unchanged();   // issue 18: the decoded data came from what was validated
        if (info.flipped_axes) reverse_axes_in_place(part.data(), d, n, scalar_type_bytes(info.type), info.flipped_axes);
        out.append(part.data(), part.size());
    }
    out.commit();   // every write, fsync and close checked
}

/// "x, z (NIfTI affine negative)" for a flipped-axes mask.
std::string flipped_text(uint8_t mask) {
    std::string s;
    for (int a = 0; a < 3; ++a)
        if (mask & (1u << a)) s += std::string(s.empty() ? "" : ", ") + "xyz"[a];
    return s;
}

std::string join(const std::vector<uint64_t>& v) {
    std::string s;
    for (size_t i = 0; i < v.size(); ++i) {
        if (i) s += ' ';
        s += std::to_string(v[i]);
    }
    return s;
}

/// What one step's values are: the root's range (what the renderer checks isovalues against) and
/// the statistics walked from the tree.
struct StepValues {
    std::optional<std::array<double, 2>> root_range;
    ValueStats stats;
};

/// One step's values in real values (CONVENTIONS 2b: real = stored * slope + inter). The tree's
/// statistics are of stored values; an affine map moves every figure with it. A negative slope
/// reverses the order: the histogram is read backwards and percentile p is the stored one of
/// level 100 - p (exact up to the one rank nearest-rank percentiles can differ by).
struct RealValues {
    std::optional<std::array<double, 2>> root_range;
    uint64_t voxels = 0, non_finite = 0;
    std::array<double, 2> range{0, 0};
    std::array<double, 7> percentiles{};
    std::vector<double> edges;      ///< counts.size() + 1 bin edges, ascending
    std::vector<uint64_t> counts;
};

RealValues real_values(const StepValues& v, const ValueScale& scale) {
    const ValueStats& s = v.stats;
    RealValues r;
    if (v.root_range) r.root_range = scale.real_range(*v.root_range);
    r.voxels = s.voxels;
    r.non_finite = s.non_finite;
    r.range = scale.real_range(s.range);
    r.counts = s.counts;
    for (int b = 0; b <= int(s.counts.size()); ++b) r.edges.push_back(scale.real(s.bin_edge(b)));
    const bool reversed = scale.slope < 0;
    if (reversed) {
        std::reverse(r.counts.begin(), r.counts.end());
        std::reverse(r.edges.begin(), r.edges.end());
    }
    const size_t n = s.percentiles.size();
    for (size_t i = 0; i < n; ++i) r.percentiles[i] = scale.real(s.percentiles[reversed ? n - 1 - i : i]);
    return r;
}

/// The union of the steps' root ranges: the isovalues octiso-render accepts for this file.
std::optional<std::array<double, 2>> file_range(const std::vector<RealValues>& values) {
    std::optional<std::array<double, 2>> r;
    for (const RealValues& v : values)
        if (v.root_range) r = r ? std::array<double, 2>{std::min((*r)[0], (*v.root_range)[0]), std::max((*r)[1], (*v.root_range)[1])}
                                : *v.root_range;
    return r;
}

void human_values(std::ostream& os, const RealValues& s) {
    os << "    values                   ";
    if (s.voxels == 0) os << "none finite";
    else os << "min " << cli::number(s.range[0]) << ", max " << cli::number(s.range[1]) << " over " << s.voxels << " voxels";
    if (s.non_finite) os << " (" << s.non_finite << " NaN or infinite)";
    os << "\n";
    if (s.voxels == 0) return;
    os << "    percentiles              ";
    for (size_t i = 0; i < s.percentiles.size(); ++i)
        os << (i ? "  " : "") << cli::number(ValueStats::percentile_levels[i]) << "%: " << cli::number(s.percentiles[i]);
    os << "\n    histogram (" << s.counts.size() << " bins from " << cli::number(s.edges.front()) << " to "
       << cli::number(s.edges.back()) << ")  " << join(s.counts) << "\n";
}

void human_report(std::ostream& os, const OctFile& file, const std::vector<StepSizes>& steps,
                  const std::vector<RealValues>& values, const Extract* ex) {
    const OctInfo& in = file.info();
    const cli::WorldBox box = cli::world_box(in.dims, in.placement);
    const auto range = file_range(values);
    const uint64_t raw = checked_volume_bytes(in.dims, in.type, file.path()) * in.step_count;
    os << std::setprecision(10);
    os << file.path() << ": .oct format version " << format::kFormatVersion << ", header "
       << sizeof(format::FileHeader) << " bytes\n";
    os << "  type        " << scalar_type_name(in.type) << "\n";
    os << "  dims        " << in.dims.x << " x " << in.dims.y << " x " << in.dims.z << "\n";
    os << "  spacing     " << in.placement.spacing[0] << ", " << in.placement.spacing[1] << ", "
       << in.placement.spacing[2] << "\n";
    os << "  origin      " << in.placement.origin[0] << ", " << in.placement.origin[1] << ", "
       << in.placement.origin[2] << "\n";
    os << "  world box   " << cli::numbers(box.lo) << " .. " << cli::numbers(box.hi) << " (voxel positions)\n";
    os << "  centre      " << cli::numbers(box.centre) << "\n";
    os << "  data range  ";
    if (range) os << cli::number((*range)[0]) << " .. " << cli::number((*range)[1]) << " (exact, the root's min/max"
                  << (in.step_count > 1 ? " over all steps" : "") << "; isovalues outside it draw nothing)\n";
    else os << "none (no cell: an extent is 1)\n";
    if (!in.value_scale.is_identity())
        os << "  values      real = stored * " << cli::number(in.value_scale.slope) << " + " << cli::number(in.value_scale.inter)
           << " (NIfTI scl_slope/scl_inter; every value here is real)\n";
    if (in.flipped_axes)
        os << "  flipped     " << flipped_text(in.flipped_axes) << " (reversed from the source file at conversion; "
           << "--extract .nii/.raw gives its order back)\n";
    os << "  dmax        " << in.dmax << " (cube side " << (uint64_t(1) << in.dmax) << ")\n";
    os << "  iso-range   ";
    if (in.iso_range) {
        const auto r = in.value_scale.real_range(*in.iso_range);
        os << r[0] << ", " << r[1] << "\n";
    } else {
        os << "none (every isovalue exact)\n";
    }
    const double tolerance = in.tolerance * std::fabs(in.value_scale.slope);
    os << "  tolerance   " << tolerance << (tolerance == 0 ? " (lossless)" : "") << "\n";
    os << "  steps       " << in.step_count << "\n";
    os << "  file bytes  " << file.file_bytes() << "\n";
    os << "  raw bytes   " << raw << " (dims x " << scalar_type_bytes(in.type) << " bytes x " << in.step_count
       << " steps)\n";
    os << "  ratio       " << std::setprecision(4) << double(file.file_bytes()) / double(raw) << " (file / raw)\n"
       << std::setprecision(10);
    for (size_t k = 0; k < steps.size(); ++k) {
        const StepSizes& s = steps[k];
        os << "  step " << k << ": interior " << s.interior_bytes << " bytes (min/max " << s.minmax_bytes
           << "), caps " << s.cap_bytes << " bytes\n";
        os << "    nodes per depth          " << join(s.nodes_per_depth) << "  (last: caps)\n";
        os << "    scalar leaves per depth  " << join(s.scalar_leaves_per_depth) << "\n";
        human_values(os, values[k]);
    }
    if (ex)
        os << "  extracted step " << ex->step << " to " << ex->path << " (" << ex->bytes << " bytes, "
           << (ex->big_endian ? "big" : "little") << "-endian)\n";
    const bool nifti = ex && (ex->path.ends_with(".nii") || ex->path.ends_with(".nii.gz"));
    if (ex && !nifti && !in.value_scale.is_identity())
        os << "  note: " << ex->path << " holds the stored values (its format has no value scale): real = stored * "
           << cli::number(in.value_scale.slope) << " + " << cli::number(in.value_scale.inter) << "\n";
}

void json_report(std::ostream& os, const OctFile& file, const std::vector<StepSizes>& steps,
                 const std::vector<RealValues>& values, const Extract* ex) {
    const OctInfo& in = file.info();
    const cli::WorldBox box = cli::world_box(in.dims, in.placement);
    const auto range = file_range(values);
    const uint64_t raw_step = checked_volume_bytes(in.dims, in.type, file.path());
    const uint64_t raw = raw_step * in.step_count;
    cli::JsonWriter j(os);
    j.begin_object();
    j.field("file", file.path());
    j.field("format_version", format::kFormatVersion);
    j.field("header_bytes", sizeof(format::FileHeader));
    j.field("type", scalar_type_name(in.type));
    j.key("dims").begin_array().value(in.dims.x).value(in.dims.y).value(in.dims.z).end_array();
    j.key("spacing").array(in.placement.spacing);
    j.key("origin").array(in.placement.origin);
    j.key("world_box").begin_object().key("min").array(box.lo).key("max").array(box.hi).end_object();
    j.key("centre").array(box.centre);
    j.key("value_range");
    if (range) j.array(*range);
    else j.null();
    j.field("dmax", in.dmax);
    j.key("iso_range");
    if (in.iso_range) j.array(in.value_scale.real_range(*in.iso_range));
    else j.null();
    j.field("tolerance", in.tolerance * std::fabs(in.value_scale.slope));
    j.key("value_scale").begin_object().field("slope", in.value_scale.slope).field("inter", in.value_scale.inter).end_object();
    j.key("flipped_axes").begin_array();
    for (int a = 0; a < 3; ++a)
        if (in.flipped_axes & (1u << a)) j.value(std::string(1, "xyz"[a]));
    j.end_array();
    j.field("steps", in.step_count);
    j.field("file_bytes", file.file_bytes());
    j.field("raw_bytes_per_step", raw_step);
    j.field("raw_bytes", raw);
    j.field("ratio", double(file.file_bytes()) / double(raw));   // file / raw, as octiso-convert
    j.key("per_step").begin_array();
    for (size_t k = 0; k < steps.size(); ++k) {
        const StepSizes& s = steps[k];
        j.begin_object();
        j.field("step", k);
        j.field("interior_bytes", s.interior_bytes);
        j.field("minmax_bytes", s.minmax_bytes);
        j.field("cap_bytes", s.cap_bytes);
        j.key("nodes_per_depth").array(s.nodes_per_depth);
        j.key("scalar_leaves_per_depth").array(s.scalar_leaves_per_depth);
        const RealValues& v = values[k];
        j.key("value_range");
        if (v.root_range) j.array(*v.root_range);
        else j.null();
        j.field("voxels", v.voxels).field("non_finite_voxels", v.non_finite);
        j.key("min");
        if (v.voxels) j.value(v.range[0]);
        else j.null();
        j.key("max");
        if (v.voxels) j.value(v.range[1]);
        else j.null();
        j.key("percentiles").begin_object();
        for (size_t i = 0; i < v.percentiles.size(); ++i) {
            j.key("p" + cli::number(ValueStats::percentile_levels[i]));
            if (v.voxels) j.value(v.percentiles[i]);
            else j.null();
        }
        j.end_object();
        j.key("histogram").begin_object().key("edges").array(v.edges);
        j.key("counts").array(v.counts).end_object();
        j.end_object();
    }
    j.end_array();
    if (ex) {
        j.key("extract").begin_object();
        j.field("path", ex->path);
        j.field("step", ex->step);
        j.field("endian", ex->big_endian ? "big" : "little");
        j.field("bytes", ex->bytes);
        j.end_object();
    }
    j.end_object();
    os << "\n";
}

}  // namespace

int main(int argc, char** argv) {
    return octiso::cli::run_main("octiso-info", argc, argv, [](std::vector<std::string>& argv_rest) {
        if (const auto status = cli::answer_help(argv_rest, kUsage)) return *status;
        const cli::Flags args(argv_rest, {"--extract-raw", "--extract", "--step", "--endian", "--bins"}, {"--json", "--verify"});
        const bool json = args.flag("--json");
        const bool verify = args.flag("--verify");
        const std::optional<std::string> extract_raw_path = args.value("--extract-raw");
        const std::optional<std::string> extract_any_path = args.value("--extract");
        if (extract_raw_path && extract_any_path) throw Error("--extract", "give --extract or --extract-raw, not both");
        const std::optional<std::string> extract_path = extract_raw_path ? extract_raw_path : extract_any_path;
        const char* extract_flag = extract_raw_path ? "--extract-raw" : "--extract";
        const std::optional<std::string> step_text = args.value("--step");
        const std::optional<std::string> endian_text = args.value("--endian");
        const std::optional<std::string> bins_text = args.value("--bins");
        const std::vector<std::string> files = args.positional();
        if (files.size() != 1)
            throw Error("", std::string(files.empty() ? "no input file" : "more than one input file") + " (octiso-info --help lists every flag)");
        if ((step_text || endian_text) && !extract_path)
            throw Error(step_text ? "--step" : "--endian", "only makes sense with --extract or --extract-raw");
        const int bins = bins_text ? int(cli::parse_int(*bins_text, "--bins", 1, 4096)) : 16;
        if (extract_path) refuse_output_onto_input(*extract_path, files, extract_flag);   // issue 18
        if (extract_any_path && !is_volume_file_format(*extract_any_path))
            throw Error("--extract", "'" + *extract_any_path + "': expected a .vti, .nrrd, .nii, .nii.gz or .raw name");
        if (extract_path) cli::check_output_file(*extract_path, extract_flag);
        Extract ex;
        if (extract_path) {
            ex.path = *extract_path;
            ex.with_header = extract_any_path && !(extract_any_path->size() >= 4 && extract_any_path->substr(extract_any_path->size() - 4) == ".raw");
            if (ex.with_header && endian_text) throw Error("--endian", "applies to raw output only (.vti, .nrrd and .nii declare their byte order)");
            if (step_text) ex.step = uint32_t(cli::parse_int(*step_text, "--step", 0, UINT32_MAX));
            if (endian_text) {
                if (*endian_text != "little" && *endian_text != "big")
                    throw Error("--endian", "expected little or big, found '" + *endian_text + "'");
                ex.big_endian = *endian_text == "big";
            }
        }

        const auto shared_file = std::make_shared<const OctFile>(OctFile::open(files[0], Verify::Full));
        const OctFile& file = *shared_file;
        if (extract_path && ex.step >= file.info().step_count)
            throw Error("--step", "step " + std::to_string(ex.step) + " does not exist in " + files[0] +
                                      " (expected 0 .. " + std::to_string(file.info().step_count - 1) + ")");
        std::vector<StepSizes> steps;
        steps.reserve(file.info().step_count);
        std::vector<RealValues> values;
        for (uint32_t k = 0; k < file.info().step_count; ++k) {
            steps.push_back(file.step_sizes(k));
            const AnyOctree step = AnyOctree::step(shared_file, k);
            values.push_back(real_values({step.info().value_range, value_stats(step, bins)}, file.info().value_scale));
        }
        if (verify) {   // issue 18: every min/max and scalar recomputed from the leaves; a lie exits 2
            const VerifyStats v = verify_octree(file);
            (json ? std::cerr : std::cout) << files[0] << ": verified " << v.nodes << " interior nodes, " << v.ranges
                                           << " child ranges: every one agrees with the leaves\n";
        }
        if (extract_path) extract_raw(shared_file, ex);

        const Extract* exp = extract_path ? &ex : nullptr;
        if (json) {
            human_report(std::cerr, file, steps, values, exp);
            json_report(std::cout, file, steps, values, exp);
        } else {
            human_report(std::cout, file, steps, values, exp);
        }
        return 0;
    });
}
