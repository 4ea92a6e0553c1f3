// octiso-bench embree (issue 3, item 4): what the Embree user-geometry dispatch costs. The same
// frames are rendered by render() through the Embree scene (rtcIntersect1 -> intersect callback
// -> traversal) and straight into the traversal (RenderOptions::use_embree = false), interleaved
// (the order alternates every round), on several datasets; the overhead is the median of the
// per-round time ratios. Both paths must return identical images, which is checked too.
#include <time.h>

#include <algorithm>
#include <cstring>
#include <iostream>
#include <sstream>

#include "bench/bench.h"
#include "octiso/build.h"
#include "octiso/error.h"
#include "octiso/reader.h"
#include "octiso/render.h"
#include "octiso/synthetic.h"
#include "reference/trace_frame.h"
#include "render/traverse.h"
#include "scene/embree_scene.h"

namespace octiso::bench {
namespace {

const char* const kEmbreeUsage =
    "usage: octiso-bench embree [--dataset NAME[,NAME...]] [--size N] [--image WxH] [--iso V] [--repeats N]\n"
    "                           [--threads N] [--mri FILE] [--quick]\n"
    "  NAME: plume, mixing (synthetic N^3, default 256), mri, sphere (mostly empty space: dispatch-bound)\n"
    "  --threads default 1 (least noise on a shared machine; the cost is per ray); --quick: 128^3, 256x256";

/// The Embree path as a tracer for trace_frame: the same scene->intersect call render() makes.
struct EmbreeTracer {
    const EmbreeVolumeScene* scene;
    TraceHit trace(const Ray& ray, bool want_normal) const { return scene->intersect(ray, want_normal); }
};

double median_of(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

struct EmbreeRow {
    std::string name;
    Dims dims;
    double iso = 0;
    std::vector<double> embree_s, direct_s, ratio;           // render(), wall seconds of the tile loop
    std::vector<double> embree_cpu, direct_cpu, cpu_ratio;   // isolated loop, thread CPU seconds
    uint64_t rays = 0;
    bool identical = false;
};

int run_embree(cli::Args& args) {
    if (args.flag("--help")) {
        std::cout << kEmbreeUsage << "\n";
        return 0;
    }
    const bool quick = args.flag("--quick");
    const auto ds = args.value("--dataset");
    const auto size_flag = args.value("--size");
    const auto image = args.value("--image");
    const auto iso_flag = args.value("--iso");
    const auto repeats_flag = args.value("--repeats");
    const auto threads_flag = args.value("--threads");
    const auto mri_flag = args.value("--mri");
    const std::string results = results_dir(args);
    args.finish();

    const uint32_t n = size_flag ? uint32_t(cli::parse_int(*size_flag, "--size", 8, 2048)) : quick ? 128 : 256;
    std::array<int, 2> wh = quick ? std::array<int, 2>{256, 256} : std::array<int, 2>{512, 512};
    if (image) wh = cli::parse_size(*image, "--image");
    const int repeats = repeats_flag ? int(cli::parse_int(*repeats_flag, "--repeats", 1, 1000)) : quick ? 3 : 7;
    const int threads = threads_flag ? int(cli::parse_int(*threads_flag, "--threads", 0, 1024)) : 1;
    std::vector<std::string> names;
    {
        std::stringstream ss(ds ? *ds : "plume,mixing,mri,sphere");
        std::string item;
        while (std::getline(ss, item, ',')) names.push_back(item);
    }

    std::vector<EmbreeRow> rows;
    for (const auto& name : names) {
        LoadedVolume volume;
        if (name == "plume" || name == "mixing" || name == "sphere") volume = synthetic_step(name, Dims{n, n, n}, 0);
        else if (name == "mri") volume = open_volume(mri_flag ? *mri_flag : "/usr/share/mricron/templates/ch2.nii.gz", RawOptions{});
        else throw Error("--dataset", "expected plume, mixing, mri or sphere, found '" + name + "'");
        EmbreeRow row;
        row.name = name;
        row.dims = volume.dims();
        row.iso = iso_flag ? cli::parse_double(*iso_flag, "--iso") : default_isovalue(name);
        const Camera camera = frame_data_box(volume.dims(), volume.placement(), wh[0], wh[1]);
        std::cerr << "embree: " << name << ", iso " << row.iso << "\n";
        dispatch_scalar_type(volume.type(), [&](auto tag) {
            using T = decltype(tag);
            const OctreeData<T> data = build_octree(volume.view<T>(), BuildOptions{});
            RenderOptions options;
            options.isovalues = {row.iso};
            options.threads = threads;
            options.want_depth = true;
            auto frame = [&](bool embree) {
                options.use_embree = embree;
                return render(data.view(), volume.placement(), camera, options);
            };
            const Frame a = frame(true), b = frame(false);   // warm-up, and the identity check
            row.identical = a.rgb == b.rgb && a.depth.size() == b.depth.size() &&
                            std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)) == 0;
            row.rays = a.stats.rays;
            for (int r = 0; r < repeats; ++r) {
                double te, td;
                if (r % 2 == 0) te = frame(true).stats.seconds, td = frame(false).stats.seconds;
                else td = frame(false).stats.seconds, te = frame(true).stats.seconds;
                row.embree_s.push_back(te);
                row.direct_s.push_back(td);
                row.ratio.push_back(te / td);
            }
            if (threads != 1) return;
            // The same two paths outside render(), timed in thread CPU seconds (one thread: the
            // frame runs on this thread), with the scene built once as render() does per frame.
            const Octree<T> tree = data.view();
            const OctreeTracer<T, Neubauer> tracer(tree, volume.placement(), &row.iso, 1, Neubauer{});
            EmbreeVolumeScene scene;
            const Dims d = volume.dims();
            const uint32_t ext[3] = {d.x, d.y, d.z};
            std::array<double, 3> lo, hi;
            for (int a = 0; a < 3; ++a) {
                const double e0 = volume.placement().origin[a];
                const double e1 = e0 + double(ext[a] - 1) * volume.placement().spacing[a];
                lo[a] = std::min(e0, e1), hi[a] = std::max(e0, e1);
            }
            scene.add_volume(lo, hi, &tracer, [](const void* user, const Ray& ray, bool normal) {
                return static_cast<const OctreeTracer<T, Neubauer>*>(user)->trace(ray, normal);
            });
            scene.commit();
            const EmbreeTracer via_embree{&scene};
            tbb::task_arena arena(1);
            auto cpu = [&](auto& tr) {
                return arena.execute([&] {
                    const double c0 = thread_cpu_seconds();
                    trace_frame(tr, camera, true);
                    return thread_cpu_seconds() - c0;
                });
            };
            cpu(via_embree), cpu(tracer);   // warm-up
            for (int r = 0; r < repeats; ++r) {
                double te, td;
                if (r % 2 == 0) te = cpu(via_embree), td = cpu(tracer);
                else td = cpu(tracer), te = cpu(via_embree);
                row.embree_cpu.push_back(te);
                row.direct_cpu.push_back(td);
                row.cpu_ratio.push_back(te / td);
            }
        });
        rows.push_back(std::move(row));
    }

