// octiso-convert: a raw array, a VTK-readable file, a synthetic volume or a time series of any
// of them -> one .oct file (CONVENTIONS 3). This file only parses the flags into a
// ConvertSource and BuildOptions and prints the ConvertReport (text on stderr, or exactly one
// JSON object on stdout); the pipeline itself is the library's convert() (octiso/convert.h).
#include <chrono>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

#include <unistd.h>

#include <fmt/format.h>

#include "cli/common/cli.h"
#include "cli/common/flags.h"
#include "cli/common/json.h"
#include "cli/common/output_path.h"
#include "cli/common/progress.h"
#include "cli/common/report.h"
#include "octiso/any_octree.h"
#include "octiso/build.h"
#include "octiso/convert.h"
#include "octiso/error.h"
#include "octiso/reader.h"
#include "octree/sparse_synthetic.h"

namespace {

using namespace octiso;

constexpr const char* kUsage =
    "usage: octiso-convert INPUT -o OUT.oct [options]\n"
    "       octiso-convert --synthetic NAME:N|NAME:NX,NY,NZ [--type T] -o OUT.oct [options]\n"
    "       octiso-convert --synthetic plume-series:N,STEPS -o SERIES.oct [options]\n"
    "       octiso-convert --synthetic sparse-spheres:N -o OUT.oct [--json]   (N^3 virtual, e.g. 16384)\n"
    "       octiso-convert --steps A:B 'pattern_%03d.raw' -o SERIES.oct [options]\n"
    "       octiso-convert STEP0 STEP1 ... -o SERIES.oct [options]   (a time series, one step per INPUT)\n"
    "\n"
    "A volume (or a time series of them) into one lossless .oct file. The report prints the range of\n"
    "values stored (a wrong --type or --endian shows there at once) and the size against the input.\n"
    "\n"
    "INPUT: .nii .nii.gz .vti .vtk .mhd .mha .nrrd .nhdr (placement from the header), or raw\n"
    "  -o, --output OUT.oct      the file to write (temporary + rename: never a partial file)\n"
    "  --dims NX,NY,NZ           raw input: grid size, x fastest (required for raw)\n"
    "  --type T                  raw input: u8 i8 u16 i16 u32 i32 f32 f64 (required for raw);\n"
    "                            --synthetic: the stored type (default: the dataset's own)\n"
    "  --endian little|big       raw input: byte order (default little)\n"
    "  --offset BYTES            raw input: header bytes to skip (default 0)\n"
    "  --spacing SX,SY,SZ        world size of a voxel step (default 1,1,1 or the header's)\n"
    "  --origin OX,OY,OZ         world position of voxel 0,0,0 (default 0,0,0 or the header's)\n"
    "  --array NAME              the point data array of a VTK file with several (default: its active\n"
    "                            scalars, else its first array)\n"
    "  --iso-range LO,HI         clamp what cannot reach (LO, HI): smaller, exact for isovalues inside\n"
    "                            (LO, HI, --tolerance and --nan-as in real values: a NIfTI's scl_slope/\n"
    "                            scl_inter applied)\n"
    "                            (default: none, every isovalue exact)\n"
    "  --tolerance EPS           merge siblings within EPS: lossy, error <= EPS (default 0, lossless)\n"
    "  --nan-as V                replace NaN and +-inf by V (default: refuse non-finite input)\n"
    "  --steps A:B               a series from a printf pattern, steps A..B inclusive\n"
    "  --synthetic NAME:N        sphere marschner-lobb sponge noise plume mixing plume-series sparse-spheres\n"
    "  --memory BYTES            memory budget (suffix K, M or G; default a quarter of physical memory):\n"
    "                            raw and NIfTI input is converted out of core, slab by slab, within it;\n"
    "                            the file is the same as the in-memory one\n"
    "  --in-memory               the whole-array path whatever the input's size (benchmarks)\n"
    "  --threads N               worker threads, 0 = all cores (default 0)\n"
    "  --json                    one JSON object on stdout; the text report goes to stderr\n"
    "  --version, -h/--help\n";

std::string dims_text(Dims d) {
    return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

std::string mib(uint64_t bytes) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(2) << double(bytes) / (1024.0 * 1024.0) << " MiB";
    return s.str();
}

std::array<double, 3> positive_vec3(const std::string& text, const std::string& flag) {
    const std::array<double, 3> v = cli::parse_vec3(text, flag);
    for (double c : v)
        if (!(c > 0)) throw Error(flag, "expected three positive numbers, found '" + text + "'");
    return v;
}

/// --memory BYTES: a positive integer with an optional K, M or G suffix (powers of 1024).
uint64_t parse_memory(const std::string& text) {
    uint64_t scale = 1;
    std::string digits = text;
    if (!digits.empty()) {
        const char last = char(std::toupper(static_cast<unsigned char>(digits.back())));
        if (last == 'K' || last == 'M' || last == 'G') {
            scale = last == 'K' ? (1ull << 10) : last == 'M' ? (1ull << 20) : (1ull << 30);
            digits.pop_back();
        }
    }
    const auto n = uint64_t(cli::parse_int(digits, "--memory", 1, (1LL << 62) / (1LL << 30)));
    return n * scale;
}

/// The flags that say where the steps come from, in the order they are checked (so that of
/// several bad flags, the same one is named first every time).
ConvertSource parse_source(const cli::Flags& args) {
    const auto synthetic = args.value("--synthetic");
    const auto steps = args.value("--steps");
    const auto dims = args.value("--dims");
    const auto type = args.value("--type");
    const auto endian = args.value("--endian");
    const auto offset = args.value("--offset");
    RawOptions raw;
    if (const auto s = args.value("--spacing")) raw.spacing = positive_vec3(*s, "--spacing");
    if (const auto o = args.value("--origin")) raw.origin = cli::parse_vec3(*o, "--origin");
    if (const auto a = args.value("--array")) {
        if (a->empty()) throw Error("--array", "expected the name of a point data array");
        raw.array = *a;
    }
    const std::vector<std::string> positional = args.positional();

    std::optional<ScalarType> t;
    if (type) {
        t = parse_scalar_type(*type);
        if (!t) throw Error("--type", "expected u8, i8, u16, i16, u32, i32, f32 or f64, found '" + *type + "'");
    }

    if (synthetic) {
        if (!positional.empty()) throw Error(positional[0], "give either INPUT or --synthetic, not both");
        if (steps) throw Error("--steps", "does not combine with --synthetic (use plume-series:N,STEPS)");
        for (const auto& [flag, given] : {std::pair{"--dims", bool(dims)}, {"--endian", bool(endian)}, {"--offset", bool(offset)}})
            if (given) throw Error(flag, "applies only to raw input, not to --synthetic");
        if (raw.array) throw Error("--array", "picks an array of a VTK file, not of --synthetic");
        return ConvertSource::synthetic(*synthetic, t, raw);
    }

    if (positional.empty()) throw Error("INPUT", "missing input file or --synthetic (see --help)");
    if (positional.size() > 1 && steps)
        throw Error(positional[1], "unexpected argument (--steps takes one pattern; a list of INPUTs needs no --steps)");
    std::array<long long, 2> range{0, 0};
    if (steps) {
        range = cli::parse_steps(*steps, "--steps");
        cli::format_step(positional[0], range[0], "--steps");   // the pattern before the other flags
    }
    if (dims) raw.dims = parse_dims(*dims, "--dims");
    raw.type = t;
    if (endian) {
        if (*endian == "little") raw.endian = Endian::little;
        else if (*endian == "big") raw.endian = Endian::big;
        else throw Error("--endian", "expected little or big, found '" + *endian + "'");
    }
    if (offset) raw.offset = uint64_t(cli::parse_int(*offset, "--offset", 0, (1LL << 62)));
    if (steps) return ConvertSource::pattern(positional[0], range[0], range[1], raw);
    return ConvertSource::files(positional, raw);
}

/// The range of values the file stores: the union of its steps' root min/max (what octiso-render
/// accepts as isovalues), read back from the finished file so that it reports what was written.
/// In real values (CONVENTIONS 2b): the stored range through the file's value scale.
std::optional<std::array<double, 2>> stored_range(const std::string& path) {
    const auto file = std::make_shared<const OctFile>(OctFile::open(path, Verify::IndicesOnly));
    std::optional<std::array<double, 2>> r;
    for (uint32_t k = 0; k < file->info().step_count; ++k)
        if (const auto v = AnyOctree::step(file, k).info().value_range)
            r = r ? std::array<double, 2>{std::min((*r)[0], (*v)[0]), std::max((*r)[1], (*v)[1])} : *v;
    if (r) r = file->info().value_scale.real_range(*r);
    return r;
}

/// "x,z" for the axes of a flipped-axes mask.
std::string axes_text(uint8_t mask) {
    std::string s;
    for (int a = 0; a < 3; ++a)
        if (mask & (1u << a)) s += std::string(s.empty() ? "" : ",") + "xyz"[a];
    return s;
}

void write_json(std::ostream& os, const ConvertReport& r, const std::optional<std::array<double, 2>>& range) {
    const Dims d = r.dims;
    const StepSizes& tot = r.total;
    cli::JsonWriter j(os);
    j.begin_object();
    j.field("input", r.input).field("format", volume_format_name(r.format)).field("output", r.output);
    j.field("type", scalar_type_name(r.type));
    j.key("dims").array(std::array<uint64_t, 3>{d.x, d.y, d.z});
    j.key("spacing").array(r.placement.spacing).key("origin").array(r.placement.origin);
    j.field("steps", r.steps).field("dmax", r.dmax);
    j.field("input_bytes", r.input_bytes).field("file_bytes", r.file_bytes);
    j.field("ratio", r.ratio());   // file / raw input
    j.field("larger_than_input", r.file_bytes > r.input_bytes);
    j.key("value_range");
    if (range) j.array(*range);
    else j.null();
    j.key("split").begin_object();
    j.field("interior_bytes", tot.interior_bytes).field("minmax_bytes", tot.minmax_bytes).field("cap_bytes", tot.cap_bytes);
    uint64_t interior_nodes = 0;
    for (size_t k = 0; k + 1 < tot.nodes_per_depth.size(); ++k) interior_nodes += tot.nodes_per_depth[k];
    j.field("interior_node_count", interior_nodes)
        .field("cap_count", tot.nodes_per_depth.empty() ? 0 : tot.nodes_per_depth.back());
    j.end_object();
    j.key("depths").begin_array();
    for (int k = 0; k < int(tot.nodes_per_depth.size()); ++k) {
        const bool caps = k == r.dmax - 1;
        j.begin_object().field("depth", k).field("nodes", caps ? 0 : tot.nodes_per_depth[size_t(k)]);
        j.field("caps", caps ? tot.nodes_per_depth[size_t(k)] : 0);
        j.field("scalar_leaves", size_t(k) < tot.scalar_leaves_per_depth.size() ? tot.scalar_leaves_per_depth[size_t(k)] : 0)
            .end_object();
    }
    j.end_array();
    if (r.iso_range) j.key("iso_range").array(*r.iso_range);
    else j.key("iso_range").null();
    j.field("tolerance", r.tolerance);
    j.key("value_scale").begin_object().field("slope", r.value_scale.slope).field("inter", r.value_scale.inter).end_object();
    j.key("flipped_axes").begin_array();
    for (int a = 0; a < 3; ++a)
        if (r.flipped_axes & (1u << a)) j.value(std::string(1, "xyz"[a]));
    j.end_array();
    j.key("warnings").array(r.warnings);
    j.field("build_seconds", r.build_seconds).field("total_seconds", r.total_seconds);
    if (!r.streamed && !r.built_directly) {   // issue 12: which parts of the conversion are serial
        const BuildPhases& p = r.build_phases;
        j.key("phases").begin_object().field("read", r.read_seconds).field("prepare", p.prepare).field("pieces", p.pieces).field("pieces_busy", p.pieces_busy)
            .field("top", p.top).field("concatenate", p.concatenate).field("release", p.release)
            .field("write", r.write_seconds).end_object();
    } else if (r.streamed) {   // out of core: reading and building interleave slab by slab
        j.key("phases").begin_object().field("slabs", r.slabs_seconds).field("top", r.top_seconds)
            .field("sections", r.sections_seconds).end_object();
    }
    j.field("mvoxels_per_second", r.mvoxels_per_second());
    j.field("peak_rss_bytes", r.peak_rss_bytes).field("threads", r.threads);
    j.field("streamed", r.streamed).field("memory_budget", r.memory_budget).field("piece_side", r.piece_side);
    j.field("bytes_read", r.bytes_read).field("spilled_bytes", r.spilled_bytes);
    j.end_object();
    os << "\n";
}

void write_human(std::ostream& os, const ConvertReport& r, const std::optional<std::array<double, 2>>& range) {
    const StepSizes& tot = r.total;
    for (const std::string& w : r.warnings) os << "octiso-convert: warning: " << r.input << ": " << w << "\n";
    os << "octiso-convert: " << r.input << " (" << volume_format_name(r.format) << ", " << scalar_type_name(r.type) << " "
       << dims_text(r.dims) << (r.steps > 1 ? ", " + std::to_string(r.steps) + " steps" : "") << ", "
       << mib(r.input_bytes) << ") -> " << r.output << "\n";
    os << "  values " << (range ? cli::number((*range)[0]) + " .. " + cli::number((*range)[1]) : std::string("none (no cell)"))
       << (r.steps > 1 ? " over all steps" : "") << " (the isovalues octiso-render accepts)\n";
    if (!r.value_scale.is_identity())
        os << "  real value = stored * " << cli::number(r.value_scale.slope) << " + " << cli::number(r.value_scale.inter)
           << " (NIfTI scl_slope/scl_inter; the tree keeps the stored " << scalar_type_name(r.type)
           << ", values and isovalues are real)\n";
    if (r.flipped_axes)
        os << "  axes " << axes_text(r.flipped_axes) << " reversed (negative in the NIfTI affine): spacing "
           << cli::number(r.placement.spacing[0]) << "," << cli::number(r.placement.spacing[1]) << ","
           << cli::number(r.placement.spacing[2]) << ", origin " << cli::number(r.placement.origin[0]) << ","
           << cli::number(r.placement.origin[1]) << "," << cli::number(r.placement.origin[2])
           << "; octiso-info --extract gives the file's order back\n";
    os << std::fixed << std::setprecision(3);
    os << "  file " << mib(r.file_bytes) << ", ratio " << r.ratio() << " (file / raw); interior " << mib(tot.interior_bytes)
       << " (min/max " << mib(tot.minmax_bytes) << "), caps " << mib(tot.cap_bytes) << "\n";
    os << "  depth       nodes  scalar leaves\n";
    for (size_t k = 0; k < tot.nodes_per_depth.size(); ++k)
        os << "  " << std::setw(5) << k << std::setw(12) << tot.nodes_per_depth[k] << std::setw(15)
           << (k < tot.scalar_leaves_per_depth.size() ? tot.scalar_leaves_per_depth[k] : 0)
           << (int(k) == r.dmax - 1 ? "  (caps)" : "") << "\n";
    os << "  build " << r.build_seconds << " s (" << r.mvoxels_per_second() << " Mvoxel/s, " << r.threads
       << " threads), total " << r.total_seconds << " s, peak RSS " << mib(r.peak_rss_bytes) << "\n";
    if (r.file_bytes > r.input_bytes)
        os << "  note: the octree is larger than its input (" << mib(r.file_bytes) << " > " << mib(r.input_bytes)
           << "): too little of the data is uniform to merge. --iso-range LO,HI (exact for every isovalue inside it)"
              " or --tolerance EPS (lossy, error <= EPS) makes it smaller\n";
    if (r.streamed)
        os << "  out of core: --memory " << mib(r.memory_budget) << ", pieces of " << r.piece_side << "^3, read "
           << mib(r.bytes_read) << ", spilled " << mib(r.spilled_bytes) << "\n";
}

/// --synthetic sparse-spheres:N (f32, N^3, N >= 64): built directly as an octree, no dense array
/// (src/octree/sparse_synthetic.h), so N may be 16384 or more. Only -o and --json apply.
int convert_sparse_spheres(const cli::Flags& args, uint32_t n) {
    const bool json = args.flag("--json");
    const auto out = args.value("--output");
    for (const std::string& flag : args.given())
        if (flag != "--output" && flag != "--synthetic")
            throw Error(flag, "does not apply to --synthetic sparse-spheres (only -o and --json do)");
    if (args.flag("--in-memory")) throw Error("--in-memory", "does not apply to --synthetic sparse-spheres (only -o and --json do)");
    if (!args.positional().empty()) throw Error(args.positional()[0], "give either INPUT or --synthetic, not both");
    if (!out) throw Error("-o", "missing output file (-o OUT.oct)");
    cli::check_output_file(*out, "-o");   // before the work, naming the user's path
    const ConvertReport r = octiso::convert(ConvertSource::sparse_spheres(n), *out, BuildOptions{});
    std::cerr << "octiso-convert: " << r.input << " (f32 " << dims_text(r.dims) << ", built directly as an octree) -> "
              << r.output << ", " << mib(r.file_bytes) << ", " << r.total_seconds << " s\n";
    if (json) {
        cli::JsonWriter j(std::cout);
        j.begin_object().field("input", r.input).field("format", "synthetic");
        j.field("output", r.output).field("type", "f32");
        j.key("dims").array(std::array<uint64_t, 3>{n, n, n});
        j.field("steps", 1).field("dmax", r.dmax).field("file_bytes", r.file_bytes);
        j.field("total_seconds", r.total_seconds).end_object();
        std::cout << "\n";
    }
    return 0;
}

int run(std::vector<std::string>& argv) {
    if (const auto status = cli::answer_help(argv, kUsage)) return *status;
    const cli::Flags args(argv,
                          {"-o,--output", "--synthetic", "--steps", "--dims", "--type", "--endian", "--offset", "--spacing",
                           "--origin", "--array", "--iso-range", "--tolerance", "--nan-as", "--threads", "--memory"},
                          {"--json", "--in-memory"});
    if (const auto spec = args.value("--synthetic"))   // sparse-spheres never makes a dense array
        if (const uint32_t n = parse_sparse_spheres(*spec)) return convert_sparse_spheres(args, n);
    const bool json = args.flag("--json");
    const auto out = args.value("--output");
    BuildOptions opt;
    if (const auto r = args.value("--iso-range")) opt.iso_range = cli::parse_range(*r, "--iso-range");
    if (const auto t = args.value("--tolerance")) {
        opt.tolerance = cli::parse_double(*t, "--tolerance");
        if (opt.tolerance < 0) throw Error("--tolerance", "must be >= 0, found '" + *t + "'");
    }
    if (const auto v = args.value("--nan-as")) opt.nan_as = cli::parse_double(*v, "--nan-as");
    if (const auto t = args.value("--threads")) opt.threads = int(cli::parse_int(*t, "--threads", 0, 4096));   // 0: all cores
    MemoryOptions memory;
    if (const auto m = args.value("--memory")) memory.budget = parse_memory(*m);
    memory.force_in_memory = args.flag("--in-memory");
    const ConvertSource src = parse_source(args);
    if (!out) throw Error("-o", "missing output file (-o OUT.oct)");
    cli::check_output_file(*out, "-o");   // before the work, naming the user's path

    // Progress (issue 17): slabs read out of core, steps built in memory; only on a terminal,
    // not with --json, and only once the conversion has run for a second.
    cli::ProgressLine progress = cli::ProgressLine::on_stderr(!json);
    const auto t0 = std::chrono::steady_clock::now();
    memory.on_progress = [&](uint64_t done, uint64_t all, uint64_t voxels) {
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        progress.update(double(done), double(all),
                        fmt::format("{:.0f} of {:.0f} MiB, {:.1f} Mvoxel/s", double(done) / 1048576.0, double(all) / 1048576.0,
                                    s > 0 ? double(voxels) / s / 1e6 : 0.0));
    };
    ConvertReport report;
    try {
        report = octiso::convert(src, *out, opt, memory);
    } catch (...) {
        progress.finish();   // the error line starts on a line of its own
        throw;
    }
    progress.finish();
    const auto range = stored_range(report.output);
    write_human(std::cerr, report, range);
    if (json) write_json(std::cout, report, range);
    return 0;
}

}  // namespace

int main(int argc, char** argv) { return octiso::cli::run_main("octiso-convert", argc, argv, run); }
