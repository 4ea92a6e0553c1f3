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

#include "cli/common/cli.h"
#include "cli/common/json.h"
#include "octiso/build.h"
#include "octiso/convert.h"
#include "octiso/error.h"
#include "octiso/reader.h"
#include "octree/sparse_synthetic.h"

namespace {

using namespace octiso;

constexpr const char* kUsage =
    "usage: octiso-convert INPUT -o OUT.oct [--dims NX,NY,NZ --type T [--endian little|big] [--offset BYTES]]\n"
    "                      [--spacing SX,SY,SZ] [--origin OX,OY,OZ] [--iso-range LO,HI] [--tolerance EPS]\n"
    "                      [--nan-as V] [--memory BYTES | --in-memory] [--threads N] [--json]\n"
    "       octiso-convert --synthetic NAME:N|NAME:NX,NY,NZ [--type T] -o OUT.oct [options]\n"
    "       octiso-convert --synthetic plume-series:N,STEPS -o SERIES.oct [options]\n"
    "       octiso-convert --synthetic sparse-spheres:N -o OUT.oct [--json]   (N^3 virtual, e.g. 16384)\n"
    "       octiso-convert --steps A:B 'pattern_%03d.raw' -o SERIES.oct [options]\n"
    "       octiso-convert STEP0 STEP1 ... -o SERIES.oct [options]   (a time series, one step per INPUT)\n"
    "INPUT: .nii .nii.gz .vti .vtk .mhd .mha .nrrd .nhdr, or raw (needs --dims and --type)\n"
    "NAME: sphere marschner-lobb sponge noise plume mixing plume-series\n"
    "T: u8 i8 u16 i16 u32 i32 f32 f64\n"
    "--memory BYTES (suffix K, M or G; default a quarter of physical memory): raw input is converted\n"
    "  out of core, slab by slab, within this budget; the file is the same as the in-memory one\n"
    "--in-memory: the whole-array path whatever the input's size (benchmarks)";

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

/// Progress of an out-of-core conversion on stderr (issue 13): only when stderr is a terminal,
/// not with --json, and only once the conversion has run for a second; redrawn at most 4 times a
/// second on one line, which finish() ends. Bytes are the input's voxel bytes.
class ProgressLine {
public:
    explicit ProgressLine(bool wanted) : wanted_(wanted && ::isatty(STDERR_FILENO)), t0_(Clock::now()) {}
    void update(uint64_t done, uint64_t all, uint64_t voxels) {
        if (!wanted_) return;
        const auto now = Clock::now();
        const double t = std::chrono::duration<double>(now - t0_).count();
        if (t < 1.0 || (shown_ && std::chrono::duration<double>(now - last_).count() < 0.25)) return;
        last_ = now;
        shown_ = true;
        const double rate = double(done) / t;
        const double eta = rate > 0 ? double(all - std::min(done, all)) / rate : 0;
        std::fprintf(stderr, "\r  read %.0f of %.0f MiB, %.1f Mvoxel/s, ETA %.0f s   ", double(done) / 1048576.0,
                     double(all) / 1048576.0, double(voxels) / t / 1e6, eta);
        std::fflush(stderr);
    }
    void finish() {
        if (shown_) std::fputc('\n', stderr);
        shown_ = false;
    }

private:
    using Clock = std::chrono::steady_clock;
    bool wanted_;
    bool shown_ = false;
    Clock::time_point t0_, last_;
};

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
ConvertSource parse_source(cli::Args& args) {
    const auto synthetic = args.value("--synthetic");
    const auto steps = args.value("--steps");
    const auto dims = args.value("--dims");
    const auto type = args.value("--type");
    const auto endian = args.value("--endian");
    const auto offset = args.value("--offset");
    RawOptions raw;
    if (const auto s = args.value("--spacing")) raw.spacing = positive_vec3(*s, "--spacing");
    if (const auto o = args.value("--origin")) raw.origin = cli::parse_vec3(*o, "--origin");
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

void write_json(std::ostream& os, const ConvertReport& r) {
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
    j.field("ratio", r.ratio());
    j.key("split").begin_object();
    j.field("interior_bytes", tot.interior_bytes).field("minmax_bytes", tot.minmax_bytes).field("cap_bytes", tot.cap_bytes);
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
    j.field("build_seconds", r.build_seconds).field("total_seconds", r.total_seconds);
    j.field("mvoxels_per_second", r.mvoxels_per_second());
    j.field("peak_rss_bytes", r.peak_rss_bytes).field("threads", r.threads);
    j.field("streamed", r.streamed).field("memory_budget", r.memory_budget).field("piece_side", r.piece_side);
    j.field("bytes_read", r.bytes_read).field("spilled_bytes", r.spilled_bytes);
    j.end_object();
    os << "\n";
}

void write_human(std::ostream& os, const ConvertReport& r) {
    const StepSizes& tot = r.total;
    os << "octiso-convert: " << r.input << " (" << volume_format_name(r.format) << ", " << scalar_type_name(r.type) << " "
       << dims_text(r.dims) << (r.steps > 1 ? ", " + std::to_string(r.steps) + " steps" : "") << ", "
       << mib(r.input_bytes) << ") -> " << r.output << "\n";
    os << std::fixed << std::setprecision(3);
    os << "  file " << mib(r.file_bytes) << ", ratio " << r.ratio() << "; interior " << mib(tot.interior_bytes)
       << " (min/max " << mib(tot.minmax_bytes) << "), caps " << mib(tot.cap_bytes) << "\n";
    os << "  depth       nodes  scalar leaves\n";
    for (size_t k = 0; k < tot.nodes_per_depth.size(); ++k)
        os << "  " << std::setw(5) << k << std::setw(12) << tot.nodes_per_depth[k] << std::setw(15)
           << (k < tot.scalar_leaves_per_depth.size() ? tot.scalar_leaves_per_depth[k] : 0)
           << (int(k) == r.dmax - 1 ? "  (caps)" : "") << "\n";
    os << "  build " << r.build_seconds << " s (" << r.mvoxels_per_second() << " Mvoxel/s, " << r.threads
       << " threads), total " << r.total_seconds << " s, peak RSS " << mib(r.peak_rss_bytes) << "\n";
    if (r.streamed)
        os << "  out of core: --memory " << mib(r.memory_budget) << ", pieces of " << r.piece_side << "^3, read "
           << mib(r.bytes_read) << ", spilled " << mib(r.spilled_bytes) << "\n";
}

/// --synthetic sparse-spheres:N (f32, N^3, N >= 64): built directly as an octree, no dense array
/// (src/octree/sparse_synthetic.h), so N may be 16384 or more. Only -o and --json apply.
int convert_sparse_spheres(cli::Args& args, uint32_t n) {
    const bool json = args.flag("--json");
    const auto out = args.value("--output", "-o");
    args.value("--synthetic");
    args.finish();
    if (!out) throw Error("-o", "missing output file (-o OUT.oct)");
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
    cli::Args args(argv);
    if (args.flag("--help") || args.flag("-h")) {
        std::cerr << kUsage << "\n";
        return 0;
    }
    if (argv.empty()) {
        std::cerr << kUsage << "\n";
        return 2;
    }
    for (size_t i = 0; i + 1 < argv.size(); ++i)   // sparse-spheres never makes a dense array
        if (argv[i] == "--synthetic")
            if (const uint32_t n = parse_sparse_spheres(argv[i + 1])) return convert_sparse_spheres(args, n);
    const bool json = args.flag("--json");
    const auto out = args.value("--output", "-o");
    BuildOptions opt;
    if (const auto r = args.value("--iso-range")) opt.iso_range = cli::parse_range(*r, "--iso-range");
    if (const auto t = args.value("--tolerance")) {
        opt.tolerance = cli::parse_double(*t, "--tolerance");
        if (opt.tolerance < 0) throw Error("--tolerance", "must be >= 0, found '" + *t + "'");
    }
    if (const auto v = args.value("--nan-as")) opt.nan_as = cli::parse_double(*v, "--nan-as");
    if (const auto t = args.value("--threads")) opt.threads = int(cli::parse_int(*t, "--threads", 1, 4096));
    MemoryOptions memory;
    if (const auto m = args.value("--memory")) memory.budget = parse_memory(*m);
    memory.force_in_memory = args.flag("--in-memory");
    const ConvertSource src = parse_source(args);
    args.finish();
    if (!out) throw Error("-o", "missing output file (-o OUT.oct)");

    ProgressLine progress(!json);
    memory.on_progress = [&](uint64_t done, uint64_t all, uint64_t voxels) { progress.update(done, all, voxels); };
    ConvertReport report;
    try {
        report = octiso::convert(src, *out, opt, memory);
    } catch (...) {
        progress.finish();   // the error line starts on a line of its own
        throw;
    }
    progress.finish();
    write_human(std::cerr, report);
    if (json) write_json(std::cout, report);
    return 0;
}

}  // namespace

int main(int argc, char** argv) { return octiso::cli::run_main("octiso-convert", argc, argv, run); }
