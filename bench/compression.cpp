// octiso-bench compression (issue 2, item 9): how small the lossless octree is, against the raw
// array and against zstd -3 of the raw, how fast it builds and how much memory the build takes,
// per dataset: the synthetic fields at --size N and the single-component MRI volumes of
// mricron-data. Each conversion runs in its own octiso-convert process, so peak RSS is that one
// conversion's; each .oct is extracted again with octiso-info and compared byte for byte.
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>

#include "bench/bench.h"
#include "bench/tools.h"
#include "octiso/error.h"
#include "octiso/reader.h"
#include "octiso/synthetic.h"

namespace octiso::bench {
namespace {

namespace fs = std::filesystem;

constexpr const char* kUsage =
    "usage: octiso-bench compression [--size N] [--dataset NAME[,NAME...]] [--no-mri] [--mri-dir DIR]\n"
    "                                [--threads N] [--markdown] [--results DIR]\n"
    "  NAME: sphere marschner-lobb sierpinski noise plume mixing, 'mri', or an MRI file name (ch2.nii.gz)";

const std::vector<std::string> kSynthetic = {"sphere", "marschner-lobb", "sierpinski", "noise", "plume", "mixing"};

struct Dataset {
    std::string name;     // table label
    std::string source;   // synthetic spec NAME:N or the file path
    bool synthetic = true;
};

struct Result {
    Dataset set;
    std::string type, dims;
    uint64_t voxels = 0, raw_bytes = 0, file_bytes = 0, interior_bytes = 0, minmax_bytes = 0, cap_bytes = 0;
    uint64_t zstd_bytes = 0, peak_rss = 0;
    double build_seconds = 0, mvoxels_per_second = 0;   ///< the octree build alone (converter's clock)
    double total_seconds = 0;     ///< converter's clock from start to the renamed file (read + build + write)
    double process_seconds = 0;   ///< whole child process, fork to exit (libraries, reading, build, writing)
    int threads = 0;
    bool round_trip = false;
    double percent() const { return 100.0 * double(file_bytes) / double(raw_bytes); }
    double zstd_percent() const { return 100.0 * double(zstd_bytes) / double(raw_bytes); }
    double rss_ratio() const { return double(peak_rss) / double(raw_bytes + file_bytes); }
};

std::vector<std::string> split_commas(const std::string& text) {
    std::vector<std::string> out;
    std::stringstream s(text);
    for (std::string part; std::getline(s, part, ',');)
        if (!part.empty()) out.push_back(part);
    return out;
}

/// The MRI volumes of `dir` (*.nii.gz, sorted by name).
std::vector<std::string> mri_files(const std::string& dir) {
    std::vector<std::string> files;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        const std::string name = e.path().filename().string();
        if (name.size() > 7 && name.compare(name.size() - 7, 7, ".nii.gz") == 0) files.push_back(e.path().string());
    }
    std::sort(files.begin(), files.end());
    return files;
}

std::string dims_text(Dims d) { return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z); }
std::string mib(uint64_t b) { return fmt(double(b) / (1024.0 * 1024.0), 2); }

/// Converts one dataset in a child process, extracts it again and compares; the reference voxels
/// (generated here, or read through VTK exactly as the converter reads them) stay in this process.
Result measure(const Dataset& set, const LoadedVolume& ref, const fs::path& tmp, int threads) {
    Result r;
    r.set = set;
    r.type = std::string(scalar_type_name(ref.type()));
    r.dims = dims_text(ref.dims());
    r.voxels = ref.dims().voxels();
    r.raw_bytes = ref.bytes();

    const std::string oct = (tmp / "dataset.oct").string(), raw = (tmp / "dataset.raw").string();
    std::vector<std::string> args;
    if (set.synthetic) args = {"--synthetic", set.source};
    else args = {set.source};
    args.insert(args.end(), {"-o", oct, "--json", "--threads", std::to_string(threads)});
    const auto t0 = std::chrono::steady_clock::now();
    const std::string json = run_tool("octiso-convert", args);
    r.process_seconds = seconds_since(t0);
    r.total_seconds = json_number(json, "total_seconds");
    r.file_bytes = uint64_t(json_number(json, "file_bytes"));
    r.interior_bytes = uint64_t(json_number(json, "interior_bytes"));
    r.minmax_bytes = uint64_t(json_number(json, "minmax_bytes"));
    r.cap_bytes = uint64_t(json_number(json, "cap_bytes"));
    r.build_seconds = json_number(json, "build_seconds");
    r.mvoxels_per_second = json_number(json, "mvoxels_per_second");
    r.peak_rss = uint64_t(json_number(json, "peak_rss_bytes"));
    r.threads = int(json_number(json, "threads"));
    if (uint64_t(json_number(json, "input_bytes")) != r.raw_bytes)
        throw Error(set.source, "converter and benchmark disagree on the input size", ErrorKind::Other);

    r.zstd_bytes = zstd_bytes(ref.data(), ref.bytes());
    // Synthetic and VTK volumes are native-endian, so the extracted bytes must equal ref's bytes.
    run_tool("octiso-info", {oct, "--extract-raw", raw});
    r.round_trip = !ref.swap_bytes() && file_equals(raw, ref.data(), ref.bytes());
    fs::remove(oct);
    fs::remove(raw);
    return r;
}

