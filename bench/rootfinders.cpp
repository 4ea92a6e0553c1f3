// octiso-bench rootfinders (issue 4, item 4): error against run time of every root finder and
// iteration count (notes/rootfinding.md section 4). Three inputs: (a) the (cell, segment) streams
// real renders hand to first_root, recorded by a Finder policy whose first_root overload (found by
// argument-dependent lookup inside OctreeTracer) logs each call; (b) random cells; (c) whole
// frames against the exact dense reference. Topology (miss, false hit, wrong root), position
// error in cell units, normal error, ns per cell test, frame seconds; a table, JSON, a Pareto plot.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "bench/bench.h"
#include "octiso/build.h"
#include "octiso/error.h"
#include "octiso/reader.h"
#include "octiso/render.h"
#include "octiso/synthetic.h"
#include "reference/reference_render.h"
#include "render/pinhole_camera.h"
#include "render/roots.h"
#include "render/traverse.h"

namespace octiso::bench {
namespace {

constexpr const char* kUsage =
    "usage: octiso-bench rootfinders [--dataset plume,marschner-lobb,mri] [--size N] [--image WxH]\n"
    "                                [--solves N] [--random-cells N] [--repeats N] [--quick]\n"
    "  plume: synthetic N^3 (default 128, iso 40.5); marschner-lobb: N^3 f32 (default 64, iso 0.5);\n"
    "  mri: /usr/share/mricron/templates/ch2.nii.gz (iso 80.5). --image default 192x192.\n"
    "  --solves: timed solves per finder and stream (default 1e6); --random-cells default 200000;\n"
    "  --repeats: frame timings per finder (median; default 3). --quick: 64^3, 96x96, 2e5 solves.";

/// One first_root call as the renderer made it.
struct CellCall {
    double corner[8];
    double iso;
    std::array<double, 3> p_in, p_out;
    bool closed_end;
};

/// A Finder policy that records every call. OctreeTracer calls first_root(finder_, ...)
/// unqualified, so this non-template overload (same namespace as the policy) is chosen over the
/// template in roots.h; it answers with Exact so the traversal is the reference's.
struct RecordingFinder {
    static constexpr const char* name = "recording";
    using Real = double;
    int iterations = 0;
    std::vector<CellCall>* calls = nullptr;
};

/// The last two parameters are nearest_root's deferred-refinement bracket, which only Neubauer
/// fills, and what it knows of the corners (cell.h), which changes no root.
template <class CornerKind = AnyCorners>
double first_root(const RecordingFinder& r, const double corner[8], double iso, const std::array<double, 3>& p_in,
                  const std::array<double, 3>& p_out, bool closed_end, RootBracket* = nullptr, CornerKind = {}) {
    CellCall c;
    std::copy(corner, corner + 8, c.corner);
    c.iso = iso, c.p_in = p_in, c.p_out = p_out, c.closed_end = closed_end;
    r.calls->push_back(c);
    return octiso::first_root(Exact{}, corner, iso, p_in, p_out, closed_end);
}

struct Config {
    RootFinder kind;
    int iterations;   ///< Neubauer's refinement steps; -1 for the others
    std::string label;
    bool is_default = false;
};

std::vector<Config> configs() {
    std::vector<Config> c;
    const int default_its = Neubauer{}.iterations;
    for (int n : {1, 2, 3, 4, 5, 6, 7, 8, 64})
        c.push_back({RootFinder::neubauer, n, "neubauer " + std::to_string(n), n == default_its});
    c.push_back({RootFinder::schwarze, -1, "schwarze"});
    c.push_back({RootFinder::linear, -1, "linear"});
    c.push_back({RootFinder::exact, -1, "exact"});
    return c;
}

double percentile(std::vector<double>& v, double q) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, size_t(q * double(v.size())))];
}

