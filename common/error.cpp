#include "common/error.h"

#include <cstdio>
#include <cstdlib>

namespace shrefract::detail {

void checkFailed(const char* what, const char* file, int line, const std::string& values) {
    std::fprintf(stderr, "shrefract: CHECK failed at %s:%d: %s %s\n", file, line, what,
                 values.c_str());
    std::abort();
}

}  // namespace shrefract::detail