void write_results(cli::JsonWriter& j, const std::vector<Result>& results, int size, int threads,
                   const std::string& command, const std::vector<std::string>& skipped) {
    j.begin_object().field("bench", "compression").field("machine", machine_description());
    j.field("command", command).field("size", size).field("threads", threads);
    j.key("datasets").begin_array();
    for (const Result& r : results) {
        j.begin_object().field("name", r.set.name).field("source", r.set.source).field("synthetic", r.set.synthetic);
        j.field("type", r.type).field("dims", r.dims).field("voxels", r.voxels);
        j.field("raw_bytes", r.raw_bytes).field("file_bytes", r.file_bytes).field("percent_of_raw", r.percent());
        j.field("interior_bytes", r.interior_bytes).field("minmax_bytes", r.minmax_bytes).field("cap_bytes", r.cap_bytes);
        j.field("zstd3_bytes", r.zstd_bytes).field("zstd3_percent_of_raw", r.zstd_percent());
        j.field("build_seconds", r.build_seconds).field("mvoxels_per_second", r.mvoxels_per_second);
        j.field("convert_total_seconds", r.total_seconds).field("process_seconds", r.process_seconds);
        j.field("peak_rss_bytes", r.peak_rss).field("rss_over_input_plus_output", r.rss_ratio());
        j.field("threads", r.threads).field("round_trip_exact", r.round_trip).end_object();
    }
    j.end_array();
    j.key("skipped").array(skipped);
    j.end_object();
}

/// The issue-2 targets, measured on the plume row: >= 100 Mvoxels/s on 2 threads for 512^3 u8,
/// and peak RSS <= 1.1 x (input + output).
void print_targets(std::ostream& out, const std::vector<Result>& results, int size) {
    for (const Result& r : results) {
        if (r.set.name != "plume") continue;
        out << "issue-2 targets on plume " << r.dims << " " << r.type << ", " << r.threads << " threads"
            << (size == 512 ? "" : " (the targets are stated for 512^3: run --size 512 --dataset plume)") << ":\n";
        out << "  throughput " << fmt(r.mvoxels_per_second, 1) << " Mvoxels/s (target >= 100: "
            << (r.mvoxels_per_second >= 100 ? "met" : "NOT met") << ")\n";
        out << "  peak RSS " << mib(r.peak_rss) << " MiB = " << fmt(r.rss_ratio(), 3) << " x (input + output) (target <= 1.1: "
            << (r.rss_ratio() <= 1.1 ? "met" : "NOT met") << ")\n";
    }
}