/// What one finder does on one stream, against Exact on the same calls.
struct StreamResult {
    uint64_t cells = 0, ref_hits = 0, misses = 0, false_hits = 0, wrong_root = 0;
    std::vector<double> pos_err, normal_err;   ///< over calls both hit: cell units, degrees
    double ns_per_cell = 0;
    double pos(double q) { return percentile(pos_err, q); }
    double normal(double q) { return percentile(normal_err, q); }
    double pct(uint64_t n) const { return ref_hits ? 100.0 * double(n) / double(ref_hits) : 0.0; }
};

std::array<double, 3> along(const CellCall& c, double s) {
    return {c.p_in[0] + s * (c.p_out[0] - c.p_in[0]), c.p_in[1] + s * (c.p_out[1] - c.p_in[1]),
            c.p_in[2] + s * (c.p_out[2] - c.p_in[2])};
}

double angle_deg(const std::array<double, 3>& a, const std::array<double, 3>& b) {
    const double d = std::clamp(a[0] * b[0] + a[1] * b[1] + a[2] * b[2], -1.0, 1.0);
    return std::acos(d) * 180.0 / M_PI;
}

/// Errors of `cfg` on `calls` given the exact roots `s_ref`, then the timing: the stream is
/// solved repeatedly until `min_solves` calls, the sum of the results is consumed, median of
/// `timing_repeats` runs, in thread CPU time.
StreamResult evaluate(const Config& cfg, const std::vector<CellCall>& calls, const std::vector<double>& s_ref,
                      uint64_t min_solves, int timing_repeats) {
    StreamResult r;
    r.cells = calls.size();
    dispatch_root_finder(cfg.kind, cfg.iterations, [&](const auto& finder) {
        for (size_t i = 0; i < calls.size(); ++i) {
            const CellCall& c = calls[i];
            const double s = first_root(finder, c.corner, c.iso, c.p_in, c.p_out, c.closed_end);
            const double sr = s_ref[i];
            r.ref_hits += sr >= 0;
            if (sr >= 0 && s < 0) { ++r.misses; continue; }
            if (sr < 0 && s >= 0) { ++r.false_hits; continue; }
            if (sr < 0) continue;
            double len = 0;
            for (int a = 0; a < 3; ++a) len += (c.p_out[a] - c.p_in[a]) * (c.p_out[a] - c.p_in[a]);
            len = std::sqrt(len);
            const double err = std::fabs(s - sr) * len;
            if (s > sr && err > 1e-9) {
                // Wrong root: the value found lies nearer a later root than the first one.
                const double m = (s + sr) / 2;
                const double s2 = octiso::first_root(Exact{}, c.corner, c.iso, along(c, m), c.p_out, c.closed_end);
                if (s2 >= 0) {
                    const double s_next = m + s2 * (1 - m);
                    if (std::fabs(s - s_next) < std::fabs(s - sr)) ++r.wrong_root;
                }
            }
            r.pos_err.push_back(err);
            const std::array<double, 3> dir{c.p_out[0] - c.p_in[0], c.p_out[1] - c.p_in[1], c.p_out[2] - c.p_in[2]};
            const auto n = world_normal(c.corner, along(c, s), {1, 1, 1}, dir);
            const auto n_ref = world_normal(c.corner, along(c, sr), {1, 1, 1}, dir);
            r.normal_err.push_back(angle_deg(n, n_ref));
        }
        if (calls.empty()) return;
        const uint64_t rounds = std::max<uint64_t>(1, (min_solves + calls.size() - 1) / calls.size());
        std::vector<double> ns;
        volatile double sink = 0;
        for (int rep = 0; rep < timing_repeats; ++rep) {
            const double t0 = thread_cpu_seconds();
            double sum = 0;
            for (uint64_t k = 0; k < rounds; ++k)
                for (const CellCall& c : calls) sum += first_root(finder, c.corner, c.iso, c.p_in, c.p_out, c.closed_end);
            sink = sink + sum;
            ns.push_back((thread_cpu_seconds() - t0) * 1e9 / double(rounds * calls.size()));
        }
        r.ns_per_cell = percentile(ns, 0.5);
    });
    return r;
}

struct Dataset {
    std::string name;
    LoadedVolume volume;
    double iso = 0;
};

