// Flags (flags.h): CLI11's App with every option declared, extras collected instead of thrown,
// and its ParseError text turned into Error(FLAG, problem).
#include "cli/common/flags.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>

#include "octiso/error.h"

namespace octiso::cli {

namespace {

/// "-o,--output" -> "--output" (the long name), else the name itself.
std::string long_name(const std::string& names) {
    const size_t comma = names.find(',');
    return comma == std::string::npos ? names : names.substr(comma + 1);
}

bool looks_like_flag(const std::string& a) {
    return a.size() > 1 && a[0] == '-' && !(std::isdigit(static_cast<unsigned char>(a[1])) || a[1] == '.');
}

/// The names of the flag whose long name is `flag` (or just `flag`), from the declarations.
std::vector<std::string> names_of(const std::string& flag, const FlagSpec& spec) {
    for (const auto* kind : {&spec.values, &spec.lists, &spec.switches})
        for (const std::string& names : *kind)
            if (long_name(names) == flag) return {names.substr(0, names.find(',')), flag};
    return {flag};
}

/// CLI11's "--origin: 1 required TEXT missing" / "--origin: At Most 1 required but received 2"
/// as the flag and our words for the problem. A missing value is named as the user wrote the
/// flag ("-o: needs a value"; CLI11 names the long form).
Error error_from(const CLI::ParseError& e, const std::vector<std::string>& argv, const FlagSpec& spec) {
    const std::string text = e.what();
    const size_t colon = text.find(": ");
    const std::string flag = colon != std::string::npos && text[0] == '-' ? text.substr(0, colon) : std::string("arguments");
    const std::string problem = colon != std::string::npos && text[0] == '-' ? text.substr(colon + 2) : text;
    if (problem.find("required") != std::string::npos && problem.find("missing") != std::string::npos) {
        const std::vector<std::string> names = names_of(flag, spec);
        const auto last = std::find_first_of(argv.rbegin(), argv.rend(), names.begin(), names.end());
        return Error(last != argv.rend() ? *last : flag, "needs a value");
    }
    if (problem.find("At Most") != std::string::npos) return Error(flag, "given more than once");
    return Error(flag, problem);
}

}  // namespace

std::optional<int> answer_help(const std::vector<std::string>& argv, std::string_view usage) {
    for (const std::string& a : argv)
        if (a == "--help" || a == "-h") {
            std::cout << usage;
            return 0;
        }
    if (argv.empty()) {
        std::cerr << usage;
        return 2;
    }
    return std::nullopt;
}

Flags::Flags(const std::vector<std::string>& argv, const FlagSpec& spec) {
    CLI::App app;
    app.set_help_flag();       // the tools print their own usage text
    app.allow_extras();        // unknown flags are named below, in our words
    auto add_slot = [&](const std::string& names) {
        slots_.push_back(std::make_unique<Slot>());
        Slot* s = slots_.back().get();
        s->name = long_name(names);
        size_t start = 0;
        for (;;) {
            const size_t comma = names.find(',', start);
            by_name_[names.substr(start, comma == std::string::npos ? std::string::npos : comma - start)] = s;
            if (comma == std::string::npos) break;
            start = comma + 1;
        }
        return s;
    };
    for (const std::string& names : spec.values) app.add_option(names, add_slot(names)->value);
    // One value per use (CLI11 would otherwise let a list flag swallow the positionals after it).
    for (const std::string& names : spec.lists) app.add_option(names, add_slot(names)->values)->allow_extra_args(false);
    for (const std::string& names : spec.switches)
        app.add_flag(names, add_slot(names)->on)->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    app.add_option("positional", positional_);

    // CLI11 parses a reversed vector of the arguments (its documented form for parse(vector)).
    // "-o=x" is "-o x" (as "--output=x" is): CLI11 alone would read the value "=x".
    std::vector<std::string> reversed;
    for (auto a = argv.rbegin(); a != argv.rend(); ++a) {
        const bool short_with_value = a->size() > 2 && (*a)[0] == '-' && (*a)[1] != '-' && (*a)[2] == '=' && by_name_.count(a->substr(0, 2));
        if (short_with_value) reversed.insert(reversed.end(), {a->substr(3), a->substr(0, 2)});
        else reversed.push_back(*a);
    }
    try {
        app.parse(reversed);
    } catch (const CLI::ParseError& e) {
        throw error_from(e, argv, spec);
    }
    for (const std::string& extra : app.remaining())
        throw Error(extra, looks_like_flag(extra) ? "unknown flag" : "unexpected argument");
}

Flags::~Flags() = default;

const Flags::Slot& Flags::slot(std::string_view name) const {
    const auto it = by_name_.find(name);
    if (it == by_name_.end()) throw Error(std::string(name), "flag read but never declared", ErrorKind::Other);
    return *it->second;
}

std::optional<std::string> Flags::value(std::string_view name) const { return slot(name).value; }
const std::vector<std::string>& Flags::values(std::string_view name) const { return slot(name).values; }
bool Flags::flag(std::string_view name) const { return slot(name).on; }

std::vector<std::string> Flags::given() const {
    std::vector<std::string> out;
    for (const auto& s : slots_)
        if (s->value || !s->values.empty()) out.push_back(s->name);
    return out;
}

}  // namespace octiso::cli