int run_compression(cli::Args& args) {
    if (args.flag("--help")) {
        std::cout << kUsage << "\n";
        return 0;
    }
    const int size = int(cli::parse_int(args.value("--size").value_or("256"), "--size", 2, 4096));
    const int threads = int(cli::parse_int(args.value("--threads").value_or("2"), "--threads", 1, 4096));
    const std::optional<std::string> only = args.value("--dataset");
    const bool no_mri = args.flag("--no-mri");
    const std::string mri_dir = args.value("--mri-dir").value_or("/usr/share/mricron/templates");
    const bool markdown = args.flag("--markdown");
    const std::string results = results_dir(args);
    args.finish();

    // 1. Which datasets: every synthetic field and every MRI file, or the --dataset list.
    const std::vector<std::string> wanted = only ? split_commas(*only) : std::vector<std::string>{};
    auto is_wanted = [&](const std::string& name, bool mri) {
        if (wanted.empty()) return !(mri && no_mri);
        return std::find(wanted.begin(), wanted.end(), name) != wanted.end() ||
               (mri && std::find(wanted.begin(), wanted.end(), "mri") != wanted.end());
    };
    std::vector<Dataset> sets;
    for (const std::string& name : kSynthetic)
        if (is_wanted(name, false)) sets.push_back({name, name + ":" + std::to_string(size), true});
    for (const std::string& path : mri_files(mri_dir)) {
        const std::string name = fs::path(path).filename().string();
        if (is_wanted(name, true)) sets.push_back({name, path, false});
    }
    if (sets.empty()) throw Error("--dataset", "selects no dataset\n" + std::string(kUsage));

    const fs::path tmp = fs::temp_directory_path() / ("octiso-bench-compression-" + std::to_string(::getpid()));
    fs::create_directories(tmp);
    std::vector<Result> rows;
    std::vector<std::string> skipped;
    for (const Dataset& set : sets) {
        std::optional<LoadedVolume> ref;
        try {
            if (set.synthetic) {
                const SyntheticSpec spec = parse_synthetic(set.source);
                ref = synthetic_step(spec.name, spec.dims, 0);
            } else {
                ref = open_volume(set.source, RawOptions{});
            }
        } catch (const Error& e) {
            // Label maps with an RGB lookup, 4-D or multi-component files: the converter refuses
            // them too (one scalar per voxel), so they are listed, not measured.
            std::cerr << "skipped " << set.name << ": " << e.problem() << "\n";
            skipped.push_back(set.name + ": " + e.problem());
            continue;
        }
        std::cerr << "converting " << set.name << " (" << scalar_type_name(ref->type()) << " " << dims_text(ref->dims())
                  << ") ...\n";
        rows.push_back(measure(set, *ref, tmp, threads));
    }
    fs::remove_all(tmp);

    // 2. The table, the targets, JSON and the plot.
    Table table({"dataset", "type", "dims", "raw MiB", "octree MiB", "% raw", "interior MiB", "min/max MiB", "caps MiB",
                 "zstd-3 MiB", "zstd % raw", "build s", "Mvox/s (build)", "convert s", "process s", "peak RSS MiB", "RSS/(in+out)", "threads", "round trip"});
    for (const Result& r : rows)
        table.add({r.set.name, r.type, r.dims, mib(r.raw_bytes), mib(r.file_bytes), fmt(r.percent(), 2),
                   mib(r.interior_bytes), mib(r.minmax_bytes), mib(r.cap_bytes), mib(r.zstd_bytes), fmt(r.zstd_percent(), 2),
                   fmt(r.build_seconds, 3), fmt(r.mvoxels_per_second, 1), fmt(r.total_seconds, 3), fmt(r.process_seconds, 3), mib(r.peak_rss), fmt(r.rss_ratio(), 3),
                   std::to_string(r.threads), r.round_trip ? "exact" : "MISMATCH"});
    std::cout << "octiso-bench compression: " << machine_description() << "\n";
    table.print(std::cout);
    if (markdown) table.print_markdown(std::cout);
    print_targets(std::cout, rows, size);

    std::string command = "octiso-bench compression --size " + std::to_string(size) + " --threads " + std::to_string(threads);
    if (only) command += " --dataset " + *only;
    if (no_mri) command += " --no-mri";
    const std::string name = size == 256 ? "compression" : "compression_" + std::to_string(size);
    const std::string json = write_json(results, name, [&](cli::JsonWriter& j) { write_results(j, rows, size, threads, command, skipped); });
    std::cerr << "results: " << json << "\n";
    plot("compression", json, results + "/" + name + ".png");
    const bool all_exact = std::all_of(rows.begin(), rows.end(), [](const Result& r) { return r.round_trip; });
    return all_exact ? 0 : 1;
}

static const bool kRegistered =
    register_bench("compression", "octree bytes vs raw and zstd -3, build speed, peak RSS, round trip", &run_compression);

}  // namespace
}  // namespace octiso::bench
