// NIfTI as nibabel reads it (CONVENTIONS 2b, issue 17 item 4; src/io/nifti_header.cpp and
// nifti_stream.cpp), through both converter paths. Each file is written with a known header
// (nifti_test_file.h); the expected affine is written out by hand from the NIfTI-1 standard
// (what nibabel's get_best_affine() returns for it), and every voxel of the tree is checked
// against the file voxel that affine puts at the same world point. Value scaling is checked
// against scl_slope/scl_inter applied by hand, in the tools' reports and isovalues.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <zlib.h>

#include "cli/cli_test_util.h"
#include "io/nifti_test_file.h"
#include "octiso/convert.h"
#include "octiso/decode.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "test_util/scratch_dir.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

namespace fs = std::filesystem;

constexpr Dims kDims{7, 5, 4};

std::vector<int16_t> file_values(int salt = 0) {
    std::vector<int16_t> v(kDims.voxels());
    for (size_t i = 0; i < v.size(); ++i) v[i] = int16_t(int(i * 29 % 97) - 40 + salt);
    return v;
}

std::string as_bytes(const std::vector<int16_t>& v) { return std::string(reinterpret_cast<const char*>(v.data()), v.size() * 2); }

/// A number as the tools print it ({fmt}'s shortest form: integral values without a point).
std::string cli_number(double v) {
    char b[40];
    if (v == std::floor(v) && std::fabs(v) < 1e15) std::snprintf(b, sizeof b, "%lld", (long long)v);
    else std::snprintf(b, sizeof b, "%.17g", v);
    return b;
}

std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string gunzip(const std::string& path) {
    gzFile f = ::gzopen(path.c_str(), "rb");
    std::string out;
    char buf[65536];
    int n;
    while (f && (n = ::gzread(f, buf, sizeof buf)) > 0) out.append(buf, size_t(n));
    if (f) ::gzclose(f);
    return out;
}

/// world = A * (i, j, k, 1), A diagonal: nibabel's affine of the test files below.
struct Affine {
    double diag[3], offset[3];
};

/// Every voxel of step `k` of `f` holds the file voxel that `A` puts at its world point.
void expect_placed_as(const OctFile& f, uint32_t k, const std::vector<int16_t>& values, const Affine& A, const std::string& what) {
    const OctInfo& in = f.info();
    ASSERT_EQ(in.dims, kDims) << what;
    std::vector<int16_t> tree(kDims.voxels());
    decode_to_dense(f.step<int16_t>(k), tree.data());
    const uint32_t n[3] = {kDims.x, kDims.y, kDims.z};
    int mismatches = 0;
    for (uint32_t z = 0; z < kDims.z; ++z)
        for (uint32_t y = 0; y < kDims.y; ++y)
            for (uint32_t x = 0; x < kDims.x; ++x) {
                const uint32_t t[3] = {x, y, z};
                int64_t file_index[3];
                for (int a = 0; a < 3; ++a) {
                    const double p = in.placement.origin[size_t(a)] + in.placement.spacing[size_t(a)] * t[a];
                    const double i = (p - A.offset[a]) / A.diag[a];
                    file_index[a] = std::llround(i);
                    ASSERT_NEAR(i, double(file_index[a]), 1e-9) << what << ": world point between file voxels";
                    ASSERT_TRUE(file_index[a] >= 0 && file_index[a] < int64_t(n[a])) << what << ": outside the file's grid";
                }
                const size_t fi = size_t(file_index[0] + n[0] * (file_index[1] + n[1] * file_index[2]));
                if (tree[x + n[0] * (y + size_t(n[1]) * z)] != values[fi]) ++mismatches;
            }
    EXPECT_EQ(mismatches, 0) << what;
}

MemoryOptions streamed() {
    MemoryOptions m;
    m.budget = uint64_t(64) << 20;
    m.piece_side = 4;
    return m;
}

