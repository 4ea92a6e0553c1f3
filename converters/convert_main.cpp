// octiso-convert: a raw array, a VTK-readable file, a synthetic volume or a time series of any
// of them -> one .oct file (CONVENTIONS 3). Every step is opened and checked against the first
// before anything is written; steps are then built and streamed one at a time, so memory stays
// near one input plus one octree. Report on stderr, or exactly one JSON object on stdout.
#include <chrono>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <sys/stat.h>

#include <tbb/global_control.h>

#include "cli/common/cli.h"
#include "cli/common/json.h"
#include "octiso/build.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/output_guard.h"
#include "octiso/reader.h"
#include "octiso/synthetic.h"
#include "octree/sparse_synthetic.h"
#include "util/process_memory.h"

namespace {

using namespace octiso;
using Clock = std::chrono::steady_clock;

constexpr const char* kUsage =
    "usage: octiso-convert INPUT -o OUT.oct [--dims NX,NY,NZ --type T [--endian little|big] [--offset BYTES]]\n"
    "                      [--spacing SX,SY,SZ] [--origin OX,OY,OZ] [--iso-range LO,HI] [--tolerance EPS]\n"
    "                      [--nan-as V] [--threads N] [--json]\n"
    "       octiso-convert --synthetic NAME:N|NAME:NX,NY,NZ [--type T] -o OUT.oct [options]\n"
    "       octiso-convert --synthetic plume-series:N,STEPS -o SERIES.oct [options]\n"
    "       octiso-convert --synthetic sparse-spheres:N -o OUT.oct [--json]   (N^3 virtual, e.g. 16384)\n"
    "       octiso-convert --steps A:B 'pattern_%03d.raw' -o SERIES.oct [options]\n"
    "       octiso-convert STEP0 STEP1 ... -o SERIES.oct [options]   (a time series, one step per INPUT)\n"
    "INPUT: .nii .nii.gz .vti .vtk .mhd .mha .nrrd .nhdr, or raw (needs --dims and --type)\n"
    "NAME: sphere marschner-lobb sponge noise plume mixing plume-series\n"
    "T: u8 i8 u16 i16 u32 i32 f32 f64";

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string dims_text(Dims d) {
    return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

std::string mib(uint64_t bytes) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(2) << double(bytes) / (1024.0 * 1024.0) << " MiB";
    return s.str();
}

/// Where the steps come from: one input, a list of inputs (one step each), a synthetic spec, or
/// a printf pattern over A..B.
struct Source {
    std::string input;                  // single file, the pattern with --steps, or the first of a list
    std::vector<std::string> list;      // several INPUTs: step i is list[i]
    std::optional<SyntheticSpec> synthetic;
    std::optional<ScalarType> synthetic_type;
    std::array<long long, 2> steps{0, 0};
    bool series_pattern = false;
    RawOptions raw;

