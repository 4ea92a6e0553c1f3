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
#include "cli/common/output_path.h"
#include "cli/common/progress.h"
#include "cli/common/report.h"
#include "cli/render_camera.h"
#include "cli/render_look.h"
#include "octiso/antialias.h"
#include "octiso/shading.h"
#include "octiso/any_octree.h"
#include "octiso/debug_trace.h"
#include "octiso/error.h"
#include "octiso/image.h"
#include "octiso/look.h"
#include "octiso/oct_file.h"
#include "octiso/output_guard.h"
#include "octiso/render.h"

namespace octiso {
namespace {

const char* kUsage =
    "usage: octiso-render FILE.oct --iso V[,V...] -o OUT.png [options]\n"
    "       octiso-render FILE.oct --iso V[,V...] --debug-pixel X,Y [camera options]   (prints that pixel's path)\n"
    "\n"
    "Ray-traces the isosurfaces f = V of a .oct file (octiso-info FILE.oct shows the data range; an\n"
    "isovalue outside it is refused).\n"
    "\n"
    "Outputs (at least one):\n"
    "  -o, --output OUT.png      colour image, 8-bit sRGB unless the format is float (.exr, .tif)\n"
    "  --depth DEPTH.exr         world distance to the first hit, +inf on a miss (float formats only)\n"
    "  --normal NORMAL.exr       world unit normal facing the ray, 0,0,0 on a miss (8-bit: n/2 + 1/2)\n"
    "  --json                    one JSON object on stdout (camera, timings in seconds); report on stderr\n"
    "Series:\n"
    "  --steps A:B               steps A..B of a time series (default: step 0); names then hold one\n"
    "                            printf field (frame_%04d.png). A name with a %d field and no --steps\n"
    "                            renders every step.\n"
    "Camera (default: the three-quarter view that frames the data; the effective camera is printed):\n"
    "  --view NAME               front|back|left|right|top|bottom|iso along the data's axes (front looks\n"
    "                            along +y, left along +x, top down -z with +y up; iso is the default)\n"
    "  --azimuth DEG             orbit angle about z from +x, counter-clockwise (default -55.3)\n"
    "  --elevation DEG           above the xy plane, |DEG| < 90 (default 26.8)\n"
    "  --zoom Z                  > 1 moves closer, < 1 farther (default 1: the data fills the view)\n"
    "  --orbit N                 N frames around the centre from --azimuth; -o needs a %d field\n"
    "  --eye X,Y,Z --look X,Y,Z --up X,Y,Z   explicit pinhole in world units (override the above)\n"
    "  --fov DEG                 vertical field of view (default 35)\n"
    "  --size WxH                image size in pixels (default 512x512)\n"
    "  --spp N                   samples per pixel, 1..256 (default 1); > 1 antialiases\n"
    "Look:\n"
    "  --shading kit|headlight   kit: a key and a fill light fixed to the camera, a little specular (default);\n"
    "                            headlight: Lambert from the eye plus ambient (the images before issue 17)\n"
    "  --background COLOUR       R,G,B in [0, 1] or #RRGGBB, as shown on screen (default #212329)\n"
    "  --colour COLOUR           colour of the k-th isovalue, given once per isovalue in order\n"
    "                            (default palette: bone, blue, green, rose, yellow, violet, cyan, grey)\n"
    "Tracing:\n"
    "  --root-finder NAME        neubauer|schwarze|linear|exact (default neubauer)\n"
    "  --iterations N            refinement steps of the root finder (default: its own, neubauer 5)\n"
    "  --no-embree               call the traversal directly instead of through Embree (same image)\n"
    "  --traversal packets|single  8-ray packets of 4x2 pixels, or one ray at a time (default packets;\n"
    "                            same image)\n"
    "  --isa auto|baseline|avx2  traversal kernel: auto = AVX2 where the CPU has it (default; same image)\n"
    "  --threads N               worker threads, 0 = all cores (default 0)\n"
    "  --version, -h/--help\n";

int run(std::vector<std::string>& argv) {
    cli::Args args(argv);
    if (args.flag("--help") || args.flag("-h")) {
        std::cout << kUsage << cli::kLookUsage;
        return 0;
    }
    if (argv.empty()) {   // the same in every tool: the help, as a usage error
        std::cerr << kUsage << cli::kLookUsage;
        return 2;
    }
    const auto iso_text = args.value("--iso");
    const auto out_path = args.value("--output", "-o");
    const cli::CameraFlags camera_flags = cli::CameraFlags::take(args);
    const auto steps = args.value("--steps"), depth_path = args.value("--depth");
    const auto normal_path = args.value("--normal"), threads = args.value("--threads");
    const auto root_finder = args.value("--root-finder"), iterations = args.value("--iterations");
    const auto spp_text = args.value("--spp");
    const auto shading_text = args.value("--shading"), background_text = args.value("--background");
    const std::vector<std::string> colour_texts = args.values("--colour");
    const bool no_embree = args.flag("--no-embree"), json = args.flag("--json");
    const auto traversal_text = args.value("--traversal"), isa_text = args.value("--isa");
    const auto debug_pixel = args.value("--debug-pixel");
    const cli::LookFlags look_flags = cli::LookFlags::take(args);   // issue 17 item 7
    const std::vector<std::string> inputs = args.positional();
    args.finish();
    if (inputs.size() != 1) throw Error("octiso-render", "expected exactly one FILE.oct (octiso-render --help lists every flag)");
    if (!iso_text) throw Error("--iso", "is required (one or more isovalues, e.g. --iso 40,120)");
    if (!out_path && !depth_path && !normal_path && !debug_pixel) throw Error("-o", "is required (or at least --depth or --normal)");

    RenderOptions options;
    options.isovalues = cli::parse_list(*iso_text, "--iso");
    options.want_colour = out_path.has_value();
    options.want_depth = depth_path.has_value();
    options.want_normal = normal_path.has_value();
    options.use_embree = !no_embree;
    if (traversal_text) {
        if (*traversal_text == "packets") options.traversal = Traversal::packets;
        else if (*traversal_text == "single") options.traversal = Traversal::single;
        else throw Error("--traversal", "expected packets or single, found '" + *traversal_text + "'");
    }
    if (isa_text) {
        if (*isa_text == "auto") options.isa = Isa::automatic;
        else if (*isa_text == "baseline") options.isa = Isa::baseline;
        else if (*isa_text == "avx2") options.isa = Isa::avx2;
        else throw Error("--isa", "expected auto, baseline or avx2, found '" + *isa_text + "'");
    }
    if (threads) options.threads = int(cli::parse_int(*threads, "--threads", 0, 4096));   // 0: all cores
    if (root_finder) options.root_finder = parse_root_finder_name(*root_finder);
    if (iterations) options.iterations = int(cli::parse_int(*iterations, "--iterations", 0, 1000));
    const int spp = spp_text ? int(cli::parse_int(*spp_text, "--spp", 1, kMaxSamplesPerPixel)) : 1;
    Shading shading;
    if (shading_text) {
        if (*shading_text == "kit") shading.model = ShadingModel::kit;
        else if (*shading_text == "headlight") shading.model = ShadingModel::headlight;
        else throw Error("--shading", "expected kit or headlight, found '" + *shading_text + "'");
    }
    if (background_text) shading.background = parse_colour(*background_text, "--background");
    if (colour_texts.size() > options.isovalues.size())
        throw Error("--colour", "given " + std::to_string(colour_texts.size()) + " times for " + std::to_string(options.isovalues.size()) +
                                    " isovalue(s) (the k-th --colour colours the k-th isovalue)");
    for (const std::string& c : colour_texts) shading.colours.push_back(parse_colour(c, "--colour"));
    // Issue 17 item 7: clip planes cut every ray; shadows, AO and opacity shade through LookShader.
    options.clip_planes = look_flags.clip_planes;
    const Look& look = look_flags.look;
    validate_look(look, options.isovalues.size(), shading.model);
    // The colour is shaded after tracing, from the depth and normal AOVs (shading.h), unless the
    // Renderer's own headlight is asked for as it is: that path stays bit for bit the old image.
    const bool deferred = out_path && (shading.model == ShadingModel::kit || background_text || !colour_texts.empty() || look.active());
    RenderOptions trace_options = options;
    if (deferred) trace_options.want_colour = false, trace_options.want_depth = trace_options.want_normal = true;

    // Everything about the outputs is checked before the first frame is rendered.
    const auto file = std::make_shared<const OctFile>(OctFile::open(inputs[0]));
    const OctInfo& info = file->info();
    // CONVENTIONS 2b: --iso is given in real values; the tree and the renderer hold stored ones.
    const std::vector<double> real_isovalues = options.isovalues;
    for (double& v : options.isovalues) v = info.value_scale.stored(v);
    trace_options.isovalues = options.isovalues;
    const std::vector<Camera> cameras = cli::cameras_for(camera_flags, info);
    const bool orbit = camera_flags.orbit.has_value();
    long long first = 0, last = 0;
    const auto has_field = [](const std::optional<std::string>& name) { return name && name->find('%') != std::string::npos; };
    bool series = steps.has_value();
    if (steps) {
        const auto range = cli::parse_steps(*steps, "--steps");
        first = range[0], last = range[1];
        if (last >= (long long)info.step_count)
            throw Error("--steps", "file has steps 0.." + std::to_string(info.step_count - 1) + ", asked for up to " + std::to_string(last));
        if (orbit && last > first) throw Error("--orbit", "renders one step (--steps K), found --steps " + *steps);
    } else if (!orbit && (has_field(out_path) || has_field(depth_path) || has_field(normal_path))) {
        // A printf field in a name and no --steps: one image per step of the whole file (issue 17:
        // never a file literally named frame_%02d.png).
        series = true;
        last = (long long)info.step_count - 1;
    } else if (info.step_count > 1 && !debug_pixel) {
        std::fprintf(stderr, "octiso-render: note: %s has %u steps; rendering step %lld (--steps A:B, or a %%04d field in -o, renders more)\n",
                     inputs[0].c_str(), info.step_count, first);
    }
    // One job per image: a step of a series, or a camera of an orbit. `index` fills the names' field.
    struct Job {
        long long step, index;
        const Camera* camera;
    };
    std::vector<Job> jobs;
    if (orbit) {
        for (size_t i = 0; i < cameras.size(); ++i) jobs.push_back({first, (long long)i, &cameras[i]});
        series = true;   // the names hold the frame number
    } else {
        for (long long k = first; k <= last; ++k) jobs.push_back({k, k, &cameras[0]});
    }
    auto name_for = [&](const std::optional<std::string>& pattern, const char* flag, long long index) {
        return series ? cli::format_step(*pattern, index, flag) : *pattern;
    };
    const long long first_index = jobs.front().index;
    if (out_path) check_image_path(name_for(out_path, "-o", first_index), "-o");
    if (depth_path) check_image_path(name_for(depth_path, "--depth", first_index), "--depth");
    if (normal_path) check_image_path(name_for(normal_path, "--normal", first_index), "--normal");
    if (depth_path && !image_format_holds_floats(name_for(depth_path, "--depth", first_index)))
        throw Error("--depth", "'" + name_for(depth_path, "--depth", first_index) +
                                   "' stores 8 bits; depth is a distance and needs a float format (.exr, .tif, .pfm, .hdr)");
    for (const Job& job : jobs) {   // issue 18: never replace the input
        if (out_path) refuse_output_onto_input(name_for(out_path, "-o", job.index), inputs, "-o");
        if (depth_path) refuse_output_onto_input(name_for(depth_path, "--depth", job.index), inputs, "--depth");
        if (normal_path) refuse_output_onto_input(name_for(normal_path, "--normal", job.index), inputs, "--normal");
        // Issue 17: a directory, a missing or read-only folder is refused before the first frame.
        if (out_path) cli::check_output_file(name_for(out_path, "-o", job.index), "-o");
        if (depth_path) cli::check_output_file(name_for(depth_path, "--depth", job.index), "--depth");
        if (normal_path) cli::check_output_file(name_for(normal_path, "--normal", job.index), "--normal");
    }
    // Issue 17: an isovalue outside the values the steps hold draws nothing; refuse it, naming the
    // range (the union of the rendered steps' root min/max, exact).
    std::optional<std::array<double, 2>> data_range;
    for (long long k = first; k <= last; ++k)
        if (const auto r = AnyOctree::step(file, uint32_t(k)).info().value_range)
            data_range = data_range ? std::array<double, 2>{std::min((*data_range)[0], (*r)[0]), std::max((*data_range)[1], (*r)[1])} : *r;
    if (data_range) data_range = info.value_scale.real_range(*data_range);
    if (data_range)
        for (const double v : real_isovalues)
            if (v < (*data_range)[0] || v > (*data_range)[1])
                throw Error(inputs[0], "isovalue " + cli::number(v) + " lies outside the data range " + cli::number((*data_range)[0]) +
                                           " .. " + cli::number((*data_range)[1]) + (last > first ? " of the rendered steps" : "") +
                                           " (nothing would be drawn; octiso-info shows the values)");
    const RenderLimits limits{info.iso_range, inputs[0]};
    validate_options(options, limits);

    // --debug-pixel X,Y: re-trace that one pixel (of the first step) and print its path; no image.
    if (debug_pixel) {
        const size_t comma = debug_pixel->find(',');
        if (comma == std::string::npos) throw Error("--debug-pixel", "expected X,Y, found '" + *debug_pixel + "'");
        const int x = int(cli::parse_int(debug_pixel->substr(0, comma), "--debug-pixel", INT32_MIN, INT32_MAX));
        const int y = int(cli::parse_int(debug_pixel->substr(comma + 1), "--debug-pixel", INT32_MIN, INT32_MAX));
        std::cout << AnyOctree::step(file, uint32_t(first)).trace_pixel(cameras[0], trace_options, x, y).text();
        return 0;
    }

    cli::JsonWriter j(std::cout);
    const auto camera_json = [&](const Camera& c) {
        j.begin_object().key("eye").array(c.eye).key("look").array(c.look).key("up").array(c.up);
        j.field("fov", c.fov_deg).field("width", c.width).field("height", c.height).end_object();
    };
    if (json) {
        j.begin_object().field("file", inputs[0]).field("type", std::string(scalar_type_name(info.type)));
        j.key("isovalues").array(real_isovalues);
        j.field("width", cameras[0].width).field("height", cameras[0].height);
        j.field("root_finder", std::string(root_finder ? *root_finder : "neubauer")).field("embree", options.use_embree);
        j.field("traversal", std::string(options.traversal == Traversal::packets ? "packets" : "single"));
        j.field("isa", std::string(resolve_isa(options.isa) == Isa::avx2 ? "avx2" : "baseline"));
        j.field("spp", spp).field("shading", deferred ? (shading.model == ShadingModel::kit ? "kit" : "headlight (deferred)") : "headlight");
        cli::write_look_json(j, look, options.clip_planes);   // issue 17 item 7
        j.key("camera");
        camera_json(cameras[0]);
        j.key("frames").begin_array();
    }
    cli::ProgressLine progress = cli::ProgressLine::on_stderr(jobs.size() > 1, 0.0);
    double total_seconds = 0;
    std::optional<Renderer> renderer;
    std::optional<AnyOctree> step_tree;
    std::optional<LookShader> look_shader;
    long long renderer_step = -1;
    for (size_t n = 0; n < jobs.size(); ++n) {
        const Job& job = jobs[n];
        // One Renderer per step, kept across the frames of an orbit; the Embree device behind it
        // is shared by the whole process.
        if (job.step != renderer_step) {
            renderer.reset();
            step_tree.emplace(AnyOctree::step(file, uint32_t(job.step)));
            renderer.emplace(step_tree->make_renderer(trace_options));
            if (deferred && look.active()) look_shader.emplace(*step_tree, trace_options, look, shading.model);
            renderer_step = job.step;
        }
        Frame frame;
        LookStats look_stats;
        const auto t0 = std::chrono::steady_clock::now();
        render_antialiased(*renderer, *job.camera, spp, frame, deferred ? SampleShader([&](const Camera& c, Frame& f) {
            if (look_shader) look_stats.add(look_shader->shade(c, shading, f));
            else shade_frame(*step_tree, options.isovalues, c, shading, f);
        }) : SampleShader());
        // The whole frame: every sample traced and shaded (frame.stats.seconds: the tile loops only).
        const double frame_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        file->check_unchanged();   // issue 18: never publish a frame of a file rewritten under us
        if (out_path) write_colour_image(name_for(out_path, "-o", job.index), frame);
        if (depth_path) write_depth_image(name_for(depth_path, "--depth", job.index), frame);
        if (normal_path) write_normal_image(name_for(normal_path, "--normal", job.index), frame);
        total_seconds += frame.stats.seconds;
        // The effective camera, as flags that reproduce it (issue 17: a view can be pasted back);
        // after the first image is written, so that a failure stays one line on stderr.
        if (n == 0)
            std::fprintf(stderr, "camera: %s%s\n", cli::camera_flags_text(cameras[0]).c_str(),
                         orbit ? (" (first of " + std::to_string(cameras.size()) + " orbit frames)").c_str() : "");
        if (json) {
            j.begin_object().field("step", job.step);
            if (orbit) j.field("frame", job.index);
            j.field("seconds", frame.stats.seconds).field("frame_seconds", frame_seconds);
            j.field("mrays_per_second", frame.stats.mrays_per_second()).field("rays", frame.stats.rays);
            j.field("hits", frame.stats.hits).field("threads", frame.stats.threads);
            if (out_path) j.field("image", name_for(out_path, "-o", job.index));
            if (look_shader) cli::write_look_stats_json(j, look_stats);
            j.key("camera");
            camera_json(*job.camera);
            j.end_object();
        }
        if (!series || !::isatty(2))
            std::fprintf(stderr, "%s%s: %dx%d in %.3f s (%.2f Mrays/s, %llu hits, %d threads%s)%s\n",
                         series ? ((orbit ? "frame " : "step ") + std::to_string(job.index) + " ").c_str() : "",
                         out_path ? name_for(out_path, "-o", job.index).c_str() : "frame", frame.width, frame.height,
                         frame.stats.seconds, frame.stats.mrays_per_second(), (unsigned long long)frame.stats.hits,
                         frame.stats.threads, spp > 1 ? (", " + std::to_string(spp) + " samples per pixel").c_str() : "",
                         orbit ? (" eye " + cli::numbers(job.camera->eye)).c_str() : "");
        if (look_shader && (!series || !::isatty(2))) cli::print_look_stats(look_stats);
        progress.update(double(n + 1), double(jobs.size()), std::to_string(n + 1) + "/" + std::to_string(jobs.size()) + " frames");
    }
    progress.finish();
    if (json) {
        j.end_array().field("total_seconds", total_seconds).end_object();
        std::cout << "\n";
    }
    if (series) std::fprintf(stderr, "%zu frames in %.3f s render time\n", jobs.size(), total_seconds);
    return 0;
}

}  // namespace
}  // namespace octiso

int main(int argc, char** argv) { return octiso::cli::run_main("octiso-render", argc, argv, octiso::run); }
