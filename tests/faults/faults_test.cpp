// Faults (ctest label "faults", docs/testing.md "Fault tests"): the tools killed, interrupted, out
// of disk, in a read-only folder, and given a symbolic link, FIFO or device node as their output.
// After each: no partial output, no stray temporary file, the previous output intact, and the
// next run succeeds. The disk and read-only cases mount a small tmpfs, which needs root (CI runs
// as root); elsewhere they are skipped with a message.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "common/bakefile.h"
#include "support/files.h"

extern char** environ;

namespace shrefract {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

const std::string kBake = SHREFRACT_BAKE_EXE, kRender = SHREFRACT_RENDER_EXE,
                  kEval = SHREFRACT_EVAL_EXE, kData = SHREFRACT_DATA_DIR;

// A scratch folder per test, emptied first.
fs::path scratch() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    ::umount2((fs::path(SHREFRACT_TEST_TMP) / "faults" / info->name() / "mnt").c_str(),
              MNT_DETACH);  // a mount a crashed run left
    return test::scratchFolder("faults");
}

using test::listing;
using test::readFile;
using test::writeFile;

struct Child {
    pid_t pid = -1;
    fs::path log;
};

// Starts argv[0] with argv, stdout and stderr into `log`.
Child spawn(const std::vector<std::string>& args, const fs::path& log) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    Child c;
    c.log = log;
    const int rc = posix_spawn(&c.pid, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    EXPECT_EQ(rc, 0) << "cannot start " << args[0];
    return c;
}

