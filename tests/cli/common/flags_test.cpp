// cli::Flags (src/cli/common/flags.h), CLI11 underneath: values by long name or alias, "=" form,
// negative numbers as values and positionals, repeated switches, and every usage error as
// Error(FLAG, problem) with exit status 2 naming the flag as the tools' messages always did.
#include <gtest/gtest.h>

#include "cli/common/flags.h"
#include "octiso/error.h"

namespace octiso::cli {
namespace {

Flags parse(std::vector<std::string> argv) {
    return Flags(argv, {"-o,--output", "--origin", "--threads"}, {"--json", "-h,--help"});
}

void expect_error(std::vector<std::string> argv, const std::string& subject, const std::string& problem) {
    try {
        parse(std::move(argv));
        ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.exit_status(), 2);
        EXPECT_EQ(e.subject(), subject);
        EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
    }
}

TEST(Flags, ValuesSwitchesAndPositionals) {
    const Flags f = parse({"in.raw", "-o", "out.oct", "--origin", "-3,4.5,7", "--threads=-1", "--json", "--json", "-5"});
    EXPECT_EQ(f.value("--output"), "out.oct");
    EXPECT_EQ(f.value("-o"), "out.oct");
    EXPECT_EQ(f.value("--origin"), "-3,4.5,7");
    EXPECT_EQ(f.value("--threads"), "-1");
    EXPECT_TRUE(f.flag("--json"));
    EXPECT_FALSE(f.flag("--help"));
    EXPECT_EQ(f.positional(), (std::vector<std::string>{"in.raw", "-5"}));
    EXPECT_EQ(f.given(), (std::vector<std::string>{"--output", "--origin", "--threads"}));
}

TEST(Flags, UsageErrorsNameTheFlag) {
    expect_error({"a", "--bogus"}, "--bogus", "unknown flag");
    expect_error({"a", "--origin"}, "--origin", "needs a value");
    expect_error({"a", "--origin", "1", "--origin", "2"}, "--origin", "given more than once");
    expect_error({"a", "-o", "x", "--output", "y"}, "--output", "given more than once");
    expect_error({"a", "-o"}, "-o", "needs a value");   // named as written, not by its long form
    expect_error({"a", "--output"}, "--output", "needs a value");
}

TEST(Flags, ShortAliasWithEqualsSign) {
    EXPECT_EQ(parse({"a", "-o=out.oct"}).value("--output"), "out.oct");
}

TEST(Flags, ListFlagsTakeOneValueEachInOrder) {
    const Flags f({"in.oct", "--clip", "1,0,0,5", "mid", "--clip=-1,0,0,3", "--clip", "-1,2,3,4", "--iso", "-.5"},
                  FlagSpec{{"--iso"}, {"--clip", "--colour"}, {}});
    EXPECT_EQ(f.values("--clip"), (std::vector<std::string>{"1,0,0,5", "-1,0,0,3", "-1,2,3,4"}));
    EXPECT_TRUE(f.values("--colour").empty());
    EXPECT_EQ(f.value("--iso"), "-.5");
    EXPECT_EQ(f.positional(), (std::vector<std::string>{"in.oct", "mid"}));
    EXPECT_EQ(f.given(), (std::vector<std::string>{"--iso", "--clip"}));
}

TEST(AnswerHelp, HelpWinsAndNoArgumentsIsAUsageError) {
    EXPECT_EQ(answer_help({"x", "--bogus", "-h"}, ""), 0);
    EXPECT_EQ(answer_help({"x", "--help"}, ""), 0);
    EXPECT_EQ(answer_help({}, ""), 2);
    EXPECT_EQ(answer_help({"x", "--json"}, ""), std::nullopt);
}

}  // namespace
}  // namespace octiso::cli
