// octiso-bench writers: what writing a rendered frame costs, per encoder setting. An orbit
// or a series encodes every frame on one writer thread beside the trace (src/cli/frame_writer.h),
// so the encode bounds the frame rate once the trace has more cores than that thread; a single
// render pays it in its wall time. Each setting encodes the same rendered frames, interleaved
// round by round (a load spike hits every setting alike); every PNG is decoded again and must give
// the frame's pixels; times and bytes are given against libpng's defaults (zlib 6, adaptive row
// filters), the file setting before this benchmark. Single-filter settings run through the strip
// encoder of png_writer.cpp (on one thread, or on every hardware thread where a row says so) or,
// for the A/B, through libpng's own rows. The depth and normal AOVs (OpenEXR, ZIP) are timed the
// same way at OpenEXR's zlib level 4 (before), at kExrZipLevel, and compressed by every hardware
// thread; each file must read back to the same float bits.
#include <png.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench.h"
#include "bench/dataset_spec.h"
#include "io/exr_writer.h"
#include "io/png_writer.h"
#include "octiso/any_octree.h"
#include "octiso/camera.h"
#include "octiso/error.h"
#include "octiso/image.h"
#include "octiso/render.h"
#include "octiso/shading.h"

namespace octiso::bench {
namespace {

const char* const kWritersUsage =
    "usage: octiso-bench writers [--frames SPEC[,SPEC...]] [--rounds N] [--mri-dir DIR] [--quick] [--markdown]\n"
    "                            [--results DIR]\n"
    "  SPEC: DATA@ISO/SIDE[/ZOOM], DATA a file in --mri-dir (default /usr/share/mricron/templates) or\n"
    "  NAME:N (plume, mixing); the default camera at SIDE^2 pixels, moved in by ZOOM (default 1)\n"
    "  default: ch2better.nii.gz@100.5/512, ch2better.nii.gz@100.5/1024, aal.nii.gz@0.5/512,\n"
    "  plume:256@40.5/1024/2.5, mixing:256@127.5/1024; --rounds default 9 (--quick: plume:48@40.5/128, 2)";

struct FrameSpec {
    DatasetSpec data;
    int side = 512;
    double zoom = 1;
    std::string label;
};

/// DATA@ISO/SIDE[/ZOOM]: the dataset part is parse_dataset_specs()'s FILE@ISO or NAME:N@ISO.
FrameSpec parse_frame_spec(const std::string& item, const std::string& mri_dir) {
    const size_t slash = item.find('/', item.rfind('@'));
    if (item.rfind('@') == std::string::npos || slash == std::string::npos)
        throw Error("--frames", "expected DATA@ISO/SIDE[/ZOOM], found '" + item + "'");
    FrameSpec f;
    f.data = parse_dataset_specs(item.substr(0, slash), mri_dir).at(0);
    if (f.data.is_oct) throw Error("--frames", "'" + item + "': give the scan or NAME:N, not a .oct file");
    const std::string rest = item.substr(slash + 1);
    const size_t zoom_slash = rest.find('/');
    f.side = int(cli::parse_int(rest.substr(0, zoom_slash), "--frames", 8, 8192));
    if (zoom_slash != std::string::npos) f.zoom = cli::parse_double(rest.substr(zoom_slash + 1), "--frames");
    if (!(f.zoom > 0)) throw Error("--frames", "the zoom must be > 0 in '" + item + "'");
    f.label = item;
    return f;
}

struct Setting {
    std::string name;
    io::PngEffort effort;
    int threads = 1;
};

/// The candidates: libpng's defaults first (the reference of the ratios), the file and stream
/// settings of png_writer.h, and their neighbours; single-filter settings are encoded in strips
/// (png_writer.cpp) unless they say libpng's rows; threads 0 is every hardware thread.
std::vector<Setting> settings() {
    using io::PngDeflate, io::PngRowFilter;
    return {{"zlib 6, adaptive (libpng defaults)", {6, PngRowFilter::adaptive}},
            {"zlib 1, adaptive", {1, PngRowFilter::adaptive}},
            {"runs, adaptive", {1, PngRowFilter::adaptive, PngDeflate::run_length}},
            {"runs, paeth, libpng's rows", {1, PngRowFilter::paeth, PngDeflate::run_length, true}},
            {"runs, paeth (kPngFile), strips", io::kPngFile},
            {"runs, paeth (kPngFile), strips, all threads", io::kPngFile, 0},
            {"zlib 1, paeth", {1, PngRowFilter::paeth}},
            {"zlib 6, paeth", {6, PngRowFilter::paeth}},
            {"runs, up", {1, PngRowFilter::up, PngDeflate::run_length}},
            {"zlib 1, none (kPngStream)", io::kPngStream},
            {"zlib 1, none (kPngStream), all threads", io::kPngStream, 0}};
}

/// The RGB pixels of PNG bytes (libpng's simplified reader), empty if they do not decode.
std::vector<uint8_t> decode_rgb(const std::vector<unsigned char>& bytes) {
    png_image image;
    std::memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&image, bytes.data(), bytes.size())) return {};
    image.format = PNG_FORMAT_RGB;
    std::vector<uint8_t> rgb(PNG_IMAGE_SIZE(image));
    if (!png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr)) return {};
    return rgb;
}