Dataset load_dataset(const std::string& name, uint32_t size) {
    if (name == "plume") return {name, synthetic_step("plume", {size, size, size}, 0), 40.5};
    if (name == "marschner-lobb") return {name, synthetic_step("marschner-lobb", {size, size, size}, 0), 0.5};
    if (name == "mri") return {name, open_volume("/usr/share/mricron/templates/ch2.nii.gz", {}), 80.5};
    throw Error("--dataset", "expected plume, marschner-lobb or mri, found '" + name + "'");
}

struct ImageResult {
    std::string label;
    ImageError error;
    double seconds = 0;
};

struct DatasetRun {
    std::string name;
    Dims dims;
    double iso = 0;
    std::vector<CellCall> calls;
    std::vector<double> s_ref;
    std::vector<StreamResult> per_config;
    std::vector<ImageResult> images;
    uint64_t ref_pixels_hit = 0;
};

/// Records the first_root calls of one render of `tree` (single thread, Exact answers), then
/// renders every config with the real tile loop and compares with the dense exact reference.
template <typename T>
void run_dataset(DatasetRun& run, const LoadedVolume& volume, const Camera& camera, const std::vector<Config>& cfgs,
                 int repeats) {
    const VolumeView<T> view = volume.view<T>();
    const OctreeData<T> data = build_octree(view, {});
    const Octree<T> tree = data.view();
    const Placement placement = volume.placement();
    const PinholeCamera pinhole(camera);
    RecordingFinder rec;
    rec.calls = &run.calls;
    const OctreeTracer<T, RecordingFinder> tracer(tree, placement, &run.iso, 1, rec);
    for (int py = 0; py < camera.height; ++py)
        for (int px = 0; px < camera.width; ++px) tracer.trace(pinhole.ray(px, py), false);

    const Frame ref = render_reference(view, placement, camera, {run.iso});
    for (float d : ref.depth) run.ref_pixels_hit += std::isfinite(d);
    const double voxel = std::min({placement.spacing[0], placement.spacing[1], placement.spacing[2]});
    for (const Config& cfg : cfgs) {
        RenderOptions options;
        options.isovalues = {run.iso};
        options.root_finder = cfg.kind;
        options.iterations = cfg.iterations;
        options.want_colour = false;
        options.want_depth = options.want_normal = true;
        ImageResult img;
        img.label = cfg.label;
        std::vector<double> secs;
        Frame frame;
        for (int k = 0; k < std::max(1, repeats); ++k) {
            frame = render(tree, placement, camera, options);
            secs.push_back(frame.stats.seconds);
        }
        img.seconds = percentile(secs, 0.5);
        img.error = compare_frames(frame, ref, voxel);
        run.images.push_back(img);
    }
}

/// Random cells in the manner of notes 1.3 ("U"): uniform corners in [-1,1], iso inside the
/// corner range, random segments through the cell.
std::vector<CellCall> random_cells(size_t n) {
    std::mt19937_64 rng(20240611);
    std::uniform_real_distribution<double> u01(0, 1), usym(-1, 1);
    std::vector<CellCall> calls(n);
    for (CellCall& c : calls) {
        double lo = 1e300, hi = -1e300;
        for (double& v : c.corner) v = usym(rng), lo = std::min(lo, v), hi = std::max(hi, v);
        c.iso = lo + (hi - lo) * u01(rng);
        for (int a = 0; a < 3; ++a) c.p_in[a] = u01(rng), c.p_out[a] = u01(rng);
        c.closed_end = false;
    }
    return calls;
}

std::vector<double> exact_roots(const std::vector<CellCall>& calls) {
    std::vector<double> s(calls.size());
    for (size_t i = 0; i < calls.size(); ++i)
        s[i] = octiso::first_root(Exact{}, calls[i].corner, calls[i].iso, calls[i].p_in, calls[i].p_out, calls[i].closed_end);
    return s;
}

/// Pooled view of several streams: errors merged, time weighted by calls.
struct Pooled {
    StreamResult r;
    double weighted_ns = 0;
};

