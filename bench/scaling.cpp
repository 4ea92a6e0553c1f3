// octiso-bench scaling (issue 5, item 3; the paper's Fig. 9): frames/s of render() (default path: packets, shading)
// on 1..nproc threads at 512^2 and 1024^2, and the load-balance bound of the dynamic tile scheduler
// on 1..64 workers: 8x8 blocks timed single-threaded, summed into tiles, list-scheduled in TBB's
// split order (each worker takes the next tile when free: work stealing without overhead); speedup
// = sum / makespan. A static split into P equal runs of tiles is shown for contrast. The model adds
// what the pure schedule leaves out: the serial per-frame time of render() (measured: call time -
// tile-loop time) and the machine's own ceiling (a compute-bound loop on 1..nproc threads, which
// sees shared caches, clocks and other processes). Every simulated figure is labelled simulated.
#include <time.h>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <queue>
#include <sstream>
#include <thread>

#include "bench/bench.h"
#include "octiso/build.h"
#include "octiso/error.h"
#include "octiso/any_octree.h"
#if OCTISO_SCALING_READS_FILES
#include "octiso/reader.h"
#endif
#include "octiso/render.h"
#include "octiso/tiles.h"
#include "octiso/synthetic.h"
#include "render/pinhole_camera.h"
#include "render/traverse.h"

