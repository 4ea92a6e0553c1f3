// octiso-bench interactive (issue 20): latency from an isovalue change to the new frame received
// and decoded, through octiso-view's own server (in process, real HTTP on loopback, one client
// connection: what the page does), at each image size. Next to it, what the same change costs
// the mesh path before its first ray: flying-edges extraction + Embree BVH build (peers_mesh.h).
// The client asks for the page's loopback format (raw RGBA, request.h), so the figure covers
// request, render, the RGBA widening, transfer; the browser's canvas and paint are not in it
// (bench/interactive_browser.py measures those).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "bench/bench.h"
#include "bench/peers_mesh.h"
#include "octiso/any_octree.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/reader.h"
#include "octiso/synthetic.h"

#ifdef OCTISO_HAVE_VIEW
#include <unistd.h>

#include <httplib.h>

#include "view/server.h"
#include "view/session.h"
#endif

namespace octiso::bench {
namespace {

const char* const kInteractiveUsage =
    "usage: octiso-bench interactive [--datasets SPEC,...] [--sizes 512,1024] [--changes N] [--threads N]\n"
    "                                [--no-mesh] [--mesh-up-to-gib G] [--quick] [--shadows] [--ao N]\n"
    "  SPEC: a volume file (default /usr/share/mricron/templates/ch2better.nii.gz), NAME:N (synthetic) or an\n"
    "  existing .oct (opened as octiso-view opens it; e.g. octiso-convert --synthetic mixing:2048,2048,1920);\n"
    "  default datasets ch2better and marschner-lobb:256 (--quick: marschner-lobb:64 for the synthetic);\n"
    "  --changes isovalue changes per size (default 60, --quick 4), --threads render threads (default 2);\n"
    "  mesh: median of 3 isovalues (--quick: 1); not run where the dense array exceeds G GiB\n"
    "  (--mesh-up-to-gib, default a quarter of the RAM: the array, its mesh and the BVH are all in memory at once).\n"
    "  Latency: GET /frame sent -> RGBA frame received (the page's loopback format), p50 and p95; mesh: extraction + BVH per change;\n"
    "  orbit: --changes azimuth steps at a third of the side (the page's drag frames), frames/s back to back;\n"
    "  --shadows, --ao N: every frame with the page's look toggles (the light kit with shadow / N AO rays per hit;\n"
    "  the orbit's drag frames skip AO, as the page's do).\n"
    "  JSON: interactive.json, or interactive_NAME_NAME.json for a --datasets list.";

#ifdef OCTISO_HAVE_VIEW

struct Row {
    std::string dataset;
    int side = 0, changes = 0;
    double p50_ms = 0, p95_ms = 0, render_p50_ms = 0, max_ms = 0;
    double mesh_extract_ms = 0, mesh_bvh_ms = 0;
    std::string mesh_skipped = {};          ///< why the mesh path was not run, if it was not
    uint64_t hits_last = 0;
    int preview_side = 0;                  ///< the page's drag frames: a third of the side
    double orbit_fps = 0, orbit_p95_ms = 0;   ///< back-to-back azimuth changes at preview_side
};

double percentile(std::vector<double> v, double p) {
    std::sort(v.begin(), v.end());
    const size_t i = std::min(v.size() - 1, size_t(std::ceil(p * double(v.size())) - 1));
    return v[i];
}

/// Checks a frame as the page receives it on loopback (raw RGBA, enc=rgba: nothing to decode,
/// request.h) and returns its pixel count; a reply of another size is an error.
size_t check_rgba(const std::string& body, int width, int height) {
    const size_t pixels = size_t(width) * size_t(height);
    if (body.size() != pixels * 4)
        throw Error("interactive", "frame of " + std::to_string(body.size()) + " bytes, expected " + std::to_string(width) + "x" +
                                       std::to_string(height) + "x4", ErrorKind::Other);
    return pixels;
}

int run_interactive(cli::Args& args) {
    if (args.flag("--help")) {
        std::cout << kInteractiveUsage << "\n";
        return 0;
    }
    const bool quick = args.flag("--quick"), no_mesh = args.flag("--no-mesh"), shadows = args.flag("--shadows");
    const auto ao_flag = args.value("--ao"), mesh_limit_flag = args.value("--mesh-up-to-gib");
    const auto datasets_flag = args.value("--datasets"), sizes_flag = args.value("--sizes");
    const auto changes_flag = args.value("--changes"), threads_flag = args.value("--threads");
    const std::string results = results_dir(args);
    args.finish();
    std::vector<std::string> datasets{"/usr/share/mricron/templates/ch2better.nii.gz", quick ? "marschner-lobb:64" : "marschner-lobb:256"};
    if (datasets_flag) {
        datasets.clear();
        std::string s = *datasets_flag;
        for (size_t at = 0; at <= s.size();) {
            const size_t comma = std::min(s.find(',', at), s.size());
            if (comma > at) datasets.push_back(s.substr(at, comma - at));
            at = comma + 1;
        }
    }
    std::vector<int> sides{512, 1024};
    if (sizes_flag) {
        sides.clear();
        for (double v : cli::parse_list(*sizes_flag, "--sizes")) sides.push_back(int(v));
    }
    const int changes = changes_flag ? int(cli::parse_int(*changes_flag, "--changes", 2, 100000)) : quick ? 4 : 60;
    const int threads = threads_flag ? int(cli::parse_int(*threads_flag, "--threads", 1, 1024)) : 2;
    const int ao = ao_flag ? int(cli::parse_int(*ao_flag, "--ao", 0, view::kMaxViewAoSamples)) : 0;
    // The look of every frame as the page asks for it (request.h); drag frames never carry AO.
    const std::string look = std::string(shadows ? "&shadows=1" : "") + (ao > 0 ? "&ao=" + std::to_string(ao) : "");
    const std::string drag_look = shadows ? "&shadows=1" : "";

    std::vector<Row> rows;
    Table table({"dataset", "image", "changes", "p50 ms", "p95 ms", "max ms", "render p50 ms", "mesh extract ms", "mesh BVH ms",
                 "orbit frames", "orbit fps", "orbit p95 ms"});
    const auto scratch = std::filesystem::temp_directory_path() / ("octiso-bench-interactive-" + std::to_string(::getpid()));
    std::filesystem::create_directories(scratch);
    for (const std::string& spec : datasets) {
        // 1. The volume, as a one-step .oct file the viewer opens like any other (an existing
        //    .oct as it is: a volume larger than a dense copy should take is converted out of core).
        const bool is_oct = spec.size() > 4 && spec.compare(spec.size() - 4, 4, ".oct") == 0;
        const bool synthetic = !is_oct && spec.find(':') != std::string::npos && !std::filesystem::exists(spec);
        std::optional<LoadedVolume> volume;
        if (!is_oct) volume = synthetic ? make_synthetic(parse_synthetic(spec)) : open_volume(spec, RawOptions{});
        const std::string name = synthetic ? spec : std::filesystem::path(spec).filename().string();
        const std::string oct = is_oct ? spec : (scratch / "bench.oct").string();
        const AnyOctree tree = is_oct ? AnyOctree::open(spec, 0, Verify::Touched) : AnyOctree::build(*volume, BuildOptions{});
        if (!is_oct) tree.save(oct);
        const auto range = tree.value_range().value_or(std::array<double, 2>{0, 1});
        // Isovalues of a drag along the slider: around the dataset's usual surface (ch2: the
        // white/grey matter boundary; a synthetic: the middle of its range), each request a change.
        const double centre = synthetic || is_oct ? (range[0] + range[1]) / 2 : default_isovalue(name);
        const double stride = (range[1] - range[0]) / 400;
        auto iso_of = [&](int i) { return centre + stride * double((i % 20) - 10); };

        // 2. The server, as octiso-view runs it (no rate bound in the way of the measurement).
        view::ViewSession session(oct, threads);
        view::ServerOptions options;
        options.port = 0;
        options.rate_capacity = 1e9;
        view::ViewServer server(session, options);
        struct Serving {   // stops and joins also when a measurement throws
            view::ViewServer& server;
            std::thread thread{[this] { server.serve(); }};
            ~Serving() {
                server.stop();
                thread.join();
            }
        };
        {
            Serving serving{server};
            httplib::Client client("127.0.0.1", server.bound_port());
            client.set_keep_alive(true);
            client.set_tcp_nodelay(true);   // as a browser does
            client.set_read_timeout(120, 0);
            for (int side : sides) {
                Row row{name, side, changes};
                std::vector<double> latency, render;
                for (int i = -2; i < changes; ++i) {   // two warm-up frames build the Renderer
                    char target[256];
                    std::snprintf(target, sizeof target, "/frame?iso=%.17g&az=%.17g&el=%.17g&w=%d&h=%d&seq=%d&enc=rgba%s", iso_of(i + 2),
                                  kDefaultAzimuthDeg, kDefaultElevationDeg, side, side, i + 3, look.c_str());
                    const auto t0 = std::chrono::steady_clock::now();
                    auto res = client.Get(target);
                    if (!res || res->status != 200)
                        throw Error(name, "viewer replied " + (res ? std::to_string(res->status) + " " + res->body : std::string("nothing")),
                                    ErrorKind::Other);
                    check_rgba(res->body, side, side);
                    const double ms = seconds_since(t0) * 1e3;
                    if (i < 0) continue;
                    latency.push_back(ms);
                    const std::string stats = res->get_header_value("X-Octiso-Stats");
                    // The frame's render: the tile loop plus the look's pass (0 without toggles).
                    render.push_back((std::stod(stats.substr(stats.find("seconds=") + 8)) + std::stod(stats.substr(stats.find(";look=") + 6))) * 1e3);
                    const size_t h = stats.find("hits=");
                    row.hits_last = std::stoull(stats.substr(h + 5));
                }
                // Orbiting: the page's drag frames (a third of the side), one azimuth step of 2
                // degrees per request, each sent when the previous one is decoded.
                row.preview_side = std::max(1, (side + 1) / 3);
                std::vector<double> orbit;
                const auto orbit_start = std::chrono::steady_clock::now();
                for (int i = 0; i < changes; ++i) {
                    char target[256];
                    std::snprintf(target, sizeof target, "/frame?iso=%.17g&az=%.17g&el=%.17g&w=%d&h=%d&seq=%d&enc=rgba%s", iso_of(0),
                                  kDefaultAzimuthDeg + 2.0 * (i + 1), kDefaultElevationDeg, row.preview_side, row.preview_side, i,
                                  drag_look.c_str());
                    const auto t0 = std::chrono::steady_clock::now();
                    auto res = client.Get(target);
                    if (!res || res->status != 200) throw Error(name, "viewer refused an orbit frame", ErrorKind::Other);
                    check_rgba(res->body, row.preview_side, row.preview_side);
                    orbit.push_back(seconds_since(t0) * 1e3);
                }
                row.orbit_fps = double(changes) / seconds_since(orbit_start);
                row.orbit_p95_ms = percentile(orbit, 0.95);
                row.p50_ms = percentile(latency, 0.5);
                row.p95_ms = percentile(latency, 0.95);
                row.max_ms = percentile(latency, 1.0);
                row.render_p50_ms = percentile(render, 0.5);
                rows.push_back(row);
            }
        }
        // 3. The mesh path for the same changes: extraction + BVH (median of 3 isovalues, 1 with
        //    --quick), on the dense array (decoded from an .oct), where it fits beside its mesh.
        std::string mesh_skipped;
        const double ram = double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGESIZE));
        const double mesh_limit = mesh_limit_flag ? cli::parse_double(*mesh_limit_flag, "--mesh-up-to-gib") * double(1 << 30) : ram / 4;
        if (!no_mesh && double(tree.dense_bytes()) > mesh_limit)
            mesh_skipped = "the dense array (" + fmt(double(tree.dense_bytes()) / double(1 << 30), 1) + " GiB) exceeds " +
                           (mesh_limit_flag ? "--mesh-up-to-gib" : "a quarter of the RAM") + ", before its mesh and BVH";
        if (!no_mesh && mesh_skipped.empty() && !volume) {
            auto dense = std::make_shared<std::vector<std::byte>>(size_t(tree.dense_bytes()));
            tree.decode(*dense);
            const std::byte* data = dense->data();
            volume.emplace(std::move(dense), data, tree.type(), tree.dims(), tree.placement(), false, spec, VolumeFormat::raw);
        }
        if (!no_mesh && mesh_skipped.empty()) {
            std::vector<double> extract, bvh;
            MeshPeerOptions mesh_options;
            mesh_options.threads = threads;
            for (int i = 0; i < (quick ? 1 : 3); ++i) {
                const Camera camera = orbit_camera(volume->dims(), volume->placement(), 64, 64, kDefaultAzimuthDeg, kDefaultElevationDeg);
                const MeshPeerResult m = run_mesh_peer(*volume, iso_of(i * 7), camera, mesh_options);
                extract.push_back(m.extract_seconds * 1e3);
                bvh.push_back(m.bvh_seconds * 1e3);
            }
            for (Row& r : rows)
                if (r.dataset == name) r.mesh_extract_ms = percentile(extract, 0.5), r.mesh_bvh_ms = percentile(bvh, 0.5);
        }
        for (Row& r : rows)
            if (r.dataset == name) r.mesh_skipped = mesh_skipped;
        if (!is_oct) std::filesystem::remove(oct);
    }
    std::filesystem::remove_all(scratch);
    for (const Row& r : rows)
        table.add({r.dataset, std::to_string(r.side) + "^2", std::to_string(r.changes), fmt(r.p50_ms, 1), fmt(r.p95_ms, 1),
                   fmt(r.max_ms, 1), fmt(r.render_p50_ms, 1), no_mesh || !r.mesh_skipped.empty() ? "-" : fmt(r.mesh_extract_ms, 1),
                   no_mesh || !r.mesh_skipped.empty() ? "-" : fmt(r.mesh_bvh_ms, 1),
                   std::to_string(r.preview_side) + "^2", fmt(r.orbit_fps, 1), fmt(r.orbit_p95_ms, 1)});
    // The machine is shared: the 1-minute load average at the end says how much others ran meanwhile.
    double load = -1;
    if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
        if (std::fscanf(f, "%lf", &load) != 1) load = -1;
        std::fclose(f);
    }
    std::cout << "isovalue change -> RGBA frame received, octiso-view over loopback, " << threads << " render thread(s)"
              << (look.empty() ? "" : ", look" + std::string(shadows ? " shadows" : "") + (ao > 0 ? " ao " + std::to_string(ao) : "")) << " ("
              << machine_description() << "; load average " << fmt(load, 2) << ")\n";
    table.print(std::cout);
    for (const Row& r : rows)
        if (!r.mesh_skipped.empty() && r.side == sides.front()) std::cout << r.dataset << ": mesh path not run: " << r.mesh_skipped << "\n";
    // interactive.json for the default datasets; interactive_<names>.json for a --datasets list,
    // so a run on other data keeps the default run's file.
    std::string json_name = "interactive";
    if (datasets_flag)
        for (const std::string& spec : datasets) {
            std::string stem = std::filesystem::path(spec).stem().string();
            if (stem.size() > 4 && stem.compare(stem.size() - 4, 4, ".nii") == 0) stem.resize(stem.size() - 4);
            for (char& c : stem)
                if (!std::isalnum((unsigned char)c)) c = '-';
            json_name += "_" + stem;
        }
    const std::string path = write_json(results, json_name, [&](cli::JsonWriter& j) {
        j.begin_object();
        j.field("threads", int64_t(threads)).field("changes", int64_t(changes)).field("machine", machine_description());
        j.field("load_average_1min", load).field("shadows", shadows).field("ao", int64_t(ao));
        j.key("rows").begin_array();
        for (const Row& r : rows) {
            j.begin_object().field("dataset", r.dataset).field("image", int64_t(r.side)).field("p50_ms", r.p50_ms);
            j.field("p95_ms", r.p95_ms).field("max_ms", r.max_ms).field("render_p50_ms", r.render_p50_ms);
            j.field("hits_last_frame", r.hits_last).field("orbit_preview_side", int64_t(r.preview_side));
            j.field("orbit_fps", r.orbit_fps).field("orbit_p95_ms", r.orbit_p95_ms);
            if (!no_mesh && r.mesh_skipped.empty()) j.field("mesh_extract_ms", r.mesh_extract_ms).field("mesh_bvh_ms", r.mesh_bvh_ms);
            if (!r.mesh_skipped.empty()) j.field("mesh_skipped", r.mesh_skipped);
            j.end_object();
        }
        j.end_array();
        j.end_object();
    });
    std::cout << "wrote " << path << "\n";
    return 0;
}

#else

int run_interactive(cli::Args& args) {
    if (args.flag("--help")) {
        std::cout << kInteractiveUsage << "\n";
        return 0;
    }
    throw Error("interactive", "octiso-view was not built (cpp-httplib missing at configure time)", ErrorKind::Other);
}

#endif

const bool kRegistered =
    register_bench("interactive", "octiso-view: isovalue change to frame received, p50/p95, vs mesh extraction + BVH", &run_interactive);

}  // namespace
}  // namespace octiso::bench
