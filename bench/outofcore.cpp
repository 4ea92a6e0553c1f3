// octiso-bench outofcore: the out-of-core converter against the in-memory one (issue 13). A large
// u8 raw file is written once (a smooth deterministic field, layer by layer, never whole in
// memory), converted in a child process with --memory BYTES and again with --in-memory; per path
// the wall time, Mvoxel/s, the child's peak RSS, bytes read and written and spilled; then the two
// files compared byte for byte, and the sha256 of the voxels octiso-info --extract-raw gives back
// compared with the input's. --quick: a small grid and a tight budget, so that CI runs the whole
// path (seams, spilling, extraction) in seconds.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <vector>

#include <unistd.h>

#include <tbb/parallel_for.h>

#include "bench/bench.h"
#include "bench/tools.h"
#include "octiso/error.h"
#include "octiso/volume.h"

namespace octiso::bench {
namespace {

const char* const kOutOfCoreUsage =
    "usage: octiso-bench outofcore [--dims NX,NY,NZ] [--memory BYTES] [--dir DIR] [--threads N] [--keep]\n"
    "                              [--streamed-only] [--quick] | --frames-of FILE.oct [--iso V]\n"
    "  u8 NX*NY*NZ (default 1024,1024,1024) written once to DIR (default $TMPDIR) as outofcore_NXxNYxNZ.raw and\n"
    "  reused; converted with --memory (default 1G) and --in-memory; --keep keeps the input for the next run.\n"
    "  --streamed-only: no in-memory run (an input larger than RAM), and the input is removed once hashed and\n"
    "  converted (unless --keep), so that the extracted copy fits on the disk beside the .oct.\n"
    "  --frames-of FILE.oct [--iso V]: only the cold frames (afar, close; --verify full, touched) of that file";

/// The value of voxel (x, y, z): nested shells and slow waves, so the octree has structure at
/// every depth (about as compressible as the paper's scans). The formula, once per voxel:
///   a = sin(0.031 x) cos(0.023 y) + sin(0.017 z + 0.004 x)
///   r = |(x mod 256, y mod 192, z mod 320)|,  v = 96 + 60 a + 40 sin(0.05 r)
/// quantised to multiples of 4 (uniform runs merge). FieldLayer computes exactly these doubles
/// from tables (the terms in x and y once per layer and row, sin(0.05 r) by the exact integer
/// r^2), so the 27 GiB input of the larger-than-RAM run is written at disk speed, not at
/// 5 transcendental calls per voxel (7.5 GiB took 10 minutes that way on one core).
class FieldLayer {
public:
    explicit FieldLayer(Dims d) : d_(d), sx_(d.x), cy_(d.y), wave_(256 * 256 + 192 * 192 + 320 * 320) {
        for (uint32_t x = 0; x < d.x; ++x) sx_[x] = std::sin(x * 0.031);
        for (uint32_t y = 0; y < d.y; ++y) cy_[y] = std::cos(y * 0.023);
        for (size_t r2 = 0; r2 < wave_.size(); ++r2) wave_[r2] = std::sin(std::sqrt(double(r2)) * 0.05);
    }
    /// Layer z into `out` (d.x * d.y values), rows in parallel.
    void fill(uint32_t z, uint8_t* out) const {
        std::vector<double> sz(d_.x);
        for (uint32_t x = 0; x < d_.x; ++x) sz[x] = std::sin(z * 0.017 + x * 0.004);
        const double zz = double(z % 320) * (z % 320);
        tbb::parallel_for(uint32_t(0), d_.y, [&](uint32_t y) {
            const double yy = double(y % 192) * (y % 192);
            uint8_t* row = out + uint64_t(y) * d_.x;
            for (uint32_t x = 0; x < d_.x; ++x) {
                const double a = sx_[x] * cy_[y] + sz[x];
                const double r2 = double(x % 256) * (x % 256) + yy + zz;   // an exact integer
                const double v = 96 + 60 * a + 40 * wave_[size_t(r2)];
                row[x] = uint8_t(std::lround(std::clamp(v, 0.0, 255.0)) & ~3);
            }
        });
    }

private:
    Dims d_;
    std::vector<double> sx_, cy_, wave_;
};

void write_input(const std::string& path, Dims d) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) throw Error(path, "cannot create", ErrorKind::Other);
    const FieldLayer field(d);
    std::vector<uint8_t> layer(uint64_t(d.x) * d.y);
    for (uint32_t z = 0; z < d.z; ++z) {
        field.fill(z, layer.data());
        if (std::fwrite(layer.data(), 1, layer.size(), f) != layer.size()) {
            std::fclose(f);
            throw Error(path, "write failed", ErrorKind::Other);
        }
    }
    if (std::fclose(f) != 0) throw Error(path, "write failed", ErrorKind::Other);
}

