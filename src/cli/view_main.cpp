// octiso-view: interactive exploration of a .oct file in the browser (issue 20). Opens the file,
// serves the page and its frames on loopback (another host only when asked, with a warning),
// prints the URL and runs until SIGINT/SIGTERM. Routes and bounds: src/view/server.h.
#include <csignal>
#include <cstdio>
#include <iostream>
#include <optional>
#include <pthread.h>
#include <thread>

#include "cli/common/cli.h"
#include "cli/common/flags.h"
#include "octiso/error.h"
#include "view/server.h"
#include "view/session.h"

namespace octiso {
namespace {

const char* kUsage =
    "usage: octiso-view FILE.oct [--port P] [--host H] [--threads N] [--iso V] [--lod F]\n"
    "  serves an interactive viewer of FILE.oct at http://H:P/ (default 127.0.0.1:8080; --port 0 picks a free port);\n"
    "  --iso: the isovalue the page starts at (default: the middle of the data's range); like every value\n"
    "  on the page a real value (a scaled NIfTI's stored * scl_slope + scl_inter, as octiso-render --iso);\n"
    "  --lod F: level of detail of every frame, as octiso-render --lod F (default 0: full resolution)";

int run(std::vector<std::string>& argv) {
    for (const std::string& a : argv)   // --help wins over every other argument
        if (a == "--help" || a == "-h") {
            std::cout << kUsage << "\n";
            return 0;
        }
    const cli::Flags args(argv, {"--port", "--host", "--threads", "--iso", "--lod"}, {});
    const auto port = args.value("--port"), host = args.value("--host"), threads = args.value("--threads");
    const auto iso = args.value("--iso");
    const std::vector<std::string> inputs = args.positional();
    if (inputs.size() != 1) throw Error("octiso-view", std::string("expected exactly one FILE.oct\n") + kUsage);
    view::ServerOptions options;
    if (port) options.port = int(cli::parse_int(*port, "--port", 0, 65535));
    if (host) {
        if (host->empty()) throw Error("--host", "expected an address, found ''");
        options.host = *host;
    }
    const int n_threads = threads ? int(cli::parse_int(*threads, "--threads", 1, 4096)) : 0;
    std::optional<double> initial_iso;
    if (iso) initial_iso = cli::parse_double(*iso, "--iso");
    const auto lod = args.value("--lod");
    const double lod_factor = lod ? cli::parse_double(*lod, "--lod") : 0.0;

    // Signals are taken by one thread with sigwait, so no handler runs inside httplib's workers;
    // blocked before any thread exists, so every thread inherits the mask. A shell starts a
    // background job with SIGINT ignored, and an ignored signal is discarded, never waited for:
    // the default disposition first.
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    sigset_t stop_signals;
    sigemptyset(&stop_signals);
    sigaddset(&stop_signals, SIGINT);
    sigaddset(&stop_signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

    view::ViewSession session(inputs[0], n_threads, initial_iso, lod_factor);
    view::ViewServer server(session, options);
    if (!view::is_loopback_host(options.host))
        std::fprintf(stderr, "octiso-view: warning: listening on %s: every machine that reaches this address can use the "
                             "viewer (it has no authentication); omit --host to stay on loopback\n", options.host.c_str());
    const bool ipv6 = options.host.find(':') != std::string::npos && options.host.front() != '[';
    std::printf("octiso-view: serving %s at http://%s%s%s:%d/\n", inputs[0].c_str(), ipv6 ? "[" : "", options.host.c_str(),
                ipv6 ? "]" : "", server.bound_port());
    std::fflush(stdout);

    std::thread waiter([&] {
        int sig = 0;
        sigwait(&stop_signals, &sig);
        server.stop();
    });
    server.serve();
    // serve() also returns if listening fails; wake the waiter so it can be joined.
    pthread_kill(waiter.native_handle(), SIGTERM);
    waiter.join();
    return 0;
}

}  // namespace
}  // namespace octiso

int main(int argc, char** argv) { return octiso::cli::run_main("octiso-view", argc, argv, octiso::run); }
