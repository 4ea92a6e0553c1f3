// The conversion pipeline (include/octiso/convert.h) without the tool: each kind of source
// gives a file whose steps decode back to the inputs; the report's totals are the sums of its
// steps and match the file; a step that differs from the first in dims, type or placement is
// refused with an exit-2 Error before anything (not even a temporary) is written.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "octiso/convert.h"
#include "octiso/decode.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/synthetic.h"
#include "test_util/scratch_dir.h"

namespace octiso::test {
namespace {

namespace fs = std::filesystem;

template <typename T> std::vector<T> decoded(const OctFile& f, uint32_t step) {
    std::vector<T> out(f.info().dims.voxels());
    decode_to_dense(f.step<T>(step), out.data());
    return out;
}

std::vector<uint8_t> ramp(Dims d, int salt) {
    std::vector<uint8_t> v(d.voxels());
    for (uint64_t i = 0; i < v.size(); ++i) v[i] = uint8_t((i * 7 + uint64_t(salt) * 13) % 97 / (i % 5 == 0 ? 1 : 3));
    return v;
}

void write_bytes(const std::string& path, const void* data, size_t n) {
    std::ofstream(path, std::ios::binary).write(static_cast<const char*>(data), std::streamsize(n));
}

/// A little-endian float NRRD of `d` with `spacing`, values i * 0.5.
void write_nrrd(const std::string& path, Dims d, std::array<double, 3> spacing) {
    std::ofstream f(path, std::ios::binary);
    f << "NRRD0004\ntype: float\ndimension: 3\nsizes: " << d.x << " " << d.y << " " << d.z << "\nspacings: " << spacing[0]
      << " " << spacing[1] << " " << spacing[2] << "\nencoding: raw\nendian: little\n\n";
    for (uint64_t i = 0; i < d.voxels(); ++i) {
        const float v = float(i) * 0.5f;
        f.write(reinterpret_cast<const char*>(&v), sizeof v);
    }
}

RawOptions raw_u8(Dims d) {
    RawOptions raw;
    raw.dims = d;
    raw.type = ScalarType::u8;
    return raw;
}

void expect_totals_are_the_sums(const ConvertReport& r) {
    ASSERT_EQ(r.per_step.size(), size_t(r.steps));
    StepSizes sum;
    double seconds = 0;
    for (const ConvertStepReport& s : r.per_step) {
        sum.nodes_per_depth.resize(s.sizes.nodes_per_depth.size());
        sum.scalar_leaves_per_depth.resize(s.sizes.scalar_leaves_per_depth.size());
        for (size_t d = 0; d < s.sizes.nodes_per_depth.size(); ++d) sum.nodes_per_depth[d] += s.sizes.nodes_per_depth[d];
        for (size_t d = 0; d < s.sizes.scalar_leaves_per_depth.size(); ++d)
            sum.scalar_leaves_per_depth[d] += s.sizes.scalar_leaves_per_depth[d];
        sum.interior_bytes += s.sizes.interior_bytes;
        sum.cap_bytes += s.sizes.cap_bytes;
        seconds += s.build_seconds;
    }
    EXPECT_EQ(r.total.nodes_per_depth, sum.nodes_per_depth);
    EXPECT_EQ(r.total.scalar_leaves_per_depth, sum.scalar_leaves_per_depth);
    EXPECT_EQ(r.total.interior_bytes, sum.interior_bytes);
    EXPECT_EQ(r.total.cap_bytes, sum.cap_bytes);
    EXPECT_DOUBLE_EQ(r.build_seconds, seconds);
    EXPECT_EQ(r.file_bytes, fs::file_size(r.output));
    EXPECT_GT(r.peak_rss_bytes, 0u);
    EXPECT_GE(r.total_seconds, r.build_seconds);
    if (!r.streamed && !r.built_directly) {   // issue 12: the phases of an in-memory conversion
        const BuildPhases& p = r.build_phases;
        EXPECT_GT(p.pieces, 0.0);
        EXPECT_LE(p.prepare + p.pieces + p.top + p.concatenate + p.release, r.build_seconds);
        EXPECT_GT(r.read_seconds, 0.0);
        EXPECT_GT(r.write_seconds, 0.0);
        EXPECT_LE(r.read_seconds + r.build_seconds + r.write_seconds, r.total_seconds);
    }
    if (r.streamed) {   // out of core: the step's phases add up to its build time
        EXPECT_GT(r.slabs_seconds, 0.0);
        EXPECT_LE(r.slabs_seconds + r.top_seconds + r.sections_seconds, r.build_seconds);
    }
}

TEST(Convert, SyntheticSeriesDecodesStepByStepAndReportsItsSums) {
    ScratchDir dir("octiso_convert_lib");
    const std::string out = dir.file("ps.oct");
    BuildOptions opt;
    opt.threads = 1;
    const ConvertReport r = convert(ConvertSource::synthetic("plume-series:16,3"), out, opt);
    EXPECT_EQ(r.input, "plume-series:16,3");
    EXPECT_EQ(r.format, VolumeFormat::synthetic);
    EXPECT_EQ(r.type, ScalarType::u8);
    EXPECT_EQ(r.dims, (Dims{16, 16, 16}));
    EXPECT_EQ(r.steps, 3u);
    EXPECT_EQ(r.dmax, 4);
    EXPECT_EQ(r.threads, 1);
    EXPECT_EQ(r.input_bytes, 3u * 16 * 16 * 16);
    EXPECT_FALSE(r.built_directly);
    expect_totals_are_the_sums(r);

    const OctFile f = OctFile::open(out);
    ASSERT_EQ(f.info().step_count, 3u);
    for (uint32_t k = 0; k < 3; ++k) {
        EXPECT_TRUE(decoded<uint8_t>(f, k) == generate_synthetic<uint8_t>("plume-series", {16, 16, 16}, k)) << k;
        EXPECT_EQ(f.step_sizes(k).nodes_per_depth, r.per_step[k].sizes.nodes_per_depth) << k;
        EXPECT_EQ(f.step_sizes(k).cap_bytes, r.per_step[k].sizes.cap_bytes) << k;
    }
}

TEST(Convert, PatternAndListOfRawFilesGiveTheSameFile) {
    ScratchDir dir("octiso_convert_lib");
    const Dims d{9, 10, 11};
    std::vector<std::string> names;
    std::vector<std::vector<uint8_t>> steps;
    for (int k = 3; k <= 5; ++k) {
        steps.push_back(ramp(d, k));
        names.push_back(dir.file("t_0" + std::to_string(k) + ".raw"));
        write_bytes(names.back(), steps.back().data(), steps.back().size());
    }
    BuildOptions opt;
    opt.iso_range = std::array<double, 2>{2.0, 60.0};
    const ConvertSource pattern = ConvertSource::pattern(dir.file("t_%02d.raw"), 3, 5, raw_u8(d));
    EXPECT_EQ(pattern.step_count(), 3u);
    EXPECT_EQ(pattern.step_path(1), names[1]);
    const ConvertReport a = convert(pattern, dir.file("a.oct"), opt);
    const ConvertReport b = convert(ConvertSource::files(names, raw_u8(d)), dir.file("b.oct"), opt);
    EXPECT_EQ(a.input, dir.file("t_%02d.raw"));
    EXPECT_EQ(b.input, names[0]);
    ASSERT_EQ(a.per_step.size(), 3u);
    EXPECT_EQ(a.per_step[2].source, names[2]);
    EXPECT_EQ(a.iso_range, opt.iso_range);
    expect_totals_are_the_sums(a);

    std::ifstream fa(dir.file("a.oct"), std::ios::binary), fb(dir.file("b.oct"), std::ios::binary);
    const std::string bytes_a((std::istreambuf_iterator<char>(fa)), {}), bytes_b((std::istreambuf_iterator<char>(fb)), {});
    EXPECT_TRUE(bytes_a == bytes_b) << "the same steps from a pattern or a list";
    // Out of core: the same file, and its own phases (slabs, top, sections) add up.
    MemoryOptions streaming;
    streaming.force_streaming = true;
    const ConvertReport streamed = convert(pattern, dir.file("c.oct"), opt, streaming);
    EXPECT_TRUE(streamed.streamed);
    expect_totals_are_the_sums(streamed);
    std::ifstream fc(dir.file("c.oct"), std::ios::binary);
    EXPECT_TRUE(std::string((std::istreambuf_iterator<char>(fc)), {}) == bytes_a) << "out of core, the same bytes";
    const OctFile f = OctFile::open(dir.file("a.oct"));
    EXPECT_EQ(f.info().iso_range, opt.iso_range);

    // Without the iso-range, every step decodes back exactly.
    convert(pattern, dir.file("c.oct"), BuildOptions{});
    const OctFile c = OctFile::open(dir.file("c.oct"));
    for (uint32_t k = 0; k < 3; ++k) EXPECT_TRUE(decoded<uint8_t>(c, k) == steps[k]) << k;
}

TEST(Convert, SingleFileKeepsItsPlacementAndOverrides) {
    ScratchDir dir("octiso_convert_lib");
    write_nrrd(dir.file("in.nrrd"), {12, 5, 4}, {2, 3, 4});
    const ConvertReport r = convert(ConvertSource::file(dir.file("in.nrrd")), dir.file("n.oct"), BuildOptions{});
    EXPECT_EQ(r.format, VolumeFormat::nrrd);
    EXPECT_EQ(r.type, ScalarType::f32);
    EXPECT_EQ(r.placement.spacing, (std::array<double, 3>{2, 3, 4}));
    EXPECT_EQ(r.steps, 1u);
    RawOptions placed;
    placed.spacing = std::array<double, 3>{1, 1, 0.5};
    placed.origin = std::array<double, 3>{7, 8, 9};
    const ConvertReport s = convert(ConvertSource::synthetic("sphere:12", ScalarType::i16, placed), dir.file("s.oct"), {});
    EXPECT_EQ(s.type, ScalarType::i16);
    EXPECT_EQ(OctFile::open(dir.file("s.oct")).info().placement.origin, placed.origin);
}

TEST(Convert, MismatchedStepIsRefusedBeforeAnythingIsWritten) {
    ScratchDir dir("octiso_convert_lib");
    write_nrrd(dir.file("a.nrrd"), {12, 5, 4}, {1, 1, 1});
    write_nrrd(dir.file("b.nrrd"), {12, 5, 4}, {1, 1, 1});
    write_nrrd(dir.file("wide.nrrd"), {13, 5, 4}, {1, 1, 1});
    write_nrrd(dir.file("stretched.nrrd"), {12, 5, 4}, {1, 2, 1});
    const std::vector<uint8_t> u8(12 * 5 * 4, 3);
    {
        std::ofstream f(dir.file("other_type.nrrd"), std::ios::binary);
        f << "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 12 5 4\nencoding: raw\n\n";
        f.write(reinterpret_cast<const char*>(u8.data()), std::streamsize(u8.size()));
    }
    const std::vector<std::string> before = dir.entries();   // sorted names
    const std::string out = dir.file("series.oct");
    const struct { const char* bad; const char* problem; } cases[] = {
        {"wide.nrrd", "dims differ from the first step (expected 12x5x4, found 13x5x4)"},
        {"other_type.nrrd", "scalar type differs from the first step (expected f32, found u8)"},
        {"stretched.nrrd", "spacing or origin differs from the first step"},
    };
    for (const auto& c : cases) {
        const ConvertSource src = ConvertSource::files({dir.file("a.nrrd"), dir.file("b.nrrd"), dir.file(c.bad)});
        try {
            convert(src, out, BuildOptions{});
            ADD_FAILURE() << c.bad << " was accepted";
        } catch (const Error& e) {
            EXPECT_EQ(e.exit_status(), 2) << c.bad;
            EXPECT_EQ(e.subject(), dir.file(c.bad));
            EXPECT_NE(e.problem().find(c.problem), std::string::npos) << e.problem();
        }
        EXPECT_FALSE(fs::exists(out)) << c.bad;
        EXPECT_EQ(dir.entries(), before) << "something was written for " << c.bad;
    }
    // A missing step of a pattern is refused the same way.
    try {
        convert(ConvertSource::pattern(dir.file("none_%d.raw"), 0, 1, raw_u8({12, 5, 4})), out, BuildOptions{});
        ADD_FAILURE() << "missing files were accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.exit_status(), 2);
    }
    EXPECT_EQ(dir.entries(), before);
}

TEST(Convert, SourcesRefuseBadPatternsAndEmptyLists) {
    for (const char* p : {"none.raw", "two_%d_%d.raw", "bad_%s.raw"}) {
        try {
            ConvertSource::pattern(p, 0, 1);
            ADD_FAILURE() << p;
        } catch (const Error& e) {
            EXPECT_EQ(e.subject(), "--steps");
            EXPECT_EQ(e.exit_status(), 2);
        }
    }
    EXPECT_THROW(ConvertSource::files({}), Error);
    EXPECT_THROW(ConvertSource::synthetic("teapot:8"), Error);
    EXPECT_THROW(ConvertSource::sparse_spheres(64).load(0), Error);
}

TEST(Convert, SparseSpheresIsBuiltDirectly) {
    ScratchDir dir("octiso_convert_lib");
    const std::string out = dir.file("sp.oct");
    const ConvertReport r = convert(ConvertSource::sparse_spheres(64), out, BuildOptions{});
    EXPECT_TRUE(r.built_directly);
    EXPECT_EQ(r.input, "sparse-spheres:64");
    EXPECT_EQ(r.type, ScalarType::f32);
    EXPECT_EQ(r.dims, (Dims{64, 64, 64}));
    EXPECT_EQ(r.file_bytes, fs::file_size(out));
    const OctFile f = OctFile::open(out);
    EXPECT_EQ(f.info().dmax, r.dmax);
    EXPECT_EQ(f.step_sizes(0).nodes_per_depth, r.total.nodes_per_depth);
}

}  // namespace
}  // namespace octiso::test
