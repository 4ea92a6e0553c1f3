// Flags: the flag parser of octiso-convert, octiso-info and octiso-view, CLI11 underneath
// (issue 17: a maintained parser instead of the hand-written one; octiso-render keeps cli::Args
// for now, its flags are being extended elsewhere). A tool declares every flag once, CLI11
// parses the command line, and every CLI11 complaint becomes Error(FLAG, problem), so messages
// keep naming the flag and usage errors keep exit status 2 (CONVENTIONS 3). The help texts and
// --version stay the tools' own (the usage texts document every default; run_main answers
// --version before any parsing).
#pragma once

#include <initializer_list>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace octiso::cli {

class Flags {
public:
    /// Declares `values` (flags taking one value, e.g. "--dims"; "-o,--output" adds a short
    /// alias) and `switches` (e.g. "--json", "-h,--help"), then parses `argv` (without the tool
    /// name). Anything that does not start with '-' (or is a negative number) is positional.
    /// Throws Error(FLAG, ...) for an unknown flag, a value flag without its value or one given
    /// twice.
    Flags(const std::vector<std::string>& argv, std::initializer_list<std::string> values,
          std::initializer_list<std::string> switches);
    ~Flags();
    Flags(const Flags&) = delete;
    Flags& operator=(const Flags&) = delete;

    /// The value of a declared value flag, by any of its names; empty when not given.
    std::optional<std::string> value(std::string_view name) const;
    /// Whether a declared switch was given (by any of its names).
    bool flag(std::string_view name) const;
    const std::vector<std::string>& positional() const { return positional_; }
    /// The long names of the value flags given, in declaration order.
    std::vector<std::string> given() const;

private:
    struct Slot {
        std::string name;                  // the long name, as messages say it
        std::optional<std::string> value;  // value flags
        bool on = false;                   // switches
    };
    const Slot& slot(std::string_view name) const;
    std::vector<std::unique_ptr<Slot>> slots_;   // stable addresses: CLI11 writes into them
    std::map<std::string, Slot*, std::less<>> by_name_;
    std::vector<std::string> positional_;
};

}  // namespace octiso::cli
