// The tests' one check of a refused input: an InputError whose message starts with the file
// ("PATH: ", shrefract/error.h inputError) and names the problem.
#pragma once

#include <gtest/gtest.h>

#include <initializer_list>
#include <string>

#include "shrefract/error.h"

namespace shrefract::test {

// Expects load(path) to throw an InputError that starts with "PATH: " and contains every fragment;
// returns the message ("" when nothing was thrown).
template <class Load>
std::string expectRefused(Load&& load, const std::string& path,
                          std::initializer_list<std::string> fragments) {
    try {
        load(path);
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
        for (const std::string& f : fragments)
            EXPECT_NE(what.find(f), std::string::npos) << "'" << f << "' not in: " << what;
        return what;
    }
    ADD_FAILURE() << "no InputError for " << path;
    return {};
}

}  // namespace shrefract::test