// Waits for the child; returns its exit code, or 128 + the signal that ended it.
int finish(const Child& c) {
    int status = 0;
    while (::waitpid(c.pid, &status, 0) < 0 && errno == EINTR) {
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

int runTool(const std::vector<std::string>& args, const fs::path& log) {
    return finish(spawn(args, log));
}

// A bake that takes a fraction of a second here: the icosphere (642 vertices) at rate 1, order 6
// on a 16 x 32 grid: 642 samples x 512 directions, a 0.33 MB file.
std::vector<std::string> bakeArgs(const fs::path& out, const fs::path& cache) {
    return {kBake, kData + "/scenes/icosphere.off", "-o", out.string(), "--rate", "1", "--order",
            "6", "--grid", "16x32", "--threads", "1", "-q", "--cache", cache.string()};
}

// The previous output a failed run must leave as it was: a real bake, made once per test.
std::string makePrevious(const fs::path& path, const fs::path& work) {
    const std::vector<std::string> args = {kBake, kData + "/scenes/icosphere.off", "-o",
                                           path.string(), "--rate", "1", "--order", "2",
                                           "--grid", "8x16", "-q", "--cache", ""};
    EXPECT_EQ(runTool(args, work / "previous.log"), 0) << readFile(work / "previous.log");
    return readFile(path);
}

// Mounts a tmpfs of `bytes` at `dir` (read-only with `readOnly`) for the scope; skips the test
// when that is not allowed (not root).
class TmpfsMount {
public:
    TmpfsMount(const fs::path& dir, size_t bytes) : dir_(dir) {
        fs::create_directories(dir);
        const std::string options = "size=" + std::to_string(bytes) + ",mode=0755";
        mounted_ = ::mount("tmpfs", dir.c_str(), "tmpfs", 0, options.c_str()) == 0;
        error_ = errno;
    }
    ~TmpfsMount() {
        if (mounted_) ::umount2(dir_.c_str(), MNT_DETACH);
    }
    bool mounted() const { return mounted_; }
    std::string why() const { return std::strerror(error_); }
    bool resize(size_t bytes) {
        const std::string options = "size=" + std::to_string(bytes);
        return ::mount("tmpfs", dir_.c_str(), "tmpfs", MS_REMOUNT, options.c_str()) == 0;
    }
    bool remountReadOnly() {
        return ::mount("tmpfs", dir_.c_str(), "tmpfs", MS_REMOUNT | MS_RDONLY, nullptr) == 0;
    }

private:
    fs::path dir_;
    bool mounted_ = false;
    int error_ = 0;
};

#define REQUIRE_MOUNT(m)                                                                      \
    if (!(m).mounted())                                                                       \
    GTEST_SKIP() << "cannot mount a tmpfs (" << (m).why()                                     \
                 << "): the full-disk and read-only cases need root; CI runs them as root"

// SIGKILL at 20 seeded moments of a bake, spread over its whole run (a third of them in its last
// fifth, where it writes): each time the previous file is intact, the output folder and the
// matrix cache hold nothing new, and the next run succeeds.
TEST(Faults, SigkillAtRandomMomentsLeavesNothing) {
    const fs::path dir = scratch(), out = dir / "out" / "bake.shrefract.exr", cache = dir / "cache";
    fs::create_directories(out.parent_path());
    fs::create_directories(cache);
    const std::string previous = makePrevious(out, dir);
    const std::set<std::string> names = listing(out.parent_path());

    // How long an undisturbed bake takes here (into another folder, with a cold cache).
    const fs::path timed = dir / "timed.shrefract.exr";
    auto t0 = Clock::now();
    ASSERT_EQ(runTool(bakeArgs(timed, dir / "cold-cache"), dir / "timed.log"), 0)
        << readFile(dir / "timed.log");
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    std::printf("[ faults   ] an undisturbed bake takes %.2f s\n", seconds);

    std::mt19937 rng(9);
    int killedBeforeExit = 0, completed = 0;
    for (int trial = 0; trial < 20; ++trial) {
        std::uniform_real_distribution<double> early(0.0, seconds), late(0.8 * seconds, 1.1 * seconds);
        const double at = trial % 3 == 2 ? late(rng) : early(rng);
        // A cold cache in every third run, so that kills land in the matrix cache's write too.
        if (trial % 3 == 0) fs::remove_all(cache), fs::create_directories(cache);
        const Child c = spawn(bakeArgs(out, cache), dir / "kill.log");
        std::this_thread::sleep_for(std::chrono::duration<double>(at));
        ::kill(c.pid, SIGKILL);
        const int code = finish(c);
        killedBeforeExit += code == 128 + SIGKILL;
        SCOPED_TRACE("trial " + std::to_string(trial) + ", killed after " + std::to_string(at) + " s");
        // The file is the previous one, byte for byte, or a complete new bake: never a part. A
        // new one is legitimate only when the bake got as far as its commit (it exited 0, or the
        // kill, late on a loaded machine, landed after the rename, during the exit).
        EXPECT_TRUE(code == 0 || code == 128 + SIGKILL) << readFile(dir / "kill.log");
        if (readFile(out) != previous) {
            ++completed;
            EXPECT_NO_THROW(readBake(out.string()));  // verified: every checksum right
            writeFile(out, previous);
        }
        EXPECT_EQ(listing(out.parent_path()), names);
        for (const std::string& name : listing(cache))
            EXPECT_EQ(name.find("tmp"), std::string::npos) << "stray temporary " << name;
    }
    std::printf("[ faults   ] %d of 20 runs killed, %d wrote a complete new bake first\n",
                killedBeforeExit, completed);
    EXPECT_GE(killedBeforeExit, 10);             // timing on a shared machine: most, not all
    // Killed during their exit, after the commit: rare. Under ASan the exit runs LeakSanitizer's
    // scan, and a clean-clone CI measured 3 such of 18 kills (5 new bakes, 2 exited 0): margin 1.
    // Kills that all landed after the bake would give about 20.
    EXPECT_LE(completed, 20 - killedBeforeExit + 4);
    // The next run succeeds, with the cache as the kills left it.
    ASSERT_EQ(runTool(bakeArgs(out, cache), dir / "next.log"), 0) << readFile(dir / "next.log");
    EXPECT_NO_THROW(readBake(out.string()));
    EXPECT_EQ(listing(out.parent_path()), names);
}

// SIGTERM and SIGINT stop a bake cleanly: exit 130, "cancelled", nothing written.
TEST(Faults, SigtermAndSigintCancelABake) {
    const fs::path dir = scratch(), out = dir / "out" / "bake.shrefract.exr";
    fs::create_directories(out.parent_path());
    const std::string previous = makePrevious(out, dir);
    const std::set<std::string> names = listing(out.parent_path());
    for (int sig : {SIGTERM, SIGINT}) {
        SCOPED_TRACE(strsignal(sig));
        // A slower bake (rate 3, 32 x 64, ~5 s here) so that the signal lands while it traces,
        // with progress on: its first line comes after the handlers are installed. A fixed delay
        // raced the start on a loaded CI machine: SIGINT arrived before the handler, the default
        // action killed the bake, and the exit status 128 + 2 looked like a clean cancel.
        std::vector<std::string> args = bakeArgs(out, "");
        args[5] = "3", args[9] = "32x64";
        args.erase(std::find(args.begin(), args.end(), "-q"));
        const Child c = spawn(args, dir / "signal.log");
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
        while (readFile(dir / "signal.log").find("bake:") == std::string::npos &&
               std::chrono::steady_clock::now() < deadline)
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        ::kill(c.pid, sig);
        EXPECT_EQ(finish(c), 130) << readFile(dir / "signal.log");
        EXPECT_NE(readFile(dir / "signal.log").find("cancelled"), std::string::npos);
        EXPECT_EQ(readFile(out), previous);
        EXPECT_EQ(listing(out.parent_path()), names);
    }
    ASSERT_EQ(runTool(bakeArgs(out, ""), dir / "next.log"), 0) << readFile(dir / "next.log");
    EXPECT_NO_THROW(readBake(out.string()));
}

// A disk that fills while the bake writes: exit 1 naming the file and the OS's reason, the
// previous file intact, no temporary; the next run, with room, succeeds.
TEST(Faults, FullDiskMidWriteLeavesThePreviousFile) {
    const fs::path dir = scratch(), mnt = dir / "mnt", out = mnt / "bake.shrefract.exr";
    // Room for the previous bake (~110 kB) and part of the new one (~330 kB).
    TmpfsMount disk(mnt, 256 * 1024);
    REQUIRE_MOUNT(disk);
    const std::string previous = makePrevious(out, dir);
    const std::set<std::string> names = listing(mnt);
    EXPECT_EQ(runTool(bakeArgs(out, ""), dir / "full.log"), 1) << readFile(dir / "full.log");
    const std::string log = readFile(dir / "full.log");
    EXPECT_NE(log.find(out.string()), std::string::npos) << log;
    EXPECT_NE(log.find("No space left on device"), std::string::npos) << log;
    EXPECT_EQ(readFile(out), previous);
    EXPECT_EQ(listing(mnt), names);
    // The next run, once there is room, succeeds.
    ASSERT_TRUE(disk.resize(16 << 20)) << std::strerror(errno);
    ASSERT_EQ(runTool(bakeArgs(out, ""), dir / "next.log"), 0) << readFile(dir / "next.log");
    EXPECT_NO_THROW(readBake(out.string()));
}

// All or nothing across outputs: shrefract-render with --out in a folder with room and --out-exr
// on a full disk writes neither, and keeps both previous files.
TEST(Faults, FullDiskForOneOutputWritesNone) {
    const fs::path dir = scratch(), mnt = dir / "mnt";
    TmpfsMount disk(mnt, 8 * 1024);
    REQUIRE_MOUNT(disk);
    const fs::path bake = dir / "ico.shrefract.exr", png = dir / "good.png", exr = mnt / "big.exr";
    makePrevious(bake, dir);
    writeFile(png, "previous png");
    writeFile(exr, "previous exr");
    const int code = runTool({kRender, bake.string(), "--env", kData + "/envmaps/studio.exr",
                              "--size", "96x96", "--frames", "1", "--out", png.string(),
                              "--out-exr", exr.string()},
                             dir / "render.log");
    const std::string log = readFile(dir / "render.log");
    EXPECT_EQ(code, 1) << log;
    EXPECT_NE(log.find("No space left on device"), std::string::npos) << log;
    EXPECT_EQ(readFile(png), "previous png");
    EXPECT_EQ(readFile(exr), "previous exr");
    EXPECT_EQ(listing(mnt), std::set<std::string>{"big.exr"});
    EXPECT_EQ(listing(dir).count("good.png"), 1u);
    for (const std::string& name : listing(dir))
        EXPECT_EQ(name.find("tmp"), std::string::npos) << "stray temporary " << name;
}

// A read-only folder is refused before the work starts (no progress, no tracing), with the OS's
// reason; the file already there stays.
TEST(Faults, ReadOnlyFolderFailsBeforeTheWork) {
    const fs::path dir = scratch(), mnt = dir / "mnt", out = mnt / "bake.shrefract.exr";
    TmpfsMount disk(mnt, 1 << 20);
    REQUIRE_MOUNT(disk);
    const std::string previous = makePrevious(out, dir);
    ASSERT_TRUE(disk.remountReadOnly()) << std::strerror(errno);
    std::vector<std::string> args = bakeArgs(out, "");
    args.pop_back(), args.pop_back(), args.pop_back();  // progress on: it must not start
    args.push_back("--cache"), args.push_back("");
    EXPECT_EQ(runTool(args, dir / "ro.log"), 1) << readFile(dir / "ro.log");
    const std::string log = readFile(dir / "ro.log");
    EXPECT_NE(log.find("Read-only file system"), std::string::npos) << log;
    EXPECT_EQ(log.find("Mrays/s"), std::string::npos) << "the bake started:\n" << log;
    EXPECT_EQ(readFile(out), previous);
    EXPECT_EQ(listing(mnt), std::set<std::string>{"bake.shrefract.exr"});
}

// A symbolic link, FIFO or device node where an output should go is refused (exit 2, named)
// before any work, by every tool and for every output, and is left exactly as it was.
TEST(Faults, SymlinkFifoAndDeviceTargetsAreNeverReplaced) {
    const fs::path dir = scratch();
    const fs::path bake = dir / "ico.shrefract.exr", env = kData + "/envmaps/studio.exr";
    const std::string previous = makePrevious(bake, dir);
    writeFile(dir / "pointee.png", "the file the link points to");
    writeFile(dir / "q.csv", "0.0,0.0,1.0,0,0,1\n");
    fs::create_symlink("pointee.png", dir / "link.png");
    ASSERT_EQ(::mkfifo((dir / "fifo.png").c_str(), 0644), 0);
    const bool device = ::mknod((dir / "null.png").c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0;
    if (!device) std::printf("[ faults   ] cannot make a device node (not root): that case skipped\n");
    std::vector<fs::path> targets = {dir / "link.png", dir / "fifo.png"};
    if (device) targets.push_back(dir / "null.png");

    for (const fs::path& t : targets) {
        const std::string name = t.string();
        const std::vector<std::vector<std::string>> runs = {
            bakeArgs(t, ""),
            {kRender, bake.string(), "--env", env.string(), "--size", "32x32", "--out", name},
            {kRender, bake.string(), "--env", env.string(), "--size", "32x32", "--out-exr", name},
            {kRender, bake.string(), "--env", env.string(), "--size", "32x32", "--dirs", name},
            {kEval, "query", bake.string(), "--in", (dir / "q.csv").string(), "--out", name},
            {kEval, "directions", bake.string(), "--pairs", "10", "--json", name},
        };
        for (const auto& args : runs) {
            SCOPED_TRACE(args[0] + " ... " + name);
            EXPECT_EQ(runTool(args, dir / "target.log"), 2) << readFile(dir / "target.log");
            const std::string log = readFile(dir / "target.log");
            EXPECT_NE(log.find(name + ": exists and is a"), std::string::npos) << log;
        }
    }
    struct stat st;
    ASSERT_EQ(::lstat((dir / "link.png").c_str(), &st), 0);
    EXPECT_TRUE(S_ISLNK(st.st_mode));
    EXPECT_EQ(fs::read_symlink(dir / "link.png"), "pointee.png");
    EXPECT_EQ(readFile(dir / "pointee.png"), "the file the link points to");
    ASSERT_EQ(::lstat((dir / "fifo.png").c_str(), &st), 0);
    EXPECT_TRUE(S_ISFIFO(st.st_mode));
    if (device) {
        ASSERT_EQ(::lstat((dir / "null.png").c_str(), &st), 0);
        EXPECT_TRUE(S_ISCHR(st.st_mode));
        EXPECT_EQ(st.st_rdev, makedev(1, 3));
    }
    EXPECT_EQ(readFile(bake), previous);
    std::set<std::string> expected = {"ico.shrefract.exr", "pointee.png", "q.csv", "link.png",
                                      "fifo.png", "previous.log", "target.log"};
    if (device) expected.insert("null.png");
    EXPECT_EQ(listing(dir), expected);
}

}  // namespace
}  // namespace shrefract