/// Converts `n` over `values` as .nii and .nii.gz, in memory and out of core; all four must be
/// placed as `A` says and give the same bytes.
void expect_both_paths(const Nifti1& n, const std::vector<int16_t>& values, const Affine& A, const std::string& what,
                       uint8_t expect_flipped) {
    ScratchDir dir("nifti_place");
    std::string first;
    for (const bool gz : {false, true}) {
        const std::string path = dir.file(gz ? "in.nii.gz" : "in.nii");
        if (gz) write_gz(path, n.bytes(as_bytes(values)));
        else write_file(path, n.bytes(as_bytes(values)));
        for (const bool stream : {false, true}) {
            const std::string tag = what + (gz ? " .nii.gz" : " .nii") + (stream ? " streamed" : " in memory");
            const std::string out = dir.file("out.oct");
            const ConvertReport r = convert(ConvertSource::file(path), out, BuildOptions{}, stream ? streamed() : MemoryOptions{});
            EXPECT_EQ(r.streamed, stream) << tag;
            EXPECT_EQ(r.flipped_axes, expect_flipped) << tag;
            const OctFile f = OctFile::open(out);
            EXPECT_EQ(f.info().flipped_axes, expect_flipped) << tag;
            expect_placed_as(f, 0, values, A, tag);
            const std::string bytes = slurp(out);
            if (first.empty()) first = bytes;
            EXPECT_TRUE(bytes == first) << tag << ": differs from the first conversion";
        }
    }
}

Nifti1 grid() {
    Nifti1 n;
    n.dim[1] = int16_t(kDims.x), n.dim[2] = int16_t(kDims.y), n.dim[3] = int16_t(kDims.z);
    return n;
}

TEST(NiftiPlacement, SformWithANegativeAxisIsThatAxisReversed) {
    Nifti1 n = grid();
    n.set_srow({-2, 0, 0, 10, 0, 1.5f, 0, -4, 0, 0, 0.5f, 3});
    expect_both_paths(n, file_values(), {{-2, 1.5, 0.5}, {10, -4, 3}}, "x flipped", 1);
}

TEST(NiftiPlacement, SformWithEveryAxisNegative) {
    Nifti1 n = grid();
    n.set_srow({-1, 0, 0, 5, 0, -2, 0, 6, 0, 0, -0.5f, 7});
    expect_both_paths(n, file_values(3), {{-1, -2, -0.5}, {5, 6, 7}}, "x, y, z flipped", 7);
}

TEST(NiftiPlacement, QformQuaternionAndQfacMinusOne) {
    // b, c, d = 0, 0, 1 is a half turn about z: R = diag(-1, -1, 1); qfac -1 negates R's z
    // column; the columns are scaled by pixdim: nibabel's affine is diag(-1.5, -2, -2.5).
    Nifti1 n = grid();
    n.qform_code = 1;
    n.quatern[2] = 1;
    n.pixdim[0] = -1, n.pixdim[1] = 1.5f, n.pixdim[2] = 2, n.pixdim[3] = 2.5f;
    n.qoffset[0] = 1, n.qoffset[1] = 2, n.qoffset[2] = 3;
    expect_both_paths(n, file_values(5), {{-1.5, -2, -2.5}, {1, 2, 3}}, "qform half turn, qfac -1", 7);
    // The identity quaternion with qfac -1: only z runs backwards.
    Nifti1 q = grid();
    q.qform_code = 1;
    q.pixdim[0] = -1, q.pixdim[3] = 3;
    q.qoffset[2] = 20;
    expect_both_paths(q, file_values(6), {{1, 1, -3}, {0, 0, 20}}, "qform identity, qfac -1", 4);
}

TEST(NiftiPlacement, QfacIsIgnoredWhereTheSformPlacesTheGrid) {
    Nifti1 n = grid();
    n.pixdim[0] = -1;
    n.qform_code = 1;
    n.set_srow({0.5f, 0, 0, -3, 0, 2, 0, 4.5f, 0, 0, 1.25f, 10});
    expect_both_paths(n, file_values(7), {{0.5, 2, 1.25}, {-3, 4.5, 10}}, "sform over qfac -1", 0);
}

