// Helpers of the issue-17 CLI suites: run a built tool capturing stdout and stderr, write a small
// raw volume, and read one number or array out of a --json report (our own reports only: the key
// is found as "KEY": and the value parsed after it).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "test_util/run_shell.h"
#include "test_util/scratch_dir.h"

namespace octiso::test {

struct ToolRun {
    int status = -1;
    std::string out, err;
    /// Lines on stderr.
    long err_lines() const { return long(std::count(err.begin(), err.end(), '\n')); }
};

/// Runs a built tool with `args` (shell words); `env` (e.g. "NAME=value") is set for it alone.
inline ToolRun run_tool(const std::string& tool, const std::string& args, const std::string& env = "") {
    ScratchDir err_dir("octiso_cli_err");
    const std::string err_file = err_dir.file("stderr");
    ToolRun r;
    const std::string prefix = env.empty() ? "" : "env " + env + " ";
    r.status = run_shell(prefix + "'" + std::string(OCTISO_TOOLS_DIR) + "/" + tool + "' " + args + " 2>'" + err_file + "'", &r.out);
    run_shell("cat '" + err_file + "'", &r.err);
    return r;
}

/// What `ldd` lists for `program` (its shared libraries, transitively); empty if ldd fails.
inline std::string shared_libraries_of(const std::string& program) {
    std::string deps;
    return run_shell("ldd '" + program + "'", &deps) == 0 ? deps : std::string();
}

template <typename T> void write_raw(const std::string& path, const std::vector<T>& values) {
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(values.data()), std::streamsize(values.size() * sizeof(T)));
}

/// The number after the first "KEY": in `json`; NaN if the key is missing.
inline double json_number(const std::string& json, const std::string& key) {
    const size_t at = json.find("\"" + key + "\":");
    if (at == std::string::npos) return std::nan("");
    return std::strtod(json.c_str() + at + key.size() + 3, nullptr);
}

/// The numbers of the array after the first "KEY": in `json` (empty if missing or not an array).
inline std::vector<double> json_numbers(const std::string& json, const std::string& key) {
    std::vector<double> out;
    size_t at = json.find("\"" + key + "\":[");
    if (at == std::string::npos) return out;
    const char* p = json.c_str() + at + key.size() + 4;
    while (*p && *p != ']') {
        char* end = nullptr;
        out.push_back(std::strtod(p, &end));
        if (end == p) break;
        p = end;
        if (*p == ',') ++p;
    }
    return out;
}

}  // namespace octiso::test
