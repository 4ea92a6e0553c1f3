// octiso-bench setup: what a frame costs besides tracing (issue 9: a persistent Renderer; issue 12:
// serial per-frame work). Interleaved in one run, on a small volume and frames so small that the
// set-up dominates: render() per frame (a Renderer built and dropped each time: scene, tracer,
// frame buffers) against one kept Renderer rendering into a reused Frame. Both draw the same
// pixels; the difference is the per-frame set-up a series or an interactive session no longer pays.
#include <algorithm>
#include <iostream>
#include <vector>

#include "bench/bench.h"
#include "octiso/build.h"
#include "octiso/render.h"
#include "octiso/synthetic.h"

namespace octiso::bench {
namespace {

const char* const kSetupUsage =
    "usage: octiso-bench setup [--size N] [--images 8,64,256] [--calls N] [--threads N] [--quick]\n"
    "  plume N^3 (default 32); per image side, median and min microseconds per frame over --calls\n"
    "  interleaved calls (default 400) of render() and of a kept Renderer; --threads default 1";

struct SetupRow {
    int side = 0;
    double once_median_us = 0, once_min_us = 0, kept_median_us = 0, kept_min_us = 0;
};

int run_setup(cli::Args& args) {
    if (args.flag("--help")) {
        std::cout << kSetupUsage << "\n";
        return 0;
    }
    const bool quick = args.flag("--quick");
    const auto size_flag = args.value("--size"), images_flag = args.value("--images");
    const auto calls_flag = args.value("--calls"), threads_flag = args.value("--threads");
    const std::string results = results_dir(args);
    args.finish();
    const uint32_t n = size_flag ? uint32_t(cli::parse_int(*size_flag, "--size", 4, 512)) : 32;
    const int calls = calls_flag ? int(cli::parse_int(*calls_flag, "--calls", 1, 100000)) : quick ? 40 : 400;
    const int threads = threads_flag ? int(cli::parse_int(*threads_flag, "--threads", 0, 1024)) : 1;
    std::vector<int> sides{8, 64, 256};
    if (images_flag) {
        sides.clear();
        for (double v : cli::parse_list(*images_flag, "--images")) sides.push_back(int(v));
    }

    const LoadedVolume volume = synthetic_step("plume", Dims{n, n, n}, 0);
    const OctreeData<uint8_t> data = build_octree(volume.view<uint8_t>(), {});
    RenderOptions options;
    options.isovalues = {default_isovalue("plume")};
    options.threads = threads;
    std::vector<SetupRow> rows;
    Table table({"image", "render() median us", "min us", "kept Renderer median us", "min us", "saved per frame us"});
    for (int side : sides) {
        const Camera camera = frame_data_box(volume.dims(), volume.placement(), side, side);
        const Renderer kept(data.view(), volume.placement(), options);
        Frame reused;
        std::vector<double> once, again;
        for (int i = 0; i < calls; ++i) {   // interleaved: a load spike hits both alike
            auto t0 = std::chrono::steady_clock::now();
            (void)render(data.view(), volume.placement(), camera, options);
            once.push_back(seconds_since(t0) * 1e6);
            t0 = std::chrono::steady_clock::now();
            kept.render(camera, reused);
            again.push_back(seconds_since(t0) * 1e6);
        }
        std::sort(once.begin(), once.end());
        std::sort(again.begin(), again.end());
        SetupRow r{side, once[once.size() / 2], once[0], again[again.size() / 2], again[0]};
        rows.push_back(r);
        table.add({std::to_string(side) + "^2", fmt(r.once_median_us, 1), fmt(r.once_min_us, 1), fmt(r.kept_median_us, 1),
                   fmt(r.kept_min_us, 1), fmt(r.once_median_us - r.kept_median_us, 1)});
    }
    std::cout << "per-frame set-up, plume " << n << "^3 u8, " << threads << " thread(s), " << calls
              << " interleaved calls each (" << machine_description() << ")\n";
    table.print(std::cout);
    const std::string path = write_json(results, "setup", [&](cli::JsonWriter& j) {
        j.begin_object();
        j.field("dataset", std::string("plume")).field("size", int64_t(n)).field("threads", int64_t(threads));
        j.field("calls", int64_t(calls)).field("machine", machine_description());
        j.key("rows").begin_array();
        for (const SetupRow& r : rows) {
            j.begin_object().field("image", int64_t(r.side)).field("render_once_median_us", r.once_median_us);
            j.field("render_once_min_us", r.once_min_us).field("kept_renderer_median_us", r.kept_median_us);
            j.field("kept_renderer_min_us", r.kept_min_us).end_object();
        }
        j.end_array();
        j.end_object();
    });
    std::cout << "wrote " << path << "\n";
    return 0;
}

const bool kRegistered = register_bench("setup", "per-frame set-up: render() per frame vs a kept Renderer", &run_setup);

}  // namespace
}  // namespace octiso::bench