struct ExrSetting {
    std::string name;
    int zip_level, threads;
};

std::vector<ExrSetting> exr_settings() {
    return {{"zip 4, 1 thread (OpenEXR's level)", 4, 1},
            {"zip " + std::to_string(io::kExrZipLevel) + ", 1 thread (kExrZipLevel)", io::kExrZipLevel, 1},
            {"zip " + std::to_string(io::kExrZipLevel) + ", all threads", io::kExrZipLevel, 0}};
}

/// Whether EXR bytes read back (through the image module, from a scratch file) to `pixels` bit for bit.
bool exr_reads_back(const std::vector<unsigned char>& bytes, const std::vector<float>& pixels, const std::string& scratch) {
    std::ofstream(scratch, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    FloatImage back;
    try {
        back = read_image(scratch);
    } catch (...) {
        std::remove(scratch.c_str());   // no scratch file left in the results folder
        throw;
    }
    std::remove(scratch.c_str());
    return back.pixels.size() == pixels.size() && std::memcmp(back.pixels.data(), pixels.data(), pixels.size() * sizeof(float)) == 0;
}

struct Cell {
    std::vector<double> ms;
    size_t bytes = 0;
    bool same_pixels = true;
};

int run_writers(cli::Args& args) {
    if (args.flag("--help")) {
        std::cout << kWritersUsage << "\n";
        return 0;
    }
    const bool quick = args.flag("--quick"), markdown = args.flag("--markdown");
    const auto frames_flag = args.value("--frames"), rounds_flag = args.value("--rounds");
    const std::string mri_dir = args.value("--mri-dir").value_or("/usr/share/mricron/templates");
    const std::string results = results_dir(args);
    args.finish();
    const int rounds = rounds_flag ? int(cli::parse_int(*rounds_flag, "--rounds", 1, 1000)) : quick ? 2 : 9;
    const std::string default_frames = quick ? "plume:48@40.5/128"
                                             : "ch2better.nii.gz@100.5/512,ch2better.nii.gz@100.5/1024,aal.nii.gz@0.5/512,"
                                               "plume:256@40.5/1024/2.5,mixing:256@127.5/1024";
    std::vector<FrameSpec> specs;
    {
        const std::string text = frames_flag.value_or(default_frames);
        size_t pos = 0;
        while (pos <= text.size()) {
            const size_t comma = std::min(text.find(',', pos), text.size());
            specs.push_back(parse_frame_spec(text.substr(pos, comma - pos), mri_dir));
            pos = comma + 1;
        }
    }

    std::vector<Frame> frames;
    for (const FrameSpec& s : specs) {
        const LoadedVolume volume = open_dense(s.data, 2048);
        const AnyOctree tree = AnyOctree::build(volume, BuildOptions{});
        RenderOptions o;   // octiso-render's default frame: traced, then shaded by the light kit
        o.isovalues = {s.data.iso};
        o.want_colour = false, o.want_depth = true, o.want_normal = true;
        const Camera camera = orbit_camera(volume.dims(), volume.placement(), s.side, s.side, kDefaultAzimuthDeg,
                                           kDefaultElevationDeg, s.zoom);
        Frame f;
        tree.make_renderer(o).render(camera, f);
        shade_frame(tree, o.isovalues, camera, Shading{}, f);
        std::cerr << "rendered " << s.label << " (" << f.stats.hits << " hits)\n";
        frames.push_back(std::move(f));
    }

    const std::vector<Setting> candidates = settings();
    std::vector<std::vector<Cell>> cells(frames.size(), std::vector<Cell>(candidates.size()));
    for (int round = 0; round < rounds; ++round) {
        for (size_t fi = 0; fi < frames.size(); ++fi) {
            const Frame& f = frames[fi];
            for (size_t si = 0; si < candidates.size(); ++si) {
                const auto t0 = std::chrono::steady_clock::now();
                const std::vector<unsigned char> bytes = io::encode_rgb8_png(f.width, f.height, f.rgb.data(), candidates[si].effort, "frame",
                                                                                       candidates[si].threads);
                cells[fi][si].ms.push_back(seconds_since(t0) * 1e3);
                cells[fi][si].bytes = bytes.size();
                if (round == 0 && decode_rgb(bytes) != f.rgb) cells[fi][si].same_pixels = false;
            }
        }
    }

    // The AOVs: depth (one channel) and normal (three) of every frame, as octiso-render writes them.
    const std::vector<ExrSetting> exr_candidates = exr_settings();
    const std::string scratch = results + "/writers_scratch.exr";
    std::vector<std::vector<Cell>> exr_cells(2 * frames.size(), std::vector<Cell>(exr_candidates.size()));
    for (int round = 0; round < rounds; ++round) {
        for (size_t fi = 0; fi < frames.size(); ++fi) {
            const Frame& f = frames[fi];
            for (int aov = 0; aov < 2; ++aov) {
                const std::vector<float>& pixels = aov == 0 ? f.depth : f.normal;
                const std::vector<std::string> names = aov == 0 ? std::vector<std::string>{"Z"} : std::vector<std::string>{"R", "G", "B"};
                for (size_t si = 0; si < exr_candidates.size(); ++si) {
                    const auto t0 = std::chrono::steady_clock::now();
                    const std::vector<unsigned char> bytes = io::encode_float_exr(f.width, f.height, pixels.data(), names, "aov",
                                                                                   exr_candidates[si].threads, exr_candidates[si].zip_level);
                    Cell& c = exr_cells[2 * fi + size_t(aov)][si];
                    c.ms.push_back(seconds_since(t0) * 1e3);
                    c.bytes = bytes.size();
                    if (round == 0 && !exr_reads_back(bytes, pixels, scratch)) c.same_pixels = false;
                }
            }
        }
    }

    Table table({"frame", "setting", "encode ms (min)", "median", "bytes", "time / defaults", "bytes / defaults", "pixels"});
    bool all_same = true;
    for (size_t fi = 0; fi < frames.size(); ++fi) {
        for (Cell& c : cells[fi]) std::sort(c.ms.begin(), c.ms.end());
        const Cell& ref = cells[fi][0];
        for (size_t si = 0; si < candidates.size(); ++si) {
            const Cell& c = cells[fi][si];
            all_same = all_same && c.same_pixels;
            table.add({specs[fi].label, candidates[si].name, fmt(c.ms[0], 2), fmt(c.ms[c.ms.size() / 2], 2), std::to_string(c.bytes),
                       fmt(c.ms[0] / ref.ms[0], 3), fmt(double(c.bytes) / double(ref.bytes), 3), c.same_pixels ? "same" : "DIFFER"});
        }
    }
    Table exr_table({"frame", "AOV", "setting", "encode ms (min)", "median", "bytes", "time / level 4", "bytes / level 4", "floats"});
    for (size_t fi = 0; fi < frames.size(); ++fi) {
        for (int aov = 0; aov < 2; ++aov) {
            std::vector<Cell>& row = exr_cells[2 * fi + size_t(aov)];
            for (Cell& c : row) std::sort(c.ms.begin(), c.ms.end());
            for (size_t si = 0; si < exr_candidates.size(); ++si) {
                const Cell& c = row[si];
                all_same = all_same && c.same_pixels;
                exr_table.add({specs[fi].label, aov == 0 ? "depth" : "normal", exr_candidates[si].name, fmt(c.ms[0], 2),
                               fmt(c.ms[c.ms.size() / 2], 2), std::to_string(c.bytes), fmt(c.ms[0] / row[0].ms[0], 3),
                               fmt(double(c.bytes) / double(row[0].bytes), 3), c.same_pixels ? "same" : "DIFFER"});
            }
        }
    }
    std::cout << "PNG encode of rendered frames, " << rounds << " interleaved rounds, 1 thread (" << machine_description() << ")\n";
    if (markdown)
        table.print_markdown(std::cout);
    else
        table.print(std::cout);
    std::cout << "\nOpenEXR encode of their depth and normal AOVs (ZIP), " << std::thread::hardware_concurrency()
              << " hardware threads\n";
    if (markdown)
        exr_table.print_markdown(std::cout);
    else
        exr_table.print(std::cout);
    const std::string path = write_json(results, "writers", [&](cli::JsonWriter& j) {
        j.begin_object();
        j.field("rounds", int64_t(rounds)).field("machine", machine_description()).field("all_pixels_same", all_same);
        j.field("reference", candidates[0].name);
        j.key("rows").begin_array();
        for (size_t fi = 0; fi < frames.size(); ++fi) {
            for (size_t si = 0; si < candidates.size(); ++si) {
                const Cell& c = cells[fi][si];
                const io::PngEffort& e = candidates[si].effort;
                j.begin_object().field("frame", specs[fi].label).field("width", int64_t(frames[fi].width));
                j.field("setting", candidates[si].name).field("zlib_level", int64_t(e.zlib_level));
                j.field("filter", int64_t(e.filter)).field("run_length", e.deflate == io::PngDeflate::run_length);
                j.field("libpng_rows", e.libpng_rows || e.filter == io::PngRowFilter::adaptive).field("threads", int64_t(candidates[si].threads));
                j.field("min_ms", c.ms[0]).field("median_ms", c.ms[c.ms.size() / 2]).field("bytes", int64_t(c.bytes));
                j.field("time_vs_defaults", c.ms[0] / cells[fi][0].ms[0]);
                j.field("bytes_vs_defaults", double(c.bytes) / double(cells[fi][0].bytes)).field("same_pixels", c.same_pixels);
                j.end_object();
            }
        }
        j.end_array();
        j.key("exr_rows").begin_array();
        for (size_t fi = 0; fi < frames.size(); ++fi) {
            for (int aov = 0; aov < 2; ++aov) {
                const std::vector<Cell>& row = exr_cells[2 * fi + size_t(aov)];
                for (size_t si = 0; si < exr_candidates.size(); ++si) {
                    const Cell& c = row[si];
                    j.begin_object().field("frame", specs[fi].label).field("aov", std::string(aov == 0 ? "depth" : "normal"));
                    j.field("setting", exr_candidates[si].name).field("zip_level", int64_t(exr_candidates[si].zip_level));
                    j.field("threads", int64_t(exr_candidates[si].threads)).field("min_ms", c.ms[0]);
                    j.field("median_ms", c.ms[c.ms.size() / 2]).field("bytes", int64_t(c.bytes));
                    j.field("time_vs_level4", c.ms[0] / row[0].ms[0]).field("bytes_vs_level4", double(c.bytes) / double(row[0].bytes));
                    j.field("same_floats", c.same_pixels).end_object();
                }
            }
        }
        j.end_array();
        j.field("hardware_threads", int64_t(std::thread::hardware_concurrency()));
        j.end_object();
    });
    std::cout << "wrote " << path << "\n";
    if (!all_same) {
        std::cerr << "octiso-bench writers: an image did not read back to its frame's pixels\n";
        return 1;
    }
    return 0;
}

const bool kRegistered = register_bench("writers", "PNG and OpenEXR encode time and bytes of rendered frames per setting", &run_writers);

}  // namespace
}  // namespace octiso::bench
