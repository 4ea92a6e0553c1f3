// Issue 18, classes 3, 7 and 10 end to end: inputs that are not regular files (a FIFO hung
// octiso-info and octiso-render), outputs that are the input (replaced it and exited 0), and
// placements at the extremes (accepted, then blamed on --up/--look). Each is refused with one
// line naming the file, exit 2, and the input left as it was.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cfloat>
#include <cstdint>

#include "hostile/hostile_util.h"
#include "octiso/error.h"
#include "octiso/oct_file.h"
#include "octiso/output_guard.h"
#include "octiso/verify.h"

namespace octiso::test {
namespace {

struct HostileFiles : ::testing::Test {
    ScratchDir dir{"octiso_hostile_files"};
    std::string err = dir.file("err.txt");
    std::string q(const std::string& name) { return "'" + dir.file(name) + "'"; }
    RunResult convert(const std::string& args) { return run_capture("'" + tool("octiso-convert") + "' " + args, err); }
    RunResult info(const std::string& args) { return run_capture("'" + tool("octiso-info") + "' " + args, err); }
    RunResult render(const std::string& args) { return run_capture("'" + tool("octiso-render") + "' " + args, err); }
    void make_oct(const std::string& name) {
        ASSERT_EQ(convert("--synthetic sphere:12 -o " + q(name)).exit_status, 0);
        ASSERT_NO_THROW(verify_octree(OctFile::open(dir.file(name))));
    }
};

// Class 3. Without the fix these block in open(); ctest's timeout would report the hang.
TEST_F(HostileFiles, FifoIsRefusedByEveryToolWithoutBlocking) {
    const std::string fifo = dir.file("pipe.oct");
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    expect_refused(info(q("pipe.oct")), fifo, "octiso-info");
    expect_refused(render(q("pipe.oct") + " --iso 50 -o " + q("a.png")), fifo, "octiso-render");
    expect_refused(convert(q("pipe.oct") + " --dims 2,2,2 --type u8 -o " + q("b.oct")), fifo, "octiso-convert raw");
    const std::string fifo_nrrd = dir.file("pipe.nrrd");
    ASSERT_EQ(::mkfifo(fifo_nrrd.c_str(), 0600), 0);
    expect_refused(convert(q("pipe.nrrd") + " -o " + q("c.oct")), fifo_nrrd, "octiso-convert NRRD");
    EXPECT_FALSE(std::filesystem::exists(dir.file("a.png")));
    EXPECT_FALSE(std::filesystem::exists(dir.file("b.oct")));
    EXPECT_TRUE(temporaries(dir.path()).empty());
}

TEST_F(HostileFiles, DevicesAndDirectoriesAreRefused) {
    expect_refused(info("/dev/zero"), "/dev/zero", "character device");
    expect_refused(info("/dev/null"), "/dev/null", "empty device");
    expect_refused(render("/dev/zero --iso 1 -o " + q("a.png")), "/dev/zero", "render a device");
    expect_refused(info(q("")), dir.path().string(), "a directory");
    expect_refused(convert("/dev/zero --dims 2,2,2 --type u8 -o " + q("b.oct")), "/dev/zero", "convert a device");
}

// Class 7: the output is the input, under its own name, a hard link, or another spelling.
TEST_F(HostileFiles, ConvertRefusesToOverwriteItsInput) {
    const uint8_t v[8] = {0, 10, 20, 30, 40, 50, 60, 70};
    write_bytes(dir.file("in.raw"), v, sizeof v);
    ASSERT_EQ(::link(dir.file("in.raw").c_str(), dir.file("alias.raw").c_str()), 0);
    const std::string before = read_all(dir.file("in.raw"));
    for (const std::string& out : {q("in.raw"), q("alias.raw"), "'" + dir.path().string() + "/./in.raw'"}) {
        SCOPED_TRACE(out);
        const RunResult r = convert(q("in.raw") + " --dims 2,2,2 --type u8 -o " + out);
        expect_refused(r, "in.raw");
        EXPECT_EQ(read_all(dir.file("in.raw")), before);
    }
    // A series whose second step is the output.
    write_bytes(dir.file("s1.raw"), v, sizeof v);
    expect_refused(convert(q("in.raw") + " " + q("s1.raw") + " --dims 2,2,2 --type u8 -o " + q("s1.raw")), "s1.raw", "series");
    EXPECT_EQ(read_all(dir.file("s1.raw")), before);
    EXPECT_TRUE(temporaries(dir.path()).empty());
}

TEST_F(HostileFiles, InfoAndRenderRefuseToOverwriteTheirInput) {
    make_oct("a.oct");
    const std::string before = read_all(dir.file("a.oct"));
    expect_refused(info(q("a.oct") + " --extract-raw " + q("a.oct")), "a.oct", "--extract-raw");
    expect_refused(render(q("a.oct") + " --iso 50 -o " + q("x.png") + " --depth " + q("a.oct")), "a.oct", "--depth");
    ASSERT_EQ(::symlink(dir.file("a.oct").c_str(), dir.file("link.exr").c_str()), 0);
    expect_refused(render(q("a.oct") + " --iso 50 --normal " + q("link.exr")), "link.exr", "--normal through a symlink");
    EXPECT_EQ(read_all(dir.file("a.oct")), before);
    // Library level: the function itself, with a path that does not exist yet (allowed).
    EXPECT_NO_THROW(refuse_output_onto_input(dir.file("new.raw"), {dir.file("a.oct")}));
    EXPECT_THROW(refuse_output_onto_input(dir.file("a.oct"), {dir.file("a.oct")}), Error);
}

// Class 10: placements at the extremes, given on the command line or forged into a header.
TEST_F(HostileFiles, ExtremePlacementIsRefusedAtConversionNamingTheFile) {
    const uint8_t v[8] = {0, 10, 20, 30, 40, 50, 60, 70};
    write_bytes(dir.file("in.raw"), v, sizeof v);
    const char* bad[] = {"--spacing 5e-324,1,1", "--spacing 1e300,1,1", "--spacing 1,1,1e-200",
                         "--origin 1.7976931348623157e308,0,0", "--origin 0,-1e308,0", "--origin 1e16,0,0 --spacing 1e-6,1,1"};
    for (const char* flags : bad) {
        SCOPED_TRACE(flags);
        const RunResult r = convert(q("in.raw") + " --dims 2,2,2 --type u8 -o " + q("out.oct") + " " + flags);
        expect_refused(r, "in.raw");
        EXPECT_FALSE(std::filesystem::exists(dir.file("out.oct")));
    }
    // The same bounds hold for synthetic volumes (refused by the writer, naming the output).
    expect_refused(convert("--synthetic sphere:8 --spacing 1e300,1,1 -o " + q("syn.oct")), "syn.oct", "synthetic");
    // In range: converts, renders.
    ASSERT_EQ(convert(q("in.raw") + " --dims 2,2,2 --type u8 -o " + q("ok.oct") + " --spacing 1e-100,1e-100,1e-100 --origin 1e-90,0,0").exit_status, 0) << read_all(err);
    EXPECT_EQ(render(q("ok.oct") + " --iso 35 --size 16x16 -o " + q("ok.png")).exit_status, 0) << read_all(err);
}

/// Rewrites the placement fields of a .oct header and fixes its checksum, as an attacker would.
void forge_placement(const std::string& path, const std::array<double, 3>& spacing, const std::array<double, 3>& origin);

TEST_F(HostileFiles, ExtremePlacementIsRefusedAtLoadNamingTheFile) {
    make_oct("a.oct");
    const std::array<std::array<double, 6>, 5> forged = {{{5e-324, 1, 1, 0, 0, 0},
                                                          {1e300, 1, 1, 0, 0, 0},
                                                          {1, 1, 1, DBL_MAX, 0, 0},
                                                          {1, 1, 1, 0, -1e200, 0},
                                                          {1e-9, 1, 1, 1e12, 0, 0}}};
    for (const auto& f : forged) {
        SCOPED_TRACE(f[0]);
        std::filesystem::copy_file(dir.file("a.oct"), dir.file("f.oct"), std::filesystem::copy_options::overwrite_existing);
        forge_placement(dir.file("f.oct"), {f[0], f[1], f[2]}, {f[3], f[4], f[5]});
        EXPECT_THROW(OctFile::open(dir.file("f.oct")), Error);
        expect_refused(render(q("f.oct") + " --iso 50 -o " + q("f.png")), "f.oct", "render");
        expect_refused(info(q("f.oct")), "f.oct", "info");
        EXPECT_FALSE(std::filesystem::exists(dir.file("f.png")));
    }
}

}  // namespace
}  // namespace octiso::test

#include "format/oct_layout.h"

namespace octiso::test {
namespace {
void forge_placement(const std::string& path, const std::array<double, 3>& spacing, const std::array<double, 3>& origin) {
    std::string bytes = read_all(path);
    format::FileHeader h;
    std::memcpy(&h, bytes.data(), sizeof h);
    for (int a = 0; a < 3; ++a) h.spacing[a] = spacing[size_t(a)], h.origin[a] = origin[size_t(a)];
    h.header_checksum = format::checksum(&h, format::kHeaderChecksummedBytes);
    std::memcpy(bytes.data(), &h, sizeof h);
    write_bytes(path, bytes.data(), bytes.size());
}
}  // namespace
}  // namespace octiso::test
