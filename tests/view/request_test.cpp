// view/request.h: parse_frame_request accepts exactly the queries the page sends and refuses
// everything else with an Error naming the parameter (the server's 400 reply).
#include <gtest/gtest.h>

#include <string>

#include "octiso/error.h"
#include "view/request.h"

namespace octiso::view {
namespace {

QueryParameters base() { return {{"iso", "12.5"}, {"az", "-55.25"}, {"el", "26.5"}, {"w", "640"}, {"h", "480"}}; }

/// The subject of the Error parse_frame_request throws for `q`, or "" if it throws none.
std::string refusal(const QueryParameters& q, uint32_t steps = 1) {
    try {
        parse_frame_request(q, steps);
    } catch (const Error& e) {
        return e.subject();
    }
    return "";
}

QueryParameters with(QueryParameters q, const std::string& name, const std::string& value) {
    for (auto& [n, v] : q)
        if (n == name) { v = value; return q; }
    q.emplace_back(name, value);
    return q;
}

TEST(ViewRequest, ParsesTheRequiredParametersAndDefaultsTheRest) {
    const FrameRequest r = parse_frame_request(base(), 1);
    EXPECT_EQ(r.iso, 12.5);
    EXPECT_EQ(r.azimuth_deg, -55.25);
    EXPECT_EQ(r.elevation_deg, 26.5);
    EXPECT_EQ(r.width, 640);
    EXPECT_EQ(r.height, 480);
    EXPECT_EQ(r.zoom, 1.0);
    EXPECT_EQ(r.step, 0u);
    EXPECT_EQ(r.seq, 0u);
    EXPECT_EQ(r.encoding, FrameEncoding::png);
}

TEST(ViewRequest, EncodingIsPngOrRgba) {
    EXPECT_EQ(parse_frame_request(with(base(), "enc", "png"), 1).encoding, FrameEncoding::png);
    EXPECT_EQ(parse_frame_request(with(base(), "enc", "rgba"), 1).encoding, FrameEncoding::rgba);
    for (const std::string bad : {"", "PNG", "rgb", "jpeg", "rgba ", "raw"})
        EXPECT_EQ(refusal(with(base(), "enc", bad)), "enc") << "'" << bad << "'";
    QueryParameters twice = with(base(), "enc", "rgba");
    twice.emplace_back("enc", "png");
    EXPECT_EQ(refusal(twice), "enc");
}

TEST(ViewRequest, ParsesOptionalParameters) {
    QueryParameters q = base();
    q.emplace_back("zoom", "2.5");
    q.emplace_back("step", "3");
    q.emplace_back("seq", "18446744073709551615");
    const FrameRequest r = parse_frame_request(q, 4);
    EXPECT_EQ(r.zoom, 2.5);
    EXPECT_EQ(r.step, 3u);
    EXPECT_EQ(r.seq, UINT64_MAX);
}

TEST(ViewRequest, NumbersReadBackExactly) {
    // The page sends what the slider holds; the command line must carry the same double.
    const FrameRequest r = parse_frame_request(with(base(), "iso", "0.1"), 1);
    EXPECT_EQ(r.iso, 0.1);
    EXPECT_EQ(parse_frame_request(with(base(), "az", "1e-300"), 1).azimuth_deg, 1e-300);
}

TEST(ViewRequest, MissingRequiredParameterIsNamed) {
    for (const std::string name : {"iso", "az", "el", "w", "h"}) {
        QueryParameters q;
        for (const auto& p : base())
            if (p.first != name) q.push_back(p);
        EXPECT_EQ(refusal(q), name);
    }
}

TEST(ViewRequest, RepeatedAndUnknownParametersAreRefused) {
    QueryParameters q = base();
    q.emplace_back("w", "10");
    EXPECT_EQ(refusal(q), "w");
    EXPECT_EQ(refusal(with(base(), "path", "/etc/passwd")), "path");
    EXPECT_EQ(refusal(with(base(), std::string(1000, 'x'), "1")), std::string(64, 'x') + "...");
    QueryParameters many = base();
    for (int i = 0; i < 20; ++i) many.emplace_back("seq", "1");
    EXPECT_EQ(refusal(many), "query");
}

TEST(ViewRequest, MalformedNumbersAreRefused) {
    for (const std::string bad : {"", " 1", "1 ", "+1", "0x10", "1e999", "inf", "-inf", "nan", "1,5", "1..2", "--1", "1e"})
        EXPECT_EQ(refusal(with(base(), "iso", bad)), "iso") << "'" << bad << "'";
    for (const std::string bad : {"1.5", "-1", "0", "4097", "1e3", "", "99999999999999999999"})
        EXPECT_EQ(refusal(with(base(), "w", bad)), "w") << "'" << bad << "'";
    for (const std::string bad : {"-1", "1.0", "18446744073709551616", ""})
        EXPECT_EQ(refusal(with(base(), "seq", bad)), "seq") << "'" << bad << "'";
    EXPECT_EQ(refusal(with(base(), "iso", std::string(65, '1'))), "iso");
}

TEST(ViewRequest, BoundsAreEnforced) {
    EXPECT_EQ(refusal(with(base(), "el", "89.5")), "el");
    EXPECT_EQ(refusal(with(base(), "el", "-90")), "el");
    EXPECT_EQ(refusal(with(base(), "el", "89")), "");
    EXPECT_EQ(refusal(with(base(), "zoom", "0")), "zoom");
    EXPECT_EQ(refusal(with(base(), "zoom", "50.5")), "zoom");
    EXPECT_EQ(refusal(with(with(base(), "w", "4096"), "h", "1024")), "");
    EXPECT_EQ(refusal(with(with(base(), "w", "4096"), "h", "1025")), "w");   // over kMaxImagePixels
    EXPECT_EQ(refusal(with(base(), "h", "4097")), "h");
    EXPECT_EQ(refusal(with(base(), "step", "1"), 1), "step");
    EXPECT_EQ(refusal(with(base(), "step", "4"), 4), "step");
    EXPECT_EQ(refusal(with(base(), "step", "0"), 0), "step");
}

}  // namespace
}  // namespace octiso::view