    uint32_t count() const {
        if (synthetic) return synthetic->steps;
        if (!list.empty()) return uint32_t(list.size());
        return uint32_t(steps[1] - steps[0] + 1);
    }
    std::string step_path(uint32_t i) const {
        if (!list.empty()) return list[i];
        return series_pattern ? cli::format_step(input, steps[0] + i, "--steps") : input;
    }
    LoadedVolume load(uint32_t i) const {
        if (synthetic) {
            LoadedVolume v = synthetic_step(synthetic->name, synthetic->dims, i, synthetic_type);
            Placement p = v.placement();
            if (raw.spacing) p.spacing = *raw.spacing;
            if (raw.origin) p.origin = *raw.origin;
            v.set_placement(p);
            return v;
        }
        return open_volume(step_path(i), raw);
    }
};

/// What the reports and the step checks need from step 0, without keeping its voxels alive.
struct StepMeta {
    std::string source;
    VolumeFormat format = VolumeFormat::raw;
    ScalarType type = ScalarType::u8;
    Dims dims;
    Placement placement;
    uint64_t bytes = 0;
    explicit StepMeta(const LoadedVolume& v)
        : source(v.source()), format(v.format()), type(v.type()), dims(v.dims()), placement(v.placement()), bytes(v.bytes()) {}
};

/// Totals over all steps, for the reports.
struct Totals {
    std::vector<uint64_t> nodes, leaves;
    uint64_t interior = 0, minmax = 0, caps = 0;
    double build_seconds = 0;
    void add(const BuildStats& s) {
        if (nodes.size() < s.nodes_per_depth.size()) nodes.resize(s.nodes_per_depth.size());
        if (leaves.size() < s.scalar_leaves_per_depth.size()) leaves.resize(s.scalar_leaves_per_depth.size());
        for (size_t d = 0; d < s.nodes_per_depth.size(); ++d) nodes[d] += s.nodes_per_depth[d];
        for (size_t d = 0; d < s.scalar_leaves_per_depth.size(); ++d) leaves[d] += s.scalar_leaves_per_depth[d];
        interior += s.interior_bytes;
        minmax += s.minmax_bytes;
        caps += s.cap_bytes;
    }
};

std::array<double, 3> positive_vec3(const std::string& text, const std::string& flag) {
    const std::array<double, 3> v = cli::parse_vec3(text, flag);
    for (double c : v)
        if (!(c > 0)) throw Error(flag, "expected three positive numbers, found '" + text + "'");
    return v;
}

Source parse_source(cli::Args& args, std::vector<std::string>& positional) {
    Source src;
    const auto synthetic = args.value("--synthetic");
    const auto steps = args.value("--steps");
    const auto dims = args.value("--dims");
    const auto type = args.value("--type");
    const auto endian = args.value("--endian");
    const auto offset = args.value("--offset");
    if (const auto s = args.value("--spacing")) src.raw.spacing = positive_vec3(*s, "--spacing");
    if (const auto o = args.value("--origin")) src.raw.origin = cli::parse_vec3(*o, "--origin");
    positional = args.positional();

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
        src.synthetic = parse_synthetic(*synthetic);
        src.synthetic_type = t;
        src.input = *synthetic;
        return src;
    }

    if (positional.empty()) throw Error("INPUT", "missing input file or --synthetic (see --help)");
    if (positional.size() > 1 && steps)
        throw Error(positional[1], "unexpected argument (--steps takes one pattern; a list of INPUTs needs no --steps)");
    src.input = positional[0];
    if (positional.size() > 1) src.list = positional;
    if (steps) {
        src.steps = cli::parse_steps(*steps, "--steps");
        src.series_pattern = true;
        cli::format_step(src.input, src.steps[0], "--steps");   // pattern check before any I/O
    }
    if (dims) src.raw.dims = parse_dims(*dims, "--dims");
    src.raw.type = t;
    if (endian) {
        if (*endian == "little") src.raw.endian = Endian::little;
        else if (*endian == "big") src.raw.endian = Endian::big;
        else throw Error("--endian", "expected little or big, found '" + *endian + "'");
    }
    if (offset) src.raw.offset = uint64_t(cli::parse_int(*offset, "--offset", 0, (1LL << 62)));
    return src;
}

/// Step i must match step 0 in everything the file header records once.
void check_same_grid(const StepMeta& first, const LoadedVolume& v) {
    if (v.dims() != first.dims)
        throw Error(v.source(), "dims differ from the first step (expected " + dims_text(first.dims) + ", found " +
                                    dims_text(v.dims()) + ")");
    if (v.type() != first.type)
        throw Error(v.source(), "scalar type differs from the first step (expected " +
                                    std::string(scalar_type_name(first.type)) + ", found " +
                                    std::string(scalar_type_name(v.type())) + ")");
    if (v.placement().spacing != first.placement.spacing || v.placement().origin != first.placement.origin)
        throw Error(v.source(), "spacing or origin differs from the first step (override both with --spacing/--origin)");
}

