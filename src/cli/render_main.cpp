// octiso-render: renders isosurfaces of a .oct file (CONVENTIONS 3), one frame, or one frame per
// time step with --steps A:B (names then hold one printf integer field, e.g. frame_%04d.png).
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>

#include "cli/common/cli.h"
#include "cli/common/json.h"
#include "octiso/any_octree.h"
#include "octiso/debug_trace.h"
#include "octiso/error.h"
#include "octiso/image.h"
#include "octiso/oct_file.h"
#include "octiso/output_guard.h"
#include "octiso/render.h"

namespace octiso {
namespace {

const char* kUsage =
    "usage: octiso-render FILE.oct --iso V[,V...] -o OUT.png [--eye X,Y,Z --look X,Y,Z --up X,Y,Z --fov DEG]\n"
    "                     [--size WxH] [--steps A:B] [--depth DEPTH.exr] [--normal NORMAL.exr] [--threads N]\n"
    "                     [--root-finder neubauer|schwarze|linear|exact] [--iterations N] [--no-embree] [--json]\n"
    "       octiso-render FILE.oct --iso V[,V...] --debug-pixel X,Y [camera flags]   (prints that pixel's path)";

/// One line of progress with an ETA, redrawn in place; only when stderr is a terminal.
class Progress {
public:
    explicit Progress(long long total) : total_(total), enabled_(total > 1 && ::isatty(2)), start_(std::chrono::steady_clock::now()) {}
    void update(long long done) {
        if (!enabled_) return;
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        const double eta = done > 0 ? elapsed / double(done) * double(total_ - done) : 0.0;
        const int width = 30, filled = int(width * done / total_);
        std::fprintf(stderr, "\r[%.*s%*s] %lld/%lld  ETA %.1f s ", filled, "##############################", width - filled,
                     "", done, total_, eta);
        if (done == total_) std::fprintf(stderr, "\n");
    }

private:
    long long total_;
    bool enabled_;
    std::chrono::steady_clock::time_point start_;
};

int run(std::vector<std::string>& argv) {
    cli::Args args(argv);
    if (args.flag("--help") || args.flag("-h")) {
        std::cout << kUsage << "\n";
        return 0;
    }
    const auto iso_text = args.value("--iso");
    const auto out_path = args.value("--output", "-o");
    const auto eye = args.value("--eye"), look = args.value("--look"), up = args.value("--up"), fov = args.value("--fov");
    const auto size = args.value("--size"), steps = args.value("--steps"), depth_path = args.value("--depth");
    const auto normal_path = args.value("--normal"), threads = args.value("--threads");
    const auto root_finder = args.value("--root-finder"), iterations = args.value("--iterations");
    const bool no_embree = args.flag("--no-embree"), json = args.flag("--json");
    const auto debug_pixel = args.value("--debug-pixel");
    const std::vector<std::string> inputs = args.positional();
    args.finish();
    if (inputs.size() != 1) throw Error("octiso-render", std::string("expected exactly one FILE.oct\n") + kUsage);
    if (!iso_text) throw Error("--iso", "is required (one or more isovalues, e.g. --iso 40,120)");
    if (!out_path && !depth_path && !normal_path && !debug_pixel) throw Error("-o", "is required (or at least --depth or --normal)");

    RenderOptions options;
    options.isovalues = cli::parse_list(*iso_text, "--iso");
    options.want_colour = out_path.has_value();
    options.want_depth = depth_path.has_value();
    options.want_normal = normal_path.has_value();
    options.use_embree = !no_embree;
    if (threads) options.threads = int(cli::parse_int(*threads, "--threads", 1, 4096));
    if (root_finder) options.root_finder = parse_root_finder_name(*root_finder);
    if (iterations) options.iterations = int(cli::parse_int(*iterations, "--iterations", 0, 1000));

    // Everything about the outputs is checked before the first frame is rendered.
    const auto file = std::make_shared<const OctFile>(OctFile::open(inputs[0]));
    const OctInfo& info = file->info();
    long long first = 0, last = 0;
    if (steps) {
        const auto range = cli::parse_steps(*steps, "--steps");
        first = range[0], last = range[1];
        if (last >= (long long)info.step_count)
            throw Error("--steps", "file has steps 0.." + std::to_string(info.step_count - 1) + ", asked for up to " + std::to_string(last));
    }
    const bool series = steps.has_value();
    auto name_for = [&](const std::optional<std::string>& pattern, const char* flag, long long k) {
        return series ? cli::format_step(*pattern, k, flag) : *pattern;
    };
    if (out_path) check_image_path(name_for(out_path, "-o", first), "-o");
    if (depth_path) check_image_path(name_for(depth_path, "--depth", first), "--depth");
    if (normal_path) check_image_path(name_for(normal_path, "--normal", first), "--normal");
    for (long long k = first; k <= last; ++k) {   // issue 18: never replace the input
        if (out_path) refuse_output_onto_input(name_for(out_path, "-o", k), inputs, "-o");
        if (depth_path) refuse_output_onto_input(name_for(depth_path, "--depth", k), inputs, "--depth");
        if (normal_path) refuse_output_onto_input(name_for(normal_path, "--normal", k), inputs, "--normal");
    }
    const RenderLimits limits{info.iso_range, inputs[0]};
    validate_options(options, limits);

    Camera camera;
    {
        int w = 512, h = 512;
        if (size) {
            const auto wh = cli::parse_size(*size, "--size");
            w = wh[0], h = wh[1];
        }
        camera = frame_data_box(info.dims, info.placement, w, h);
        if (eye) camera.eye = cli::parse_vec3(*eye, "--eye");
        if (look) camera.look = cli::parse_vec3(*look, "--look");
        if (up) camera.up = cli::parse_vec3(*up, "--up");
        if (fov) camera.fov_deg = cli::parse_double(*fov, "--fov");
    }

    // --debug-pixel X,Y: re-trace that one pixel (of the first step) and print its path; no image.
    if (debug_pixel) {
        const size_t comma = debug_pixel->find(',');
        if (comma == std::string::npos) throw Error("--debug-pixel", "expected X,Y, found '" + *debug_pixel + "'");
        const int x = int(cli::parse_int(debug_pixel->substr(0, comma), "--debug-pixel", INT32_MIN, INT32_MAX));
        const int y = int(cli::parse_int(debug_pixel->substr(comma + 1), "--debug-pixel", INT32_MIN, INT32_MAX));
        std::cout << AnyOctree::step(file, uint32_t(first)).trace_pixel(camera, options, x, y).text();
        return 0;
    }

    cli::JsonWriter j(std::cout);
    if (json) {
        j.begin_object().field("file", inputs[0]).field("type", std::string(scalar_type_name(info.type)));
        j.key("isovalues").array(options.isovalues);
        j.field("width", camera.width).field("height", camera.height);
        j.field("root_finder", std::string(root_finder ? *root_finder : "neubauer")).field("embree", options.use_embree);
        j.key("frames").begin_array();
    }
    Progress progress(last - first + 1);
    double total_seconds = 0;
    for (long long k = first; k <= last; ++k) {
        // One Renderer per step; the Embree device behind it is shared by the whole process.
        Frame frame;
        const AnyOctree step = AnyOctree::step(file, uint32_t(k));
        step.make_renderer(options).render(camera, frame);
        file->check_unchanged();   // issue 18: never publish a frame of a file rewritten under us
        if (out_path) write_colour_image(name_for(out_path, "-o", k), frame);
        if (depth_path) write_depth_image(name_for(depth_path, "--depth", k), frame);
        if (normal_path) write_normal_image(name_for(normal_path, "--normal", k), frame);
        total_seconds += frame.stats.seconds;
        if (json) {
            j.begin_object().field("step", k).field("seconds", frame.stats.seconds);
            j.field("mrays_per_second", frame.stats.mrays_per_second()).field("rays", frame.stats.rays);
            j.field("hits", frame.stats.hits).field("threads", frame.stats.threads);
            if (out_path) j.field("image", name_for(out_path, "-o", k));
            j.end_object();
        }
        if (!series || !::isatty(2))
            std::fprintf(stderr, "%s%s: %dx%d in %.3f s (%.2f Mrays/s, %llu hits, %d threads)\n",
                         series ? ("step " + std::to_string(k) + " ").c_str() : "",
                         out_path ? name_for(out_path, "-o", k).c_str() : "frame", frame.width, frame.height,
                         frame.stats.seconds, frame.stats.mrays_per_second(), (unsigned long long)frame.stats.hits,
                         frame.stats.threads);
        progress.update(k - first + 1);
    }
    if (json) {
        j.end_array().field("total_seconds", total_seconds).end_object();
        std::cout << "\n";
    }
    if (series) std::fprintf(stderr, "%lld frames in %.3f s render time\n", last - first + 1, total_seconds);
    return 0;
}

}  // namespace
}  // namespace octiso

int main(int argc, char** argv) { return octiso::cli::run_main("octiso-render", argc, argv, octiso::run); }