void write_stream(cli::JsonWriter& j, const Config& cfg, StreamResult& r) {
    j.begin_object().field("label", cfg.label).field("finder", root_finder_name(cfg.kind)).field("iterations", cfg.iterations);
    j.field("default", cfg.is_default);
    j.field("cells", r.cells).field("ref_hits", r.ref_hits);
    j.field("miss_pct", r.pct(r.misses)).field("false_hits", r.false_hits).field("false_hit_pct", r.pct(r.false_hits));
    j.field("wrong_root_pct", r.pct(r.wrong_root));
    j.field("pos_p50", r.pos(0.5)).field("pos_p99", r.pos(0.99)).field("pos_max", r.pos(1.0));
    j.field("normal_p50_deg", r.normal(0.5)).field("normal_p99_deg", r.normal(0.99)).field("normal_max_deg", r.normal(1.0));
    j.field("ns_per_cell", r.ns_per_cell);
    j.end_object();
}

Table stream_table(const std::vector<Config>& cfgs, std::vector<StreamResult>& rs) {
    Table t({"finder", "miss %", "false hits", "wrong root %", "pos p50", "pos p99", "pos max", "normal p99 deg",
             "normal max deg", "ns/cell"});
    for (size_t i = 0; i < cfgs.size(); ++i) {
        StreamResult& r = rs[i];
        t.add({cfgs[i].label + (cfgs[i].is_default ? " *" : ""), fmt(r.pct(r.misses), 4), std::to_string(r.false_hits),
               fmt(r.pct(r.wrong_root), 4), fmt(r.pos(0.5)), fmt(r.pos(0.99)), fmt(r.pos(1.0)), fmt(r.normal(0.99)),
               fmt(r.normal(1.0)), fmt(r.ns_per_cell, 1)});
    }
    return t;
}

