// octiso-bench grid (issue 5, item 1): the paper's Table 3 (Knoll et al. 2006, Sec. 5.3). A
// hierarchical macrocell grid (Parker et al. 1998, src/reference/macrocell.h) and the octree, each
// as the acceleration structure over either the dense array or the octree data (2x2), same camera,
// isovalue, root finder, tile loop (reference/trace_frame.h, no Embree, no shading) and repeats
// interleaved, plus each image's error against the exact dense reference (CONVENTIONS 4).
#include <time.h>

#include <algorithm>
#include <iostream>
#include <sstream>

#include <tbb/task_arena.h>

#include "bench/bench.h"
#include "octiso/build.h"
#include "octiso/error.h"
#include "octiso/reader.h"
#include "octiso/synthetic.h"
#include "reference/macrocell.h"
#include "reference/reference_render.h"
#include "reference/trace_frame.h"
#include "render/traverse.h"

namespace octiso::bench {
namespace {

const char* const kGridUsage =
    "usage: octiso-bench grid [--dataset NAME[,NAME...]] [--size N] [--image WxH] [--iso V] [--repeats N]\n"
    "                         [--threads N] [--mri FILE] [--grid B:L[,B:L...]] [--quick] [--no-reference]\n"
    "  NAME: plume, mixing (synthetic N^3, default 256; --size 512 for the large run) or mri\n"
    "  --grid: macrocell configurations, B cells per macrocell edge, L levels (default 4:2,4:3,8:1)\n"
    "  --threads 1 times each frame in thread CPU seconds (robust on a busy machine); else wall seconds\n"
    "  --image default 512x512; --quick: 128^3, 256x256, 2 repeats";

struct VariantResult {
    std::string structure, data, config;
    std::vector<double> seconds;
    uint64_t structure_bytes = 0, data_bytes = 0;
    uint64_t hits = 0;
    ImageError error;
    bool has_error = false;
    VariantResult(std::string s, std::string d, std::string c, uint64_t sb, uint64_t db)
        : structure(std::move(s)), data(std::move(d)), config(std::move(c)), structure_bytes(sb), data_bytes(db) {}
    double median() const {
        std::vector<double> s = seconds;
        std::sort(s.begin(), s.end());
        return s.empty() ? 0 : s[s.size() / 2];
    }
};

struct DatasetRun {
    std::string name, source, type;
    Dims dims;
    double iso = 0, build_seconds = 0, reference_seconds = 0;
    std::vector<VariantResult> variants;
    double ratio = 0;   // octree/octree fps over the best grid/array fps
};

template <typename T>
void run_variants(DatasetRun& run, const LoadedVolume& volume, const Camera& camera, int repeats,
                  const std::vector<MacrocellOptions>& configs, bool reference, bool cpu_time) {
    const VolumeView<T> view = volume.view<T>();
    const Placement placement = volume.placement();
    const double iso = run.iso;
    auto t0 = std::chrono::steady_clock::now();
    const OctreeData<T> data = build_octree(view, BuildOptions{});
    run.build_seconds = seconds_since(t0);
    const Octree<T> tree = data.view();
    const uint64_t octree_bytes = data.stats.interior_bytes + data.stats.cap_bytes;
    const uint64_t array_bytes = volume.bytes();
    std::vector<std::unique_ptr<MacrocellGrid<T>>> grids;
    for (const auto& o : configs) grids.push_back(std::make_unique<MacrocellGrid<T>>(view, o));

    // Each variant: a name and a function rendering one frame (depth + normals).
    std::vector<std::function<Frame()>> render;
    const ArrayCorners<T> array_corners{view};
    const OctreeCorners<T> tree_corners{tree};
    const Neubauer finder;
    for (size_t g = 0; g < grids.size(); ++g) {
        const MacrocellGrid<T>& grid = *grids[g];
        const std::string cfg = std::to_string(configs[g].branching) + ":" + std::to_string(configs[g].levels);
        run.variants.emplace_back("grid", "array", cfg, grid.bytes(), array_bytes);
        render.push_back([&] {
            const MacrocellTracer<T, Neubauer, ArrayCorners<T>> tr(grid, array_corners, placement, &iso, 1, finder);
            return trace_frame(tr, camera, true);
        });
        run.variants.emplace_back("grid", "octree", cfg, grid.bytes(), octree_bytes);
        render.push_back([&] {
            const MacrocellTracer<T, Neubauer, OctreeCorners<T>> tr(grid, tree_corners, placement, &iso, 1, finder);
            return trace_frame(tr, camera, true);
        });
    }
    run.variants.emplace_back("octree", "array", "", octree_bytes, array_bytes);
    render.push_back([&] {
        const OctreeTracer<T, Neubauer, ArrayCorners<T>> tr(tree, placement, &iso, 1, finder, array_corners);
        return trace_frame(tr, camera, true);
    });
    run.variants.emplace_back("octree", "octree", "", 0, octree_bytes);
    render.push_back([&] {
        const OctreeTracer<T, Neubauer> tr(tree, placement, &iso, 1, finder);
        return trace_frame(tr, camera, true);
    });

    Frame ref;
    if (reference) {
        t0 = std::chrono::steady_clock::now();
        ref = render_reference(view, placement, camera, std::vector<double>{iso});
        run.reference_seconds = seconds_since(t0);
    }
    const double voxel = std::min({placement.spacing[0], placement.spacing[1], placement.spacing[2]});
    // Warm-up round (also the error check), then `repeats` rounds, variants interleaved so that
    // drift of a shared machine hits every variant alike.
    for (size_t v = 0; v < render.size(); ++v) {
        const Frame f = render[v]();
        run.variants[v].hits = f.stats.hits;
        if (reference) run.variants[v].error = compare_frames(f, ref, voxel), run.variants[v].has_error = true;
    }
    for (int r = 0; r < repeats; ++r)
        for (size_t v = 0; v < render.size(); ++v) {
            const double c0 = thread_cpu_seconds();
            const double wall = render[v]().stats.seconds;
            run.variants[v].seconds.push_back(cpu_time ? thread_cpu_seconds() - c0 : wall);
        }

    double best_grid = 0, octree_fps = 0;
    for (const auto& v : run.variants) {
        const double fps = 1.0 / v.median();
        if (v.structure == "grid" && v.data == "array") best_grid = std::max(best_grid, fps);
        if (v.structure == "octree" && v.data == "octree") octree_fps = fps;
    }
    run.ratio = best_grid > 0 ? octree_fps / best_grid : 0;
}

std::vector<MacrocellOptions> parse_grid_configs(const std::string& text) {
    std::vector<MacrocellOptions> out;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        const size_t colon = item.find(':');
        if (colon == std::string::npos) throw Error("--grid", "expected B:L, found '" + item + "'");
        MacrocellOptions o;
        o.branching = int(cli::parse_int(item.substr(0, colon), "--grid", 2, 64));
        o.levels = int(cli::parse_int(item.substr(colon + 1), "--grid", 0, 10));
        out.push_back(o);
    }
    if (out.empty()) throw Error("--grid", "no configuration given");
    return out;
}

int run_grid(cli::Args& args) {
    if (args.flag("--help")) {
        std::cout << kGridUsage << "\n";
        return 0;
    }
    const bool quick = args.flag("--quick");
    const bool reference = !args.flag("--no-reference");
    const auto ds = args.value("--dataset");
    const auto size_flag = args.value("--size");
    const auto image = args.value("--image");
    const auto iso_flag = args.value("--iso");
    const auto repeats_flag = args.value("--repeats");
    const auto threads_flag = args.value("--threads");
    const auto mri_flag = args.value("--mri");
    const auto grid_flag = args.value("--grid");
    const std::string results = results_dir(args);
    args.finish();

    const uint32_t n = size_flag ? uint32_t(cli::parse_int(*size_flag, "--size", 8, 2048)) : quick ? 128 : 256;
    std::array<int, 2> wh = quick ? std::array<int, 2>{256, 256} : std::array<int, 2>{512, 512};
    if (image) wh = cli::parse_size(*image, "--image");
    const int repeats = repeats_flag ? int(cli::parse_int(*repeats_flag, "--repeats", 1, 1000)) : quick ? 2 : 3;
    const int threads = threads_flag ? int(cli::parse_int(*threads_flag, "--threads", 0, 1024)) : 0;
    const std::string mri = mri_flag ? *mri_flag : "/usr/share/mricron/templates/ch2.nii.gz";
    const auto configs = parse_grid_configs(grid_flag ? *grid_flag : "4:2,4:3,8:1");
    std::vector<std::string> names;
    {
        std::stringstream ss(ds ? *ds : "plume,mixing,mri");
        std::string item;
        while (std::getline(ss, item, ',')) names.push_back(item);
    }

    std::vector<DatasetRun> runs;
    auto body = [&] {
        for (const auto& name : names) {
            LoadedVolume volume;
            if (name == "plume" || name == "mixing") volume = synthetic_step(name, Dims{n, n, n}, 0);
            else if (name == "mri") volume = open_volume(mri, RawOptions{});
            else throw Error("--dataset", "expected plume, mixing or mri, found '" + name + "'");
            DatasetRun run;
            run.name = name;
            run.source = volume.source();
            run.type = std::string(scalar_type_name(volume.type()));
            run.dims = volume.dims();
            run.iso = iso_flag ? cli::parse_double(*iso_flag, "--iso") : default_isovalue(name);
            const Camera camera = frame_data_box(volume.dims(), volume.placement(), wh[0], wh[1]);
            std::cerr << "grid: " << name << " " << run.dims.x << "x" << run.dims.y << "x" << run.dims.z << " " << run.type
                      << ", iso " << run.iso << ", " << wh[0] << "x" << wh[1] << "\n";
            dispatch_scalar_type(volume.type(), [&](auto tag) {
                run_variants<decltype(tag)>(run, volume, camera, repeats, configs, reference, threads == 1);
            });
            runs.push_back(std::move(run));
        }
    };
    int used_threads = 0;
    if (threads > 0) {
        tbb::task_arena arena(threads);
        arena.execute(body);
        used_threads = threads;
    } else {
        body();
        used_threads = tbb::this_task_arena::max_concurrency();
    }

    Table table({"dataset", "structure", "data", "grid B:L", "frames/s", "Mrays/s", "vs grid/array", "structure MB",
                 "data MB", "mask mism.", "depth p99 vox", "normal med deg"});
    const double rays = double(wh[0]) * wh[1];
    for (const auto& run : runs) {
        double best_grid = 0;
        for (const auto& v : run.variants)
            if (v.structure == "grid" && v.data == "array") best_grid = std::max(best_grid, 1.0 / v.median());
        for (const auto& v : run.variants) {
            const double fps = 1.0 / v.median();
            table.add({run.name, v.structure, v.data, v.config.empty() ? "-" : v.config, fmt(fps, 2),
                       fmt(rays * fps * 1e-6, 2), fmt(fps / best_grid, 3), fmt(double(v.structure_bytes) / 1e6, 2),
                       fmt(double(v.data_bytes) / 1e6, 2), v.has_error ? fmt(v.error.mask_mismatch_fraction, 6) : "-",
                       v.has_error ? fmt(v.error.depth_p99, 6) : "-", v.has_error ? fmt(v.error.normal_median_deg, 4) : "-"});
        }
    }
    std::cout << "machine: " << machine_description() << ", " << used_threads << " threads, timing "
              << (threads == 1 ? "thread CPU seconds" : "wall seconds of the tile loop") << "\n";
    table.print(std::cout);
    std::cout << "\n";
    table.print_markdown(std::cout);
    for (const auto& run : runs)
        std::cout << run.name << ": octree on octree data / best grid on array = " << fmt(run.ratio, 3)
                  << " (paper: 17.5/18.9 = 0.93; target >= 1.0)\n";

    const std::string json = write_json(results, "grid", [&](cli::JsonWriter& j) {
        j.begin_object();
        j.field("machine", machine_description()).field("threads", used_threads);
        j.field("timing", threads == 1 ? "thread_cpu" : "wall");
        j.field("width", wh[0]).field("height", wh[1]).field("repeats", repeats);
        j.key("datasets").begin_array();
        for (const auto& run : runs) {
            j.begin_object();
            j.field("name", run.name).field("source", run.source).field("type", run.type);
            j.key("dims").array(std::vector<uint32_t>{run.dims.x, run.dims.y, run.dims.z});
            j.field("iso", run.iso).field("octree_build_seconds", run.build_seconds);
            j.field("reference_seconds", run.reference_seconds).field("ratio_octree_octree_vs_grid_array", run.ratio);
            j.key("variants").begin_array();
            for (const auto& v : run.variants) {
                j.begin_object();
                j.field("structure", v.structure).field("data", v.data).field("grid", v.config);
                j.key("seconds").array(v.seconds);
                j.field("median_seconds", v.median()).field("fps", 1.0 / v.median());
                j.field("mrays_per_second", rays / v.median() * 1e-6).field("hits", v.hits);
                j.field("structure_bytes", v.structure_bytes).field("data_bytes", v.data_bytes);
                if (v.has_error) {
                    j.key("error").begin_object();
                    j.field("mask_mismatch_fraction", v.error.mask_mismatch_fraction);
                    j.field("depth_median_voxels", v.error.depth_median).field("depth_p99_voxels", v.error.depth_p99);
                    j.field("depth_max_voxels", v.error.depth_max);
                    j.field("normal_median_deg", v.error.normal_median_deg).field("normal_max_deg", v.error.normal_max_deg);
                    j.end_object();
                }
                j.end_object();
            }
            j.end_array();
            j.end_object();
        }
        j.end_array();
        j.end_object();
    });
    std::cerr << "results: " << json << "\n";
    plot("grid", json, results + "/grid.png");
    return 0;
}

static const bool kRegistered =
    register_bench("grid", "paper Table 3: macrocell grid vs octree, each over array or octree data", &run_grid);

}  // namespace
}  // namespace octiso::bench
