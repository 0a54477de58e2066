#include "common/error.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace shrefract {

IoError ioError(const std::string& file, const std::string& what, int err) {
    return IoError(file + ": " + what + ": " + (err != 0 ? std::strerror(err) : "unknown error"));
}

}  // namespace shrefract

namespace shrefract::detail {

void checkFailed(const char* what, const char* file, int line, const std::string& values) {
    std::fprintf(stderr, "shrefract: CHECK failed at %s:%d: %s %s\n", file, line, what,
                 values.c_str());
    std::abort();
}

}  // namespace shrefract::detail
