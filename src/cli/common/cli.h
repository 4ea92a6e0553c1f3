// What every octiso command-line tool shares: turning exceptions into one stderr line and the
// exit status of CONVENTIONS 3, and the parsers for the value forms the contract uses (X,Y,Z
// vectors, WxH sizes, A:B step ranges). The tools parse flags with cli::Flags (flags.h, CLI11);
// the small hand-written cli::Args here is left to octiso-bench's subcommands.
#pragma once

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "octiso/step_pattern.h"

namespace octiso::cli {

/// Runs body(args without argv[0]); prints "TOOL: SUBJECT: PROBLEM" for an octiso::Error and
/// returns its exit status (2 bad input/usage, 1 other); any other exception gives 1. With
/// --version among the arguments it prints "TOOL VERSION" on stdout and returns 0 instead.
int run_main(const char* tool, int argc, char** argv, const std::function<int(std::vector<std::string>&)>& body);

/// octiso-bench's flag reader. Flags are "--name value" or "--name=value"; everything not
/// starting with "--" (or "-o") is positional. Unknown flags are an error at finish().
class Args {
public:
    explicit Args(std::vector<std::string> argv);
    /// Value of --name (or the short alias, e.g. "-o"); throws if given without a value.
    std::optional<std::string> value(std::string_view name, std::string_view alias = {});
    /// Every value of a repeatable flag, in order.
    std::vector<std::string> values(std::string_view name);
    bool flag(std::string_view name);   ///< a boolean switch such as --json
    std::vector<std::string> positional();
    /// Throws Error(flag, "unknown flag") for anything not consumed by the calls above.
    void finish();

private:
    std::vector<std::string> argv_;
    std::vector<bool> used_;
};

double parse_double(std::string_view text, const std::string& flag);
long long parse_int(std::string_view text, const std::string& flag, long long lo, long long hi);
std::array<double, 3> parse_vec3(std::string_view text, const std::string& flag);    ///< X,Y,Z
std::array<double, 2> parse_range(std::string_view text, const std::string& flag);   ///< LO,HI with LO < HI
std::array<int, 2> parse_size(std::string_view text, const std::string& flag);       ///< WxH
std::array<long long, 2> parse_steps(std::string_view text, const std::string& flag); ///< A:B inclusive
std::vector<double> parse_list(std::string_view text, const std::string& flag);      ///< V1,V2,...

/// Series names (frame_%04d.png): the library's expansion, octiso/step_pattern.h.
using octiso::format_step;

}  // namespace octiso::cli