int run_rootfinders(cli::Args& args) {
    if (args.flag("--help")) {
        std::cout << kUsage << "\n";
        return 0;
    }
    const bool quick = args.flag("--quick");
    const auto dataset_flag = args.value("--dataset");
    const auto size_flag = args.value("--size");
    const auto image_flag = args.value("--image");
    const auto solves_flag = args.value("--solves");
    const auto random_flag = args.value("--random-cells");
    const auto repeats_flag = args.value("--repeats");
    const std::string dir = results_dir(args);
    args.finish();

    std::vector<std::string> names = {"plume", "marschner-lobb", "mri"};
    if (dataset_flag) {
        names.clear();
        std::string s = *dataset_flag;
        for (size_t at = 0; at <= s.size();) {
            const size_t comma = s.find(',', at);
            names.push_back(s.substr(at, comma == std::string::npos ? std::string::npos : comma - at));
            if (comma == std::string::npos) break;
            at = comma + 1;
        }
    }
    const int image = quick ? 96 : 192;
    std::array<int, 2> wh{image, image};
    if (image_flag) wh = cli::parse_size(*image_flag, "--image");
    const uint64_t min_solves = solves_flag ? uint64_t(cli::parse_int(*solves_flag, "--solves", 1000, 1LL << 40))
                                            : (quick ? 200000 : 1000000);
    const size_t n_random = random_flag ? size_t(cli::parse_int(*random_flag, "--random-cells", 100, 1LL << 30))
                                        : (quick ? 50000 : 200000);
    const int repeats = repeats_flag ? int(cli::parse_int(*repeats_flag, "--repeats", 1, 100)) : (quick ? 1 : 3);
    const std::vector<Config> cfgs = configs();
    const int timing_repeats = 3;

    std::cerr << "rootfinders: " << machine_description() << "\n";
    std::vector<DatasetRun> runs;
    for (const std::string& name : names) {
        const uint32_t def = name == "plume" ? 128 : 64;
        const uint32_t n = size_flag ? uint32_t(cli::parse_int(*size_flag, "--size", 8, 4096)) : (quick ? 64 : def);
        const Dataset ds = load_dataset(name, n);
        DatasetRun run;
        run.name = name;
        run.dims = ds.volume.dims();
        run.iso = ds.iso;
        const Camera camera = frame_data_box(run.dims, ds.volume.placement(), wh[0], wh[1]);
        std::cerr << "  " << name << " " << run.dims.x << "x" << run.dims.y << "x" << run.dims.z << " "
                  << scalar_type_name(ds.volume.type()) << ", iso " << run.iso << ": recording and rendering\n";
        dispatch_scalar_type(ds.volume.type(), [&](auto tag) {
            run_dataset<decltype(tag)>(run, ds.volume, camera, cfgs, repeats);
        });
        run.s_ref = exact_roots(run.calls);
        std::cerr << "    " << run.calls.size() << " cell tests recorded; timing the finders\n";
        for (const Config& cfg : cfgs)
            run.per_config.push_back(evaluate(cfg, run.calls, run.s_ref, min_solves, cfg.kind == RootFinder::exact ? 1 : timing_repeats));
        runs.push_back(std::move(run));
    }

    // (b) random cells
    const std::vector<CellCall> random = random_cells(n_random);
    const std::vector<double> random_ref = exact_roots(random);
    std::vector<StreamResult> random_results;
    for (const Config& cfg : cfgs)
        random_results.push_back(evaluate(cfg, random, random_ref, min_solves, cfg.kind == RootFinder::exact ? 1 : timing_repeats));

    // Pooled recorded streams: errors merged, ns weighted by the calls of each stream.
    std::vector<StreamResult> pooled(cfgs.size());
    for (size_t i = 0; i < cfgs.size(); ++i) {
        StreamResult& p = pooled[i];
        double ns_weighted = 0;
        for (DatasetRun& run : runs) {
            const StreamResult& r = run.per_config[i];
            p.cells += r.cells, p.ref_hits += r.ref_hits, p.misses += r.misses, p.false_hits += r.false_hits;
            p.wrong_root += r.wrong_root;
            p.pos_err.insert(p.pos_err.end(), r.pos_err.begin(), r.pos_err.end());
            p.normal_err.insert(p.normal_err.end(), r.normal_err.begin(), r.normal_err.end());
            ns_weighted += r.ns_per_cell * double(r.cells);
        }
        p.ns_per_cell = p.cells ? ns_weighted / double(p.cells) : 0;
    }

    // Pareto front over the pooled recorded streams: (ns/cell, p99 position error, topology %),
    // all lower-is-better; a config is on the front unless another is no worse in all three and
    // better in one.
    std::vector<double> ns(cfgs.size()), p99(cfgs.size()), topo(cfgs.size());
    for (size_t i = 0; i < cfgs.size(); ++i) {
        ns[i] = pooled[i].ns_per_cell;
        p99[i] = pooled[i].pos(0.99);
        topo[i] = pooled[i].pct(pooled[i].misses + pooled[i].false_hits + pooled[i].wrong_root);
    }
    std::vector<bool> on_front(cfgs.size(), true);
    std::vector<std::vector<std::string>> dominated_by(cfgs.size());
    for (size_t i = 0; i < cfgs.size(); ++i)
        for (size_t k = 0; k < cfgs.size(); ++k) {
            if (k == i) continue;
            const bool no_worse = ns[k] <= ns[i] && p99[k] <= p99[i] && topo[k] <= topo[i];
            const bool better = ns[k] < ns[i] || p99[k] < p99[i] || topo[k] < topo[i];
            if (no_worse && better) {
                on_front[i] = false;
                dominated_by[i].push_back(cfgs[k].label);
            }
        }

    // Tables.
    for (DatasetRun& run : runs) {
        std::cout << "\n(a) recorded stream, " << run.name << " (" << run.calls.size() << " cell tests, iso " << run.iso
                  << "); position error in cell units\n";
        stream_table(cfgs, run.per_config).print(std::cout);
    }
    std::cout << "\n(a) all recorded streams pooled (Pareto input)\n";
    Table pooled_table = stream_table(cfgs, pooled);
    pooled_table.print(std::cout);
    std::cout << "\n(b) random cells (" << random.size() << ")\n";
    stream_table(cfgs, random_results).print(std::cout);
    Table image_table({"dataset", "finder", "mask mismatch", "depth median", "depth p99", "depth max", "normal median deg",
                       "normal max deg", "frame s"});
    for (DatasetRun& run : runs)
        for (const ImageResult& img : run.images)
            image_table.add({run.name, img.label, fmt(img.error.mask_mismatch_fraction, 5), fmt(img.error.depth_median),
                             fmt(img.error.depth_p99), fmt(img.error.depth_max), fmt(img.error.normal_median_deg),
                             fmt(img.error.normal_max_deg), fmt(img.seconds, 4)});
    std::cout << "\n(c) whole frames " << wh[0] << "x" << wh[1] << " against the exact dense reference (depth in voxels)\n";
    image_table.print(std::cout);
    std::cout << "\nPareto front (pooled recorded streams: ns/cell, p99 position error, miss+false+wrong %):\n";
    for (size_t i = 0; i < cfgs.size(); ++i) {
        std::cout << "  " << cfgs[i].label << (cfgs[i].is_default ? " (default)" : "") << ": "
                  << (on_front[i] ? "on the front" : "dominated by");
        for (const auto& d : dominated_by[i]) std::cout << " " << d;
        std::cout << "\n";
    }
    std::cout << "\nmarkdown (pooled recorded streams):\n";
    pooled_table.print_markdown(std::cout);
    std::cout << "\nmarkdown (frames):\n";
    image_table.print_markdown(std::cout);

    const std::string json = write_json(dir, "rootfinders", [&](cli::JsonWriter& j) {
        j.begin_object();
        j.field("machine", machine_description()).field("width", wh[0]).field("height", wh[1]);
        j.field("min_solves", min_solves).field("random_cells", uint64_t(random.size()));
        j.key("datasets").begin_array();
        for (DatasetRun& run : runs) {
            j.begin_object().field("name", run.name).field("iso", run.iso);
            j.key("dims").array(std::array<uint64_t, 3>{run.dims.x, run.dims.y, run.dims.z});
            j.field("cell_tests", uint64_t(run.calls.size())).field("reference_pixels_hit", run.ref_pixels_hit);
            j.key("stream").begin_array();
            for (size_t i = 0; i < cfgs.size(); ++i) write_stream(j, cfgs[i], run.per_config[i]);
            j.end_array();
            j.key("images").begin_array();
            for (const ImageResult& img : run.images) {
                const ImageError& e = img.error;
                j.begin_object().field("label", img.label).field("mask_mismatch_fraction", e.mask_mismatch_fraction);
                j.field("depth_median", e.depth_median).field("depth_p99", e.depth_p99).field("depth_max", e.depth_max);
                j.field("normal_median_deg", e.normal_median_deg).field("normal_max_deg", e.normal_max_deg);
                j.field("frame_seconds", img.seconds).end_object();
            }
            j.end_array();
            j.end_object();
        }
        j.end_array();
        j.key("pooled").begin_array();
        for (size_t i = 0; i < cfgs.size(); ++i) write_stream(j, cfgs[i], pooled[i]);
        j.end_array();
        j.key("random").begin_array();
        for (size_t i = 0; i < cfgs.size(); ++i) write_stream(j, cfgs[i], random_results[i]);
        j.end_array();
        j.key("pareto").begin_array();
        for (size_t i = 0; i < cfgs.size(); ++i) {
            j.begin_object().field("label", cfgs[i].label).field("on_front", bool(on_front[i]));
            j.key("dominated_by").array(dominated_by[i]).end_object();
        }
        j.end_array();
        j.end_object();
    });
    std::cerr << "results: " << json << "\n";
    plot("rootfinders", json, dir + "/rootfinders.png");
    return 0;
}

static const bool kRegistered = register_bench(
    "rootfinders", "error against time of every root finder and iteration count (recorded, random, frames)",
    &run_rootfinders);

}  // namespace
}  // namespace octiso::bench