std::string sha256_of(const std::string& path) {
    const std::string out = [&] {
        std::FILE* p = ::popen(("sha256sum " + shell_quote(path)).c_str(), "r");
        if (!p) throw Error("sha256sum", "cannot start", ErrorKind::Other);
        char buf[128] = {};
        const size_t n = std::fread(buf, 1, 64, p);
        ::pclose(p);
        return std::string(buf, n);
    }();
    if (out.size() != 64) throw Error("sha256sum", "no digest for " + path, ErrorKind::Other);
    return out;
}

bool same_files(const std::string& a, const std::string& b) {
    std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
    std::vector<char> ba(1 << 20), bb(1 << 20);
    while (fa && fb) {
        fa.read(ba.data(), std::streamsize(ba.size()));
        fb.read(bb.data(), std::streamsize(bb.size()));
        if (fa.gcount() != fb.gcount() || std::memcmp(ba.data(), bb.data(), size_t(fa.gcount())) != 0) return false;
    }
    return fa.eof() && fb.eof();
}

struct PathRow {
    std::string name;
    double wall_seconds = 0, build_seconds = 0, mvoxels_per_second = 0;
    uint64_t peak_rss = 0, bytes_read = 0, file_bytes = 0, spilled = 0, piece_side = 0;
    bool streamed = false, lossless = false;
};

double mib(uint64_t b) { return double(b) / 1048576.0; }

uint64_t physical_memory_bytes() { return uint64_t(::sysconf(_SC_PHYS_PAGES)) * uint64_t(::sysconf(_SC_PAGESIZE)); }

/// One frame of the converted file from a cold page cache: what opening and validating cost
/// before the first pixel, and what the frame left resident (issue 13, --verify).
struct RenderRow {
    std::string verify, view;
    double open_to_first_frame = 0, frame_seconds = 0;
    uint64_t resident = 0, blocks = 0, checked = 0;
    uint64_t hits = 0;
};

/// A 512^2 frame (--quick: 64^2) of `oct` at `iso`, afar (the default camera: the whole data)
/// and close up (zoom 8: a corner of it), under --verify full and touched, each from a cold
/// page cache, interleaved.
std::vector<RenderRow> cold_frames(const std::string& oct, const std::string& iso, bool quick,
                                   const std::optional<std::string>& threads, const std::string& image) {
    std::vector<RenderRow> renders;
    for (const char* view : {"afar", "close"})
        for (const char* verify : {"full", "touched"}) {
            evict_page_cache(oct);
            std::vector<std::string> args{oct, "--iso", iso, "--size", quick ? "64x64" : "512x512", "--verify", verify, "--json", "-o", image};
            if (std::string(view) == "close") args.insert(args.end(), {"--zoom", "8"});
            if (threads) args.insert(args.end(), {"--threads", *threads});
            const std::string json = run_tool("octiso-render", args);
            RenderRow r{verify, view};
            r.open_to_first_frame = json_number(json, "open_to_first_frame_seconds");
            r.frame_seconds = json_number(json, "frame_seconds");
            r.resident = uint64_t(json_number(json, "file_resident_bytes"));
            r.hits = uint64_t(json_number(json, "hits"));
            if (std::string(verify) == "touched") {
                r.blocks = uint64_t(json_number(json, "blocks"));
                r.checked = uint64_t(json_number(json, "checked"));
            }
            renders.push_back(r);
        }
    std::error_code ec;
    std::filesystem::remove(image, ec);
    return renders;
}

void print_frames(const std::vector<RenderRow>& renders, uint64_t file_bytes) {
    Table frames({"view", "--verify", "open to first frame s", "frame s", "file resident MiB", "% of file", "blocks checked", "hits"});
    for (const RenderRow& r : renders)
        frames.add({r.view, r.verify, fmt(r.open_to_first_frame, 2), fmt(r.frame_seconds, 2), fmt(mib(r.resident), 1),
                    fmt(100.0 * double(r.resident) / double(std::max<uint64_t>(1, file_bytes)), 1),
                    r.verify == "touched" ? std::to_string(r.checked) + " / " + std::to_string(r.blocks) : "-", std::to_string(r.hits)});
    frames.print(std::cout);
}

