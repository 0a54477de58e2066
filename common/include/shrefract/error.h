// The errors shrefract's libraries throw, installed with the runtime so that an app can catch
// them by type: InputError for bad input (a file's name and its problem), IoError for what the
// operating system refused, Cancelled for work the user stopped. Bugs are not exceptions: they
// abort through SHREFRACT_CHECK (common/error.h).
#pragma once

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
