// Issue 18, classes 2, 6 and 11: headers that crash VTK's readers or make them zero-fill.
// NIfTI datatypes VTK does not handle segfaulted inside it (1234, 1536, 2048) or threw
// length_error (255); NRRD, legacy VTK and MetaImage headers declaring more voxels than the file
// holds converted with exit 0 and zeros. Each variant must be refused with one line naming the
// file, exit 2, before any voxel is allocated; the same headers with honest sizes still convert.
#include <gtest/gtest.h>

#include <zlib.h>

#include <cmath>
#include <cstring>

#include "hostile/hostile_util.h"
#include "io/header_check.h"
#include "octiso/error.h"

namespace octiso::test {
namespace {

struct NiftiSpec {
    int16_t dim[8] = {3, 4, 4, 4, 1, 1, 1, 1};
    int16_t datatype = 2, bitpix = 8;
    float vox_offset = 352;
    int64_t data_bytes = 64;   // voxel bytes actually written after vox_offset
};

std::string nifti1(const NiftiSpec& s) {
    std::string h(352, '\0');
    const int32_t sizeof_hdr = 348;
    std::memcpy(&h[0], &sizeof_hdr, 4);
    std::memcpy(&h[40], s.dim, 16);
    std::memcpy(&h[70], &s.datatype, 2);
    std::memcpy(&h[72], &s.bitpix, 2);
    const float pixdim[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    std::memcpy(&h[76], pixdim, 32);
    std::memcpy(&h[108], &s.vox_offset, 4);
    const int16_t sform = 0, qform = 0;
    std::memcpy(&h[252], &qform, 2);
    std::memcpy(&h[254], &sform, 2);
    std::memcpy(&h[344], "n+1\0", 4);
    if (std::isfinite(s.vox_offset) && s.vox_offset > 352 && s.vox_offset < 1e6) h.resize(size_t(s.vox_offset), '\0');
    for (int64_t i = 0; i < s.data_bytes; ++i) h.push_back(char(i * 7));
    return h;
}

void write_gz(const std::string& path, const std::string& bytes) {
    gzFile f = ::gzopen(path.c_str(), "wb");
    ::gzwrite(f, bytes.data(), unsigned(bytes.size()));
    ::gzclose(f);
}

struct HostileHeaders : ::testing::Test {
    ScratchDir dir{"octiso_hostile_headers"};
    std::string err = dir.file("err.txt");
    RunResult convert(const std::string& in) {
        return run_capture("'" + tool("octiso-convert") + "' '" + dir.file(in) + "' -o '" + dir.file("out.oct") + "'", err);
    }
    void expect_converts(const std::string& in) {
        const RunResult r = convert(in);
        EXPECT_EQ(r.exit_status, 0) << in << ": " << r.err;
        std::filesystem::remove(dir.file("out.oct"));
    }
    void expect_refused_file(const std::string& in, const std::string& what) {
        const RunResult r = convert(in);
        expect_refused(r, dir.file(in), what);
        EXPECT_FALSE(std::filesystem::exists(dir.file("out.oct")));
        EXPECT_TRUE(temporaries(dir.path()).empty());
    }
};

TEST_F(HostileHeaders, NiftiHonestFileConverts) {
    write_text(dir.file("ok.nii"), nifti1({}));
    expect_converts("ok.nii");
    write_gz(dir.file("ok.nii.gz"), nifti1({}));
    expect_converts("ok.nii.gz");
}

TEST_F(HostileHeaders, NiftiDatatypesVtkCannotHandleAreRefused) {
    for (int16_t dt : {int16_t(1234), int16_t(1536), int16_t(2048), int16_t(255), int16_t(1), int16_t(32), int16_t(128),
                       int16_t(1024), int16_t(1280), int16_t(1792), int16_t(2304), int16_t(0), int16_t(-1)}) {
        SCOPED_TRACE(dt);
        NiftiSpec s;
        s.datatype = dt;
        write_text(dir.file("dt.nii"), nifti1(s));
        expect_refused_file("dt.nii", "datatype");
        write_gz(dir.file("dt.nii.gz"), nifti1(s));
        expect_refused_file("dt.nii.gz", "datatype, gzip");
    }
}

TEST_F(HostileHeaders, NiftiDimsOffsetsAndSizesAreValidated) {
    std::vector<std::pair<std::string, NiftiSpec>> cases;
    auto add = [&](const std::string& what, auto edit) {
        NiftiSpec s;
        edit(s);
        cases.emplace_back(what, s);
    };
    add("dim0 0", [](NiftiSpec& s) { s.dim[0] = 0; });
    add("dim0 8", [](NiftiSpec& s) { s.dim[0] = 8; });
    add("negative extent", [](NiftiSpec& s) { s.dim[2] = -4; });
    add("zero extent", [](NiftiSpec& s) { s.dim[3] = 0; });
    add("huge dims, small file", [](NiftiSpec& s) { s.dim[1] = s.dim[2] = s.dim[3] = 32767; });
    add("4-D declares more steps than held", [](NiftiSpec& s) { s.dim[0] = 4, s.dim[4] = 1000; });
    add("bitpix mismatch", [](NiftiSpec& s) { s.bitpix = 16; });
    add("vox_offset NaN", [](NiftiSpec& s) { s.vox_offset = NAN; });
    add("vox_offset negative", [](NiftiSpec& s) { s.vox_offset = -1e9f; });
    add("vox_offset inside the header", [](NiftiSpec& s) { s.vox_offset = 100; });
    add("vox_offset fractional", [](NiftiSpec& s) { s.vox_offset = 352.5f; });
    add("vox_offset past the end", [](NiftiSpec& s) { s.vox_offset = 1e12f; });
    add("data one byte short", [](NiftiSpec& s) { s.data_bytes = 63; });
    for (const auto& [what, spec] : cases) {
        SCOPED_TRACE(what);
        write_text(dir.file("bad.nii"), nifti1(spec));
        expect_refused_file("bad.nii", what);
    }
    // Truncated headers and a broken gzip stream.
    write_text(dir.file("short.nii"), nifti1({}).substr(0, 200));
    expect_refused_file("short.nii", "truncated header");
    write_text(dir.file("junk.nii.gz"), "\x1f\x8b garbage that is no deflate stream");
    expect_refused_file("junk.nii.gz", "broken gzip");
    // gzip bound: 1000^3 voxels from a few hundred compressed bytes cannot be real.
    NiftiSpec huge;
    huge.dim[1] = huge.dim[2] = huge.dim[3] = 1000;
    write_gz(dir.file("huge.nii.gz"), nifti1(huge));
    expect_refused_file("huge.nii.gz", "gzip bound");
}

TEST(HostileHeaderUnit, NiftiCheckerRejectsGarbageWithoutReadingPastTheBuffer) {
    std::vector<unsigned char> h(348, 0);
    EXPECT_THROW(io::check_nifti_header(h.data(), h.size(), 1000, true, "x.nii"), Error);
    EXPECT_THROW(io::check_nifti_header(h.data(), 10, 1000, true, "x.nii"), Error);
}

TEST_F(HostileHeaders, NrrdDeclaringMoreVoxelsThanHeldIsRefused) {
    // VTK reads a first axis of 9 or fewer samples as components: keep it at 16.
    const std::string data(256, 'v');
    write_text(dir.file("ok.nrrd"), "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 16 4 4\nencoding: raw\n\n" + data);
    expect_converts("ok.nrrd");
    write_text(dir.file("short.nrrd"), "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 16 4 4\nencoding: raw\n\n" + data.substr(1));
    expect_refused_file("short.nrrd", "one byte short");
    write_text(dir.file("huge.nrrd"), "NRRD0004\ntype: float\ndimension: 3\nsizes: 1000 1000 1000\nencoding: raw\n\n" + data);
    expect_refused_file("huge.nrrd", "1000^3");
    write_text(dir.file("gz.nrrd"), "NRRD0004\ntype: float\ndimension: 3\nsizes: 1000 1000 1000\nencoding: gzip\n\n" + data);
    expect_refused_file("gz.nrrd", "gzip 1000^3");
    write_text(dir.file("det.nhdr"), "NRRD0004\ntype: short\ndimension: 3\nsizes: 16 4 4\nencoding: raw\ndata file: det.raw\n\n");
    write_text(dir.file("det.raw"), data);   // 256 bytes, 512 declared
    expect_refused_file("det.nhdr", "detached, short");
    write_text(dir.file("missing.nhdr"), "NRRD0004\ntype: short\ndimension: 3\nsizes: 16 4 4\nencoding: raw\ndata file: nothere.raw\n\n");
    expect_refused_file("missing.nhdr", "detached, missing");
    write_text(dir.file("neg.nrrd"), "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 16 -4 4\nencoding: raw\n\n" + data);
    expect_refused_file("neg.nrrd", "negative size");
    write_text(dir.file("zero.nrrd"), "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 16 0 4\nencoding: raw\n\n" + data);
    expect_refused_file("zero.nrrd", "zero size");
}

TEST_F(HostileHeaders, LegacyVtkDeclaringMoreVoxelsThanHeldIsRefused) {
    const std::string head = "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 4 4 4\n"
                             "SPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 64\nSCALARS s unsigned_char 1\nLOOKUP_TABLE default\n";
    write_text(dir.file("ok.vtk"), head + std::string(64, 'v'));
    expect_converts("ok.vtk");
    write_text(dir.file("short.vtk"), head + std::string(63, 'v'));
    expect_refused_file("short.vtk", "binary, one byte short");
    std::string big = head;
    big.replace(big.find("DIMENSIONS 4 4 4"), 16, "DIMENSIONS 1000 1000 1000");
    big.replace(big.find("POINT_DATA 64"), 13, "POINT_DATA 1000000000");
    write_text(dir.file("huge.vtk"), big + std::string(64, 'v'));
    expect_refused_file("huge.vtk", "binary, 1000^3");
    std::string mismatch = head;
    mismatch.replace(mismatch.find("POINT_DATA 64"), 13, "POINT_DATA 60");
    write_text(dir.file("mismatch.vtk"), mismatch + std::string(64, 'v'));
    expect_refused_file("mismatch.vtk", "DIMENSIONS vs POINT_DATA");
    std::string ascii = head;
    ascii.replace(ascii.find("BINARY"), 6, "ASCII");
    write_text(dir.file("ascii.vtk"), ascii + "1 2 3\n");
    expect_refused_file("ascii.vtk", "ASCII, 3 of 64 values");
}

TEST_F(HostileHeaders, MetaImageDeclaringMoreVoxelsThanHeldIsRefused) {
    const std::string head = "ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\nElementType = MET_UCHAR\n";
    write_text(dir.file("ok.mha"), head + "ElementDataFile = LOCAL\n" + std::string(64, 'v'));
    expect_converts("ok.mha");
    write_text(dir.file("short.mha"), head + "ElementDataFile = LOCAL\n" + std::string(63, 'v'));
    expect_refused_file("short.mha", "LOCAL, one byte short");
    write_text(dir.file("huge.mha"), "ObjectType = Image\nNDims = 3\nDimSize = 1000 1000 1000\nElementType = MET_FLOAT\n"
                                     "ElementDataFile = LOCAL\n" + std::string(64, 'v'));
    expect_refused_file("huge.mha", "LOCAL, 1000^3");
    write_text(dir.file("ext.raw"), std::string(32, 'v'));
    write_text(dir.file("ext.mhd"), head + "ElementDataFile = ext.raw\n");
    expect_refused_file("ext.mhd", "detached, short");
    write_text(dir.file("gone.mhd"), head + "ElementDataFile = gone.raw\n");
    expect_refused_file("gone.mhd", "detached, missing");
    write_text(dir.file("z.mha"), "ObjectType = Image\nNDims = 3\nDimSize = 1000 1000 1000\nElementType = MET_FLOAT\n"
                                  "CompressedData = True\nElementDataFile = LOCAL\n" + std::string(64, 'v'));
    expect_refused_file("z.mha", "compressed, 1000^3");
}

// Class 11: a declared grid too big for the memory allowed. Where the test may mount a tmpfs
// (root), the raw file is a sparse 256 TiB there: more than the 128 TiB a process can map, in any
// build. Otherwise an 8 GiB sparse file of two 4 GiB layers under ulimit -v (which AddressSanitizer's
// shadow memory cannot start under): the out-of-core converter (issue 13) would convert a grid
// of many thin layers within the limit, but not one whose single slab exceeds it.
TEST_F(HostileHeaders, OutOfMemoryOnAHugeGridNamesTheFileAndExits2) {
    SmallTmpfs fs(dir.file("tmpfs"));
    std::string raw, dims, limit;
    if (fs.mounted()) {
        raw = dir.file("tmpfs/huge.raw"), dims = "1048576,1048576,256";
        { std::ofstream f(raw, std::ios::binary); }
        std::filesystem::resize_file(raw, uint64_t(1) << 48);
    } else {
#if defined(__SANITIZE_ADDRESS__)
        OCTISO_SKIP("needs a tmpfs (" << fs.why() << "): ulimit -v cannot run under ASan");
#endif
        raw = dir.file("huge.raw"), dims = "65536,65536,2", limit = "ulimit -v 4000000 && ";
        { std::ofstream f(raw, std::ios::binary); }
        std::filesystem::resize_file(raw, uint64_t(2048) * 2048 * 2048);
    }
    const RunResult r = run_capture(limit + "'" + tool("octiso-convert") + "' '" + raw + "' --dims " + dims +
                                        " --type u8 -o '" + dir.file("out.oct") + "'", err);
    expect_refused(r, raw, fs.mounted() ? "256 TiB sparse file" : "ulimit -v 4 GB");
    EXPECT_NE(r.err.find("out of memory"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("out.oct")));
}

}  // namespace
}  // namespace octiso::test
