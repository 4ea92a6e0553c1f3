// octiso-bench mpi: octiso-render under mpirun on this machine (issue 15). For each mode of
// --distribute (steps: the frames dealt to free ranks; image: sort-first; data: sort-last) and
// ranks x threads in {1x1, 2x1, 1x2}: frame time at 512^2 and 1024^2 and the bytes each rank sends
// per frame. Then the series target (32 steps, R ranks of one thread against one rank, runs
// interleaved), the sort-last residency (each rank's mapped bytes of the file against the bytes of
// the nodes its brick overlaps, which is all it may need) and a written model of compositing on a
// cluster, marked as a model. Every run is a real mpirun of the built octiso-render, parsed from
// its --json (nlohmann-json); the images are the tool's (tests/mpi checks them bit for bit).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <vector>

#include "bench/bench.h"
#include "bench/tools.h"
#include "octiso/any_octree.h"
#include "octiso/bricks.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"

#ifndef OCTISO_MPIEXEC
#define OCTISO_MPIEXEC ""
#endif

namespace octiso::bench {
namespace {

const char* const kMpiUsage =
    "usage: octiso-bench mpi [--size N] [--series N,STEPS] [--rounds K] [--only series] [--quick] [--results DIR]\n"
    "  plume N^3 (default 512) for the frames and the residency, plume-series N,STEPS (default 128,32)\n"
    "  for the series; K interleaved rounds of the series runs (default 3)";

using nlohmann::json;

/// Runs `mpirun -np ranks octiso-render args` and returns its --json (rank 0's stdout).
json mpirun_render(int ranks, const std::vector<std::string>& args, double& outer_seconds) {
    // --bind-to none: Open MPI binds each rank to one core by default (np <= 2), which would put
    // a rank's TBB threads on one core (measured: 1 rank x 2 threads no faster than x 1).
    std::string cmd = shell_quote(OCTISO_MPIEXEC) + " --bind-to none --oversubscribe -np " + std::to_string(ranks) + " " +
                      shell_quote(tools_dir() + "/octiso-render");
    for (const std::string& a : args) cmd += " " + shell_quote(a);
    cmd += " --json 2>/dev/null";
    const auto t0 = std::chrono::steady_clock::now();
    std::FILE* p = ::popen(cmd.c_str(), "r");
    if (!p) throw Error("mpirun", "cannot start", ErrorKind::Other);
    std::string out;
    char buf[65536];
    for (size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
    const int status = ::pclose(p);
    outer_seconds = seconds_since(t0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) throw Error("mpirun", "failed: " + cmd, ErrorKind::Other);
    return json::parse(out);
}

/// Bytes of the records a brick's cells reach: every interior node and cap whose cube meets the
/// box (the root and the coarse nodes over the face included).
template <typename T> uint64_t brick_bytes(const Octree<T>& t, const CellBox& b) {
    if (b.empty()) return 0;
    uint64_t bytes = 0;
    const auto meets = [&](const Coord& o, uint64_t side) {
        const uint32_t lo[3] = {o.x, o.y, o.z};
        for (int a = 0; a < 3; ++a)
            if (lo[a] + side <= b.lo[a] || lo[a] >= b.hi[a]) return false;
        return true;
    };
    const auto visit = [&](auto&& self, int d, uint32_t index, const Coord& o) -> void {
        bytes += sizeof(InteriorNode<T>);
        const InteriorNode<T>& n = t.node(d, index);
        const uint32_t half = t.child_bit(d);
        for (int c = 0; c < 8; ++c) {
            const Coord co{o.x + ((c & 4) ? half : 0), o.y + ((c & 2) ? half : 0), o.z + ((c & 1) ? half : 0)};
            if (n.is_scalar_leaf(c) || !meets(co, half)) continue;
            if (d + 1 == t.dmax() - 1) bytes += n.cap_record_bytes();   // a packed cap (octree.h)
            else self(self, d + 1, t.child_index(d, index, n, c), co);
        }
    };
    visit(visit, 0, 0, Coord{});
    return bytes;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

struct ModeRow {
    std::string mode;
    int ranks = 1, threads = 1, size = 512;
    double frame_seconds = 0;
    double bytes_per_rank = 0;   // mean over ranks and frames
};

int run_mpi(cli::Args& args) {
    if (args.flag("--help")) {
        std::cout << kMpiUsage << "\n";
        return 0;
    }
    const bool quick = args.flag("--quick");
    const auto size_flag = args.value("--size"), series_flag = args.value("--series"), rounds_flag = args.value("--rounds");
    const auto only = args.value("--only");
    const std::string results = results_dir(args);
    args.finish();
    if (only && *only != "series") throw Error("--only", "expected series, found '" + *only + "'");
    const bool all_parts = !only;
    if (std::string(OCTISO_MPIEXEC).empty()) throw Error("mpi", "this octiso-bench was built without MPI", ErrorKind::Other);
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);   // CI runs as root
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    const int n = size_flag ? int(cli::parse_int(*size_flag, "--size", 8, 4096)) : quick ? 64 : 512;
    const std::string series_spec = series_flag ? *series_flag : quick ? "40,4" : "128,32";
    const int rounds = rounds_flag ? int(cli::parse_int(*rounds_flag, "--rounds", 1, 100)) : quick ? 1 : 3;
    const std::vector<int> sizes = quick ? std::vector<int>{96} : std::vector<int>{512, 1024};
    const int orbit = quick ? 2 : 4;
    const std::string dir = std::filesystem::temp_directory_path().string() + "/octiso-bench-mpi-" + std::to_string(::getpid());
    std::filesystem::create_directories(dir);
    const std::string volume = dir + "/plume.oct", series = dir + "/series.oct";
    if (all_parts) run_tool("octiso-convert", {"--synthetic", "plume:" + std::to_string(n), "-o", volume});
    run_tool("octiso-convert", {"--synthetic", "plume-series:" + series_spec, "-o", series});
    const std::string iso = fmt(default_isovalue("plume"), 1);

    // 1. Modes x ranks x threads: frame time (an orbit's frames; steps: wall / frames, as the
    // frames run side by side) and bytes sent per rank per frame.
    std::vector<ModeRow> modes;
    for (const int size : all_parts ? sizes : std::vector<int>{})
        for (const std::string mode : {"steps", "image", "data"})
            for (const auto& [ranks, threads] : {std::pair{1, 1}, std::pair{2, 1}, std::pair{1, 2}}) {
                const std::string s = std::to_string(size);
                double outer = 0;
                const json r = mpirun_render(ranks, {volume, "--iso", iso, "--distribute", mode, "--orbit", std::to_string(orbit),
                                                     "-o", dir + "/m_%02d.png", "--size", s + "x" + s, "--threads",
                                                     std::to_string(threads)},
                                             outer);
                ModeRow row{mode, ranks, threads, size};
                std::vector<double> frames;
                double bytes = 0, shares = 0;
                for (const json& f : r["frames"]) {
                    frames.push_back(f["frame_seconds"].get<double>());
                    if (f.contains("ranks"))
                        for (const json& q : f["ranks"]) bytes += q["bytes_sent"].get<double>(), shares += 1;
                }
                row.frame_seconds = mode == std::string("steps") ? r["wall_seconds"].get<double>() / double(frames.size()) : median(frames);
                row.bytes_per_rank = shares > 0 ? bytes / shares : 0;
                modes.push_back(row);
            }

    // 2. The series target: R ranks x 1 thread against 1 rank, runs interleaved, median of rounds.
    std::vector<double> wall[3], outer_wall[3];
    long long steps = 0;
    for (int k = 0; k < rounds; ++k)
        for (const int ranks : {1, 2}) {
            double outer = 0;
            const json r = mpirun_render(ranks, {series, "--iso", iso, "-o", dir + "/s_%04d.png", "--threads", "1"}, outer);
            wall[ranks].push_back(r["wall_seconds"].get<double>());
            outer_wall[ranks].push_back(outer);
            steps = (long long)r["frames"].size();
        }
    const double speedup = median(wall[1]) / median(wall[2]), outer_speedup = median(outer_wall[1]) / median(outer_wall[2]);

    // 3. Sort-last residency: 2 and 4 ranks, one frame each at the first size.
    struct Residency {
        int ranks, rank;
        uint64_t resident, brick, share;
    };
    std::vector<Residency> residency;
    for (const int ranks : all_parts ? std::vector<int>{2, 4} : std::vector<int>{}) {
        const std::shared_ptr<const OctFile> file = std::make_shared<const OctFile>(OctFile::open(volume));
        const AnyOctree tree = AnyOctree::step(file, 0);
        const Octree<uint8_t>* typed = tree.as<uint8_t>();
        if (!typed) throw Error(volume, "expected u8 plume", ErrorKind::Other);
        const std::string s = std::to_string(sizes.front());
        double outer = 0;
        const json r = mpirun_render(ranks, {volume, "--iso", iso, "--distribute", "data", "-o", dir + "/r.png", "--size", s + "x" + s,
                                             "--threads", "1"},
                                     outer);
        const std::vector<CellBox> bricks = slab_bricks(tree.info().dims, ranks);
        for (const json& q : r["per_rank"]) {
            const int rank = q["rank"].get<int>();
            residency.push_back({ranks, rank, q["file_resident_bytes"].get<uint64_t>(), brick_bytes(*typed, bricks[size_t(rank)]),
                                 file->file_bytes() / uint64_t(ranks)});
        }
    }
    std::filesystem::remove_all(dir);

    std::cout << "octiso-render under mpirun (" << machine_description() << "), plume " << n << "^3, iso " << iso << "\n";
    Table t({"mode", "ranks x threads", "size", "frame ms", "vs 1x1", "bytes sent per rank per frame"});
    for (const ModeRow& m : modes) {
        double base = 0;
        for (const ModeRow& b : modes)
            if (b.mode == m.mode && b.size == m.size && b.ranks == 1 && b.threads == 1) base = b.frame_seconds;
        t.add({m.mode, std::to_string(m.ranks) + "x" + std::to_string(m.threads), std::to_string(m.size), fmt(1e3 * m.frame_seconds, 1),
               fmt(base / m.frame_seconds, 2) + "x", m.bytes_per_rank > 0 ? fmt(m.bytes_per_rank / 1048576.0, 2) + " MiB" : "-"});
    }
    t.print(std::cout);
    std::cout << "\nseries, " << steps << " steps of plume-series " << series_spec << " at 512^2, 1 thread per rank, median of " << rounds
              << " interleaved rounds: 1 rank " << fmt(median(wall[1]), 3) << " s, 2 ranks " << fmt(median(wall[2]), 3)
              << " s: " << fmt(speedup, 2) << "x (target >= 1.8x; with process start-up " << fmt(outer_speedup, 2) << "x)\n\n";
    Table rt({"ranks", "rank", "mapped MiB", "brick's nodes MiB", "mapped / brick", "file / ranks MiB"});
    bool residency_ok = true;
    for (const Residency& r : residency) {
        const double ratio = r.brick ? double(r.resident) / double(r.brick) : 0;
        residency_ok &= ratio <= 1.10;
        rt.add({std::to_string(r.ranks), std::to_string(r.rank), fmt(r.resident / 1048576.0, 2), fmt(r.brick / 1048576.0, 2),
                fmt(ratio, 2), fmt(r.share / 1048576.0, 2)});
    }
    rt.print(std::cout);

    // 4. The model (not a measurement): a radix-k / binary-swap style reduce-scatter moves
    // (1 - 1/R) of the frame per rank in log2 R rounds, then the gather of 1/R slices to rank 0.
    std::cout << "\nMODEL, not measured: sort-last compositing of a 1024^2 frame (12-byte samples: depth, ordinal, colour) on\n"
                 "a cluster with 10 GB/s links, 2 us latency, 1 GB/s of compositing per core\n";
    Table mt({"ranks", "sent per rank MiB", "rank 0 gathers MiB", "reduce-scatter ms", "gather ms", "total ms"});
    const double frame = 1024.0 * 1024.0 * 12.0, link = 10e9, latency = 2e-6, merge = 1e9;
    for (const int ranks : {2, 8, 64, 512, 4096}) {
        const double rs = std::log2(double(ranks)) * latency + (1 - 1.0 / ranks) * frame / link + (1 - 1.0 / ranks) * frame / merge;
        const double gather = latency * std::log2(double(ranks)) + (1 - 1.0 / ranks) * frame / link;
        mt.add({std::to_string(ranks), fmt((1 - 1.0 / ranks) * frame / 1048576.0 + frame / ranks / 1048576.0, 2),
                fmt((1 - 1.0 / ranks) * frame / 1048576.0, 2), fmt(1e3 * rs, 2), fmt(1e3 * gather, 2), fmt(1e3 * (rs + gather), 2)});
    }
    mt.print(std::cout);
    std::cout << "(the cost levels off at about two frames' transfer and one frame's merge per rank: compositing does not\n"
                 " grow with the rank count, the gather to rank 0 is the serial part)\n";

    const std::string path = write_json(results, quick ? "mpi_quick" : all_parts ? "mpi" : "mpi_series", [&](cli::JsonWriter& j) {
        j.begin_object();
        j.field("machine", machine_description()).field("plume", n).field("series_spec", series_spec).field("iso", iso);
        j.key("modes").begin_array();
        for (const ModeRow& m : modes)
            j.begin_object().field("mode", m.mode).field("ranks", m.ranks).field("threads", m.threads).field("size", m.size)
                .field("frame_seconds", m.frame_seconds).field("bytes_sent_per_rank", m.bytes_per_rank).end_object();
        j.end_array();
        j.key("series").begin_object().field("steps", steps).field("rounds", rounds);
        j.key("wall_1_rank").array(wall[1]).key("wall_2_ranks").array(wall[2]);
        j.field("speedup", speedup).field("speedup_with_startup", outer_speedup).end_object();
        j.key("residency").begin_array();
        for (const Residency& r : residency)
            j.begin_object().field("ranks", r.ranks).field("rank", r.rank).field("mapped_bytes", r.resident)
                .field("brick_node_bytes", r.brick).field("file_bytes_over_ranks", r.share).end_object();
        j.end_array();
        j.end_object();
    });
    std::cout << "wrote " << path << "\n";
    if (!residency_ok) std::cout << "note: a rank mapped more than 110 % of its brick's nodes\n";
    return 0;
}

const bool kRegistered = register_bench("mpi", "octiso-render under mpirun: modes x ranks x threads, series speed-up, sort-last residency",
                                        &run_mpi);

}  // namespace
}  // namespace octiso::bench
