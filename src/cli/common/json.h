// JsonWriter: the tiny streaming writer behind every --json report (CONVENTIONS 3: exactly one
// JSON object on stdout). It tracks commas and nesting; every string and number is encoded by
// nlohmann-json (RFC 8259 escaping, invalid UTF-8 replaced by U+FFFD instead of passed through,
// the shortest decimal that reads back to the same double), and non-finite numbers are null,
// which JSON cannot express otherwise. Streaming stays ours: reports are written as they are
// computed, and a fragment (a key and its value) can be written on its own.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ostream>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

namespace octiso::cli {

/// Usage: JsonWriter j(std::cout); j.begin_object(); j.key("n").value(3); j.end_object();
/// Keys are only legal directly inside an object, values after a key or inside an array; the
/// writer does not police misuse beyond that, it is for our own reports.
class JsonWriter {
public:
    explicit JsonWriter(std::ostream& out) : out_(out) {}

    JsonWriter& begin_object() { return open('{'); }
    JsonWriter& end_object() { return close('}'); }
    JsonWriter& begin_array() { return open('['); }
    JsonWriter& end_array() { return close(']'); }

    JsonWriter& key(std::string_view k) {
        separate();
        write_string(k);
        out_ << ':';
        after_key_ = true;
        return *this;
    }

    JsonWriter& value(std::string_view s) {
        separate();
        write_string(s);
        return *this;
    }
    JsonWriter& value(const char* s) { return value(std::string_view(s)); }
    JsonWriter& value(const std::string& s) { return value(std::string_view(s)); }
    JsonWriter& value(bool b) {
        separate();
        out_ << (b ? "true" : "false");
        return *this;
    }
    JsonWriter& null() {
        separate();
        out_ << "null";
        return *this;
    }
    /// Integers exactly; floating point as the shortest text that round-trips, NaN/Inf as null.
    template <typename N, std::enable_if_t<std::is_arithmetic_v<N> && !std::is_same_v<N, bool>, int> = 0>
    JsonWriter& value(N v) {
        separate();
        if constexpr (std::is_integral_v<N>) {
            if constexpr (std::is_signed_v<N>) out_ << nlohmann::json(static_cast<long long>(v)).dump();
            else out_ << nlohmann::json(static_cast<unsigned long long>(v)).dump();
        } else {
            // An integral value is written without nlohmann's ".0" ("7", as every report wrote it
            // before; below 2^53 the integer is the double exactly). nlohmann writes NaN, +-inf as null.
            const double d = static_cast<double>(v);
            if (d == std::trunc(d) && std::fabs(d) < 9007199254740992.0 && !(d == 0 && std::signbit(d)))
                out_ << nlohmann::json(static_cast<long long>(d)).dump();
            else
                out_ << nlohmann::json(d).dump();
        }
        return *this;
    }
    /// key(k).value(v) in one call.
    template <typename V> JsonWriter& field(std::string_view k, const V& v) { return key(k).value(v); }
    /// An array of numbers or strings.
    template <typename Seq> JsonWriter& array(const Seq& seq) {
        begin_array();
        for (const auto& v : seq) value(v);
        return end_array();
    }

    /// Escapes `s` as the body of a JSON string (no quotes): ", \, control characters; invalid
    /// UTF-8 becomes U+FFFD.
    static std::string escape(std::string_view s) {
        const std::string quoted = nlohmann::json(std::string(s)).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
        return quoted.substr(1, quoted.size() - 2);
    }

private:
    JsonWriter& open(char c) {
        separate();
        out_ << c;
        first_.push_back(true);
        return *this;
    }
    JsonWriter& close(char c) {
        if (!first_.empty()) first_.pop_back();
        out_ << c;
        return *this;
    }
    void separate() {
        if (after_key_) {   // the value of a key: no comma
            after_key_ = false;
            return;
        }
        if (first_.empty()) return;
        if (!first_.back()) out_ << ',';
        first_.back() = false;
    }
    void write_string(std::string_view s) { out_ << '"' << escape(s) << '"'; }

    std::ostream& out_;
    std::vector<bool> first_;   // per open container: nothing written in it yet
    bool after_key_ = false;
};

}  // namespace octiso::cli
