// cli::JsonWriter (src/cli/common/json.h), the writer behind every --json report: commas and
// nesting, string escaping (nlohmann-json's), and non-finite numbers as null, finite ones shortest.
#include <cmath>
#include <limits>
#include <sstream>

#include <gtest/gtest.h>

#include "cli/common/json.h"

namespace octiso::cli {
namespace {

TEST(JsonWriter, NestsAndSeparates) {
    std::ostringstream os;
    JsonWriter j(os);
    j.begin_object();
    j.field("a", 1);
    j.key("b").begin_array().value(1u).value(-2).begin_object().end_object().begin_array().end_array().end_array();
    j.key("c").begin_object().field("d", true).field("e", "x").key("f").null().end_object();
    j.field("g", uint64_t(18446744073709551615ull));
    j.end_object();
    EXPECT_EQ(os.str(), R"({"a":1,"b":[1,-2,{},[]],"c":{"d":true,"e":"x","f":null},"g":18446744073709551615})");
}

TEST(JsonWriter, EscapesStrings) {
    EXPECT_EQ(JsonWriter::escape("plain"), "plain");
    EXPECT_EQ(JsonWriter::escape("a\"b\\c"), "a\\\"b\\\\c");
    EXPECT_EQ(JsonWriter::escape("\n\t\r\b\f"), "\\n\\t\\r\\b\\f");
    EXPECT_EQ(JsonWriter::escape(std::string("\x01\x1f\x7f", 3)), "\\u0001\\u001f\x7f");   // DEL needs no escape (RFC 8259)
    EXPECT_EQ(JsonWriter::escape(std::string("nul\0x", 5)), "nul\\u0000x");
    EXPECT_EQ(JsonWriter::escape("\xc3\xa9"), "\xc3\xa9");   // UTF-8 passes through
    EXPECT_EQ(JsonWriter::escape("a\xff" "b"), "a\xef\xbf\xbd" "b");   // invalid UTF-8: U+FFFD, the output stays JSON
    std::ostringstream os;
    JsonWriter(os).key("k\"ey").value("v\nal");
    EXPECT_EQ(os.str(), "\"k\\\"ey\":\"v\\nal\"");
}

TEST(JsonWriter, NonFiniteNumbersAreNullAndFiniteOnesRoundTrip) {
    std::ostringstream os;
    JsonWriter j(os);
    j.begin_array()
        .value(std::numeric_limits<double>::quiet_NaN())
        .value(std::numeric_limits<double>::infinity())
        .value(-std::numeric_limits<float>::infinity())
        .value(0.1)
        .value(-2.5e-300)
        .end_array();
    const std::string s = os.str();
    EXPECT_EQ(s.rfind("[null,null,null,", 0), 0u) << s;
    std::istringstream in(s.substr(16, s.size() - 17));
    double a = 0, b = 0;
    char comma = 0;
    in >> a >> comma >> b;
    EXPECT_EQ(a, 0.1);
    EXPECT_EQ(b, -2.5e-300);
    EXPECT_EQ(s.substr(16), "0.1,-2.5e-300]") << "the shortest text that round-trips";
}

TEST(JsonWriter, IntegralDoublesAreWrittenAsIntegers) {
    std::ostringstream os;
    JsonWriter(os).begin_array().value(7.0).value(-1.5).value(-500.0).value(1e300).value(-0.0).end_array();
    EXPECT_EQ(os.str(), "[7,-1.5,-500,1e+300,-0.0]");
}

}  // namespace
}  // namespace octiso::cli
