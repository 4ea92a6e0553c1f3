// Error: the one exception type that leaves the octiso library. It names the file (or the flag)
// and the problem, and says whether the input was bad (exit 2) or something else failed (exit 1).
// Only the *_main.cpp front ends turn it into a stderr line and an exit status (CONVENTIONS 3).
#pragma once

#include <stdexcept>
#include <string>

namespace octiso {

enum class ErrorKind { BadInput, Other };

class Error : public std::runtime_error {
public:
    Error(std::string subject, std::string problem, ErrorKind kind = ErrorKind::BadInput)
        : std::runtime_error(subject.empty() ? problem : subject + ": " + problem),
          subject_(std::move(subject)), problem_(std::move(problem)), kind_(kind) {}

    const std::string& subject() const { return subject_; }   ///< file name or flag
    const std::string& problem() const { return problem_; }
    ErrorKind kind() const { return kind_; }
    int exit_status() const { return kind_ == ErrorKind::BadInput ? 2 : 1; }

private:
    std::string subject_, problem_;
    ErrorKind kind_;
};

}  // namespace octiso
