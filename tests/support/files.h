// Small file helpers the tests share: a scratch folder per test, whole-file reads and writes,
// listings.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

namespace shrefract::test {

// SHREFRACT_TEST_TMP/GROUP/TEST_NAME, emptied and created.
inline std::filesystem::path scratchFolder(const std::string& group) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const std::filesystem::path dir =
        std::filesystem::path(SHREFRACT_TEST_TMP) / group / info->name();
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

inline std::string readFile(const std::filesystem::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

// `bytes` as the whole of `p` (a plain write, not writeAtomically: tests plant files with it).
inline void writeFile(const std::filesystem::path& p, const std::string& bytes) {
    std::ofstream(p, std::ios::binary) << bytes;
}

// Every name in `dir` (no recursion), sorted.
inline std::set<std::string> listing(const std::filesystem::path& dir) {
    std::set<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        names.insert(e.path().filename().string());
    return names;
}

}  // namespace shrefract::test
