// Time series end to end (issue 6): frame k of a series render is bit-identical to rendering step k
// converted alone (library and command line); every step comes back byte for byte through
// octiso-info --extract-raw --step K; a missing or mismatched step, or --steps out of range,
// exits 2 and leaves no output; a mapped series only becomes resident for the steps rendered.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "test_util/run_shell.h"
#include "format/oct_test_util.h"
#include "octiso/build.h"
#include "octiso/image.h"
#include "octiso/oct_file.h"
#include "octiso/render.h"
#include "octiso/synthetic.h"
#include "util/process_memory.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

namespace fs = std::filesystem;
const std::string kTools = OCTISO_TOOLS_DIR;

/// Exit status of TOOL ARGS run through the shell; stdout and stderr are discarded.
int run(const std::string& tool, const std::string& args) {
    return run_shell("'" + kTools + "/" + tool + "' " + args + " >/dev/null 2>&1");
}

template <typename T> void write_values(const std::string& path, const std::vector<T>& v) {
    write_bytes(path, reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

/// A MetaImage header naming a raw data file beside it (a self-describing step for the
/// mismatch tests: its dims and type come from the file, not from flags).
void write_mhd(const std::string& path, Dims d, const char* element_type, const std::string& data_file) {
    std::ofstream(path) << "ObjectType = Image\nNDims = 3\nDimSize = " << d.x << " " << d.y << " " << d.z
                        << "\nElementType = " << element_type << "\nElementDataFile = " << data_file << "\n";
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

class SeriesCli : public ::testing::Test {
protected:
    void SetUp() override {
        for (const char* tool : {"octiso-convert", "octiso-info", "octiso-render"})
            if (!fs::exists(kTools + "/" + tool)) {
                OCTISO_SKIP(tool << " not built");
            }
    }
};

// Frame k of a 4-step series equals step k converted and rendered on its own, bit for bit, in
// colour, depth and normal; once through the library and once through the command-line outputs.
TEST_F(SeriesCli, FrameKOfSeriesEqualsStepKAlone) {
    ScratchDir dir;
    const Dims d{40, 36, 44};
    const std::string dims = " --dims 40,36,44 --type u8";
    constexpr uint32_t kSteps = 4;
    for (uint32_t k = 0; k < kSteps; ++k) {
        write_values(dir.file("step_" + std::to_string(k) + ".raw"), generate_synthetic<uint8_t>("plume-series", d, k));
        ASSERT_EQ(run("octiso-convert", dir.file("step_" + std::to_string(k) + ".raw") + dims + " -o " +
                                            dir.file("single_" + std::to_string(k) + ".oct")), 0);
    }
    ASSERT_EQ(run("octiso-convert", "--steps 0:3 '" + dir.file("step_%d.raw") + "'" + dims + " -o " + dir.file("series.oct")), 0);

    // Library.
    const OctFile series = OctFile::open(dir.file("series.oct"));
    ASSERT_EQ(series.info().step_count, kSteps);
    const Camera camera = frame_data_box(d, series.info().placement, 64, 48);
    RenderOptions options;
    options.isovalues = {40};
    options.want_depth = options.want_normal = true;
    std::vector<Frame> frames;
    for (uint32_t k = 0; k < kSteps; ++k) {
        const OctFile single = OctFile::open(dir.file("single_" + std::to_string(k) + ".oct"));
        const Frame a = render(series.step<uint8_t>(k), series.info().placement, camera, options);
        const Frame b = render(single.step<uint8_t>(0), single.info().placement, camera, options);
        EXPECT_GT(a.stats.hits, 0u) << "step " << k << " shows no surface: the comparison would be vacuous";
        EXPECT_TRUE(a.rgb == b.rgb) << "step " << k;
        EXPECT_TRUE(same_bits(a.depth, b.depth)) << "step " << k;
        EXPECT_TRUE(same_bits(a.normal, b.normal)) << "step " << k;
        frames.push_back(a);
    }
    EXPECT_FALSE(same_bits(frames[0].depth, frames[kSteps - 1].depth)) << "the steps should differ";

    // Command line: the series' frame files against the single-step renders, and against the library.
    const std::string view = " --iso 40 --size 64x48";
    ASSERT_EQ(run("octiso-render", dir.file("series.oct") + view + " --steps 0:3 -o " + dir.file("frame_%02d.png") +
                                       " --depth " + dir.file("depth_%02d.exr") + " --normal " + dir.file("normal_%02d.exr")), 0);
    for (uint32_t k = 0; k < kSteps; ++k) {
        const std::string s = std::to_string(k);
        ASSERT_EQ(run("octiso-render", dir.file("single_" + s + ".oct") + view + " -o " + dir.file("single_" + s + ".png") +
                                           " --depth " + dir.file("sdepth_" + s + ".exr") + " --normal " +
                                           dir.file("snormal_" + s + ".exr")), 0);
        const std::string k2 = (k < 10 ? "0" : "") + s;
        for (const auto& [from_series, alone] : {std::pair{"frame_" + k2 + ".png", "single_" + s + ".png"},
                                                 {"depth_" + k2 + ".exr", "sdepth_" + s + ".exr"},
                                                 {"normal_" + k2 + ".exr", "snormal_" + s + ".exr"}}) {
            const FloatImage a = read_image(dir.file(from_series)), b = read_image(dir.file(alone));
            EXPECT_EQ(a.width, 64);
            EXPECT_EQ(a.height, 48);
            EXPECT_EQ(a.channels, b.channels) << from_series;
            EXPECT_TRUE(same_bits(a.pixels, b.pixels)) << from_series << " vs " << alone;
        }
        EXPECT_TRUE(same_bits(read_image(dir.file("depth_" + k2 + ".exr")).pixels, frames[k].depth)) << "step " << k;
        EXPECT_TRUE(same_bits(read_image(dir.file("normal_" + k2 + ".exr")).pixels, frames[k].normal)) << "step " << k;
    }
}

// Every step of a series made from a list of files (one INPUT per step), from a pattern and from
// the synthetic plume series comes back byte for byte through octiso-info --extract-raw --step K.
TEST_F(SeriesCli, EveryStepRoundTripsThroughExtractRaw) {
    ScratchDir dir;
    std::mt19937 rng(6);
    const Dims d{17, 9, 23};

    // A list of i16 files, one INPUT per step: smooth, random, constant, sparse.
    std::vector<std::vector<int16_t>> steps(4, std::vector<int16_t>(d.voxels()));
    for (uint64_t i = 0; i < d.voxels(); ++i) {
        steps[0][i] = int16_t(int(i % 17) * 100 - 700 + int(i / 391));
        steps[1][i] = int16_t(rng());
        steps[2][i] = -5;
        steps[3][i] = rng() % 50 == 0 ? int16_t(rng()) : int16_t(0);
    }
    std::string list;
    for (size_t k = 0; k < steps.size(); ++k) {
        write_values(dir.file("in" + std::to_string(k) + ".raw"), steps[k]);
        list += " " + dir.file("in" + std::to_string(k) + ".raw");
    }
    ASSERT_EQ(run("octiso-convert", list + " --dims 17,9,23 --type i16 -o " + dir.file("list.oct")), 0);
    ASSERT_EQ(OctFile::open(dir.file("list.oct")).info().step_count, 4u);
    for (size_t k = 0; k < steps.size(); ++k) {
        const std::string out = dir.file("out" + std::to_string(k) + ".raw");
        ASSERT_EQ(run("octiso-info", dir.file("list.oct") + " --extract-raw " + out + " --step " + std::to_string(k)), 0);
        EXPECT_TRUE(read_bytes(out) == read_bytes(dir.file("in" + std::to_string(k) + ".raw"))) << "step " << k;
    }
    // The same files as a pattern give the same file contents step by step.
    ASSERT_EQ(run("octiso-convert", "--steps 1:3 '" + dir.file("in%d.raw") + "' --dims 17,9,23 --type i16 -o " +
                                        dir.file("pattern.oct")), 0);
    for (int k = 0; k < 3; ++k) {
        const std::string out = dir.file("p" + std::to_string(k) + ".raw");
        ASSERT_EQ(run("octiso-info", dir.file("pattern.oct") + " --extract-raw " + out + " --step " + std::to_string(k)), 0);
        EXPECT_TRUE(read_bytes(out) == read_bytes(dir.file("in" + std::to_string(k + 1) + ".raw"))) << "step " << k;
    }

    // The synthetic plume series against the generator, every step.
    ASSERT_EQ(run("octiso-convert", "--synthetic plume-series:30,26,34,6 -o " + dir.file("plume.oct")), 0);
    for (uint32_t k = 0; k < 6; ++k) {
        const std::string out = dir.file("plume" + std::to_string(k) + ".raw");
        ASSERT_EQ(run("octiso-info", dir.file("plume.oct") + " --extract-raw " + out + " --step " + std::to_string(k)), 0);
        const std::vector<uint8_t> expected = generate_synthetic<uint8_t>("plume-series", {30, 26, 34}, k);
        const std::vector<char> got = read_bytes(out);
        ASSERT_EQ(got.size(), expected.size());
        EXPECT_EQ(std::memcmp(got.data(), expected.data(), got.size()), 0) << "step " << k;
    }
    // A step past the end is bad input and writes nothing.
    EXPECT_EQ(run("octiso-info", dir.file("plume.oct") + " --extract-raw " + dir.file("none.raw") + " --step 6"), 2);
    EXPECT_FALSE(fs::exists(dir.file("none.raw")));
}

// A missing, wrongly sized, or differently shaped or typed step fails with exit 2 before any
// output exists, whichever position it holds in the series.
TEST_F(SeriesCli, MissingOrMismatchedStepExitsTwoAndWritesNothing) {
    ScratchDir dir;
    const Dims d{4, 5, 6};
    const std::vector<uint8_t> v(d.voxels(), 9);
    for (const char* name : {"a.raw", "b.raw", "c_1.raw", "c_3.raw"}) write_values(dir.file(name), v);
    write_values(dir.file("short.raw"), std::vector<uint8_t>(d.voxels() - 1, 9));
    write_values(dir.file("wide.raw"), std::vector<uint16_t>(d.voxels(), 9));
    write_mhd(dir.file("a.mhd"), d, "MET_UCHAR", "a.raw");
    write_mhd(dir.file("b.mhd"), d, "MET_UCHAR", "b.raw");
    write_values(dir.file("flat.raw"), std::vector<uint8_t>(4 * 5 * 5, 9));
    write_mhd(dir.file("flat.mhd"), {4, 5, 5}, "MET_UCHAR", "flat.raw");
    write_mhd(dir.file("wide.mhd"), d, "MET_USHORT", "wide.raw");

    // The self-describing steps are fine on their own, so what fails below is the mismatch.
    ASSERT_EQ(run("octiso-convert", dir.file("a.mhd") + " " + dir.file("b.mhd") + " -o " + dir.file("ok.oct")), 0);
    ASSERT_EQ(run("octiso-convert", dir.file("flat.mhd") + " -o " + dir.file("ok2.oct")), 0);
    ASSERT_EQ(run("octiso-convert", dir.file("wide.mhd") + " -o " + dir.file("ok3.oct")), 0);
    fs::remove(dir.file("ok.oct")), fs::remove(dir.file("ok2.oct")), fs::remove(dir.file("ok3.oct"));

    const size_t before = dir.entries().size();
    const std::string out = dir.file("out.oct"), raw = " --dims 4,5,6 --type u8 -o " + out;
    const std::string bad[] = {
        dir.file("a.raw") + " " + dir.file("b.raw") + " " + dir.file("missing.raw") + raw,   // last step missing
        dir.file("missing.raw") + " " + dir.file("a.raw") + raw,                             // first step missing
        dir.file("a.raw") + " " + dir.file("short.raw") + " " + dir.file("b.raw") + raw,     // wrong size
        "--steps 1:3 '" + dir.file("c_%d.raw") + "'" + raw,                                  // c_2 missing
        "--steps 0:1 '" + dir.file("c_%d.raw") + "' " + dir.file("a.raw") + raw,             // pattern plus a list
        dir.file("a.mhd") + " " + dir.file("b.mhd") + " " + dir.file("flat.mhd") + " -o " + out,   // dims differ
        dir.file("a.mhd") + " " + dir.file("wide.mhd") + " -o " + out,                       // type differs
    };
    for (const std::string& args : bad) {
        EXPECT_EQ(run("octiso-convert", args), 2) << args;
        EXPECT_FALSE(fs::exists(out)) << args;
        EXPECT_EQ(dir.entries().size(), before) << "leftover file after: " << args;
    }
}

// The renderer checks --steps against the file before it renders or writes anything.
TEST_F(SeriesCli, RenderStepsOutOfRangeExitsTwo) {
    ScratchDir dir;
    ASSERT_EQ(run("octiso-convert", "--synthetic plume-series:16,3 -o " + dir.file("s.oct")), 0);
    ASSERT_EQ(run("octiso-render", dir.file("s.oct") + " --iso 40 --size 16x16 --steps 1:2 -o " + dir.file("ok_%d.png")), 0);
    EXPECT_TRUE(fs::exists(dir.file("ok_2.png")));
    const size_t before = dir.entries().size();
    for (const char* steps : {"0:3", "3:3", "2:1", "5", "-1:1", "0:x"}) {
        EXPECT_EQ(run("octiso-render", dir.file("s.oct") + " --iso 40 --size 16x16 --steps " + steps + " -o " +
                                           dir.file("f_%d.png") + " --depth " + dir.file("d_%d.exr")), 2) << steps;
        EXPECT_EQ(dir.entries().size(), before) << "a frame was written for --steps " << steps;
    }
}

// Touch only what is rendered: after opening a mapped 12-step series only its header and section
// table are resident; rendering a step makes that step resident (its checksums read it whole at
// first use) and nothing of the steps not rendered, up to the kernel's fault-around of 64 KiB.
TEST(SeriesMemory, OnlyRenderedStepsBecomeResident) {
    ScratchDir dir;
    const Dims d{64, 64, 64};
    constexpr uint32_t kSteps = 12;
    std::mt19937 rng(12);
    {
        OctInfo info;
        info.type = ScalarType::u8;
        info.dims = d;
        info.dmax = dmax_for(d);
        OctWriter writer(dir.file("s.oct"), info);
        std::vector<uint8_t> v(d.voxels());
        for (uint32_t k = 0; k < kSteps; ++k) {
            for (auto& x : v) x = uint8_t(rng() % 200);   // little merges: each step is about raw size
            VolumeView<uint8_t> view;
            view.data = reinterpret_cast<const std::byte*>(v.data());
            view.dims = d;
            const auto tree = build_octree(view, {});
            writer.add_step(tree.view());
        }
        writer.finish();
    }
    const std::string path = dir.file("s.oct");
    const OctFile file = OctFile::open(path);
    const uint64_t file_bytes = fs::file_size(path);
    auto step_bytes = [&](uint32_t k) {
        const StepSizes s = file.step_sizes(k);
        return s.interior_bytes + s.cap_bytes;
    };
    const uint64_t slack = 4 * 65536;   // fault-around on both ends of each touched range, page rounding

    // Measured before anything asks for a step: step_sizes() validates (reads) the step too.
    const uint64_t after_open = mapped_resident_bytes(path);
    EXPECT_LT(after_open, slack) << "opening should read the header and section table only";

    RenderOptions options;
    options.isovalues = {100};
    const Camera camera = frame_data_box(d, file.info().placement, 32, 32);
    render(file.step<uint8_t>(7), file.info().placement, camera, options);
    const uint64_t after_one = mapped_resident_bytes(path);
    const uint64_t one_step = step_bytes(7);   // step 7 is validated already: this reads nothing new
    ASSERT_GT(one_step, 200000u);
    EXPECT_GE(after_one, after_open + one_step * 9 / 10) << "the rendered step is resident";
    EXPECT_LE(after_one, after_open + step_bytes(7) + slack) << "only the rendered step is resident";

    render(file.step<uint8_t>(2), file.info().placement, camera, options);
    const uint64_t after_two = mapped_resident_bytes(path);
    EXPECT_LE(after_two, after_open + step_bytes(7) + step_bytes(2) + 2 * slack);
    EXPECT_GE(after_two, after_one + one_step * 9 / 10);
    EXPECT_LT(after_two, file_bytes / 4) << "12 steps in the file, 2 rendered";
}

}  // namespace
}  // namespace octiso::test