TEST(NiftiPlacement, NoTransformIsPixdimAtOriginZero) {
    Nifti1 n = grid();
    n.pixdim[1] = 0.5f, n.pixdim[2] = 2, n.pixdim[3] = 3;
    expect_both_paths(n, file_values(8), {{0.5, 2, 3}, {0, 0, 0}}, "no qform, no sform", 0);
}

TEST(NiftiPlacement, ObliqueAffineIsPlacedAsVtkDoesWithAWarning) {
    ScratchDir dir("nifti_oblique");
    Nifti1 n = grid();
    n.pixdim[1] = 0.8f, n.pixdim[2] = 1.2f, n.pixdim[3] = 2;
    n.set_srow({0.8f * 0.6f, -1.2f * 0.8f, 0, 1, 0.8f * 0.8f, 1.2f * 0.6f, 0, 2, 0, 0, 2, 3});   // a turn about z
    const std::vector<int16_t> values = file_values(9);
    const std::string path = dir.file("oblique.nii");
    write_file(path, n.bytes(as_bytes(values)));
    for (const bool stream : {false, true}) {
        const ConvertReport r = convert(ConvertSource::file(path), dir.file("o.oct"), BuildOptions{}, stream ? streamed() : MemoryOptions{});
        ASSERT_EQ(r.warnings.size(), 1u);
        EXPECT_NE(r.warnings[0].find("oblique"), std::string::npos) << r.warnings[0];
        EXPECT_NE(r.warnings[0].find("as VTK does"), std::string::npos) << r.warnings[0];
        // VTK: pixdim spacing, origin 0, the file's order.
        expect_placed_as(OctFile::open(dir.file("o.oct")), 0, values, {{0.8f, 1.2f, 2}, {0, 0, 0}}, "oblique");
    }
    // VTK reverses the slices of a qfac -1 file.
    n.pixdim[0] = -1;
    write_file(path, n.bytes(as_bytes(values)));
    convert(ConvertSource::file(path), dir.file("o.oct"), BuildOptions{});
    expect_placed_as(OctFile::open(dir.file("o.oct")), 0, values, {{0.8f, 1.2f, -2}, {0, 0, 2 * (kDims.z - 1)}}, "oblique, qfac -1");
    // The tool says so in one line naming the file, and still converts.
    const ToolRun t = run_tool("octiso-convert", "'" + path + "' -o '" + dir.file("t.oct") + "'");
    EXPECT_EQ(t.status, 0) << t.err;
    EXPECT_NE(t.err.find("warning: " + path + ": NIfTI sform is oblique"), std::string::npos) << t.err;
}

TEST(NiftiPlacement, RealTemplateWithAFlippedXAxis) {
    const std::string path = "/usr/share/mricron/templates/HarvardOxford-cort-maxprob-thr0-1mm.nii.gz";
    if (!fs::exists(path)) { OCTISO_SKIP(path << " (mricron) not installed"); }
    // srow_x = -1 0 0 90 with 182 columns: nibabel puts column 181 at x = -91.
    ScratchDir dir("nifti_ho");
    const ConvertReport r = convert(ConvertSource::file(path), dir.file("h.oct"), BuildOptions{});
    EXPECT_EQ(r.flipped_axes, 1);
    EXPECT_EQ(r.placement.origin, (std::array<double, 3>{-91, -126, -72}));
    EXPECT_EQ(r.placement.spacing, (std::array<double, 3>{1, 1, 1}));
}

// ---- values ------------------------------------------------------------------------------

