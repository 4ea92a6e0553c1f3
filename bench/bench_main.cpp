// octiso-bench SUBCOMMAND [flags]: scaling and comparison benchmarks, one file per question.
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <unistd.h>
#include <sstream>
#include <thread>

#include "bench/bench.h"
#include "octiso/error.h"

#ifndef OCTISO_SOURCE_DIR
#define OCTISO_SOURCE_DIR "."
#endif

namespace octiso::bench {

namespace {
struct Entry {
    std::string summary;
    BenchFn run;
};
std::map<std::string, Entry>& registry() {
    static std::map<std::string, Entry> r;
    return r;
}
}  // namespace

bool register_bench(const char* name, const char* summary, BenchFn run) {
    registry()[name] = Entry{summary, run};
    return true;
}

void Table::print(std::ostream& out) const {
    std::vector<size_t> w(header_.size(), 0);
    for (size_t c = 0; c < header_.size(); ++c) w[c] = header_[c].size();
    for (const auto& r : rows_)
        for (size_t c = 0; c < r.size() && c < w.size(); ++c) w[c] = std::max(w[c], r[c].size());
    auto line = [&](const std::vector<std::string>& r) {
        for (size_t c = 0; c < w.size(); ++c) out << (c ? "  " : "") << std::setw(int(w[c])) << (c < r.size() ? r[c] : "");
        out << "\n";
    };
    line(header_);
    size_t total = 0;
    for (size_t c : w) total += c + 2;
    out << std::string(total > 2 ? total - 2 : 0, '-') << "\n";
    for (const auto& r : rows_) line(r);
}

void Table::print_markdown(std::ostream& out) const {
    out << "|";
    for (const auto& h : header_) out << " " << h << " |";
    out << "\n|";
    for (size_t c = 0; c < header_.size(); ++c) out << "---|";
    out << "\n";
    for (const auto& r : rows_) {
        out << "|";
        for (const auto& cell : r) out << " " << cell << " |";
        out << "\n";
    }
}

std::string fmt(double v, int precision) {
    std::ostringstream s;
    const double a = std::fabs(v);
    if (v != 0 && (a < 1e-3 || a >= 1e7)) s << std::scientific << std::setprecision(2) << v;
    else s << std::fixed << std::setprecision(precision) << v;
    return s.str();
}

std::string results_dir(cli::Args& args) {
    // Never into the source tree unless asked (`--results bench/results`): by default a folder
    // under the system temp dir, named in the "results:" line each subcommand prints.
    const auto dir = args.value("--results");
    const std::string d = dir ? *dir : (std::filesystem::temp_directory_path() / "octiso-bench-results").string();
    std::error_code ec;
    std::filesystem::create_directories(d, ec);
    if (ec) throw Error(d, "cannot create the results folder: " + ec.message(), ErrorKind::Other);
    return d;
}

std::string write_json(const std::string& dir, const std::string& name, const std::function<void(cli::JsonWriter&)>& fill) {
    const std::string path = dir + "/" + name + ".json";
    std::ofstream out(path);
    if (!out) throw Error(path, "cannot write", ErrorKind::Other);
    // Filled in memory first: a benchmark whose fill forgets its outer object (four did, until
    // their JSON was found unparsable) fails here instead of writing a file no tool can read.
    std::ostringstream text;
    cli::JsonWriter j(text);
    fill(j);
    const std::string s = text.str();
    if (s.empty() || s.front() != '{' || s.back() != '}')
        throw Error(path, "the benchmark's JSON is not one object (a bug in its fill)", ErrorKind::Other);
    out << s << "\n";
    return path;
}

bool plot(const std::string& kind, const std::string& json_path, const std::string& png_path) {
    const std::string cmd = "/usr/bin/python3 '" + std::string(OCTISO_SOURCE_DIR) + "/bench/plot.py' '" + kind + "' '" +
                            json_path + "' '" + png_path + "'";
    const int rc = std::system(cmd.c_str());
    if (rc != 0) std::cerr << "octiso-bench: plotting failed (" << cmd << ")\n";
    else std::cerr << "plot: " << png_path << "\n";
    return rc == 0;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double median_seconds(int repeats, const std::function<void()>& fn) {
    fn();
    std::vector<double> t;
    for (int i = 0; i < std::max(repeats, 1); ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        fn();
        t.push_back(seconds_since(t0));
    }
    std::sort(t.begin(), t.end());
    return t[t.size() / 2];
}

double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double default_isovalue(const std::string& dataset) {
    if (dataset == "plume") return 40.5;
    if (dataset == "mixing") return 127.5;
    if (dataset == "sphere") return 20.5;
    return 80.5;
}

std::string machine_description() {
    std::ifstream cpu("/proc/cpuinfo");
    std::string line, model = "unknown CPU";
    while (std::getline(cpu, line))
        if (line.rfind("model name", 0) == 0) {
            model = line.substr(line.find(':') + 2);
            break;
        }
    return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " hardware threads, g++ " + __VERSION__;
}

}  // namespace octiso::bench

int main(int argc, char** argv) {
    using namespace octiso;
    return cli::run_main("octiso-bench", argc, argv, [](std::vector<std::string>& argv) {
        auto& reg = bench::registry();
        if (argv.empty() || argv[0] == "--help" || argv[0] == "-h" || !reg.count(argv[0])) {
            std::ostream& out = argv.empty() || argv[0].rfind("-", 0) == 0 ? std::cout : std::cerr;
            out << "usage: octiso-bench SUBCOMMAND [flags]   (--results DIR: where JSON and plots go; default $TMPDIR/octiso-bench-results, never the source tree)\n";
            for (const auto& [name, e] : reg) out << "  " << name << std::string(name.size() < 14 ? 14 - name.size() : 1, ' ') << e.summary << "\n";
            if (!argv.empty() && argv[0].rfind("-", 0) != 0) throw Error(argv[0], "unknown subcommand");
            return 0;
        }
        const std::string name = argv[0];
        cli::Args args(std::vector<std::string>(argv.begin() + 1, argv.end()));
        return reg.at(name).run(args);
    });
}
