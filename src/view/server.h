// ViewServer: octiso-view's HTTP face (cpp-httplib). Exactly three routes, all GET:
//   /       the page (web/viewer.html, compiled into the binary; no file is ever read for a request)
//   /info   ViewSession::info_json()
//   /frame  ?iso=&az=&el=&zoom=&w=&h=&step=&seq=&enc=  (request.h) -> image/png (enc=png, the
//           default) or raw RGBA rows as application/octet-stream (enc=rgba; X-Octiso-Size WxH),
//           or 204 with X-Octiso-Superseded: 1 when a newer frame request arrived while this one waited
// Anything else is 404; a malformed /frame is 400 with a one-line text reason; a render error
// (an isovalue outside the file's iso-range) 422; over the request-rate bound 429. Requests are
// bounded in size by cpp-httplib (URI, headers) and here (no bodies). Frame statistics (render,
// encode, wait behind another render, whole handler, in seconds) and the reproducing command
// ride in X-Octiso-* headers (percent-encoded where they carry text).
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "view/session.h"

namespace octiso::view {

struct ServerOptions {
    std::string host = "127.0.0.1";
    int port = 8080;                    ///< 0: any free port (bound_port() tells which)
    double rate_capacity = 240;         ///< request-rate bound: burst ...
    double rate_per_second = 120;       ///< ... and sustained (a drag sends one request per mouse move)
};

class ViewServer {
public:
    /// Binds host:port (throws Error("--port", ...) / ("--host", ...) if it cannot).
    ViewServer(ViewSession& session, const ServerOptions& options);
    ~ViewServer();
    int bound_port() const;
    /// Serves until stop() (from another thread or a signal handler's helper thread).
    void serve();
    void stop();

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

/// True for an address that only this machine reaches (127.0.0.0/8, ::1, localhost).
bool is_loopback_host(const std::string& host);

/// Percent-encodes everything but unreserved characters, for header values the page decodes with
/// decodeURIComponent (a file name may hold bytes a header must not).
std::string percent_encode(const std::string& s);

}  // namespace octiso::view
