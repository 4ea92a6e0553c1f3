// octiso-bench compression (issue 2, item 9; issue 19): how small the lossless octree is, against
// the raw array and against zstd -3 of the raw, where its bytes go (scalars, bounds, indices, caps)
// in this build's format and in format 2 (the wide layout before issue 19, whose sizes follow
// exactly from the same node and cap counts), how fast it builds and how much memory the build takes, per
// dataset: the synthetic fields at --size N (ct-head at N x N x N/2), the real CT of
// invesalius-examples (Cranium, i16) when installed, and the single-component MRI volumes of
// mricron-data. Each conversion runs in its own octiso-convert process, so peak RSS is that one
// conversion's; each .oct is extracted again with octiso-info and compared byte for byte (a
// NIfTI with the file's own stored bytes, the rest with the voxels generated or read here).
// --frames adds the frame time of octiso-render on each file (1 thread, 4 orbit frames at
// 384^2, the minimum of 3 rounds); --baseline DIR renders the same data converted by the tools
// in DIR (a build of an earlier commit, e.g. format 4) interleaved with ours, reports its file
// size, and checks that the images are identical.
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>

#include <zlib.h>

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
    "                                [--threads N] [--frames] [--baseline DIR] [--markdown] [--results DIR]\n"
    "  NAME: sphere marschner-lobb sierpinski noise plume mixing ct-head cranium, 'mri', or an MRI file name\n"
    "        (ch2.nii.gz)\n"
    "  --frames        also time octiso-render on each file (1 thread, 384^2, 4 frames, min of 3 rounds)\n"
    "  --baseline DIR  also convert and render with the tools in DIR (an earlier build), interleaved";

const std::vector<std::string> kSynthetic = {"sphere", "marschner-lobb", "sierpinski", "noise", "plume", "mixing", "ct-head"};
/// The real CT head of invesalius-examples: a tar of a raw int16 array, z slowest (main.plist).
const char* kCraniumArchive = "/usr/share/doc/invesalius-examples/examples/Cranium.inv3";
const RawOptions kCranium = [] {
    RawOptions o;
    o.dims = Dims{256, 256, 108};
    o.type = ScalarType::i16;
    return o;
}();

struct Dataset {
    std::string name;     // table label
    std::string source;   // synthetic spec NAME:N or the file path
    bool synthetic = true;
    std::optional<RawOptions> raw;   // a raw file's grid and type (the converter's --dims/--type)
};