    std::cout << "machine: " << machine_description() << ", threads " << (threads ? std::to_string(threads) : "all") << "\n";
    Table table({"dataset", "timing", "embree s", "direct s", "Mrays/s direct", "overhead (median ratio - 1)",
                 "min..max ratio", "ns/ray", "identical images"});
    auto add = [&](const EmbreeRow& r, const char* timing, const std::vector<double>& e, const std::vector<double>& d,
                   const std::vector<double>& ratios) {
        if (ratios.empty()) return;
        const double ratio = median_of(ratios);
        const auto [lo, hi] = std::minmax_element(ratios.begin(), ratios.end());
        const double ns = (median_of(e) - median_of(d)) / double(r.rays) * 1e9 * (threads ? threads : 1);
        table.add({r.name, timing, fmt(median_of(e), 4), fmt(median_of(d), 4), fmt(double(r.rays) / median_of(d) * 1e-6, 2),
                   fmt(100.0 * (ratio - 1.0), 2) + " %", fmt(*lo, 3) + ".." + fmt(*hi, 3), fmt(ns, 1),
                   r.identical ? "yes" : "NO"});
    };
    for (const auto& r : rows) {
        add(r, "render() wall", r.embree_s, r.direct_s, r.ratio);
        add(r, "loop thread-CPU", r.embree_cpu, r.direct_cpu, r.cpu_ratio);
    }
    table.print(std::cout);
    std::cout << "\n";
    table.print_markdown(std::cout);

    const std::string json = write_json(results, "embree", [&](cli::JsonWriter& j) {
        j.begin_object();
        j.field("machine", machine_description()).field("threads", threads);
        j.field("width", wh[0]).field("height", wh[1]).field("repeats", repeats);
        j.key("datasets").begin_array();
        for (const auto& r : rows) {
            j.begin_object();
            j.field("name", r.name).field("iso", r.iso);
            j.key("dims").array(std::vector<uint32_t>{r.dims.x, r.dims.y, r.dims.z});
            j.key("embree_seconds").array(r.embree_s);
            j.key("direct_seconds").array(r.direct_s);
            j.key("ratio").array(r.ratio);
            j.field("median_ratio", median_of(r.ratio)).field("identical_images", r.identical);
            j.key("embree_cpu_seconds").array(r.embree_cpu);
            j.key("direct_cpu_seconds").array(r.direct_cpu);
            j.key("cpu_ratio").array(r.cpu_ratio);
            if (!r.cpu_ratio.empty()) j.field("median_cpu_ratio", median_of(r.cpu_ratio));
            j.end_object();
        }
        j.end_array();
        j.end_object();
    });
    std::cerr << "results: " << json << "\n";
    return 0;
}

static const bool kRegistered =
    register_bench("embree", "Embree user-geometry dispatch vs calling the traversal directly", &run_embree);

}  // namespace
}  // namespace octiso::bench
