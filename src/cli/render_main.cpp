// octiso-render: renders isosurfaces of a .oct file (CONVENTIONS 3), one frame, or one frame per
// time step with --steps A:B (names then hold one printf integer field, e.g. frame_%04d.png).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <utility>

#include "cli/common/cli.h"
#include "cli/common/flags.h"
#include "cli/common/json.h"
#include "cli/frame_writer.h"
#include "cli/common/output_path.h"
#include "cli/common/progress.h"
#include "cli/common/report.h"
#include "cli/render_camera.h"
#include "cli/render_look.h"
#include "cli/render_progress.h"
#include "cli/render_ranks.h"
#include "util/process_memory.h"
#include "octiso/antialias.h"
#include "octiso/clip_cap.h"
#include "octiso/bricks.h"
#include "octiso/depth_composite.h"
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
    "Isovalues:\n"
    "  --iso V[,V...]            isovalues in the data's real values, up to 8 (required; no default)\n"
    "Outputs (at least one):\n"
    "  -o, --output OUT.png      colour image, 8-bit sRGB unless the format is float (.exr, .tif)\n"
    "  --depth DEPTH.exr         world distance to the first hit, +inf on a miss (float formats only)\n"
    "  --normal NORMAL.exr       world unit normal facing the ray, 0,0,0 on a miss (8-bit: n/2 + 1/2)\n"
    "  --json                    one JSON object on stdout (camera, timings in seconds); report on stderr\n"
    "  --debug-pixel X,Y         no image: prints the path of pixel X,Y (column, row from the top-left) of the\n"
    "                            first step through the tree instead (default: off)\n"
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
    "  --lod F                   level of detail: stop where a node's cells are at most F pixels wide at its\n"
    "                            nearest point and trace its coarse lattice (default 0: full resolution;\n"
    "                            close up, below 2 voxels per F pixels, the image is the exact one)\n"
    "Look:\n"
    "  --shading kit|headlight   kit: a key and a fill light fixed to the camera, a little specular (default);\n"
    "                            headlight: Lambert from the eye plus ambient (the images before issue 17)\n"
    "  --background COLOUR       R,G,B in [0, 1] or #RRGGBB, as shown on screen (default #212329)\n"
    "  --colour COLOUR           colour of the k-th isovalue, given once per isovalue in order\n"
    "                            (default palette: bone, blue, green, rose, yellow, violet, cyan, grey)\n"
    "Tracing:\n"
    "  --root-finder NAME        neubauer|schwarze|linear|exact (default neubauer)\n"
    "  --iterations N            refinement steps of the root finder (default: its own, neubauer 5)\n"
    "  --embree                  primary rays through an Embree scene holding the volume (same image; default:\n"
    "                            the traversal is called directly, 0-9 % less per frame)\n"
    "  --no-embree               the traversal directly: the default (kept for scripts that pass it)\n"
    "  --traversal packets|single  packets of 4x4 pixels (4x2 through --embree), or one ray at a time\n"
    "                            (default packets; same image)\n"
    "  --isa auto|baseline|avx2  traversal kernel: auto = AVX2 where the CPU has it (default; same image)\n"
    "  --threads N               worker threads, 0 = all cores (default 0)\n"
    "  --verify auto|full|touched  full: every node and checksum of a step before its first ray; touched:\n"
    "                            each block of nodes when a ray first reads it, no checksums, same safety\n"
    "                            (a frame of a huge file reads what it needs); auto: full up to 1 GiB\n"
    "                            files, touched above (default auto; octiso-info --verify checks it all)\n"
    "  --progress                draw the progress line (bar, ETA) on stderr even when it is not a terminal\n"
    "                            (default: only on a terminal, for a series at once, for one frame after 1 s)\n"
    "  --distribute steps|image|data  under mpirun: frames dealt to free ranks, each frame's tiles shared, or\n"
    "                            the volume cut into slabs and composited by depth (default steps)\n"
    "  --version, -h/--help\n";

