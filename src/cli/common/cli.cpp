#include "cli/common/cli.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <exception>
#include <iostream>

#include "octiso/error.h"
#include "octiso/version.h"

namespace octiso::cli {

int run_main(const char* tool, int argc, char** argv, const std::function<int(std::vector<std::string>&)>& body) {
    std::vector<std::string> args(argv + 1, argv + argc);
    // --version anywhere wins over everything else, as in the GNU tools.
    for (const std::string& a : args)
        if (a == "--version") {
            std::cout << tool << " " << OCTISO_VERSION_STRING << "\n";
            return 0;
        }
    try {
        return body(args);
    } catch (const Error& e) {
        std::cerr << tool << ": " << e.what() << "\n";
        return e.exit_status();
    } catch (const std::bad_alloc&) {
        std::cerr << tool << ": out of memory\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << tool << ": " << e.what() << "\n";
        return 1;
    }
}

Args::Args(std::vector<std::string> argv) : argv_(std::move(argv)), used_(argv_.size(), false) {}

namespace {
bool is_flag(const std::string& a) { return a.size() > 1 && a[0] == '-' && !(a.size() > 1 && (std::isdigit(static_cast<unsigned char>(a[1])) || a[1] == '.')); }
}  // namespace

std::vector<std::string> Args::values(std::string_view name) {
    std::vector<std::string> out;
    const std::string eq = std::string(name) + "=";
    for (size_t i = 0; i < argv_.size(); ++i) {
        if (used_[i]) continue;
        if (argv_[i] == name) {
            if (i + 1 >= argv_.size()) throw Error(std::string(name), "needs a value");
            used_[i] = used_[i + 1] = true;
            out.push_back(argv_[i + 1]);
            ++i;
        } else if (argv_[i].rfind(eq, 0) == 0) {
            used_[i] = true;
            out.push_back(argv_[i].substr(eq.size()));
        }
    }
    return out;
}

std::optional<std::string> Args::value(std::string_view name, std::string_view alias) {
    std::vector<std::string> v = values(name);
    if (!alias.empty()) {
        std::vector<std::string> w = values(alias);
        v.insert(v.end(), w.begin(), w.end());
    }
    if (v.size() > 1) throw Error(std::string(name), "given more than once");
    if (v.empty()) return std::nullopt;
    return v[0];
}

bool Args::flag(std::string_view name) {
    bool found = false;
    for (size_t i = 0; i < argv_.size(); ++i)
        if (!used_[i] && argv_[i] == name) used_[i] = found = true;
    return found;
}

std::vector<std::string> Args::positional() {
    std::vector<std::string> out;
    for (size_t i = 0; i < argv_.size(); ++i)
        if (!used_[i] && !is_flag(argv_[i])) {
            used_[i] = true;
            out.push_back(argv_[i]);
        }
    return out;
}

void Args::finish() {
    for (size_t i = 0; i < argv_.size(); ++i)
        if (!used_[i]) throw Error(argv_[i], is_flag(argv_[i]) ? "unknown flag" : "unexpected argument");
}

double parse_double(std::string_view text, const std::string& flag) {
    double v = 0;
    auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || p != text.data() + text.size() || !std::isfinite(v))
        throw Error(flag, "expected a finite number, found '" + std::string(text) + "'");
    return v;
}

long long parse_int(std::string_view text, const std::string& flag, long long lo, long long hi) {
    long long v = 0;
    auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || p != text.data() + text.size() || v < lo || v > hi)
        throw Error(flag, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                              "], found '" + std::string(text) + "'");
    return v;
}

std::vector<double> parse_list(std::string_view text, const std::string& flag) {
    std::vector<double> out;
    size_t start = 0;
    for (;;) {
        const size_t comma = text.find(',', start);
        out.push_back(parse_double(text.substr(start, comma == std::string_view::npos ? text.npos : comma - start), flag));
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    return out;
}

std::array<double, 3> parse_vec3(std::string_view text, const std::string& flag) {
    const std::vector<double> v = parse_list(text, flag);
    if (v.size() != 3) throw Error(flag, "expected X,Y,Z, found '" + std::string(text) + "'");
    return {v[0], v[1], v[2]};
}

std::array<double, 2> parse_range(std::string_view text, const std::string& flag) {
    const std::vector<double> v = parse_list(text, flag);
    if (v.size() != 2 || !(v[0] < v[1])) throw Error(flag, "expected LO,HI with LO < HI, found '" + std::string(text) + "'");
    return {v[0], v[1]};
}

std::array<int, 2> parse_size(std::string_view text, const std::string& flag) {
    const size_t x = text.find('x');
    if (x == std::string_view::npos) throw Error(flag, "expected WxH, found '" + std::string(text) + "'");
    return {int(parse_int(text.substr(0, x), flag, 1, 1 << 15)), int(parse_int(text.substr(x + 1), flag, 1, 1 << 15))};
}

std::array<long long, 2> parse_steps(std::string_view text, const std::string& flag) {
    const size_t colon = text.find(':');
    if (colon == std::string_view::npos) {
        const long long k = parse_int(text, flag, 0, 1LL << 31);
        return {k, k};
    }
    const long long a = parse_int(text.substr(0, colon), flag, 0, 1LL << 31);
    const long long b = parse_int(text.substr(colon + 1), flag, 0, 1LL << 31);
    if (b < a) throw Error(flag, "expected A:B with A <= B, found '" + std::string(text) + "'");
    return {a, b};
}

}  // namespace octiso::cli