void json_frames(cli::JsonWriter& j, const std::vector<RenderRow>& renders) {
    j.key("frames").begin_array();
    for (const RenderRow& r : renders) {
        j.begin_object().field("view", r.view).field("verify", r.verify).field("open_to_first_frame_seconds", r.open_to_first_frame);
        j.field("frame_seconds", r.frame_seconds).field("file_resident_bytes", r.resident).field("hits", r.hits);
        j.field("blocks", r.blocks).field("blocks_checked", r.checked).end_object();
    }
    j.end_array();
}

/// --frames-of FILE.oct: only the cold frames of an existing file (issue 13 names the 1.84 GiB
/// RM-like step, octiso-convert --synthetic mixing:2048,2048,1920).
int frames_of(const std::string& oct, const std::string& iso, bool quick, const std::optional<std::string>& threads,
              const std::string& results) {
    const uint64_t file_bytes = std::filesystem::file_size(oct);
    const std::string stem = std::filesystem::path(oct).stem().string();
    const std::vector<RenderRow> renders =
        cold_frames(oct, iso, quick, threads, (std::filesystem::temp_directory_path() / (stem + "_frame.png")).string());
    std::cout << "one frame of " << oct << " (" << fmt(mib(file_bytes), 1) << " MiB), iso " << iso << ", cold page cache ("
              << machine_description() << "):\n";
    print_frames(renders, file_bytes);
    const std::string path = write_json(results, "outofcore_frames_" + stem, [&](cli::JsonWriter& j) {
        j.begin_object().field("file", oct).field("file_bytes", file_bytes).field("iso", iso).field("machine", machine_description());
        json_frames(j, renders);
        j.end_object();
    });
    std::cout << "wrote " << path << "\n";
    return 0;
}

