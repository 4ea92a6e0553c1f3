// Issue 17 made the NIfTI reader follow more of the header (quaternion, qoffset, srow signs,
// scl_slope/scl_inter), so those fields get the hostile treatment of issue 18: NaN, infinities,
// values at the ends of float and quaternions that are not unit length must each give one line
// naming the file and exit 2, or a placement that passes the placement limits; never a crash,
// never an output file, never a temporary left, in memory and streamed alike.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "hostile/hostile_util.h"
#include "io/nifti_test_file.h"

namespace octiso::test {
namespace {

struct HostileNiftiAffine : ::testing::Test {
    ScratchDir dir{"octiso_hostile_affine"};
    std::string err = dir.file("err.txt");

    /// 0: converted; else the run's result was a refusal as CONVENTIONS 3 wants it.
    int convert(const Nifti1& n, const std::string& what, const std::string& flags) {
        const std::string in = dir.file("h.nii");
        write_text(in, n.bytes(std::string(4 * 4 * 4 * 2, '\x01')));
        const RunResult r = run_capture("'" + tool("octiso-convert") + "' '" + in + "' -o '" + dir.file("out.oct") + "' " + flags, err);
        SCOPED_TRACE(what + " " + flags);
        EXPECT_EQ(r.signal, 0) << r.err;
        if (r.exit_status == 0) {
            // Whatever was accepted must load and render: the placement passed its limits.
            const RunResult i = run_capture("'" + tool("octiso-info") + "' '" + dir.file("out.oct") + "'", err);
            EXPECT_EQ(i.exit_status, 0) << i.err;
            std::filesystem::remove(dir.file("out.oct"));
        } else {
            expect_refused(r, in, what);
            EXPECT_FALSE(std::filesystem::exists(dir.file("out.oct")));
        }
        EXPECT_TRUE(temporaries(dir.path()).empty());
        return r.exit_status;
    }
};

TEST_F(HostileNiftiAffine, EveryBadFieldIsRefusedOrPlacedWithinTheLimits) {
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const float big = std::numeric_limits<float>::max(), tiny = std::numeric_limits<float>::denorm_min();
    std::vector<std::pair<std::string, std::function<void(Nifti1&)>>> cases = {
        {"srow NaN diagonal", [&](Nifti1& n) { n.set_srow({nan, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}); }},
        {"srow NaN off the diagonal", [&](Nifti1& n) { n.set_srow({1, nan, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}); }},
        {"srow inf translation", [&](Nifti1& n) { n.set_srow({1, 0, 0, inf, 0, 1, 0, 0, 0, 0, 1, 0}); }},
        {"srow NaN translation of a flipped axis", [&](Nifti1& n) { n.set_srow({-1, 0, 0, nan, 0, 1, 0, 0, 0, 0, 1, 0}); }},
        {"srow largest float", [&](Nifti1& n) { n.set_srow({big, 0, 0, big, 0, 1, 0, 0, 0, 0, 1, 0}); }},
        {"srow flipped largest float", [&](Nifti1& n) { n.set_srow({-big, 0, 0, -big, 0, 1, 0, 0, 0, 0, 1, 0}); }},
        {"srow denormal spacing", [&](Nifti1& n) { n.set_srow({tiny, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}); }},
        {"srow zero diagonal", [&](Nifti1& n) { n.set_srow({0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0}); }},
        {"srow all zero", [&](Nifti1& n) { n.set_srow({0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}); }},
        {"quaternion NaN", [&](Nifti1& n) { n.qform_code = 1, n.quatern[0] = nan; }},
        {"quaternion longer than 1", [&](Nifti1& n) { n.qform_code = 1, n.quatern[0] = 2, n.quatern[1] = -3; }},
        {"quaternion inf", [&](Nifti1& n) { n.qform_code = 1, n.quatern[2] = inf; }},
        {"qoffset inf", [&](Nifti1& n) { n.qform_code = 1, n.qoffset[1] = -inf; }},
        {"qform pixdim NaN", [&](Nifti1& n) { n.qform_code = 1, n.pixdim[2] = nan; }},
        {"qform pixdim zero, qfac -1", [&](Nifti1& n) { n.qform_code = 1, n.pixdim[0] = -1, n.pixdim[3] = 0; }},
        {"no transform, pixdim zero", [&](Nifti1& n) { n.pixdim[1] = 0; }},
        {"no transform, pixdim inf", [&](Nifti1& n) { n.pixdim[2] = inf; }},
        {"oblique with pixdim NaN", [&](Nifti1& n) { n.set_srow({0.6f, 0.8f, 0, 0, -0.8f, 0.6f, 0, 0, 0, 0, 1, 0}), n.pixdim[1] = nan; }},
        {"negative sform_code", [&](Nifti1& n) { n.sform_code = -5, n.srow[0] = nan; }},
        {"scl_slope inf (no scaling)", [&](Nifti1& n) { n.slope = inf, n.inter = nan; }},
        {"scl_inter NaN", [&](Nifti1& n) { n.slope = 2, n.inter = nan; }},
        {"scl_slope largest float", [&](Nifti1& n) { n.slope = big, n.inter = big; }},
        {"scl_slope denormal", [&](Nifti1& n) { n.slope = tiny; }},
    };
    for (const auto& [what, edit] : cases) {
        Nifti1 n;
        n.dim[1] = n.dim[2] = n.dim[3] = 4;
        edit(n);
        const int plain = convert(n, what, "");
        const int streamed = convert(n, what, "--memory 64M");
        EXPECT_EQ(plain, streamed) << what << ": the two paths disagree";
        // Real-valued flags through an extreme scale: refused or exact, never a NaN range.
        convert(n, what, "--iso-range 0,1");
    }
}

}  // namespace
}  // namespace octiso::test