TEST(NiftiScaling, SlopeAndInterceptAreRecordedAndTheTreeKeepsTheStoredValues) {
    ScratchDir dir("nifti_scale");
    Nifti1 n = grid();
    n.slope = 0.5f, n.inter = -10;
    const std::vector<int16_t> values = file_values();
    const std::string path = dir.file("s.nii");
    write_file(path, n.bytes(as_bytes(values)));
    for (const bool stream : {false, true}) {
        const ConvertReport r = convert(ConvertSource::file(path), dir.file("s.oct"), BuildOptions{}, stream ? streamed() : MemoryOptions{});
        EXPECT_EQ(r.value_scale, (ValueScale{0.5, -10}));
        const OctFile f = OctFile::open(dir.file("s.oct"));
        EXPECT_EQ(f.info().type, ScalarType::i16);
        EXPECT_EQ(f.info().value_scale, (ValueScale{0.5, -10}));
        expect_placed_as(f, 0, values, {{1, 1, 1}, {0, 0, 0}}, "scaled");
    }
    // nibabel's get_slope_inter(): a zero or non-finite slope means no scaling at all.
    for (const float slope : {0.0f, std::nanf("")}) {
        n.slope = slope, n.inter = 7;
        write_file(path, n.bytes(as_bytes(values)));
        EXPECT_TRUE(convert(ConvertSource::file(path), dir.file("s.oct"), BuildOptions{}).value_scale.is_identity()) << slope;
    }
    // A valid slope with a non-finite intercept is refused, as nibabel refuses it.
    n.slope = 2, n.inter = INFINITY;
    write_file(path, n.bytes(as_bytes(values)));
    const ToolRun t = run_tool("octiso-convert", "'" + path + "' -o '" + dir.file("bad.oct") + "'");
    EXPECT_EQ(t.status, 2);
    EXPECT_EQ(t.err_lines(), 1) << t.err;
    EXPECT_NE(t.err.find(path + ": NIfTI scl_slope is 2 but scl_inter is not finite"), std::string::npos) << t.err;
    EXPECT_FALSE(fs::exists(dir.file("bad.oct")));
}