void write_json(std::ostream& os, const Source& src, const StepMeta& first, const std::string& out, uint32_t n_steps,
                uint64_t file_bytes, const Totals& tot, double total_seconds, uint64_t peak_rss, int threads,
                const BuildOptions& opt) {
    const Dims d = first.dims;
    const uint64_t input_bytes = first.bytes * n_steps;
    cli::JsonWriter j(os);
    j.begin_object();
    j.field("input", src.input).field("format", volume_format_name(first.format)).field("output", out);
    j.field("type", scalar_type_name(first.type));
    j.key("dims").array(std::array<uint64_t, 3>{d.x, d.y, d.z});
    j.key("spacing").array(first.placement.spacing).key("origin").array(first.placement.origin);
    j.field("steps", n_steps).field("dmax", dmax_for(d));
    j.field("input_bytes", input_bytes).field("file_bytes", file_bytes);
    j.field("ratio", input_bytes ? double(file_bytes) / double(input_bytes) : 0.0);
    j.key("split").begin_object();
    j.field("interior_bytes", tot.interior).field("minmax_bytes", tot.minmax).field("cap_bytes", tot.caps);
    j.end_object();
    j.key("depths").begin_array();
    const int dmax = dmax_for(d);
    for (int k = 0; k < int(tot.nodes.size()); ++k) {
        const bool caps = k == dmax - 1;
        j.begin_object().field("depth", k).field("nodes", caps ? 0 : tot.nodes[size_t(k)]);
        j.field("caps", caps ? tot.nodes[size_t(k)] : 0);
        j.field("scalar_leaves", size_t(k) < tot.leaves.size() ? tot.leaves[size_t(k)] : 0).end_object();
    }
    j.end_array();
    if (opt.iso_range) j.key("iso_range").array(*opt.iso_range);
    else j.key("iso_range").null();
    j.field("tolerance", opt.tolerance);
    j.field("build_seconds", tot.build_seconds).field("total_seconds", total_seconds);
    j.field("mvoxels_per_second", tot.build_seconds > 0 ? double(d.voxels()) * n_steps / tot.build_seconds / 1e6 : 0.0);
    j.field("peak_rss_bytes", peak_rss).field("threads", threads);
    j.end_object();
    os << "\n";
}

void write_human(std::ostream& os, const Source& src, const StepMeta& first, const std::string& out,
                 uint32_t n_steps, uint64_t file_bytes, const Totals& tot, double total_seconds, uint64_t peak_rss,
                 int threads) {
    const Dims d = first.dims;
    const uint64_t input_bytes = first.bytes * n_steps;
    os << "octiso-convert: " << src.input << " (" << volume_format_name(first.format) << ", "
       << scalar_type_name(first.type) << " " << dims_text(d) << (n_steps > 1 ? ", " + std::to_string(n_steps) + " steps" : "")
       << ", " << mib(input_bytes) << ") -> " << out << "\n";
    os << std::fixed << std::setprecision(3);
    os << "  file " << mib(file_bytes) << ", ratio " << (input_bytes ? double(file_bytes) / double(input_bytes) : 0.0)
       << "; interior " << mib(tot.interior) << " (min/max " << mib(tot.minmax) << "), caps " << mib(tot.caps) << "\n";
    os << "  depth       nodes  scalar leaves\n";
    for (size_t k = 0; k < tot.nodes.size(); ++k)
        os << "  " << std::setw(5) << k << std::setw(12) << tot.nodes[k] << std::setw(15)
           << (k < tot.leaves.size() ? tot.leaves[k] : 0) << (int(k) == dmax_for(d) - 1 ? "  (caps)" : "") << "\n";
    os << "  build " << tot.build_seconds << " s ("
       << (tot.build_seconds > 0 ? double(d.voxels()) * n_steps / tot.build_seconds / 1e6 : 0.0) << " Mvoxel/s, "
       << threads << " threads), total " << total_seconds << " s, peak RSS " << mib(peak_rss) << "\n";
}

