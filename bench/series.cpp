// octiso-bench series (issue 6): the time-series analogues of the paper's Table 4 (frames/s per
// step at 512^2 and 1024^2, Knoll et al. 2006, sec. 5.5) and Table 1 (per-step and whole-sequence
// size against raw and zstd -3 of the raw) for the synthetic plume series, plus resident memory
// while a 100-step series is rendered step by step: the file is mmap'd, so only the steps
// rendered should become resident. Conversion runs in an octiso-convert child process.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "bench/bench.h"
#include "bench/tools.h"
#include "octiso/decode.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/render.h"
#include "octiso/synthetic.h"

namespace octiso::bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr const char* kUsage =
    "usage: octiso-bench series [--size N] [--steps S] [--iso V] [--threads N] [--resolutions 512,1024]\n"
    "                           [--rss-steps 100] [--rss-size N] [--no-rss] [--keep DIR] [--results DIR]\n"
    "  default: --size 128 --steps 32 (quick); the paper's case is --size 302 --steps 153";

std::string mib(uint64_t b) { return fmt(double(b) / (1024.0 * 1024.0), 2); }

struct StepRow {
    uint32_t step = 0;
    uint64_t raw_bytes = 0, octree_bytes = 0, zstd_bytes = 0;
    bool exact = false;
    std::vector<double> seconds;   // wall seconds of render() per resolution
    std::vector<double> hit_fraction;
};

struct RssPoint {
    uint32_t rendered = 0;
    uint64_t mapped = 0, expected = 0, total = 0;
};

struct Conversion {
    uint64_t file_bytes = 0, input_bytes = 0, peak_rss = 0;
    double build_seconds = 0, total_seconds = 0, mvoxels_per_second = 0;
};

Conversion convert_series(int size, int steps, int threads, const std::string& out) {
    const std::string json = run_tool("octiso-convert", {"--synthetic", "plume-series:" + std::to_string(size) + "," +
                                                             std::to_string(steps), "-o", out, "--json", "--threads",
                                                         std::to_string(threads)});
    Conversion c;
    c.file_bytes = uint64_t(json_number(json, "file_bytes"));
    c.input_bytes = uint64_t(json_number(json, "input_bytes"));
    c.peak_rss = uint64_t(json_number(json, "peak_rss_bytes"));
    c.build_seconds = json_number(json, "build_seconds");
    c.total_seconds = json_number(json, "total_seconds");
    c.mvoxels_per_second = json_number(json, "mvoxels_per_second");
    return c;
}

uint64_t step_bytes(const StepSizes& s) { return s.interior_bytes + s.cap_bytes; }   // interior includes min/max

Frame render_step(const OctFile& file, uint32_t k, const Camera& camera, const RenderOptions& options) {
    return dispatch_scalar_type(file.info().type, [&](auto tag) {
        using T = decltype(tag);
        return render(file.step<T>(k), file.info().placement, camera, options);
    });
}

/// Opens `path` fresh and renders steps 0, 1, ... at 256^2, recording resident memory of the
/// mapping (and of the process) after opening and after each checkpoint count of steps.
std::vector<RssPoint> measure_rss(const std::string& path, const std::vector<uint32_t>& checkpoints, double iso, int threads) {
    std::vector<RssPoint> points;
    const OctFile file = OctFile::open(path);
    RenderOptions options;
    options.isovalues = {iso};
    options.threads = threads;
    const Camera camera = frame_data_box(file.info().dims, file.info().placement, 256, 256);
    const uint64_t header = mapped_resident_bytes(path);   // header + section table after open
    points.push_back({0, header, 0, current_rss_bytes()});
    uint64_t expected = 0;
    uint32_t done = 0;
    for (uint32_t target : checkpoints) {
        target = std::min(target, file.info().step_count);
        for (; done < target; ++done) {
            expected += step_bytes(file.step_sizes(done));
            render_step(file, done, camera, options);
        }
        points.push_back({done, mapped_resident_bytes(path), expected, current_rss_bytes()});
    }
    return points;
}

