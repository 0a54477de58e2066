// Running the command-line tools from tests as a user would: exit code and everything printed.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace shrefract::test {

struct CommandResult {
    int code;
    std::string out;  // stdout and stderr together
};

// A path under the test binary's scratch folder SHREFRACT_TEST_TMP.
inline std::string tmp(const std::string& name) {
    return std::string(SHREFRACT_TEST_TMP) + "/" + name;
}

// Runs a shell command line; its output goes to a log named after the current test (ctest runs
// the cases as parallel processes).
inline CommandResult run(const std::string& args) {
    std::filesystem::create_directories(SHREFRACT_TEST_TMP);
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "." + info->name();
    std::replace(name.begin(), name.end(), '/', '_');
    const std::string log = tmp("log_" + name + ".txt");
    const int status = std::system((args + " > " + log + " 2>&1").c_str());
    std::ifstream f(log);
    std::stringstream ss;
    ss << f.rdbuf();
    return CommandResult{WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
}

// Where the file system refuses unnamed files, a tool stages `target` as the named temporary
// TARGET.shrefract-tmp.PID.N (common/output.h): none may be left once the tool has exited.
inline void expectNoStagedFileLeft(const std::string& target) {
    const std::string prefix = target + ".shrefract-tmp.";
    for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(target).parent_path()))
        EXPECT_NE(e.path().string().rfind(prefix, 0), 0u) << "left behind: " << e.path();
}

inline void writeText(const std::string& path, const std::string& text) {
    std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    std::ofstream(path) << text;
}

}  // namespace shrefract::test