/// --synthetic sparse-spheres:N (f32, N^3, N >= 64): built directly as an octree, no dense array
/// (src/octree/sparse_synthetic.h), so N may be 16384 or more. Only -o and --json apply.
int convert_sparse_spheres(cli::Args& args, uint32_t n) {
    const bool json = args.flag("--json");
    const auto out = args.value("--output", "-o");
    args.value("--synthetic");
    args.finish();
    if (!out) throw Error("-o", "missing output file (-o OUT.oct)");
    const Clock::time_point t0 = Clock::now();
    const SparseSpheres field = sparse_spheres_layout(n);
    const OctreeData<float> tree = build_sparse_octree<float>(field);
    OctInfo info;
    info.type = ScalarType::f32;
    info.dims = field.dims;
    info.dmax = tree.dmax;
    OctWriter writer(*out, info);
    writer.add_step(tree.view());
    writer.finish();
    const double seconds = seconds_since(t0);
    std::cerr << "octiso-convert: sparse-spheres:" << n << " (f32 " << dims_text(field.dims)
              << ", built directly as an octree) -> " << *out << ", " << mib(writer.bytes_written()) << ", " << seconds << " s\n";
    if (json) {
        cli::JsonWriter j(std::cout);
        j.begin_object().field("input", "sparse-spheres:" + std::to_string(n)).field("format", "synthetic");
        j.field("output", *out).field("type", "f32");
        j.key("dims").array(std::array<uint64_t, 3>{n, n, n});
        j.field("steps", 1).field("dmax", tree.dmax).field("file_bytes", writer.bytes_written());
        j.field("total_seconds", seconds).end_object();
        std::cout << "\n";
    }
    return 0;
}

int convert(std::vector<std::string>& argv) {
    const Clock::time_point t_start = Clock::now();
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
    std::optional<tbb::global_control> limit;
    if (const auto t = args.value("--threads")) {
        opt.threads = int(cli::parse_int(*t, "--threads", 1, 4096));
        limit.emplace(tbb::global_control::max_allowed_parallelism, size_t(opt.threads));
    }
    std::vector<std::string> positional;
    const Source src = parse_source(args, positional);
    args.finish();
    if (!out) throw Error("-o", "missing output file (-o OUT.oct)");
    if (!src.synthetic) {   // issue 18: never replace an input (same device and inode)
        std::vector<std::string> inputs;
        for (uint32_t i = 0; i < src.count(); ++i) inputs.push_back(src.step_path(i));
        refuse_output_onto_input(*out, inputs);
    }
    const int threads = int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));

    // 1. Open every step and compare it with the first before anything is written. For raw
    //    input this only maps files; other formats are read once here and once when converted.
    const uint32_t n_steps = src.count();
    std::optional<LoadedVolume> step0 = src.load(0);
    const StepMeta first(*step0);
    if (!src.synthetic)
        for (uint32_t i = 1; i < n_steps; ++i) check_same_grid(first, src.load(i));

    OctInfo info;
    info.type = first.type;
    info.dims = first.dims;
    info.placement = first.placement;
    info.dmax = dmax_for(first.dims);
    info.iso_range = opt.iso_range;
    info.tolerance = opt.tolerance;

    // 2. Build and stream one step at a time; the writer keeps only a temporary file until finish().
    Totals tot;
    OctWriter writer(*out, info);
    for (uint32_t i = 0; i < n_steps; ++i) {
        LoadedVolume v = i == 0 ? std::move(*step0) : src.load(i);
        step0.reset();
        if (i > 0) check_same_grid(first, v);   // a file may have changed since step 1
        opt.source_name = v.source();
        dispatch_scalar_type(v.type(), [&](auto tag) {
            using T = decltype(tag);
            const Clock::time_point t0 = Clock::now();
            const OctreeData<T> tree = build_octree(v.view<T>(), opt);
            tot.build_seconds += seconds_since(t0);
            tot.add(tree.stats);
            writer.add_step(tree.view());
        });
    }
    writer.finish();

    struct stat st {};
    const uint64_t file_bytes = ::stat(out->c_str(), &st) == 0 ? uint64_t(st.st_size) : writer.bytes_written();
    const uint64_t peak_rss = peak_rss_bytes();
    const double total_seconds = seconds_since(t_start);
    write_human(std::cerr, src, first, *out, n_steps, file_bytes, tot, total_seconds, peak_rss, threads);
    if (json) write_json(std::cout, src, first, *out, n_steps, file_bytes, tot, total_seconds, peak_rss, threads, opt);
    return 0;
}

}  // namespace

int main(int argc, char** argv) { return octiso::cli::run_main("octiso-convert", argc, argv, convert); }
