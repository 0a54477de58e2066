// OutputSet (common/output.h): targets checked before the work, staged files invisible until all
// are complete, refused targets left exactly as they were, the OS's reason in every error.
#include "common/output.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "common/error.h"
#include "support/files.h"

namespace shrefract {
namespace {

namespace fs = std::filesystem;

fs::path scratch() { return test::scratchFolder("output"); }
using test::listing;
using test::readFile;

// Expects `f` to throw E whose message contains every fragment.
template <class E, class F>
void expectThrows(F f, std::initializer_list<std::string> fragments) {
    try {
        f();
        FAIL() << "did not throw";
    } catch (const E& e) {
        for (const std::string& s : fragments)
            EXPECT_NE(std::string(e.what()).find(s), std::string::npos) << e.what();
    }
}

TEST(Output, StagedFilesAppearOnlyOnCommitAllTogether) {
    const fs::path dir = scratch();
    std::ofstream(dir / "b.txt") << "previous b";
    {
        OutputSet outputs;
        const std::string a = outputs.add((dir / "a.txt").string());
        const std::string b = outputs.add((dir / "b.txt").string());
        EXPECT_TRUE(isStagedOutput(a));
        EXPECT_EQ(outputName(a), (dir / "a.txt").string());
        writeFile(a, "new a");
        writeFile(b, "new b");
        // Written but not committed: nothing new under any name in the folder.
        EXPECT_EQ(listing(dir), std::set<std::string>{"b.txt"});
        EXPECT_EQ(readFile(dir / "b.txt"), "previous b");
        outputs.commit();
        EXPECT_FALSE(isStagedOutput(a));
    }
    EXPECT_EQ(readFile(dir / "a.txt"), "new a");
    EXPECT_EQ(readFile(dir / "b.txt"), "new b");
    EXPECT_EQ(listing(dir), (std::set<std::string>{"a.txt", "b.txt"}));
    // New files get the usual permissions (0666 less the umask), not a temporary file's 0600.
    struct stat st;
    ASSERT_EQ(::stat((dir / "a.txt").c_str(), &st), 0);
    const mode_t mask = ::umask(0);
    ::umask(mask);
    EXPECT_EQ(st.st_mode & 0777, 0666 & ~mask);
}

TEST(Output, WithoutCommitNothingChanges) {
    const fs::path dir = scratch();
    std::ofstream(dir / "a.txt") << "previous";
    try {
        OutputSet outputs;
        writeFile(outputs.add((dir / "a.txt").string()), "half of it");
        writeFile(outputs.add((dir / "b.txt").string()), "all of it");
        throw std::runtime_error("the work failed");
    } catch (const std::runtime_error&) {
    }
    EXPECT_EQ(readFile(dir / "a.txt"), "previous");
    EXPECT_EQ(listing(dir), std::set<std::string>{"a.txt"});
}

TEST(Output, RefusesLinksPipesDevicesFoldersAndMissingFolders) {
    const fs::path dir = scratch();
    std::ofstream(dir / "real.txt") << "pointed at";
    fs::create_symlink("real.txt", dir / "link.txt");
    fs::create_symlink("nowhere.txt", dir / "dangling.txt");
    ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0644), 0);
    fs::create_directory(dir / "folder");
    OutputSet outputs;
    const std::pair<std::string, std::string> cases[] = {
        {"link.txt", "exists and is a symbolic link"}, {"dangling.txt", "exists and is a symbolic link"},
        {"fifo", "exists and is a FIFO"}, {"folder", "exists and is a folder"},
        {"missing/x.txt", "folder " + (dir / "missing").string() + " does not exist"},
        {"real.txt/x", "is not a folder"}};
    for (const auto& [name, what] : cases) {
        SCOPED_TRACE(name);
        const std::string path = (dir / name).string();
        expectThrows<InputError>([&] { outputs.add(path); }, {path + ": ", what});
    }
    // A device node of our own (as root; /dev/null itself may have been clobbered on a shared
    // machine by a tool that does not check, the very bug this refuses to repeat).
    if (::mknod((dir / "null").c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0)
        expectThrows<InputError>([&] { outputs.add((dir / "null").string()); },
                                 {(dir / "null").string() + ": exists and is a device"});
    expectThrows<InputError>([&] { outputs.add(""); }, {"empty"});
    outputs.add((dir / "new.txt").string());
    expectThrows<InputError>([&] { outputs.add((dir / "." / "new.txt").string()); },
                             {"is named twice"});
    EXPECT_TRUE(fs::is_symlink(dir / "link.txt"));
    EXPECT_EQ(readFile(dir / "real.txt"), "pointed at");
    struct stat st;
    ASSERT_EQ(::lstat((dir / "fifo").c_str(), &st), 0);
    EXPECT_TRUE(S_ISFIFO(st.st_mode));
}

// A writer's error names the user's path, never /proc/self/fd/N, and carries the OS's reason.
TEST(Output, ErrorsNameTheTargetAndTheReason) {
    const fs::path dir = scratch();
    OutputSet outputs;
    const std::string staged = outputs.add((dir / "a.exr").string());
    const IoError e = outputError(staged, "cannot open \"" + staged + "\": No space left on device");
    EXPECT_EQ(std::string(e.what()), (dir / "a.exr").string() + ": cannot write: cannot open \"" +
                                         (dir / "a.exr").string() + "\": No space left on device");
    // (The OS's reason from a real failure, a full disk: Faults.FullDiskMidWriteLeavesThePreviousFile.)
}

// A temporary left by a process killed outright (the named fallback where O_TMPFILE is missing)
// is removed by the next add() for the same target once that process is gone.
TEST(Output, StaleTemporariesOfDeadProcessesAreRemoved) {
    const fs::path dir = scratch();
    const pid_t child = ::fork();
    if (child == 0) _exit(0);
    ::waitpid(child, nullptr, 0);  // its pid is now free
    const std::string stale = "out.txt.shrefract-tmp." + std::to_string(child) + ".0";
    const std::string mine = "out.txt.shrefract-tmp." + std::to_string(::getpid()) + ".99";
    std::ofstream(dir / stale) << "left by a killed run";
    std::ofstream(dir / mine) << "this process's own";
    std::ofstream(dir / "other.txt.shrefract-tmp.1.0") << "another target's";
    OutputSet outputs;
    outputs.add((dir / "out.txt").string());
    EXPECT_FALSE(fs::exists(dir / stale));
    EXPECT_TRUE(fs::exists(dir / mine));
    EXPECT_TRUE(fs::exists(dir / "other.txt.shrefract-tmp.1.0"));
}

}  // namespace
}  // namespace shrefract