struct Result {
    Dataset set;
    std::string type, dims;
    uint64_t voxels = 0, raw_bytes = 0, file_bytes = 0, interior_bytes = 0, minmax_bytes = 0, cap_bytes = 0;
    uint64_t zstd_bytes = 0, peak_rss = 0;
    uint64_t interior_nodes = 0, caps = 0, scalar_bytes_size = 0;
    double iso = 0;
    /// Seconds per frame: the minimum over rounds of the mean of 4 orbit frames (--frames).
    std::optional<double> frame, baseline_frame;
    uint64_t baseline_file_bytes = 0;
    bool baseline_images_equal = false;
    uint64_t scalars() const { return interior_nodes * 8 * scalar_bytes_size; }
    /// What the interior levels hold beside scalars and bounds (format 5: child offsets, masks,
    /// cap widths, group bases and their padding).
    uint64_t indices() const { return interior_bytes - scalars() - minmax_bytes; }
    /// Format 2 (before issue 19): InteriorNode 24 s + 8 bytes, Cap 8 s bytes, same counts.
    uint64_t format2_interior() const { return interior_nodes * (24 * scalar_bytes_size + 8); }
    uint64_t format2_caps() const { return caps * 8 * scalar_bytes_size; }
    uint64_t format2_minmax() const { return interior_nodes * 16 * scalar_bytes_size; }
    double format2_percent() const { return 100.0 * double(format2_interior() + format2_caps()) / double(raw_bytes); }
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
/// The voxel bytes of a little-endian NIfTI-1 file (.nii or .nii.gz) exactly as stored: x fastest,
/// the file's own axis order, which `octiso-info --extract-raw` gives back. The independent
/// reference for the round trip of a NIfTI: VTK's reader reorders a file with reversed axes
/// (AICHAmc, HarvardOxford, jhu189, natbrainlab), so comparing with it reported mismatches that
/// nibabel's reading of the same file does not show. Empty for anything else.
std::optional<std::string> nifti_stored_bytes(const std::string& path, uint64_t bytes) {
    const bool nifti = path.size() > 4 && (path.ends_with(".nii") || path.ends_with(".nii.gz"));
    if (!nifti) return std::nullopt;
    gzFile f = gzopen(path.c_str(), "rb");   // reads plain files too
    if (!f) return std::nullopt;
    char header[348];
    int32_t sizeof_hdr = 0;
    float vox_offset = 0;
    std::optional<std::string> out;
    if (gzread(f, header, sizeof header) == int(sizeof header)) {
        std::memcpy(&sizeof_hdr, header, 4);
        std::memcpy(&vox_offset, header + 108, 4);
        if (sizeof_hdr == 348 && vox_offset >= 348 && bytes < (uint64_t(1) << 31)) {
            std::string skip(size_t(vox_offset) - sizeof header, '\0');
            std::string data(size_t(bytes), '\0');
            if ((skip.empty() || gzread(f, skip.data(), unsigned(skip.size())) == int(skip.size())) &&
                gzread(f, data.data(), unsigned(data.size())) == int(data.size()))
                out = std::move(data);
        }
    }
    gzclose(f);
    return out;
}

/// An isovalue inside the data: 40 % of the way up the range (+0.5 for integers, so that it
/// never equals a stored value), the same for every layout.
double iso_for(const std::string& json, bool integer) {
    const size_t at = json.find("\"value_range\":[");
    if (at == std::string::npos) return 0.5;
    const char* p = json.c_str() + at + 15;
    char* end = nullptr;
    const double lo = std::strtod(p, &end);
    const double hi = std::strtod(end + 1, nullptr);
    const double v = lo + 0.4 * (hi - lo);
    return integer ? std::floor(v) + 0.5 : v;
}

/// Per-frame seconds of octiso-render from `dir` on `oct` (4 orbit frames), writing PNGs to
/// `png_pattern` (a %d field). `--no-embree` on both sides: a --baseline build from before issue
/// 11 went through Embree by default, this one calls the traversal directly; the same path for
/// both keeps the comparison about the format.
double frame_seconds(const std::string& dir, const std::string& oct, double iso, const std::string& png_pattern) {
    const std::string json = run_tool("octiso-render", {oct, "--iso", fmt(iso, 6), "-o", png_pattern, "--orbit", "4",
                                                        "--threads", "1", "--size", "384x384", "--no-embree", "--json"}, dir);
    double total = 0;
    for (size_t at = json.find("\"frame_seconds\":"); at != std::string::npos; at = json.find("\"frame_seconds\":", at + 1))
        total += std::strtod(json.c_str() + at + 16, nullptr);
    return total / 4;
}

bool same_files(const std::string& a, const std::string& b) {
    std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
    const std::string x((std::istreambuf_iterator<char>(fa)), std::istreambuf_iterator<char>());
    const std::string y((std::istreambuf_iterator<char>(fb)), std::istreambuf_iterator<char>());
    return fa && fb && !x.empty() && x == y;
}

/// Converts one dataset in a child process, extracts it again and compares; the reference voxels
/// (generated here, or read through VTK exactly as the converter reads them) stay in this process.
Result measure(const Dataset& set, const LoadedVolume& ref, const fs::path& tmp, int threads, bool frames,
               const std::optional<std::string>& baseline) {
    Result r;
    r.set = set;
    r.type = std::string(scalar_type_name(ref.type()));
    r.dims = dims_text(ref.dims());
    r.voxels = ref.dims().voxels();
    r.raw_bytes = ref.bytes();
    r.scalar_bytes_size = scalar_type_bytes(ref.type());

    const std::string oct = (tmp / "dataset.oct").string(), raw = (tmp / "dataset.raw").string();
    std::vector<std::string> args;
    if (set.synthetic) args = {"--synthetic", set.source};
    else args = {set.source};
    if (set.raw) {
        const Dims d = *set.raw->dims;
        args.insert(args.end(), {"--dims", std::to_string(d.x) + "," + std::to_string(d.y) + "," + std::to_string(d.z),
                                 "--type", std::string(scalar_type_name(*set.raw->type))});
    }
    std::vector<std::string> convert_args = args;
    convert_args.insert(convert_args.end(), {"-o", oct, "--json", "--threads", std::to_string(threads)});
    const auto t0 = std::chrono::steady_clock::now();
    const std::string json = run_tool("octiso-convert", convert_args);
    r.process_seconds = seconds_since(t0);
    r.total_seconds = json_number(json, "total_seconds");
    r.file_bytes = uint64_t(json_number(json, "file_bytes"));
    r.interior_bytes = uint64_t(json_number(json, "interior_bytes"));
    r.minmax_bytes = uint64_t(json_number(json, "minmax_bytes"));
    r.cap_bytes = uint64_t(json_number(json, "cap_bytes"));
    r.interior_nodes = uint64_t(json_number(json, "interior_node_count"));
    r.caps = uint64_t(json_number(json, "cap_count"));
    r.build_seconds = json_number(json, "build_seconds");
    r.mvoxels_per_second = json_number(json, "mvoxels_per_second");
    r.peak_rss = uint64_t(json_number(json, "peak_rss_bytes"));
    r.threads = int(json_number(json, "threads"));
    if (uint64_t(json_number(json, "input_bytes")) != r.raw_bytes)
        throw Error(set.source, "converter and benchmark disagree on the input size", ErrorKind::Other);
    const bool integer = ref.type() != ScalarType::f32 && ref.type() != ScalarType::f64;
    r.iso = iso_for(json, integer);

    r.zstd_bytes = zstd_bytes(ref.data(), ref.bytes());
    // Synthetic and VTK volumes are native-endian, so the extracted bytes must equal ref's bytes.
    run_tool("octiso-info", {oct, "--extract-raw", raw});
    if (const auto stored = set.synthetic ? std::nullopt : nifti_stored_bytes(set.source, r.raw_bytes))
        r.round_trip = file_equals(raw, stored->data(), stored->size());
    else
        r.round_trip = !ref.swap_bytes() && file_equals(raw, ref.data(), ref.bytes());
    fs::remove(raw);

    // Frame time, ours and the baseline's interleaved round by round (minimum per side).
    if (frames || baseline) {
        const std::string base_oct = (tmp / "baseline.oct").string();
        if (baseline) {
            // A synthetic field goes to the baseline as raw bytes (spacing 1, origin 0, as the
            // generator places it): an earlier build may not know the generator.
            std::vector<std::string> b = args;
            const std::string dump = (tmp / "baseline.raw").string();
            if (set.synthetic) {
                std::ofstream(dump, std::ios::binary).write(reinterpret_cast<const char*>(ref.data()), std::streamsize(ref.bytes()));
                const Dims d = ref.dims();
                b = {dump, "--dims", std::to_string(d.x) + "," + std::to_string(d.y) + "," + std::to_string(d.z), "--type", r.type};
            }
            b.insert(b.end(), {"-o", base_oct, "--json", "--threads", std::to_string(threads)});
            r.baseline_file_bytes = uint64_t(json_number(run_tool("octiso-convert", b, *baseline), "file_bytes"));
            fs::remove(dump);
        }
        const std::string ours_png = (tmp / "ours_%d.png").string(), base_png = (tmp / "base_%d.png").string();
        double best = 1e300, best_base = 1e300;
        for (int round = 0; round < 3; ++round) {
            best = std::min(best, frame_seconds(tools_dir(), oct, r.iso, ours_png));
            if (baseline) best_base = std::min(best_base, frame_seconds(*baseline, base_oct, r.iso, base_png));
        }
        r.frame = best;
        if (baseline) {
            r.baseline_frame = best_base;
            r.baseline_images_equal = true;
            for (int k = 0; k < 4; ++k)
                r.baseline_images_equal &= same_files((tmp / ("ours_" + std::to_string(k) + ".png")).string(),
                                                      (tmp / ("base_" + std::to_string(k) + ".png")).string());
        }
        for (int k = 0; k < 4; ++k) {
            fs::remove(tmp / ("ours_" + std::to_string(k) + ".png"));
            fs::remove(tmp / ("base_" + std::to_string(k) + ".png"));
        }
        fs::remove(base_oct);
    }
    fs::remove(oct);
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
        j.field("interior_nodes", r.interior_nodes).field("caps", r.caps);
        j.field("scalar_bytes", r.scalars()).field("index_bytes", r.indices());
        j.field("format2_interior_bytes", r.format2_interior()).field("format2_minmax_bytes", r.format2_minmax());
        j.field("format2_cap_bytes", r.format2_caps()).field("format2_percent_of_raw", r.format2_percent());
        j.field("iso", r.iso);
        if (r.frame) j.field("frame_seconds", *r.frame);
        if (r.baseline_frame)
            j.field("baseline_frame_seconds", *r.baseline_frame)
                .field("baseline_file_bytes", r.baseline_file_bytes)
                .field("speedup_over_baseline", *r.baseline_frame / *r.frame)
                .field("images_equal_to_baseline", r.baseline_images_equal);
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
    const bool frames = args.flag("--frames");
    const std::optional<std::string> baseline = args.value("--baseline");
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
        if (is_wanted(name, false))
            sets.push_back({name, name + ":" + (name == "ct-head" ? std::to_string(size) + "," + std::to_string(size) + "," +
                                                                        std::to_string(std::max(2, size / 2))
                                                                  : std::to_string(size)),
                            true, std::nullopt});
    const fs::path tmp = fs::temp_directory_path() / ("octiso-bench-compression-" + std::to_string(::getpid()));
    fs::create_directories(tmp);
    if (is_wanted("cranium", true) && fs::exists(kCraniumArchive)) {
        // The archive holds matrix.dat: 256 x 256 x 108 int16, x fastest (numpy C order z, y, x).
        const std::string out = (tmp / "cranium").string();
        fs::create_directories(out);
        const std::string cmd = "tar -xzf " + shell_quote(kCraniumArchive) + " -C " + shell_quote(out) + " --wildcards '*/matrix.dat'";
        if (std::system(cmd.c_str()) != 0) throw Error(kCraniumArchive, "cannot unpack", ErrorKind::Other);
        for (const auto& e : fs::recursive_directory_iterator(out))
            if (e.path().filename() == "matrix.dat")
                sets.push_back({"cranium (CT)", e.path().string(), false, kCranium});
    }
    for (const std::string& path : mri_files(mri_dir)) {
        const std::string name = fs::path(path).filename().string();
        if (is_wanted(name, true)) sets.push_back({name, path, false, std::nullopt});
    }
    if (sets.empty()) throw Error("--dataset", "selects no dataset\n" + std::string(kUsage));
    std::vector<Result> rows;
    std::vector<std::string> skipped;
    for (const Dataset& set : sets) {
        std::optional<LoadedVolume> ref;
        try {
            if (set.synthetic) {
                const SyntheticSpec spec = parse_synthetic(set.source);
                ref = synthetic_step(spec.name, spec.dims, 0);
            } else {
                ref = open_volume(set.source, set.raw.value_or(RawOptions{}));
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
        rows.push_back(measure(set, *ref, tmp, threads, frames, baseline));
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
    // Where the bytes go, this format against format 2 and the baseline (issue 19), and the frame time where measured.
    Table parts({"dataset", "type", "nodes", "caps", "scalars MiB", "bounds MiB", "indices MiB", "caps MiB", "% raw",
                 "baseline % raw", "format 2: min/max MiB", "caps MiB", "% raw", "zstd-3 % raw", "iso", "frame ms",
                 "baseline ms", "speed-up", "same image"});
    for (const Result& r : rows) {
        const bool b = r.baseline_frame.has_value();
        parts.add({r.set.name, r.type, std::to_string(r.interior_nodes), std::to_string(r.caps), mib(r.scalars()),
                   mib(r.minmax_bytes), mib(r.indices()), mib(r.cap_bytes),
                   fmt(r.percent(), 1), b ? fmt(100.0 * double(r.baseline_file_bytes) / double(r.raw_bytes), 1) : "-",
                   mib(r.format2_minmax()), mib(r.format2_caps()),
                   fmt(r.format2_percent(), 1), fmt(r.zstd_percent(), 1), fmt(r.iso, 6),
                   r.frame ? fmt(1e3 * *r.frame, 1) : "-", b ? fmt(1e3 * *r.baseline_frame, 1) : "-",
                   b ? fmt(*r.baseline_frame / *r.frame, 3) : "-", b ? (r.baseline_images_equal ? "yes" : "NO") : "-"});
    }
    std::cout << "\nbytes by part (this format), the baseline's file and format 2 from the same counts; frames: 1 thread, "
                 "384^2, min of 3 rounds\n";
    parts.print(std::cout);
    if (markdown) parts.print_markdown(std::cout);
    print_targets(std::cout, rows, size);

    std::string command = "octiso-bench compression --size " + std::to_string(size) + " --threads " + std::to_string(threads);
    if (only) command += " --dataset " + *only;
    if (no_mri) command += " --no-mri";
    if (frames) command += " --frames";
    if (baseline) command += " --baseline " + *baseline;
    const std::string name = size == 256 ? "compression" : "compression_" + std::to_string(size);
    const std::string json = write_json(results, name, [&](cli::JsonWriter& j) { write_results(j, rows, size, threads, command, skipped); });
    std::cerr << "results: " << json << "\n";
    plot("compression", json, results + "/" + name + ".png");
    const bool all_exact = std::all_of(rows.begin(), rows.end(), [&](const Result& r) {
        return r.round_trip && (!baseline || r.baseline_images_equal);
    });
    return all_exact ? 0 : 1;
}

static const bool kRegistered =
    register_bench("compression", "octree bytes vs raw and zstd -3, build speed, peak RSS, round trip", &run_compression);

}  // namespace
}  // namespace octiso::bench