int run(std::vector<std::string>& argv, cli::Ranks& ranks) {
    using cli::Distribute, cli::FrameRecord, cli::RankExchange;
    // --help (stdout, 0) and no argument (stderr, 2) as in every tool; under mpirun one rank prints.
    const std::string usage = std::string(kUsage) + cli::kLookUsage;
    if (const auto status = cli::answer_help(argv, ranks.rank == 0 ? usage : std::string())) return *status;
    cli::FlagSpec spec{{"-o,--output", "--iso", "--steps", "--depth", "--normal", "--threads", "--root-finder", "--iterations", "--spp", "--lod",
                        "--shading", "--background", "--traversal", "--isa", "--debug-pixel", "--distribute", "--verify"},
                       {"--colour"},
                       {"--embree", "--no-embree", "--json", "--progress"}};
    cli::CameraFlags::declare(spec);
    cli::LookFlags::declare(spec);   // issue 17 item 7
    const cli::Flags args(argv, spec);
    const auto iso_text = args.value("--iso");
    const auto out_path = args.value("--output");
    const cli::CameraFlags camera_flags = cli::CameraFlags::take(args);
    const auto steps = args.value("--steps"), depth_path = args.value("--depth");
    const auto normal_path = args.value("--normal"), threads = args.value("--threads");
    const auto root_finder = args.value("--root-finder"), iterations = args.value("--iterations");
    const auto spp_text = args.value("--spp"), lod_text = args.value("--lod");
    const auto shading_text = args.value("--shading"), background_text = args.value("--background");
    const std::vector<std::string>& colour_texts = args.values("--colour");
    const bool embree = args.flag("--embree"), no_embree = args.flag("--no-embree");
    const bool json = args.flag("--json"), progress_forced = args.flag("--progress");
    const auto traversal_text = args.value("--traversal"), isa_text = args.value("--isa");
    const auto debug_pixel = args.value("--debug-pixel");
    const auto distribute_text = args.value("--distribute");
    const auto verify_text = args.value("--verify");
    const cli::LookFlags look_flags = cli::LookFlags::take(args);
    const std::vector<std::string>& inputs = args.positional();
    if (inputs.size() != 1) throw Error("octiso-render", "expected exactly one FILE.oct (octiso-render --help lists every flag)");
    if (!iso_text) throw Error("--iso", "is required (one or more isovalues, e.g. --iso 40,120)");
    if (!out_path && !depth_path && !normal_path && !debug_pixel) throw Error("-o", "is required (or at least --depth or --normal)");

    const Distribute distribute = distribute_text ? cli::parse_distribute(*distribute_text) : Distribute::steps;
    if (distribute == Distribute::data && look_flags.look.active())
        throw Error("--distribute", "data traces each slab alone, so shadow, AO and translucent-layer rays cannot cross "
                                    "into other slabs; use --distribute image or steps with --shadows, --ao or --opacity");
    if (distribute == Distribute::data && look_flags.clip_cap)
        throw Error("--distribute", "data traces each slab alone, and a cap needs the field where each ray enters the kept part; "
                                    "use --distribute image or steps with --clip-cap");
    if (distribute_text && !ranks.mpi_built())
        throw Error("--distribute", "this octiso-render was built without MPI (install libopenmpi-dev and rebuild)");

    RenderOptions options;
    options.isovalues = cli::parse_list(*iso_text, "--iso");
    options.want_colour = out_path.has_value();
    options.want_depth = depth_path.has_value();
    options.want_normal = normal_path.has_value();
    if (embree && no_embree) throw Error("--embree", "contradicts --no-embree: give one of them");
    options.use_embree = embree;
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
    if (lod_text) options.lod = cli::parse_double(*lod_text, "--lod");
    if (lod_text && distribute_text && *distribute_text == "data")
        throw Error("--lod", "level of detail is not available with --distribute data (each rank's cut would differ)");
    const int spp = spp_text ? int(cli::parse_int(*spp_text, "--spp", 1, kMaxSamplesPerPixel)) : 1;
    Shading shading;
    shading.threads = options.threads;
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
    // --clip-cap draws its faces into the depth and normal AOVs (octiso/clip_cap.h), so it shades deferred too.
    const bool deferred = out_path && (shading.model == ShadingModel::kit || background_text || !colour_texts.empty() || look.active() ||
                                       look_flags.clip_cap);
    RenderOptions trace_options = options;
    if (deferred) trace_options.want_colour = false, trace_options.want_depth = trace_options.want_normal = true;
    if (look_flags.clip_cap) trace_options.want_depth = true;

    // Issue 13: checking every node of a 30 GB file before the first ray costs minutes and
    // leaves it all resident; from 1 GiB up the nodes are checked as rays reach them. Below,
    // the whole check takes under a second, and it also catches what Touched cannot (checksums).
    constexpr uint64_t kTouchedFromBytes = uint64_t(1) << 30;
    Verify verify = Verify::Full;
    if (!verify_text || *verify_text == "auto") {
        std::error_code ec;
        const auto size = std::filesystem::file_size(inputs[0], ec);
        verify = !ec && size > kTouchedFromBytes ? Verify::Touched : Verify::Full;
    } else if (*verify_text == "touched") {
        verify = Verify::Touched;
    } else if (*verify_text != "full") {
        throw Error("--verify", "expected auto, full or touched, found '" + *verify_text + "'");
    }
    // Everything about the outputs is checked before the first frame is rendered.
    const auto open_start = std::chrono::steady_clock::now();
    std::optional<double> open_to_first_frame;   // seconds from open to the first frame traced
    const auto file = std::make_shared<const OctFile>(OctFile::open(inputs[0], verify));
    const OctInfo& info = file->info();
    // CONVENTIONS 2b: --iso is given in real values; the tree and the renderer hold stored ones.
    const std::vector<double> real_isovalues = options.isovalues;
    for (double& v : options.isovalues) v = info.value_scale.stored(v);
    trace_options.isovalues = options.isovalues;
    const std::vector<Camera> cameras = cli::cameras_for(camera_flags, info);
    // Inside is value >= V in real values: in stored values too unless the scale's slope is negative.
    if (look_flags.clip_cap) shading.cap = ClipCap{options.clip_planes, !(info.value_scale.slope < 0)};
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
    } else if (info.step_count > 1 && !debug_pixel && ranks.rank == 0) {
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
    if (out_path) check_image_path(name_for(out_path, "-o", first_index), "-o", ImageContent::Colour);
    if (depth_path) check_image_path(name_for(depth_path, "--depth", first_index), "--depth", ImageContent::Aov);
    if (normal_path) check_image_path(name_for(normal_path, "--normal", first_index), "--normal", ImageContent::Aov);
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
    // Reading a step's range validates the step (checksums, structure): a series dealt over ranks
    // splits that work (step k on rank k mod R) and unites the ranges after the agreement below.
    const bool split_validation = ranks.size > 1 && distribute == Distribute::steps;
    std::optional<std::array<double, 2>> data_range;
    for (long long k = first; k <= last; ++k)
        if (!split_validation || (k - first) % ranks.size == ranks.rank)
            if (const auto r = AnyOctree::step(file, uint32_t(k)).value_range())
                data_range = data_range ? std::array<double, 2>{std::min((*data_range)[0], (*r)[0]), std::max((*data_range)[1], (*r)[1])} : *r;
    file->check_unchanged();   // the ranges came from root nodes: under --verify touched, checked ones
    const auto refuse_outside_range = [&]() -> int {
        if (data_range) data_range = info.value_scale.real_range(*data_range);
        if (data_range)
            for (const double v : real_isovalues)
                if (v < (*data_range)[0] || v > (*data_range)[1]) {
                    const Error e(inputs[0], "isovalue " + cli::number(v) + " lies outside the data range " + cli::number((*data_range)[0]) +
                                                 " .. " + cli::number((*data_range)[1]) + (last > first ? " of the rendered steps" : "") +
                                                 " (nothing would be drawn; octiso-info shows the values)");
                    if (!split_validation) throw e;
                    // Every rank holds the same united range, so every rank decides the same: one prints.
                    if (ranks.rank == 0) std::fprintf(stderr, "octiso-render: %s\n", e.what());
                    return e.exit_status();
                }
        return 0;
    };
    if (!split_validation)
        if (const int refused = refuse_outside_range()) return refused;
    const RenderLimits limits{info.iso_range, inputs[0]};
    validate_options(options, limits);

    // --debug-pixel X,Y: re-trace that one pixel (of the first step) and print its path; no image.
    if (debug_pixel) {
        const size_t comma = debug_pixel->find(',');
        if (comma == std::string::npos) throw Error("--debug-pixel", "expected X,Y, found '" + *debug_pixel + "'");
        const int x = int(cli::parse_int(debug_pixel->substr(0, comma), "--debug-pixel", INT32_MIN, INT32_MAX));
        const int y = int(cli::parse_int(debug_pixel->substr(comma + 1), "--debug-pixel", INT32_MIN, INT32_MAX));
        if (ranks.rank == 0) std::cout << AnyOctree::step(file, uint32_t(first)).trace_pixel(cameras[0], trace_options, x, y).text();
        return 0;
    }

    // ---- Distribution over MPI ranks (issue 15; one rank, the default, is the serial tool) ----
    const int rank = ranks.rank, rank_count = ranks.size;
    const bool root = rank == 0;
    const bool split_frames = distribute != Distribute::steps && rank_count > 1;
    RenderOptions rank_options = trace_options;
    CompositeLayout layout;
    const std::vector<CellBox> bricks = slab_bricks(info.dims, rank_count);
    if (distribute == Distribute::data) {
        // Each rank traces its slab of cells (octiso/bricks.h) and the frames are composited by
        // depth, which needs the depth of every sample whatever is written.
        rank_options.want_depth = true;
        rank_options.owned_cells = bricks[size_t(rank)];
        layout = CompositeLayout{rank_options.want_colour || deferred, normal_path.has_value()};
    }
    // Every rank got this far (or a lower one reports why not): from here a failure aborts all.
    if (const int failed = ranks.agree_ready(0)) return failed;
    if (split_validation) {
        data_range = ranks.unite_range(data_range);
        if (const int refused = refuse_outside_range()) return refused;
    }
    // Sort-last: validation read the whole file; from here this rank holds only what its brick reads.
    if (split_frames && distribute == Distribute::data) file->release_resident_pages();

    cli::JsonWriter j(std::cout);
    const auto camera_json = [&](const Camera& c) {
        j.begin_object().key("eye").array(c.eye).key("look").array(c.look).key("up").array(c.up);
        j.field("fov", c.fov_deg).field("width", c.width).field("height", c.height).end_object();
    };
    // Issue 17 item 5: one line for the run, frames and the tiles inside each (cli/render_progress.h).
    const bool one_process = root && rank_count == 1;
    cli::RenderProgress progress(one_process, progress_forced && one_process, jobs.size(), spp);
    std::optional<Renderer> renderer;
    std::optional<AnyOctree> step_tree;
    std::optional<LookShader> look_shader;
    long long renderer_step = -1;
    uint64_t ghost_bytes = 0;   // sent with the latest step's ghost exchange
    std::vector<FrameRecord> records;   // this rank's frames
    std::vector<size_t> job_of_record;  // the job each record is of
    // Issue 12: with more than one frame, the images are written on a thread of their own while
    // the next frame renders; each frame's write time lands in write_seconds[job].
    std::vector<double> write_seconds(jobs.size(), 0.0);
    std::optional<cli::FrameWriter> writer;
    if (jobs.size() > 1) writer.emplace();
    // The previous frame's buffers, rendered into again (a frame this rank did not hand to the
    // writer, else the writer's latest written one): a fresh frame's buffers are page faults and
    // zeroing on every frame of a series (BENCHMARKS "Frame buffers").
    Frame spare_frame;
    const auto wall_start = std::chrono::steady_clock::now();
    const auto render_job = [&](size_t n) {
        const Job& job = jobs[n];
        // One Renderer per step, kept across the frames of an orbit; the Embree device behind it
        // is shared by the whole process.
        double step_setup_seconds = 0;
        if (job.step != renderer_step) {
            const auto setup_start = std::chrono::steady_clock::now();
            renderer.reset();
            step_tree.emplace(AnyOctree::step(file, uint32_t(job.step)));
            if (split_frames && distribute == Distribute::data)   // the voxels beyond the slab, from their owner
                rank_options.ghost_plane = ranks.ghost_plane(bricks, [&](uint32_t x) { return step_tree->x_plane(x); }, ghost_bytes);
            renderer.emplace(step_tree->make_renderer(rank_options));
            if (deferred && look.active()) look_shader.emplace(*step_tree, rank_options, look, shading.model);
            renderer_step = job.step;
            step_setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count();
        }
        FrameRecord record;
        record.index = job.index, record.step = job.step, record.rank = rank;
        record.step_setup_seconds = step_setup_seconds;
        record.bytes_sent = std::exchange(ghost_bytes, 0);
        // One sample: traced by this rank (its tiles or its brick when frames are split), shaded
        // here (deferred shading reads only the pixel's own hit), then assembled on rank 0.
        const auto render_sample = [&](const Camera& c, Frame& f) {
            RenderStats stats;
            if (split_frames && distribute == Distribute::image) {
                renderer->prepare_frame(c, f);
                // Pixels of other ranks' tiles are misses here, so shading them costs nothing.
                std::fill(f.depth.begin(), f.depth.end(), std::numeric_limits<float>::infinity());
                std::fill(f.normal.begin(), f.normal.end(), 0.0f);
                const TileGrid grid = renderer->tile_grid(c.width, c.height);
                stats = renderer->render_tiles(c, ranks.tiles_of(grid.count()), f);
            } else {
                stats = progress.trace(*renderer, c, f, n);   // in batches of tiles while a progress line is on
            }
            progress.shading();
            const auto shade_start = std::chrono::steady_clock::now();
            if (shading.cap) cap_clip_planes(*step_tree, options.isovalues, *shading.cap, c, f);
            if (deferred && look_shader) record.look.add(look_shader->shade(c, shading, f));
            else if (deferred) shade_frame(*step_tree, options.isovalues, c, shading, f);
            record.shade_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - shade_start).count();
            progress.sample_done();
            if (split_frames) {
                const RankExchange cost = distribute == Distribute::image
                                              ? ranks.gather_tiles(renderer->tile_grid(c.width, c.height), out_path.has_value(),
                                                                   depth_path.has_value(), normal_path.has_value(), f)
                                              : ranks.composite(layout, f);
                record.exchange_seconds += cost.seconds;
                record.bytes_sent += cost.bytes_sent;
            }
            record.rays += stats.rays;
            for (size_t k = 0; k < stats.hits_by_cell_log2.size(); ++k) record.hits_by_cell_log2[k] += stats.hits_by_cell_log2[k];
            record.seconds += stats.seconds;
            record.busy_seconds += stats.busy_seconds;
            record.threads = stats.threads;
            return stats;
        };
        Frame frame = std::exchange(spare_frame, Frame{});
        if (writer && frame.width == 0) frame = writer->take_written();
        const auto t0 = std::chrono::steady_clock::now();
        render_antialiased(SampleRenderer(render_sample), *job.camera, spp, frame);
        // The whole frame: every sample traced and shaded (record.seconds: the tile loops only).
        record.frame_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        record.hits = frame.stats.hits;
        if (!open_to_first_frame) open_to_first_frame = std::chrono::duration<double>(std::chrono::steady_clock::now() - open_start).count();
        file->check_unchanged();   // issue 18: never publish a frame of a file rewritten under us
        const int frame_width = frame.width, frame_height = frame.height;
        if (root || !split_frames) {
            const long long index = job.index;
            const auto write = [&, index](const Frame& f) {
                // Each file's PNG strips or OpenEXR blocks compressed by as many threads as the
                // trace has (the writer runs beside the next frame: BENCHMARKS "Image writers").
                if (out_path) write_colour_image(name_for(out_path, "-o", index), f, options.threads);
                if (depth_path) write_depth_image(name_for(depth_path, "--depth", index), f, options.threads);
                if (normal_path) write_normal_image(name_for(normal_path, "--normal", index), f, options.threads);
            };
            if (writer) {   // written while the next frame renders (cli/frame_writer.h)
                writer->submit(std::move(frame), write, &write_seconds[n]);
                if (records.empty()) writer->finish();   // the first image before the camera line
            } else {
                const auto write_start = std::chrono::steady_clock::now();
                write(frame);
                write_seconds[n] = std::chrono::duration<double>(std::chrono::steady_clock::now() - write_start).count();
                spare_frame = std::move(frame);
            }
            record.wrote = true;
        } else {
            spare_frame = std::move(frame);
        }
        // The effective camera, as flags that reproduce it (issue 17: a view can be pasted back);
        // after the first image is written, so that a failure stays one line on stderr.
        if (root && records.empty()) progress.break_line();
        if ((root || !split_frames) && (!series || !::isatty(2))) progress.break_line();
        if (root && records.empty())
            std::fprintf(stderr, "camera: %s%s\n", cli::camera_flags_text(cameras[0]).c_str(),
                         orbit ? (" (first of " + std::to_string(cameras.size()) + " orbit frames)").c_str() : "");
        if ((root || !split_frames) && (!series || !::isatty(2)))
            std::fprintf(stderr, "%s%s%s: %dx%d in %.3f s (%.2f Mrays/s, %llu hits, %d threads%s)%s\n",
                         rank_count > 1 && !split_frames ? ("rank " + std::to_string(rank) + ": ").c_str() : "",
                         series ? ((orbit ? "frame " : "step ") + std::to_string(job.index) + " ").c_str() : "",
                         out_path ? name_for(out_path, "-o", job.index).c_str() : "frame", frame_width, frame_height,
                         record.seconds, record.seconds > 0 ? double(record.rays) / record.seconds * 1e-6 : 0.0,
                         (unsigned long long)record.hits, record.threads,
                         spp > 1 ? (", " + std::to_string(spp) + " samples per pixel").c_str() : "",
                         orbit ? (" eye " + cli::numbers(job.camera->eye)).c_str() : "");
        if (look_shader && (root || !split_frames) && (!series || !::isatty(2))) cli::print_look_stats(record.look);
        records.push_back(record);
        job_of_record.push_back(n);
    };
    if (!split_frames && rank_count > 1) {
        // Series across ranks: rank 0 deals the jobs one at a time to whichever rank is free.
        ranks.deal(jobs.size(), render_job);
    } else {
        for (size_t n = 0; n < jobs.size(); ++n) render_job(n);
    }
    if (writer) writer->finish();
    for (size_t i = 0; i < records.size(); ++i) records[i].write_seconds = write_seconds[job_of_record[i]];
    progress.break_line();
    const double wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    // Rank 0 learns every rank's frames: all of them (steps), or each rank's share of each frame.
    // Sort-last: how much of the file this rank mapped (issue 15: its brick's pages and little
    // else; /proc/self/smaps, the kernel's fault-around included).
    const uint64_t resident = rank_count > 1 ? mapped_resident_bytes(inputs[0]) : 0;
    const std::vector<FrameRecord> all = ranks.gather_records(records, wall_seconds, resident);
    if (!root) return 0;
    std::vector<FrameRecord> frames;   // one per image, in index order, rank 0's share when split
    for (const FrameRecord& r : all)
        if (r.wrote) frames.push_back(r);
    std::sort(frames.begin(), frames.end(), [](const FrameRecord& a, const FrameRecord& b) { return a.index < b.index; });
    double total_seconds = 0;
    for (const FrameRecord& r : all) total_seconds += r.seconds;
    if (json) {
        j.begin_object().field("file", inputs[0]).field("type", std::string(scalar_type_name(info.type)));
        j.key("isovalues").array(real_isovalues);
        j.field("width", cameras[0].width).field("height", cameras[0].height);
        j.field("root_finder", std::string(root_finder ? *root_finder : "neubauer")).field("embree", options.use_embree);
        j.field("traversal", std::string(options.traversal == Traversal::packets ? "packets" : "single"));
        j.field("isa", std::string(resolve_isa(options.isa) == Isa::avx2 ? "avx2" : "baseline"));
        j.field("lod", options.lod);
        j.field("verify", std::string(file->verify() == Verify::Touched ? "touched" : "full"));
        if (const auto t = file->touch_stats())
            j.key("touched_blocks").begin_object().field("blocks", (long long)t->blocks).field("checked", (long long)t->checked)
                .field("block_bytes", (long long)t->block_bytes).end_object();
        if (open_to_first_frame) j.field("open_to_first_frame_seconds", *open_to_first_frame);
        j.field("file_resident_bytes", (long long)(rank_count > 1 ? resident : mapped_resident_bytes(inputs[0])));
        j.field("spp", spp).field("shading", deferred ? (shading.model == ShadingModel::kit ? "kit" : "headlight (deferred)") : "headlight");
        cli::write_look_json(j, look_flags);   // issue 17 item 7
        j.field("ranks", rank_count).field("distribute", std::string(distribute_name(distribute)));
        j.key("camera");
        camera_json(cameras[0]);
        j.key("frames").begin_array();
        for (const FrameRecord& r : frames) {
            j.begin_object().field("step", r.step);
            if (orbit) j.field("frame", r.index);
            j.field("seconds", r.seconds).field("frame_seconds", r.frame_seconds);
            // Issue 12: where the frame's time goes. trace is the tile loops (parallel; busy is its
            // thread seconds, utilisation busy / (threads x trace)); shade the deferred passes;
            // other the rest of the frame (buffers, antialiasing sums, the MPI exchange); write
            // the image files (for a series or an orbit on the writer thread, while the next frame
            // renders: not part of frame_seconds); step_setup the Renderer of a new step.
            j.key("phases").begin_object().field("trace", r.seconds).field("trace_busy", r.busy_seconds)
                .field("utilisation", r.seconds > 0 && r.threads > 0 ? r.busy_seconds / (r.seconds * r.threads) : 0.0)
                .field("shade", r.shade_seconds).field("other", std::max(0.0, r.frame_seconds - r.seconds - r.shade_seconds))
                .field("write", r.write_seconds).field("step_setup", r.step_setup_seconds).end_object();
            j.field("mrays_per_second", r.seconds > 0 ? double(r.rays) / r.seconds * 1e-6 : 0.0).field("rays", r.rays);
            j.field("hits", r.hits).field("threads", r.threads);
            if (options.lod > 0) {   // issue 14: hits by the depth whose cells they lie in (dmax: full resolution)
                j.key("hit_depths").begin_object();
                for (size_t k = 0; k < r.hits_by_cell_log2.size(); ++k)
                    if (r.hits_by_cell_log2[k]) j.field(std::to_string(info.dmax - int(k)), r.hits_by_cell_log2[k]);
                j.end_object();
            }
            if (rank_count > 1) j.field("rank", r.rank);
            if (out_path) j.field("image", name_for(out_path, "-o", r.index));
            if (look.active()) cli::write_look_stats_json(j, r.look);
            j.key("camera");
            camera_json(*jobs[size_t(r.index - jobs.front().index)].camera);
            if (split_frames) {   // every rank's share of this frame
                j.key("ranks").begin_array();
                for (const FrameRecord& q : all)
                    if (q.index == r.index)
                        j.begin_object().field("rank", q.rank).field("seconds", q.seconds).field("rays", q.rays)
                            .field("exchange_seconds", q.exchange_seconds).field("bytes_sent", q.bytes_sent).end_object();
                j.end_array();
            }
            j.end_object();
        }
        j.end_array().field("total_seconds", total_seconds).field("wall_seconds", wall_seconds);
        if (rank_count > 1) {   // per rank: its steps (or frame shares) and seconds
            j.key("per_rank").begin_array();
            for (int q = 0; q < rank_count; ++q) {
                std::vector<long long> steps_done;
                double seconds = 0, rank_wall = 0;
                uint64_t rank_resident = 0;
                for (const FrameRecord& r : all)
                    if (r.rank == q)
                        steps_done.push_back(r.step), seconds += r.seconds, rank_wall = r.rank_wall_seconds,
                            rank_resident = r.file_resident_bytes;
                j.begin_object().field("rank", q).field("frames", (long long)steps_done.size());
                j.key("steps").array(steps_done);
                j.field("seconds", seconds).field("wall_seconds", rank_wall).field("file_resident_bytes", rank_resident);
                if (distribute == Distribute::data) {
                    const CellBox& b = bricks[size_t(q)];
                    j.key("brick").begin_object().key("lo").array(b.lo).key("hi").array(b.hi).end_object();
                }
                j.end_object();
            }
            j.end_array();
        }
        j.end_object();
        std::cout << "\n";
    }
    if (series) std::fprintf(stderr, "%zu frames in %.3f s render time%s\n", frames.size(), total_seconds,
                             rank_count > 1 ? (", " + cli::number(wall_seconds) + " s wall on " + std::to_string(rank_count) + " ranks").c_str() : "");
    return 0;
}

}  // namespace
}  // namespace octiso

int main(int argc, char** argv) {
    std::optional<octiso::cli::Ranks> ranks;
    try {
        ranks.emplace(octiso::cli::Ranks::for_process(argc, argv));   // MPI_Init under mpirun
    } catch (const std::exception& e) {
        std::fprintf(stderr, "octiso-render: %s\n", e.what());
        return 1;
    }
    // Under mpirun every rank prepares the same work; a failure is reported once, by the lowest
    // rank that met it, and every rank exits with it (cli/render_ranks.h).
    return octiso::cli::run_main("octiso-render", argc, argv, [&](std::vector<std::string>& args) {
        try {
            return octiso::run(args, *ranks);
        } catch (const octiso::Error& e) {
            if (ranks->should_report(e.exit_status(), e.what())) throw;
            return e.exit_status();
        } catch (const std::exception& e) {
            if (ranks->should_report(1, e.what())) throw;
            return 1;
        }
    });
}