int run_outofcore(cli::Args& args) {
    if (args.flag("--help")) {
        std::cout << kOutOfCoreUsage << "\n";
        return 0;
    }
    const bool quick = args.flag("--quick"), keep = args.flag("--keep"), streamed_only = args.flag("--streamed-only");
    const auto dims_flag = args.value("--dims"), memory_flag = args.value("--memory");
    const auto dir_flag = args.value("--dir"), threads_flag = args.value("--threads");
    const auto frames_flag = args.value("--frames-of"), iso_flag = args.value("--iso");
    const std::string results = results_dir(args);
    args.finish();
    if (frames_flag) return frames_of(*frames_flag, iso_flag.value_or("98"), quick, threads_flag, results);
    const Dims d = dims_flag ? parse_dims(*dims_flag, "--dims") : quick ? Dims{160, 144, 130} : Dims{1024, 1024, 1024};
    const std::string memory = memory_flag ? *memory_flag : quick ? "4M" : "1G";
    const std::string dir = dir_flag ? *dir_flag : std::filesystem::temp_directory_path().string();
    const std::string tag = std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
    const std::string input = dir + "/outofcore_" + tag + ".raw";
    const uint64_t voxels = d.voxels();

    // 1. The input, once: reused while its size is right (written by an earlier run with --keep).
    std::error_code ec;
    const auto t_write = std::chrono::steady_clock::now();
    bool written = false;
    if (std::filesystem::file_size(input, ec) != voxels || ec) {
        write_input(input, d);
        written = true;
    }
    const double write_seconds = seconds_since(t_write);
    const std::string input_sha = sha256_of(input);

    // 2. Both paths, in child processes (each peak RSS is its own), then the data back.
    std::vector<PathRow> rows;
    const std::string dims_arg = std::to_string(d.x) + "," + std::to_string(d.y) + "," + std::to_string(d.z);
    for (const bool streamed : {true, false}) {
        if (!streamed && streamed_only) break;
        PathRow r;
        r.name = streamed ? "--memory " + memory : "--in-memory";
        const std::string out = dir + "/outofcore_" + tag + (streamed ? "_streamed.oct" : "_in_memory.oct");
        std::vector<std::string> a{input, "--dims", dims_arg, "--type", "u8", "-o", out, "--json"};
        if (streamed) a.insert(a.end(), {"--memory", memory});
        else a.push_back("--in-memory");
        if (threads_flag) a.insert(a.end(), {"--threads", *threads_flag});
        const auto t0 = std::chrono::steady_clock::now();
        const std::string json = run_tool("octiso-convert", a);
        r.wall_seconds = seconds_since(t0);
        r.build_seconds = json_number(json, "build_seconds");
        r.mvoxels_per_second = double(voxels) / r.wall_seconds / 1e6;
        r.peak_rss = uint64_t(json_number(json, "peak_rss_bytes"));
        r.file_bytes = uint64_t(json_number(json, "file_bytes"));
        r.streamed = json.find("\"streamed\":true") != std::string::npos;
        r.bytes_read = streamed ? uint64_t(json_number(json, "bytes_read")) : voxels;   // in memory: mapped
        r.spilled = uint64_t(json_number(json, "spilled_bytes"));
        r.piece_side = uint64_t(json_number(json, "piece_side"));
        if (streamed_only && !keep) std::filesystem::remove(input, ec);   // hashed already: room for the copy
        const std::string extracted = dir + "/outofcore_" + tag + "_extracted.raw";
        run_tool("octiso-info", {out, "--extract-raw", extracted});
        r.lossless = sha256_of(extracted) == input_sha;
        std::filesystem::remove(extracted, ec);
        rows.push_back(r);
    }
    const std::string a = dir + "/outofcore_" + tag + "_streamed.oct", b = dir + "/outofcore_" + tag + "_in_memory.oct";
    const bool identical = !streamed_only && same_files(a, b);

    // 3. A 512^2 frame of the file, afar and close up, --verify full and touched, cold.
    const std::vector<RenderRow> renders = cold_frames(a, "98", quick, threads_flag, dir + "/outofcore_" + tag + "_frame.png");
    std::filesystem::remove(a, ec);
    std::filesystem::remove(b, ec);
    if (!keep) std::filesystem::remove(input, ec);

    std::cout << "out-of-core conversion, u8 " << tag << " (" << fmt(mib(voxels), 1) << " MiB; this machine's RAM "
              << fmt(mib(physical_memory_bytes()), 0) << " MiB), input "
              << (written ? "written in " + fmt(write_seconds, 1) + " s" : "reused") << " (" << machine_description() << ")\n";
    Table table({"path", "wall s", "build s", "Mvoxel/s", "peak RSS MiB", "read MiB", "written MiB", "spilled MiB",
                 "piece", "extracted sha256 = input"});
    for (const PathRow& r : rows)
        table.add({r.name, fmt(r.wall_seconds, 2), fmt(r.build_seconds, 2), fmt(r.mvoxels_per_second, 1),
                   fmt(mib(r.peak_rss), 1), r.streamed ? fmt(mib(r.bytes_read), 1) : fmt(mib(r.bytes_read), 1) + " (mapped)",
                   fmt(mib(r.file_bytes), 1), fmt(mib(r.spilled), 1), r.streamed ? std::to_string(r.piece_side) + "^3" : "-",
                   r.lossless ? "yes" : "NO"});
    table.print(std::cout);
    if (!streamed_only)
        std::cout << "the two .oct files are " << (identical ? "identical, byte for byte" : "DIFFERENT") << "; throughput "
                  << fmt(100.0 * rows[0].mvoxels_per_second / rows[1].mvoxels_per_second, 1) << " % of in-memory\n";
    std::cout << "one frame of the " << fmt(mib(rows[0].file_bytes), 1) << " MiB file, cold page cache:\n";
    print_frames(renders, rows[0].file_bytes);
    const std::string path = write_json(results, quick ? "outofcore" : "outofcore_" + tag, [&](cli::JsonWriter& j) {
        j.begin_object();
        j.field("dims", tag).field("type", std::string("u8")).field("input_bytes", voxels).field("memory", memory);
        j.field("machine", machine_description()).field("input_sha256", input_sha);
        j.field("physical_memory_bytes", physical_memory_bytes()).field("input_written_seconds", written ? write_seconds : 0.0);
        if (!streamed_only) j.field("identical", identical);
        j.key("paths").begin_array();
        for (const PathRow& r : rows) {
            j.begin_object().field("path", r.name).field("streamed", r.streamed).field("wall_seconds", r.wall_seconds);
            j.field("build_seconds", r.build_seconds).field("mvoxels_per_second", r.mvoxels_per_second);
            j.field("peak_rss_bytes", r.peak_rss).field("bytes_read", r.bytes_read).field("file_bytes", r.file_bytes);
            j.field("spilled_bytes", r.spilled).field("piece_side", r.piece_side).field("lossless", r.lossless).end_object();
        }
        j.end_array();
        json_frames(j, renders);
        j.end_object();
    });
    std::cout << "wrote " << path << "\n";
    const bool all_lossless = std::all_of(rows.begin(), rows.end(), [](const PathRow& r) { return r.lossless; });
    return (identical || streamed_only) && all_lossless ? 0 : 1;
}

const bool kRegistered =
    register_bench("outofcore", "out-of-core conversion under --memory vs in memory: time, RSS, lossless", &run_outofcore);

}  // namespace
}  // namespace octiso::bench
