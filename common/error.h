// Errors, in two channels (docs/design.md#errors): CHECK for bugs, InputError (shrefract/error.h)
// for bad input.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

#include "shrefract/enum_names.h"
#include "shrefract/error.h"

namespace shrefract {

// The parts, streamed one after the other into one string: how messages are built.
template <class... T>
std::string str(const T&... parts) {
    std::ostringstream os;
    (os << ... << parts);
    return os.str();
}

// parseName<E> (shrefract/enum_names.h) for a word read from a file: a wrong word is the file's
// problem, so InputError instead of std::invalid_argument.
template <class E>
E parseInput(std::string_view text) {
    try {
        return parseName<E>(text);
    } catch (const std::invalid_argument& e) {
        throw InputError(e.what());
    }
}

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
