// run_shell: runs a shell command line (the CLI tests call the built tools this way), returns its
// exit status (-1 if it did not exit normally) and, if asked, what it wrote to stdout. The caller
// decides about stderr with the redirections in the command line.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace octiso::test {

inline int run_shell(const std::string& command, std::string* out = nullptr) {
    std::FILE* p = ::popen(command.c_str(), "r");
    if (!p) return -1;
    std::string text;
    char buf[4096];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) text.append(buf, n);
    const int status = ::pclose(p);
    if (out) *out = std::move(text);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace octiso::test
