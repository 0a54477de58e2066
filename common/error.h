// Errors, in two channels (STYLE.md): CHECK for bugs, InputError for bad input.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace shrefract {

// Bad input from a user: the message names the file and the problem. Libraries throw it and
// never exit; the command-line tools print it and exit non-zero.
struct InputError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// "FILE: problem" — the one format for every user-facing input error.
inline InputError inputError(const std::string& file, const std::string& problem) {
    return InputError(file + ": " + problem);
}

// The operating system refused a read or write that the input could not have foreseen (disk
// full, permission denied, I/O error): not bad input, so the tools exit 1, not 2. The message
// names the file and gives the OS's reason.
struct IoError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// "FILE: what: strerror(err)" (errno err, as the failing call left it).
IoError ioError(const std::string& file, const std::string& what, int err);

// The user asked to stop (Ctrl-C, SIGTERM): work is abandoned, nothing is written, the tools
// exit 130.
struct Cancelled : std::runtime_error {
    Cancelled() : std::runtime_error("cancelled") {}
};

}  // namespace shrefract

// A broken invariant is a bug in shrefract, not in the input: print both sides and abort.
#define SHREFRACT_CHECK(cond)                                                              \
    do {                                                                                   \
        if (!(cond)) ::shrefract::detail::checkFailed(#cond, __FILE__, __LINE__, "");      \
    } while (0)
#define SHREFRACT_CHECK_EQ(a, b)                                                           \
    do {                                                                                   \
        auto&& va_ = (a);                                                                  \
        auto&& vb_ = (b);                                                                  \
        if (!(va_ == vb_)) {                                                               \
            std::ostringstream os_;                                                        \
            os_ << va_ << " vs " << vb_;                                                   \
            ::shrefract::detail::checkFailed(#a " == " #b, __FILE__, __LINE__, os_.str()); \
        }                                                                                  \
    } while (0)

namespace shrefract::detail {
[[noreturn]] void checkFailed(const char* what, const char* file, int line,
                              const std::string& values);
}
