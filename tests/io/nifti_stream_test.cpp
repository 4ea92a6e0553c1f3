// The streaming NIfTI reader (src/io/nifti_stream.cpp, nifti_header.cpp; issue 13) through the
// converter: real templates (/usr/share/mricron/templates) and hand-made files converted out of
// core must give the same .oct bytes as the whole-file path, placement from the sform/qform
// included (CONVENTIONS 2b); a 4-D file becomes a series. Scaling, flips and oblique affines
// against nibabel's reading: nifti_placement_test.cpp.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <zlib.h>

#include "octiso/convert.h"
#include "octiso/decode.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "io/nifti_test_file.h"
#include "test_util/scratch_dir.h"
#include "test_util/skip.h"

namespace octiso::test {
namespace {

std::string slurp(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

MemoryOptions streamed(uint32_t side = 0) {
    MemoryOptions m;
    m.budget = uint64_t(256) << 20;
    m.piece_side = side;
    return m;
}

void expect_same_both_ways(ScratchDir& dir, const std::string& in, uint32_t side, const std::string& what) {
    const ConvertReport a = convert(ConvertSource::file(in), dir.file("whole.oct"), BuildOptions{});
    const ConvertReport b = convert(ConvertSource::file(in), dir.file("streamed.oct"), BuildOptions{}, streamed(side));
    EXPECT_FALSE(a.streamed);
    EXPECT_TRUE(b.streamed);
    EXPECT_EQ(a.placement.origin, b.placement.origin) << what;
    EXPECT_EQ(a.placement.spacing, b.placement.spacing) << what;
    EXPECT_TRUE(slurp(dir.file("whole.oct")) == slurp(dir.file("streamed.oct"))) << what << ": streamed file differs";
}

TEST(NiftiStream, RealTemplatesGiveTheBytesOfTheWholeFilePath) {
    const char* names[] = {"ch2.nii.gz", "aal.nii.gz", "inia19-t1-brain.nii.gz", "inia19-NeuroMaps.nii.gz", "brodmann.nii.gz"};
    const std::string root = "/usr/share/mricron/templates/";
    if (!std::filesystem::exists(root + names[0])) {
        OCTISO_SKIP(root << " (mricron) not installed");
    }
    for (const char* name : names) {
        if (!std::filesystem::exists(root + name)) continue;
        ScratchDir dir("nifti_real");
        expect_same_both_ways(dir, root + name, 0, name);
        expect_same_both_ways(dir, root + name, 16, std::string(name) + ", pieces of 16");
    }
    // ch2: the MNI placement of its sform, not VTK's origin 0.
    ScratchDir dir("nifti_ch2");
    const ConvertReport r = convert(ConvertSource::file(root + "ch2.nii.gz"), dir.file("c.oct"), BuildOptions{}, streamed());
    EXPECT_EQ(r.placement.origin, (std::array<double, 3>{-90, -125, -71}));
    EXPECT_EQ(r.placement.spacing, (std::array<double, 3>{1, 1, 1}));
}

std::string i16_data(uint64_t n, int salt, bool big) {
    std::string d(n * 2, '\0');
    for (uint64_t i = 0; i < n; ++i) {
        const int16_t v = int16_t((i * 37 + uint64_t(salt) * 11) % 300 / (i % 7 == 0 ? 1 : 50) - 3);
        unsigned char b[2];
        std::memcpy(b, &v, 2);
        if (big) std::swap(b[0], b[1]);
        std::memcpy(&d[2 * i], b, 2);
    }
    return d;
}

TEST(NiftiStream, BigEndianWithSformAndGzipMatchTheWholeFilePath) {
    for (const bool big : {false, true})
        for (const bool gz : {false, true}) {
            ScratchDir dir("nifti_hand");
            Nifti1 n;
            n.dim[1] = 23, n.dim[2] = 10, n.dim[3] = 37;
            n.big = big;
            n.sform_code = 1;
            const float srow[12] = {0.5f, 0, 0, -3, 0, 2, 0, 4.5f, 0, 0, 1.25f, 10};
            std::memcpy(n.srow, srow, sizeof srow);
            const std::string bytes = n.bytes(i16_data(23 * 10 * 37, 1, big));
            const std::string path = dir.file(gz ? "h.nii.gz" : "h.nii");
            if (gz) write_gz(path, bytes);
            else std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
            const std::string what = std::string(big ? "big" : "little") + (gz ? " .nii.gz" : " .nii");
            expect_same_both_ways(dir, path, 4, what);
            const OctFile f = OctFile::open(dir.file("streamed.oct"));
            EXPECT_EQ(f.info().placement.spacing, (std::array<double, 3>{0.5, 2, 1.25})) << what;
            EXPECT_EQ(f.info().placement.origin, (std::array<double, 3>{-3, 4.5, 10})) << what;
        }
}

TEST(NiftiStream, FourDimensionalFileIsASeries) {
    ScratchDir dir("nifti_4d");
    Nifti1 n;
    n.dim[0] = 4, n.dim[1] = 9, n.dim[2] = 14, n.dim[3] = 11, n.dim[4] = 3;
    const uint64_t v = 9 * 14 * 11;
    std::string data;
    for (int t = 0; t < 3; ++t) data += i16_data(v, 10 + t, false);
    const std::string path = dir.file("t.nii.gz");
    write_gz(path, n.bytes(data));
    const ConvertReport r = convert(ConvertSource::file(path), dir.file("t.oct"), BuildOptions{}, streamed(4));
    ASSERT_EQ(r.steps, 3u);
    EXPECT_EQ(r.bytes_read, std::filesystem::file_size(path));
    const OctFile f = OctFile::open(dir.file("t.oct"));
    ASSERT_EQ(f.info().step_count, 3u);
    for (uint32_t t = 0; t < 3; ++t) {
        std::vector<int16_t> out(v);
        decode_to_dense(f.step<int16_t>(t), out.data());
        EXPECT_EQ(std::memcmp(out.data(), data.data() + t * v * 2, v * 2), 0) << "step " << t;
    }
    // Without --memory too: VTK would read the time points as components, so it streams.
    const ConvertReport d = convert(ConvertSource::file(path), dir.file("d.oct"), BuildOptions{});
    EXPECT_TRUE(d.streamed);
    EXPECT_TRUE(slurp(dir.file("t.oct")) == slurp(dir.file("d.oct")));
}

TEST(NiftiStream, WholeFileFormatsOverAnExplicitBudgetAreRefused) {
    ScratchDir dir("whole_budget");
    const std::string path = dir.file("v.nrrd");
    {
        std::ofstream f(path, std::ios::binary);
        // hex: an encoding the stream does not read (text_stream.cpp), so VTK reads it whole.
        f << "NRRD0004\ntype: unsigned char\ndimension: 3\nsizes: 64 64 64\nencoding: hex\n\n";
        std::string d;
        for (int i = 0; i < 64 * 64 * 64; ++i) d += "07";
        f << d;
    }
    MemoryOptions m;
    m.budget = 100000;   // below the 262144 voxel bytes VTK must hold at once
    try {
        convert(ConvertSource::file(path), dir.file("out.oct"), BuildOptions{}, m);
        ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.exit_status(), 2);
        EXPECT_NE(std::string(e.what()).find("read whole"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("262144 voxel bytes"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(dir.file("out.oct")));
    // A detached header (.nhdr + data file) over the budget: refused with the bytes its header
    // declares (convert() asks header_check.h before VTK reads; this test cannot tell the two
    // moments apart without making VTK allocate more than the machine has).
    const std::string big = dir.file("big.nhdr");
    {
        std::ofstream f(big, std::ios::binary);
        f << "NRRD0004\ntype: float\ndimension: 3\nsizes: 200 200 200\nencoding: hex\ndata file: big.raw\n\n";
    }
    {
        std::ofstream(dir.file("big.raw"), std::ios::binary);
    }
    std::filesystem::resize_file(dir.file("big.raw"), uint64_t(200) * 200 * 200 * 4 * 2);
    m.budget = uint64_t(16) << 20;
    try {
        convert(ConvertSource::file(big), dir.file("out.oct"), BuildOptions{}, m);
        ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.exit_status(), 2);
        EXPECT_NE(std::string(e.what()).find("32000000 voxel bytes exceed --memory"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace octiso::test