int run_series(cli::Args& args) {
    if (args.flag("--help")) {
        std::cout << kUsage << "\n";
        return 0;
    }
    const int size = int(cli::parse_int(args.value("--size").value_or("128"), "--size", 2, 4096));
    const int n_steps = int(cli::parse_int(args.value("--steps").value_or("32"), "--steps", 1, 100000));
    const double iso = cli::parse_double(args.value("--iso").value_or("40"), "--iso");
    const int threads = int(cli::parse_int(args.value("--threads").value_or("2"), "--threads", 1, 4096));
    std::vector<int> resolutions;
    for (double r : cli::parse_list(args.value("--resolutions").value_or("512,1024"), "--resolutions")) {
        if (!(r >= 1 && r <= 16384)) throw Error("--resolutions", "expected sizes in 1..16384");
        resolutions.push_back(int(r));
    }
    const int rss_steps = int(cli::parse_int(args.value("--rss-steps").value_or("100"), "--rss-steps", 1, 100000));
    const int rss_size = int(cli::parse_int(args.value("--rss-size").value_or(std::to_string(size)), "--rss-size", 2, 4096));
    const bool no_rss = args.flag("--no-rss");
    const std::optional<std::string> keep = args.value("--keep");
    const std::string results = results_dir(args);
    args.finish();

    const fs::path tmp = keep ? fs::path(*keep) : fs::temp_directory_path() / ("octiso-bench-series-" + std::to_string(::getpid()));
    fs::create_directories(tmp);
    const std::string series_path = (tmp / "series.oct").string();
    const Dims dims{uint32_t(size), uint32_t(size), uint32_t(size)};

    // 1. Convert the sequence in a child process: its peak RSS against one step of input.
    std::cerr << "converting plume-series:" << size << "," << n_steps << " ...\n";
    const Conversion conv = convert_series(size, n_steps, threads, series_path);
    const uint64_t step_input = conv.input_bytes / uint64_t(n_steps);

    // 2. Resident memory while rendering, on a fresh mapping of a (by default 100-step) series.
    std::vector<RssPoint> rss;
    uint64_t rss_file_bytes = 0;
    int rss_file_steps = n_steps, rss_file_size = size;   // the series measured (reused when big enough)
    if (!no_rss) {
        std::string rss_path = series_path;
        if (n_steps < rss_steps || rss_size != size) {
            rss_file_steps = rss_steps, rss_file_size = rss_size;
            rss_path = (tmp / "series_rss.oct").string();
            std::cerr << "converting plume-series:" << rss_size << "," << rss_steps << " for the memory measurement ...\n";
            convert_series(rss_size, rss_steps, threads, rss_path);
        }
        rss_file_bytes = fs::file_size(rss_path);
        std::vector<uint32_t> checkpoints;
        for (uint32_t c : {1u, 10u, 50u})
            if (c <= uint32_t(rss_steps)) checkpoints.push_back(c);
        rss = measure_rss(rss_path, checkpoints, iso, threads);
        if (rss_path != series_path) fs::remove(rss_path);
    }

    // 3. Per step: sizes, zstd -3 of the generated raw step, exact decode, and frames per second.
    const OctFile file = OctFile::open(series_path);
    std::vector<StepRow> rows;
    RenderOptions options;
    options.isovalues = {iso};
    options.threads = threads;
    for (uint32_t k = 0; k < uint32_t(n_steps); ++k) {
        StepRow row;
        row.step = k;
        const LoadedVolume raw = synthetic_step("plume-series", dims, k);
        row.raw_bytes = raw.bytes();
        row.octree_bytes = step_bytes(file.step_sizes(k));
        row.zstd_bytes = zstd_bytes(raw.data(), raw.bytes());
        std::vector<uint8_t> decoded(raw.bytes());
        decode_to_dense(file.step<uint8_t>(k), decoded.data());
        row.exact = std::equal(decoded.begin(), decoded.end(), reinterpret_cast<const uint8_t*>(raw.data()));
        for (int r : resolutions) {
            const Camera camera = frame_data_box(dims, file.info().placement, r, r);
            const Clock::time_point t0 = Clock::now();
            const Frame frame = render_step(file, k, camera, options);
            row.seconds.push_back(seconds_since(t0));
            row.hit_fraction.push_back(double(frame.stats.hits) / double(std::max<uint64_t>(frame.stats.rays, 1)));
        }
        std::cerr << "\rstep " << k + 1 << "/" << n_steps << std::flush;
        rows.push_back(std::move(row));
    }
    std::cerr << "\n";

    // 4. Tables: per step, the Table 4 / Table 1 summaries, memory.
    std::vector<std::string> header = {"step", "raw MiB", "octree MiB", "% raw", "zstd-3 MiB", "zstd % raw", "exact"};
    for (int r : resolutions) header.push_back("fps " + std::to_string(r) + "^2");
    Table per_step(header);
    uint64_t raw_sum = 0, oct_sum = 0, zstd_sum = 0;
    bool all_exact = true;
    for (const StepRow& s : rows) {
        std::vector<std::string> cells = {std::to_string(s.step), mib(s.raw_bytes), mib(s.octree_bytes),
                                          fmt(100.0 * double(s.octree_bytes) / double(s.raw_bytes), 2), mib(s.zstd_bytes),
                                          fmt(100.0 * double(s.zstd_bytes) / double(s.raw_bytes), 2), s.exact ? "yes" : "NO"};
        for (double t : s.seconds) cells.push_back(fmt(1.0 / t, 2));
        per_step.add(cells);
        raw_sum += s.raw_bytes, oct_sum += s.octree_bytes, zstd_sum += s.zstd_bytes;
        all_exact = all_exact && s.exact;
    }
    std::cout << "octiso-bench series: plume-series " << size << "^3 x " << n_steps << " steps, iso " << iso << ", "
              << threads << " threads; " << machine_description() << "\n";
    per_step.print(std::cout);

    Table fps({"resolution", "mean fps", "min fps", "median fps", "max fps", "frames", "sequence s", "hit fraction"});
    for (size_t r = 0; r < resolutions.size(); ++r) {
        std::vector<double> f;
        double total = 0, hits = 0;
        for (const StepRow& s : rows) {
            f.push_back(1.0 / s.seconds[r]);
            total += s.seconds[r];
            hits += s.hit_fraction[r];
        }
        std::sort(f.begin(), f.end());
        fps.add({std::to_string(resolutions[r]) + "^2", fmt(double(rows.size()) / total, 2), fmt(f.front(), 2),
                 fmt(f[f.size() / 2], 2), fmt(f.back(), 2), std::to_string(rows.size()), fmt(total, 2),
                 fmt(hits / double(rows.size()), 3)});
    }
    std::cout << "\nTable 4 analogue (frames/s, wall time of render() per frame):\n";
    fps.print(std::cout);

    Table sizes({"", "raw MiB", "octree MiB", "% raw", "zstd-3 MiB", "zstd % raw"});
    auto pct = [](uint64_t a, uint64_t b) { return fmt(100.0 * double(a) / double(b), 2); };
    std::vector<double> per_pct;
    for (const StepRow& s : rows) per_pct.push_back(100.0 * double(s.octree_bytes) / double(s.raw_bytes));
    std::sort(per_pct.begin(), per_pct.end());
    sizes.add({"one step (median % raw)", mib(step_input), "", fmt(per_pct[per_pct.size() / 2], 2), "", ""});
    sizes.add({"sequence: sum of steps", mib(raw_sum), mib(oct_sum), pct(oct_sum, raw_sum), mib(zstd_sum), pct(zstd_sum, raw_sum)});
    sizes.add({"sequence: .oct file", mib(raw_sum), mib(conv.file_bytes), pct(conv.file_bytes, raw_sum), "", ""});
    std::cout << "\nTable 1 analogue (sizes; zstd -3 per step, summed):\n";
    sizes.print(std::cout);
    std::cout << "conversion: " << fmt(conv.build_seconds, 2) << " s build (" << fmt(conv.mvoxels_per_second, 1)
              << " Mvoxels/s), " << fmt(conv.total_seconds, 2) << " s total, peak RSS " << mib(conv.peak_rss) << " MiB = "
              << fmt(double(conv.peak_rss) / double(step_input), 2) << " x one step's input (" << mib(step_input) << " MiB)\n";
    if (!rss.empty()) {
        Table mem({"steps rendered", "mapped resident MiB", "bytes of rendered steps MiB", "file MiB", "process RSS MiB"});
        for (const RssPoint& p : rss)
            mem.add({std::to_string(p.rendered), mib(p.mapped), mib(p.expected), mib(rss_file_bytes), mib(p.total)});
        std::cout << "\nResident memory of a " << rss_file_steps << "-step " << rss_file_size << "^3 series while rendering steps 0.. in order at 256^2:\n";
        mem.print(std::cout);
    }

    std::string command = "octiso-bench series --size " + std::to_string(size) + " --steps " + std::to_string(n_steps) +
                          " --iso " + fmt(iso, 1) + " --threads " + std::to_string(threads);
    const std::string name = size == 128 && n_steps == 32 ? "series" : "series_" + std::to_string(size) + "x" + std::to_string(n_steps);
    const std::string json = write_json(results, name, [&](cli::JsonWriter& j) {
        j.begin_object().field("bench", "series").field("machine", machine_description()).field("command", command);
        j.field("size", size).field("steps", n_steps).field("iso", iso).field("threads", threads);
        j.key("resolutions").array(resolutions);
        j.key("conversion").begin_object().field("file_bytes", conv.file_bytes).field("input_bytes", conv.input_bytes);
        j.field("step_input_bytes", step_input).field("peak_rss_bytes", conv.peak_rss);
        j.field("build_seconds", conv.build_seconds).field("total_seconds", conv.total_seconds);
        j.field("mvoxels_per_second", conv.mvoxels_per_second).end_object();
        j.key("per_step").begin_array();
        for (const StepRow& s : rows) {
            j.begin_object().field("step", s.step).field("raw_bytes", s.raw_bytes).field("octree_bytes", s.octree_bytes);
            j.field("zstd3_bytes", s.zstd_bytes).field("exact", s.exact);
            j.key("seconds").array(s.seconds).key("hit_fraction").array(s.hit_fraction).end_object();
        }
        j.end_array();
        j.key("sequence").begin_object().field("raw_bytes", raw_sum).field("octree_bytes", oct_sum);
        j.field("file_bytes", conv.file_bytes).field("zstd3_bytes", zstd_sum).end_object();
        j.key("rss").begin_object().field("steps_in_file", rss_file_steps).field("size", rss_file_size).field("file_bytes", rss_file_bytes);
        j.key("points").begin_array();
        for (const RssPoint& p : rss)
            j.begin_object().field("rendered", p.rendered).field("mapped_resident_bytes", p.mapped)
                .field("rendered_step_bytes", p.expected).field("process_rss_bytes", p.total).end_object();
        j.end_array().end_object();
        j.end_object();
    });
    std::cerr << "results: " << json << "\n";
    plot("series", json, results + "/" + name + ".png");
    if (!keep) fs::remove_all(tmp);
    return all_exact ? 0 : 1;
}

static const bool kRegistered =
    register_bench("series", "time series: fps per step, per-step/sequence size vs zstd -3, RSS as steps render", &run_series);

}  // namespace
}  // namespace octiso::bench
