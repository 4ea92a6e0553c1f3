// Flags: the flag parser of every octiso tool, CLI11 underneath (issue 17: a maintained parser
// instead of the hand-written cli::Args, which only octiso-bench still uses). A tool declares
// every flag once (a FlagSpec; octiso-render's camera and look modules add their own), CLI11
// parses the command line, and every CLI11 complaint becomes Error(FLAG, problem), so messages
// keep naming the flag and usage errors keep exit status 2 (CONVENTIONS 3). The help texts and
// --version stay the tools' own (the usage texts document every default; run_main answers
// --version before any parsing, answer_help --help and the empty command line).
#pragma once

#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace octiso::cli {

/// --help or -h anywhere: `usage` on stdout and 0 (help wins over every other argument, as
/// --version does in run_main); no argument at all: `usage` on stderr and 2 (a usage error, the
/// same in every tool); otherwise nothing printed and no value.
std::optional<int> answer_help(const std::vector<std::string>& argv, std::string_view usage);

/// The flags a tool declares, by kind. A name is "--dims", or "-o,--output" for a short alias.
struct FlagSpec {
    std::vector<std::string> values;     ///< one value, at most once
    std::vector<std::string> lists;      ///< one value per use, repeatable ("--colour a --colour b")
    std::vector<std::string> switches;   ///< no value ("--json")
};

class Flags {
public:
    /// Declares the flags of `spec`, then parses `argv` (without the tool name). Anything that
    /// does not start with '-' (or is a negative number) is positional. Throws Error(FLAG, ...)
    /// for an unknown flag, a flag without its value or a value flag given twice.
    Flags(const std::vector<std::string>& argv, const FlagSpec& spec);
    Flags(const std::vector<std::string>& argv, std::initializer_list<std::string> values,
          std::initializer_list<std::string> switches)
        : Flags(argv, FlagSpec{values, {}, switches}) {}
    ~Flags();
    Flags(const Flags&) = delete;
    Flags& operator=(const Flags&) = delete;

    /// The value of a declared value flag, by any of its names; empty when not given.
    std::optional<std::string> value(std::string_view name) const;
    /// Every value of a declared list flag, in command-line order.
    const std::vector<std::string>& values(std::string_view name) const;
    /// Whether a declared switch was given (by any of its names).
    bool flag(std::string_view name) const;
    const std::vector<std::string>& positional() const { return positional_; }
    /// The long names of the value and list flags given, in declaration order.
    std::vector<std::string> given() const;

private:
    struct Slot {
        std::string name;                  // the long name, as messages say it
        std::optional<std::string> value;  // value flags
        std::vector<std::string> values;   // list flags
        bool on = false;                   // switches
    };
    const Slot& slot(std::string_view name) const;
    std::vector<std::unique_ptr<Slot>> slots_;   // stable addresses: CLI11 writes into them
    std::map<std::string, Slot*, std::less<>> by_name_;
    std::vector<std::string> positional_;
};

}  // namespace octiso::cli