namespace octiso::bench {

double avx2_fma_chains(int iterations);   // ceiling_avx2.cpp (built for AVX2 + FMA)

namespace {

const char* const kScalingUsage =
    "usage: octiso-bench scaling [--dataset NAME] [--size N] [--images 512,1024] [--iso V] [--repeats N]\n"
    "                            [--max-threads N] [--threads 1,2,4,8,16] [--tile-order split|sweep|both] [--no-build]\n"
    "                            [--mri FILE] [--quick]\n"
    "  NAME: plume (default), mixing (synthetic N^3, default 256), mri, or a .oct file (step 0; no build rows)\n"
    "  --threads: the thread counts measured (default 1 .. --max-threads, all cores)\n"
    "  --tile-order: how tiles go to threads (tiles.h; default split, the renderer's); both: rows of each\n"
    "  --no-build: render rows only (the build is measured on 1..N threads for a synthetic or mri volume)\n"
    "  --quick: 128^3, images 256 and 512, 2 repeats";

/// Makespan of greedy list scheduling: tiles in order, each to the worker that is free first.
double list_schedule_makespan(const std::vector<double>& cost, int workers) {
    std::priority_queue<double, std::vector<double>, std::greater<double>> free_at;
    for (int i = 0; i < workers; ++i) free_at.push(0.0);
    double makespan = 0;
    for (double c : cost) {
        const double start = free_at.top();
        free_at.pop();
        free_at.push(start + c);
        makespan = std::max(makespan, start + c);
    }
    return makespan;
}

/// Makespan of a static split: P contiguous runs of (nearly) equal tile count.
double static_makespan(const std::vector<double>& cost, int workers) {
    double makespan = 0;
    const size_t n = cost.size();
    for (int w = 0; w < workers; ++w) {
        double sum = 0;
        for (size_t i = n * size_t(w) / size_t(workers); i < n * size_t(w + 1) / size_t(workers); ++i) sum += cost[i];
        makespan = std::max(makespan, sum);
    }
    return makespan;
}

/// Wall seconds of `work()` (which returns a value, kept observable) run once on each of `threads`
/// threads at once in a task arena; median of `repeats` runs. The ceiling speedup at P is
/// P * t(1) / t(P).
template <class Work> double ceiling_seconds(int threads, int repeats, Work&& work) {
    std::vector<double> s;
    for (int r = 0; r < repeats; ++r) {
        tbb::task_arena arena(threads);
        std::atomic<double> sink{0};
        const auto t0 = std::chrono::steady_clock::now();
        arena.execute([&] { tbb::parallel_for(0, threads, [&](int) { sink = sink + work(); }, tbb::static_partitioner()); });
        s.push_back(seconds_since(t0));
        if (sink.load() == -1.0) std::cerr << "";   // keep the loop observable
    }
    std::sort(s.begin(), s.end());
    return s[s.size() / 2];
}

/// The machine's ceiling: a compute-bound loop (8 independent scalar multiply-add chains, no
/// memory traffic) of fixed length per thread.
double compute_bound_seconds(int threads, int repeats) {
    return ceiling_seconds(threads, repeats, [] {
        double x[8] = {1, 2, 3, 4, 5, 6, 7, 8};
        for (int i = 0; i < 20'000'000; ++i)
            for (double& v : x) v = v * 0.999999 + 1e-7;
        double sum = 0;
        for (double v : x) sum += v;
        return sum;
    });
}

/// The same ceiling with 256-bit FMA chains (the renderer's kernel is AVX2; AVX2 CPUs only).
double avx2_bound_seconds(int threads, int repeats) {
    return ceiling_seconds(threads, repeats, [] { return avx2_fma_chains(20'000'000); });
}

/// CPU seconds of the whole process (all threads, spinning workers included).
double process_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct Measured {
    int width = 0, threads = 0;
    TileOrder order = TileOrder::split;
    std::vector<double> seconds;       // wall seconds of the tile loop (RenderStats)
    std::vector<double> cpu_seconds;   // process CPU seconds of the whole render() call
    std::vector<double> call_seconds;  // wall seconds of the whole render() call (setup included)
    std::vector<double> busy_seconds;  // thread seconds inside tiles (RenderStats::busy_seconds)
    static double median_of(std::vector<double> s) {
        std::sort(s.begin(), s.end());
        return s.empty() ? 0 : s[s.size() / 2];
    }
    double median() const {
        std::vector<double> s = seconds;
        std::sort(s.begin(), s.end());
        return s[s.size() / 2];
    }
};

/// One thread count of the build (in memory, the octree only: build_octree's own phases).
struct BuildRow {
    int threads = 0;
    std::vector<double> seconds;
    std::vector<BuildPhases> phases;
    double median() const { return Measured::median_of(seconds); }
    /// The per-phase medians.
    BuildPhases median_phases() const {
        const auto med = [&](double BuildPhases::*f) {
            std::vector<double> v;
            for (const BuildPhases& p : phases) v.push_back(p.*f);
            return Measured::median_of(v);
        };
        return {med(&BuildPhases::prepare), med(&BuildPhases::pieces), med(&BuildPhases::top),
                med(&BuildPhases::concatenate), med(&BuildPhases::release), med(&BuildPhases::pieces_busy)};
    }
};

const char* order_name(TileOrder order) { return order == TileOrder::sweep ? "sweep" : "split"; }

/// Amdahl's bound at P threads for a run whose `serial` seconds of `total` cannot overlap.
double amdahl_efficiency(double serial, double total, int p) {
    if (total <= 0) return 1;
    const double f = std::clamp(serial / total, 0.0, 1.0);
    return 1.0 / (f * p + (1.0 - f));
}

struct Simulated {
    int width = 0, tile = 16;
    uint64_t tiles = 0;
    double sum_seconds = 0, max_tile_seconds = 0;
    double serial_seconds = 0;   ///< measured per-frame serial time of render() at this size
    std::vector<int> workers;
    std::vector<double> dynamic_speedup, static_speedup;
    /// (serial + sum) / (serial + makespan): the schedule with the serial per-frame work.
    std::vector<double> serial_speedup;
    /// The same with every worker slowed to the machine's measured ceiling efficiency at P (at
    /// P > nproc the ceiling cannot be measured here and the value at nproc is used, an upper bound).
    std::vector<double> model_speedup;
};

/// Seconds of each 8x8 block of the frame (row-major, ceil(W/8) per row), single-threaded on the
/// direct path; the minimum of `passes` timings per block, so an interruption by another process
/// does not count as cost. Tiles of 16 (or 8) are sums of their blocks.
template <typename T>
std::vector<double> block_costs(const Octree<T>& tree, const Placement& placement, const Camera& camera, double iso,
                                int passes) {
    const OctreeTracer<T, Neubauer> tracer(tree, placement, &iso, 1, Neubauer{});
    const PinholeCamera pinhole(camera);
    const int bw = (camera.width + 7) / 8, bh = (camera.height + 7) / 8;
    std::vector<double> cost(size_t(bw) * bh, 1e300);
    uint64_t sink = 0;
    for (int p = 0; p < passes; ++p)
        for (int by = 0; by < bh; ++by)
            for (int bx = 0; bx < bw; ++bx) {
                const auto t0 = std::chrono::steady_clock::now();
                for (int py = by * 8; py < std::min(by * 8 + 8, camera.height); ++py)
                    for (int px = bx * 8; px < std::min(bx * 8 + 8, camera.width); ++px)
                        sink += tracer.trace(pinhole.ray(px, py), true).is_hit();
                double& c = cost[size_t(by) * bw + bx];
                c = std::min(c, seconds_since(t0));
            }
    if (sink == uint64_t(-1)) std::cerr << "";   // keep the traces observable
    return cost;
}

/// Costs of the tiles of render()'s TileGrid of side `ts`, in the order its tile loop hands them
/// out when run serially (row-major: tile_loop.h splits the tile index range, lowest first): the
/// sum of the 8x8 blocks whose corner lies in each.
std::vector<double> tile_costs(const std::vector<double>& blocks, int width, int height, int ts) {
    const TileGrid grid{width, height, ts};
    const int bw = (width + 7) / 8;
    std::vector<double> cost;
    for (int i = 0; i < grid.count(); ++i) {
        const PixelRect t = grid.rect(i);
        double c = 0;
        for (int by = (t.y0 + 7) / 8; by * 8 < t.y1; ++by)
            for (int bx = (t.x0 + 7) / 8; bx * 8 < t.x1; ++bx) c += blocks[size_t(by) * bw + bx];
        cost.push_back(c);
    }
    return cost;
}

int run_scaling(cli::Args& args) {
    if (args.flag("--help")) {
        std::cout << kScalingUsage << "\n";
        return 0;
    }
    const bool quick = args.flag("--quick"), no_build = args.flag("--no-build");
    const auto ds = args.value("--dataset");
    const auto size_flag = args.value("--size");
    const auto images_flag = args.value("--images");
    const auto iso_flag = args.value("--iso");
    const auto repeats_flag = args.value("--repeats");
    const auto max_threads_flag = args.value("--max-threads");
    const auto threads_flag = args.value("--threads");
    const auto order_flag = args.value("--tile-order");
    const auto mri_flag = args.value("--mri");
    const std::string results = results_dir(args);
    args.finish();

    const std::string name = ds ? *ds : "plume";
    const uint32_t n = size_flag ? uint32_t(cli::parse_int(*size_flag, "--size", 8, 2048)) : quick ? 128 : 256;
    std::vector<int> widths = quick ? std::vector<int>{256, 512} : std::vector<int>{512, 1024};
    if (images_flag) {
        widths.clear();
        for (double w : cli::parse_list(*images_flag, "--images")) {
            if (!(w >= 16 && w <= 16384 && w == std::floor(w))) throw Error("--images", "expected square sizes 16 .. 16384");
            widths.push_back(int(w));
        }
    }
    const int repeats = repeats_flag ? int(cli::parse_int(*repeats_flag, "--repeats", 1, 1000)) : quick ? 2 : 3;
    const int hw = int(std::max(1u, std::thread::hardware_concurrency()));
    const int max_threads = max_threads_flag ? int(cli::parse_int(*max_threads_flag, "--max-threads", 1, 1024)) : hw;
    std::vector<int> thread_counts;
    if (threads_flag) {
        for (double t : cli::parse_list(*threads_flag, "--threads")) {
            if (!(t >= 1 && t <= 1024 && t == std::floor(t))) throw Error("--threads", "expected thread counts 1 .. 1024");
            thread_counts.push_back(int(t));
        }
        std::sort(thread_counts.begin(), thread_counts.end());
        thread_counts.erase(std::unique(thread_counts.begin(), thread_counts.end()), thread_counts.end());
        if (thread_counts.front() != 1) thread_counts.insert(thread_counts.begin(), 1);   // speed-ups are against 1
    } else {
        for (int p = 1; p <= max_threads; ++p) thread_counts.push_back(p);
    }
    std::vector<TileOrder> orders{TileOrder::split};
    if (order_flag) {
        if (*order_flag == "sweep") orders = {TileOrder::sweep};
        else if (*order_flag == "both") orders = {TileOrder::split, TileOrder::sweep};
        else if (*order_flag != "split") throw Error("--tile-order", "expected split, sweep or both, found '" + *order_flag + "'");
    }
    // The volume (synthetic or read; the build is measured on it) or a converted file (render only).
    const bool from_file = name.size() > 4 && name.compare(name.size() - 4, 4, ".oct") == 0;
    std::optional<LoadedVolume> volume;
    std::optional<AnyOctree> tree;
    if (from_file) tree = AnyOctree::open(name);
    else if (name == "plume" || name == "mixing") volume = synthetic_step(name, Dims{n, n, n}, 0);
#if OCTISO_SCALING_READS_FILES
    else if (name == "mri") volume = open_volume(mri_flag ? *mri_flag : "/usr/share/mricron/templates/ch2.nii.gz", RawOptions{});
#else
    else if (name == "mri") throw Error("--dataset", "mri is read through VTK, which octiso-probe leaves out: convert it and pass the .oct");
#endif
    else throw Error("--dataset", "expected plume, mixing, mri or a .oct file, found '" + name + "'");
    if (!volume && mri_flag) throw Error("--mri", "only with --dataset mri");
    if (volume) tree = AnyOctree::build(*volume, BuildOptions{});
    const double iso = iso_flag ? cli::parse_double(*iso_flag, "--iso") : default_isovalue(name);
    const Dims dims = tree->dims();
    const Placement placement = tree->placement();
    std::cerr << "scaling: " << name << " " << dims.x << "x" << dims.y << "x" << dims.z << ", iso " << iso << "\n";

    // The machine's ceiling on each thread count (compute-bound, so the renderer cannot beat it).
    std::vector<double> ceiling_speedup(size_t(thread_counts.back()), 0.0);   // index P-1; 0 where not measured
    {
        const int ceiling_repeats = quick ? 1 : 3;
        const double one = compute_bound_seconds(1, ceiling_repeats);
        for (int p : thread_counts)
            ceiling_speedup[size_t(p - 1)] = p == 1 ? 1.0 : double(p) * one / compute_bound_seconds(p, ceiling_repeats);
    }
    // The same with 256-bit FMA work, where the CPU has AVX2 (reported beside, not in the model).
    std::vector<double> avx2_ceiling_speedup(size_t(thread_counts.back()), 0.0);
    if (cpu_has_avx2()) {
        const int ceiling_repeats = quick ? 1 : 3;
        const double one = avx2_bound_seconds(1, ceiling_repeats);
        for (int p : thread_counts)
            avx2_ceiling_speedup[size_t(p - 1)] = p == 1 ? 1.0 : double(p) * one / avx2_bound_seconds(p, ceiling_repeats);
    }
    // The nearest measured ceiling at or below P (the model's input where P was not measured).
    const auto ceiling_at = [&](int p) {
        for (int q = std::min(p, int(ceiling_speedup.size())); q >= 1; --q)
            if (ceiling_speedup[size_t(q - 1)] > 0) return std::pair<int, double>(q, ceiling_speedup[size_t(q - 1)]);
        return std::pair<int, double>(1, 1.0);
    };

    // The build on each thread count, interleaved round by round (issue 12: conversion scaling).
    std::vector<BuildRow> builds;
    if (volume && !no_build) {
        for (int p : thread_counts) builds.push_back(BuildRow{p, {}, {}});
        for (int k = 0; k < repeats; ++k)
            for (size_t i = 0; i < builds.size(); ++i) {
                BuildRow& b = builds[k % 2 ? builds.size() - 1 - i : i];
                BuildOptions bo;
                bo.threads = b.threads;
                const auto t0 = std::chrono::steady_clock::now();
                const AnyOctree built = AnyOctree::build(*volume, bo);
                b.seconds.push_back(seconds_since(t0));
                b.phases.push_back(built.info().build_phases.value_or(BuildPhases{}));
            }
    }

    std::vector<Measured> measured;
    std::vector<Simulated> simulated;
    std::vector<int> sim_workers = {1, 2, 4, 8, 16, 32, 64};
    for (int p : thread_counts) sim_workers.push_back(p);   // the model is checked against every measured P
    std::sort(sim_workers.begin(), sim_workers.end());
    sim_workers.erase(std::unique(sim_workers.begin(), sim_workers.end()), sim_workers.end());
    dispatch_scalar_type(tree->type(), [&](auto tag) {
        using T = decltype(tag);
        const Octree<T>& octree = *tree->as<T>();
        for (int w : widths) {
            const Camera camera = frame_data_box(dims, placement, w, w);
            RenderOptions options;
            options.isovalues = {iso};
            std::vector<Measured> rows;   // the orders' rows interleave round by round
            for (TileOrder order : orders)
                for (int p : thread_counts) {
                    Measured m;
                    m.width = w, m.threads = p, m.order = order;
                    rows.push_back(m);
                }
            for (auto& r : rows) {   // warm-up
                options.threads = r.threads;
                options.tile_order = r.order;
                render(octree, placement, camera, options);
            }
            for (int k = 0; k < repeats; ++k)
                for (size_t i = 0; i < rows.size(); ++i) {
                    auto& r = rows[k % 2 ? rows.size() - 1 - i : i];   // alternate the order per round
                    options.threads = r.threads;
                    options.tile_order = r.order;
                    const double c0 = process_cpu_seconds();
                    const auto w0 = std::chrono::steady_clock::now();
                    const RenderStats stats = render(octree, placement, camera, options).stats;
                    r.call_seconds.push_back(seconds_since(w0));
                    r.cpu_seconds.push_back(process_cpu_seconds() - c0);
                    r.seconds.push_back(stats.seconds);
                    r.busy_seconds.push_back(stats.busy_seconds);
                }
            for (auto& r : rows) measured.push_back(r);
            // Serial per-frame time: the whole render() call minus its tile loop (one thread).
            std::vector<double> serial;
            for (size_t k = 0; k < rows.front().seconds.size(); ++k)
                serial.push_back(std::max(0.0, rows.front().call_seconds[k] - rows.front().seconds[k]));
            const double serial_seconds = Measured::median_of(serial);

            const std::vector<double> blocks = block_costs(octree, placement, camera, iso, quick ? 1 : 3);
            for (int ts : {16, 8}) {   // 16: the renderer's tiles; 8: what finer tiles would give
                Simulated s;
                s.width = w;
                s.tile = ts;
                const std::vector<double> cost = tile_costs(blocks, w, w, ts);
                s.tiles = cost.size();
                for (double c : cost) s.sum_seconds += c, s.max_tile_seconds = std::max(s.max_tile_seconds, c);
                s.serial_seconds = serial_seconds;
                for (int p : sim_workers) {
                    s.workers.push_back(p);
                    const double makespan = list_schedule_makespan(cost, p);
                    s.dynamic_speedup.push_back(s.sum_seconds / makespan);
                    s.static_speedup.push_back(s.sum_seconds / static_makespan(cost, p));
                    s.serial_speedup.push_back((serial_seconds + s.sum_seconds) / (serial_seconds + makespan));
                    const auto [q, ceiling] = ceiling_at(p);
                    const double ceiling_eff = ceiling / q;
                    s.model_speedup.push_back((serial_seconds + s.sum_seconds) / (serial_seconds + makespan / ceiling_eff));
                }
                simulated.push_back(s);
            }
        }
    });

    std::string load;   // other processes on the machine distort the measured (not the simulated) rows
    {
        std::ifstream f("/proc/loadavg");
        std::getline(f, load);
    }
    std::cout << "machine: " << machine_description() << "; load average at the end: " << load << "\n";
    // The model's speed-up at P for this image size and the renderer's 16^2 tiles.
    const auto model_at = [&](int width, int p) {
        for (const auto& s : simulated)
            if (s.width == width && s.tile == 16)
                for (size_t i = 0; i < s.workers.size(); ++i)
                    if (s.workers[i] == p) return s.model_speedup[i];
        return 0.0;
    };
    Table mt({"image", "tiles to threads", "threads", "frames/s", "Mrays/s", "speedup", "efficiency", "utilisation", "busy / busy(1)",
              "CPU s/frame", "CPU-work eff.", "render() setup s", "model eff.", "measured - model"});
    for (const auto& m : measured) {
        double one = 0, one_cpu = 0, one_busy = 0, one_call = 0;
        for (const auto& o : measured)   // against 1 thread of the first order (split, where measured)
            if (o.width == m.width && o.threads == 1 && o.order == orders.front())
                one = o.median(), one_cpu = Measured::median_of(o.cpu_seconds), one_busy = Measured::median_of(o.busy_seconds),
                one_call = Measured::median_of(o.call_seconds);
        const double speedup = one / m.median();
        const double cpu = Measured::median_of(m.cpu_seconds), busy = Measured::median_of(m.busy_seconds);
        const double model_eff = model_at(m.width, m.threads) / m.threads;
        // The wall-clock speed-up counts the whole render() call, as the model does (serial set-up included).
        const double call_speedup = one_call / Measured::median_of(m.call_seconds);
        mt.add({std::to_string(m.width) + "^2", order_name(m.order), std::to_string(m.threads), fmt(1.0 / m.median(), 2),
                fmt(double(m.width) * m.width / m.median() * 1e-6, 2), fmt(speedup, 3), fmt(100.0 * speedup / m.threads, 1) + " %",
                fmt(100.0 * busy / (m.threads * m.median()), 1) + " %", fmt(one_busy > 0 ? busy / one_busy : 0.0, 3),
                fmt(cpu, 3), fmt(100.0 * one_cpu / cpu, 1) + " %",
                fmt(Measured::median_of(m.call_seconds) - m.median(), 4), fmt(100.0 * model_eff, 1) + " %",
                fmt(100.0 * (call_speedup / m.threads - model_eff), 1) + " pt"});
    }
    std::cout << "measured (render(), default path: direct packet traversal, colour, median of " << repeats << " interleaved repeats); "
                 "efficiency = tile-loop speedup / P; utilisation = thread seconds inside tiles / (P x tile-loop "
                 "wall); busy / busy(1) > 1 is each tile costing more on P threads (shared caches, memory), not "
                 "scheduling; CPU-work eff. = process CPU of 1 thread / process CPU of P threads; model eff. = the "
                 "simulated schedule + serial set-up + measured ceiling at P, against the measured whole-call "
                 "efficiency (measured - model)\n";
    mt.print(std::cout);
    std::cout << "\n";
    mt.print_markdown(std::cout);
    if (!builds.empty()) {
        const double one = builds.front().median();
        const BuildPhases p1 = builds.front().median_phases();
        const double serial1 = p1.top + p1.release;
        Table bt({"threads", "build s", "Mvox/s", "speedup", "efficiency", "prepare s", "pieces s", "pieces util.",
                  "piece busy / busy(1)", "top s", "concatenate s", "release s", "serial s (top + release)",
                  "Amdahl bound eff. from 1-thread serial"});
        for (const BuildRow& b : builds) {
            const BuildPhases ph = b.median_phases();
            const double speedup = one / b.median();
            bt.add({std::to_string(b.threads), fmt(b.median(), 3), fmt(double(dims.voxels()) / b.median() * 1e-6, 1),
                    fmt(speedup, 3), fmt(100.0 * speedup / b.threads, 1) + " %", fmt(ph.prepare, 4), fmt(ph.pieces, 4),
                    fmt(ph.pieces > 0 ? 100.0 * ph.pieces_busy / (b.threads * ph.pieces) : 0.0, 1) + " %",
                    fmt(p1.pieces_busy > 0 ? ph.pieces_busy / p1.pieces_busy : 0.0, 3), fmt(ph.top, 4), fmt(ph.concatenate, 4), fmt(ph.release, 4), fmt(ph.top + ph.release, 4),
                    fmt(100.0 * amdahl_efficiency(serial1, one, b.threads), 1) + " %"});
        }
        std::cout << "\nbuild (build_octree in memory, " << dims.x << "x" << dims.y << "x" << dims.z
                  << ", median of " << repeats << " interleaved repeats; phases from BuildStats::phases)\n";
        bt.print(std::cout);
        std::cout << "\n";
        bt.print_markdown(std::cout);
    }
    Table ct({"threads", "compute-bound speedup (measured ceiling)", "ceiling eff.", "AVX2 FMA ceiling eff."});
    for (int p : thread_counts)
        ct.add({std::to_string(p), fmt(ceiling_speedup[size_t(p - 1)], 3), fmt(100.0 * ceiling_speedup[size_t(p - 1)] / p, 1) + " %",
                avx2_ceiling_speedup[size_t(p - 1)] > 0 ? fmt(100.0 * avx2_ceiling_speedup[size_t(p - 1)] / p, 1) + " %" : "-"});
    std::cout << "\nmachine ceiling (measured): a compute-bound loop of fixed length per thread (scalar; and 256-bit "
                 "FMA chains where the CPU has AVX2: clocks may drop under it on many cores)\n";
    ct.print(std::cout);
    std::cout << "\n";
    ct.print_markdown(std::cout);
    Table st({"image", "tile", "tiles", "max tile / mean", "P", "simulated dynamic eff.", "simulated static eff.",
              "serial s/frame (measured)", "simulated eff. + serial", "simulated eff. + serial + ceiling"});
    for (const auto& s : simulated)
        for (size_t i = 0; i < s.workers.size(); ++i)
            st.add({std::to_string(s.width) + "^2", std::to_string(s.tile), std::to_string(s.tiles),
                    fmt(s.max_tile_seconds / (s.sum_seconds / double(s.tiles)), 2), std::to_string(s.workers[i]),
                    fmt(100.0 * s.dynamic_speedup[i] / s.workers[i], 1) + " %", fmt(100.0 * s.static_speedup[i] / s.workers[i], 1) + " %",
                    fmt(s.serial_seconds, 4), fmt(100.0 * s.serial_speedup[i] / s.workers[i], 1) + " %",
                    fmt(100.0 * s.model_speedup[i] / s.workers[i], 1) + " %"});
    std::cout << "\nSIMULATED schedule of measured tile costs (no scheduling overhead; the last two columns add the "
                 "measured serial per-frame time and the measured machine ceiling, which beyond "
              << thread_counts.back() << " threads is assumed to stay at its " << thread_counts.back()
              << "-thread value)\n";
    st.print(std::cout);
    std::cout << "\n";
    st.print_markdown(std::cout);

    // scaling_plume_512.json, scaling_ch2better.json (a .oct by its stem): one file per dataset,
    // with _split_sweep or _sweep when the tile order is not only the default.
    const std::string stem = (from_file ? std::filesystem::path(name).stem().string()
                                        : name + (name == "mri" ? "" : "_" + std::to_string(n))) +
                             (orders.size() > 1 ? "_split_sweep" : orders.front() == TileOrder::sweep ? "_sweep" : "");
    const std::string json = write_json(results, "scaling_" + stem, [&](cli::JsonWriter& j) {
        j.begin_object();
        j.field("machine", machine_description()).field("dataset", name).field("source", tree->info().source);
        j.key("dims").array(std::vector<uint32_t>{dims.x, dims.y, dims.z});
        j.field("iso", iso).field("repeats", repeats).field("loadavg", load);
        j.key("threads").array(thread_counts);
        j.key("ceiling_speedup").array(ceiling_speedup);   // measured, index = threads - 1 (0: not measured)
        j.key("avx2_ceiling_speedup").array(avx2_ceiling_speedup);   // the same with 256-bit FMA chains (0: no AVX2)
        j.key("measured").begin_array();
        for (const auto& m : measured) {
            j.begin_object();
            j.field("width", m.width).field("tile_order", std::string(order_name(m.order))).field("threads", m.threads)
                .field("median_seconds", m.median());
            j.key("seconds").array(m.seconds);
            j.key("busy_seconds").array(m.busy_seconds);
            j.key("cpu_seconds").array(m.cpu_seconds);
            j.key("call_seconds").array(m.call_seconds);
            j.field("model_speedup", model_at(m.width, m.threads));
            j.end_object();
        }
        j.end_array();
        j.key("build").begin_array();
        for (const BuildRow& b : builds) {
            j.begin_object().field("threads", b.threads).field("median_seconds", b.median());
            j.key("seconds").array(b.seconds);
            const BuildPhases ph = b.median_phases();
            j.key("phases").begin_object().field("prepare", ph.prepare).field("pieces", ph.pieces).field("pieces_busy", ph.pieces_busy).field("top", ph.top)
                .field("concatenate", ph.concatenate).field("release", ph.release).end_object();
            j.end_object();
        }
        j.end_array();
        j.key("simulated").begin_array();
        for (const auto& s : simulated) {
            j.begin_object();
            j.field("width", s.width).field("tile", s.tile).field("tiles", s.tiles).field("sum_seconds", s.sum_seconds);
            j.field("max_tile_seconds", s.max_tile_seconds);
            j.key("workers").array(s.workers);
            j.key("dynamic_speedup").array(s.dynamic_speedup);
            j.key("static_speedup").array(s.static_speedup);
            j.field("serial_seconds", s.serial_seconds);
            j.key("serial_speedup").array(s.serial_speedup);
            j.key("model_speedup").array(s.model_speedup);
            j.end_object();
        }
        j.end_array();
        j.end_object();
    });
    std::cerr << "results: " << json << "\n";
    plot("scaling", json, results + "/scaling_" + stem + ".png");
    return 0;
}

static const bool kRegistered =
    register_bench("scaling", "frames/s on 1..nproc threads, and the simulated tile schedule on 1..64", &run_scaling);

}  // namespace
}  // namespace octiso::bench