TEST(NiftiScaling, ToolsTakeAndReportRealValues) {
    for (const char* tool : {"octiso-convert", "octiso-info", "octiso-render"})
        if (!fs::exists(std::string(OCTISO_TOOLS_DIR) + "/" + tool)) { OCTISO_SKIP(tool << " not built"); }
    ScratchDir dir("nifti_scale_cli");
    const std::vector<int16_t> values = file_values();
    int16_t lo = values[0], hi = values[0];
    for (const int16_t v : values) lo = std::min(lo, v), hi = std::max(hi, v);
    Nifti1 plain = grid(), scaled = grid(), negative = grid();
    scaled.slope = 2, scaled.inter = 1;
    negative.slope = -4, negative.inter = 3;
    write_file(dir.file("plain.nii"), plain.bytes(as_bytes(values)));
    write_file(dir.file("scaled.nii"), scaled.bytes(as_bytes(values)));
    write_file(dir.file("negative.nii"), negative.bytes(as_bytes(values)));
    for (const char* name : {"plain", "scaled", "negative"}) {
        const ToolRun c = run_tool("octiso-convert", "'" + dir.file(std::string(name) + ".nii") + "' -o '" + dir.file(std::string(name) + ".oct") + "' --json");
        ASSERT_EQ(c.status, 0) << c.err;
    }
    // Ranges in real values: stored * slope + inter, ends swapped by a negative slope.
    const ToolRun c = run_tool("octiso-convert", "'" + dir.file("scaled.nii") + "' -o '" + dir.file("s2.oct") + "' --json");
    EXPECT_EQ(json_numbers(c.out, "value_range"), (std::vector<double>{2.0 * lo + 1, 2.0 * hi + 1}));
    EXPECT_NE(c.err.find("real value = stored * 2 + 1"), std::string::npos) << c.err;
    const ToolRun i = run_tool("octiso-info", "'" + dir.file("negative.oct") + "' --json");
    ASSERT_EQ(i.status, 0) << i.err;
    EXPECT_EQ(json_numbers(i.out, "value_range"), (std::vector<double>{-4.0 * hi + 3, -4.0 * lo + 3}));
    const std::string per_step = i.out.substr(i.out.find("\"per_step\""));
    EXPECT_EQ(json_number(per_step, "min"), -4.0 * hi + 3);
    EXPECT_EQ(json_number(per_step, "max"), -4.0 * lo + 3);
    const std::vector<double> edges = json_numbers(per_step, "edges");
    ASSERT_FALSE(edges.empty());
    EXPECT_EQ(edges.front(), -4.0 * hi + 3);
    EXPECT_EQ(edges.back(), -4.0 * lo + 3);
    // An isovalue in real values draws what its stored value draws in the unscaled file.
    const double stored_iso = 0.5 * (lo + hi) + 0.25;
    const std::string camera = " --size 48x40 --eye 3,2,-14 --look 3,2,1.5 --up 0,1,0 --fov 40";
    const ToolRun a = run_tool("octiso-render", "'" + dir.file("plain.oct") + "' --iso " + cli_number(stored_iso) + " -o '" + dir.file("a.png") + "'" + camera);
    const ToolRun b = run_tool("octiso-render", "'" + dir.file("scaled.oct") + "' --iso " + cli_number(2 * stored_iso + 1) + " -o '" + dir.file("b.png") + "' --json" + camera);
    const ToolRun d = run_tool("octiso-render", "'" + dir.file("negative.oct") + "' --iso " + cli_number(-4 * stored_iso + 3) + " -o '" + dir.file("d.png") + "'" + camera);
    ASSERT_EQ(a.status, 0) << a.err;
    ASSERT_EQ(b.status, 0) << b.err;
    ASSERT_EQ(d.status, 0) << d.err;
    EXPECT_EQ(json_numbers(b.out, "isovalues"), (std::vector<double>{2 * stored_iso + 1}));
    EXPECT_TRUE(slurp(dir.file("a.png")) == slurp(dir.file("b.png")));
    EXPECT_TRUE(slurp(dir.file("a.png")) == slurp(dir.file("d.png")));
    // The refusal of an isovalue outside the data names the real range.
    const ToolRun out = run_tool("octiso-render", "'" + dir.file("scaled.oct") + "' --iso " + cli_number(2.0 * hi + 10) + " -o '" + dir.file("x.png") + "'" + camera);
    EXPECT_EQ(out.status, 2);
    EXPECT_NE(out.err.find("outside the data range " + cli_number(2.0 * lo + 1) + " .. " + cli_number(2.0 * hi + 1)), std::string::npos) << out.err;
    // --iso-range is given in real values too: the recorded range maps back to what was asked.
    const ToolRun r = run_tool("octiso-convert", "'" + dir.file("negative.nii") + "' -o '" + dir.file("r.oct") + "' --iso-range -100,20");
    ASSERT_EQ(r.status, 0) << r.err;
    const ToolRun ri = run_tool("octiso-info", "'" + dir.file("r.oct") + "' --json");
    EXPECT_EQ(json_numbers(ri.out, "iso_range"), (std::vector<double>{-100, 20}));
}

TEST(NiftiScaling, FourDimensionalScaledAndFlippedFileIsASeries) {
    ScratchDir dir("nifti_4d_scaled");
    Nifti1 n = grid();
    n.dim[0] = 4, n.dim[4] = 3;
    n.slope = 3, n.inter = 0.5f;
    n.set_srow({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -2, 9});
    std::string data;
    std::vector<std::vector<int16_t>> steps;
    for (int t = 0; t < 3; ++t) {
        steps.push_back(file_values(10 * t));
        data += as_bytes(steps.back());
    }
    const std::string path = dir.file("t.nii.gz");
    write_gz(path, n.bytes(data));
    const ConvertReport r = convert(ConvertSource::file(path), dir.file("t.oct"), BuildOptions{});
    ASSERT_EQ(r.steps, 3u);
    const OctFile f = OctFile::open(dir.file("t.oct"));
    EXPECT_EQ(f.info().value_scale, (ValueScale{3, 0.5}));
    for (uint32_t t = 0; t < 3; ++t) expect_placed_as(f, t, steps[t], {{1, 1, -2}, {0, 0, 9}}, "step " + std::to_string(t));
}

// ---- extraction ----------------------------------------------------------------------------

