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

// The tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1) as an OFF file, its faces turned outward: the
// smallest closed mesh the tools accept.
inline constexpr const char* kTetraOff =
    "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

// Every name in `dir` (no recursion), sorted.
inline std::set<std::string> listing(const std::filesystem::path& dir) {
    std::set<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        names.insert(e.path().filename().string());
    return names;
}

}  // namespace shrefract::test
