// view/request.h: parse_frame_request accepts exactly the queries the page sends and refuses
// everything else with an Error naming the parameter (the server's 400 reply).
#include <gtest/gtest.h>

#include <string>
#include <vector>

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
    EXPECT_FALSE(r.shadows);
    EXPECT_EQ(r.ao_samples, 0);
}

TEST(ViewRequest, ShadowsAreZeroOrOneAndAoIsBounded) {
    EXPECT_TRUE(parse_frame_request(with(base(), "shadows", "1"), 1).shadows);
    EXPECT_FALSE(parse_frame_request(with(base(), "shadows", "0"), 1).shadows);
    for (const std::string bad : {"", "true", "on", "yes", "01", "2", "-1", "1 ", " 1", "1.0", "+1"})
        EXPECT_EQ(refusal(with(base(), "shadows", bad)), "shadows") << "'" << bad << "'";
    EXPECT_EQ(parse_frame_request(with(base(), "ao", "8"), 1).ao_samples, 8);
    EXPECT_EQ(parse_frame_request(with(base(), "ao", "0"), 1).ao_samples, 0);
    EXPECT_EQ(parse_frame_request(with(base(), "ao", std::to_string(kMaxViewAoSamples)), 1).ao_samples, kMaxViewAoSamples);
    const std::vector<std::string> bad_ao = {"", "-1", std::to_string(kMaxViewAoSamples + 1), "256", "8.0", "1e1", "+8", " 8", "8 ",
                                             "0x8", "99999999999999999999"};
    for (const std::string& bad : bad_ao)
        EXPECT_EQ(refusal(with(base(), "ao", bad)), "ao") << "'" << bad << "'";
    QueryParameters twice = with(base(), "shadows", "1");
    twice.emplace_back("shadows", "1");
    EXPECT_EQ(refusal(twice), "shadows");
    QueryParameters ao_twice = with(base(), "ao", "8");
    ao_twice.emplace_back("ao", "0");
    EXPECT_EQ(refusal(ao_twice), "ao");
    // Every parameter the page can send, at once, stays within the parameter bound.
    QueryParameters all = base();
    for (const auto& [n, v] : QueryParameters{{"zoom", "2"}, {"step", "0"}, {"seq", "3"}, {"enc", "rgba"}, {"shadows", "1"}, {"ao", "8"}})
        all.emplace_back(n, v);
    const FrameRequest r = parse_frame_request(all, 1);
    EXPECT_TRUE(r.shadows);
    EXPECT_EQ(r.ao_samples, 8);
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
    EXPECT_EQ(refusal(base(), 0), "step");   // no step asked for: the default 0 is not a step either
}

}  // namespace
}  // namespace octiso::view