TEST(NiftiExtract, NiftiComesBackInTheFilesOrderWithItsSformAndScale) {
    for (const char* tool : {"octiso-convert", "octiso-info"})
        if (!fs::exists(std::string(OCTISO_TOOLS_DIR) + "/" + tool)) { OCTISO_SKIP(tool << " not built"); }
    ScratchDir dir("nifti_extract");
    Nifti1 n = grid();
    n.set_srow({-1, 0, 0, 5, 0, 2, 0, 6, 0, 0, -0.5f, 7});
    n.slope = 0.25f, n.inter = -2;
    const std::vector<int16_t> values = file_values(11);
    write_file(dir.file("in.nii"), n.bytes(as_bytes(values)));
    ASSERT_EQ(run_tool("octiso-convert", "'" + dir.file("in.nii") + "' -o '" + dir.file("in.oct") + "'").status, 0);
    for (const char* ext : {".nii", ".nii.gz"}) {
        SCOPED_TRACE(ext);
        const std::string out = dir.file(std::string("x") + ext);
        const ToolRun e = run_tool("octiso-info", "'" + dir.file("in.oct") + "' --extract '" + out + "'");
        ASSERT_EQ(e.status, 0) << e.err;
        const std::string b = std::string(ext) == ".nii" ? slurp(out) : gunzip(out);
        ASSERT_GE(b.size(), 352u);
        auto f32 = [&](size_t at) {
            float v;
            std::memcpy(&v, b.data() + at, 4);
            return v;
        };
        int16_t sform_code, datatype;
        std::memcpy(&sform_code, b.data() + 254, 2);
        std::memcpy(&datatype, b.data() + 70, 2);
        EXPECT_GT(sform_code, 0);
        EXPECT_EQ(datatype, 4);
        for (int i = 0; i < 12; ++i) EXPECT_EQ(f32(280 + 4 * size_t(i)), n.srow[i]) << "srow element " << i;
        EXPECT_EQ(f32(112), 0.25f);
        EXPECT_EQ(f32(116), -2.0f);
        const size_t vox = size_t(f32(108));
        ASSERT_EQ(b.size(), vox + values.size() * 2);
        EXPECT_TRUE(b.substr(vox) == as_bytes(values)) << "voxels not in the file's order";
    }
    // --extract-raw: the file's voxel block, byte for byte.
    ASSERT_EQ(run_tool("octiso-info", "'" + dir.file("in.oct") + "' --extract-raw '" + dir.file("x.raw") + "'").status, 0);
    EXPECT_TRUE(slurp(dir.file("x.raw")) == as_bytes(values));
    // In slabs of 1 and 3 layers (x and z reversed: the stored layers go out from the top), and
    // big-endian: the same bytes (a step larger than memory is extracted this way).
    for (const uint64_t layers : {1, 3}) {
        ::setenv("OCTISO_EXTRACT_SLAB_BYTES", std::to_string(layers * kDims.x * kDims.y * 2).c_str(), 1);
        ASSERT_EQ(run_tool("octiso-info", "'" + dir.file("in.oct") + "' --extract-raw '" + dir.file("s.raw") + "'").status, 0);
        EXPECT_TRUE(slurp(dir.file("s.raw")) == as_bytes(values)) << layers << "-layer slabs";
        ASSERT_EQ(run_tool("octiso-info", "'" + dir.file("in.oct") + "' --extract-raw '" + dir.file("b.raw") + "' --endian big").status, 0);
        std::string big = as_bytes(values);
        for (size_t i = 0; i + 1 < big.size(); i += 2) std::swap(big[i], big[i + 1]);
        EXPECT_TRUE(slurp(dir.file("b.raw")) == big) << layers << "-layer slabs, big-endian";
        ::unsetenv("OCTISO_EXTRACT_SLAB_BYTES");
    }
    // And the extracted NIfTI converts to the same tree.
    ASSERT_EQ(run_tool("octiso-convert", "'" + dir.file("x.nii.gz") + "' -o '" + dir.file("back.oct") + "'").status, 0);
    EXPECT_TRUE(slurp(dir.file("back.oct")) == slurp(dir.file("in.oct")));
}

}  // namespace
}  // namespace octiso::test
