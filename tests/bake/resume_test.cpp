// A checkpointed bake loses nothing (docs/bake.md "Checkpoints"): killed at any moment
// (SIGKILL), cut off by a full disk, or with its last checkpoints damaged as a power cut could
// leave them, it leaves complete verified files or none, and `--resume` finishes with the same
// file an uninterrupted bake writes.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "bake/shard.h"
#include "common/bakefile.h"
#include "same_bake.h"
#include "support/cli_run.h"

namespace shrefract {
namespace {

namespace fs = std::filesystem;
using test::CommandResult;
using test::run;
using test::tmp;

const std::string kBake = SHREFRACT_BAKE_EXE;
// cow at rate 1 on an 8 x 16 grid: 2904 samples, 372 k paths, under a second on 2 cores, cut
// into 12 checkpoints.
const std::string kInput = std::string(SHREFRACT_DATA_DIR) + "/meshes/cow.off";
// (--cache "": these commands also run inside sh -c '...', where '' would end the quoting.)
const std::string kArgs = " --rate 1 --grid 8x16 --order 4 --cache \"\" -q";

std::string bakeCommand(const std::string& out, const std::string& extra = "") {
    return kBake + " " + kInput + " -o " + out + kArgs + " --checkpoints 12" + extra;
}

// The uninterrupted bake, without checkpoints.
const BakeData& reference() {
    static const BakeData data = [] {
        const std::string out = tmp("resume_ref_" + std::to_string(::getpid()) + ".shrefract.exr");
        CommandResult r = run(kBake + " " + kInput + " -o " + out + kArgs + " --checkpoints 1");
        EXPECT_EQ(r.code, 0) << r.out;
        BakeData d = readBake(out);
        fs::remove(out);
        return d;
    }();
    return data;
}

// "" when `path` is a complete bake equal to the reference, else what is wrong.
std::string differenceFromReference(const std::string& path) {
    BakeData d;
    try {
        d = readBake(path);
    } catch (const std::exception& e) {
        return std::string("unreadable: ") + e.what();
    }
    return test::bakeDifference(d, reference());
}

// Files beside `out` that start with its name: the output, its work folder, temporaries.
std::vector<std::string> filesOf(const std::string& out) {
    std::vector<std::string> found;
    const std::string name = fs::path(out).filename().string();
    for (const auto& e : fs::directory_iterator(fs::path(out).parent_path()))
        if (e.path().filename().string().rfind(name, 0) == 0) found.push_back(e.path().filename().string());
    return found;
}

TEST(Resume, CheckpointedBakeEqualsTheSingleSliceBake) {
    const std::string out = tmp("resume_plain.shrefract.exr");
    fs::remove_all(out + ".work");
    CommandResult r = run(bakeCommand(out));
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(differenceFromReference(out), "");
    EXPECT_EQ(filesOf(out), std::vector<std::string>{fs::path(out).filename().string()})
        << "the work folder is removed once the bake file is written";
}

// SIGKILL at 10 random moments (seeded) over the whole run, the final write included; after
// each, every file on disk is complete and valid or a temporary, and --resume finishes with the
// reference's bytes.
TEST(Resume, AfterSigkillAtRandomMomentsResumeGivesTheSameFile) {
    const std::string out = tmp("resume_kill.shrefract.exr");
    const std::string work = out + ".work";
    fs::remove_all(work);
    fs::remove(out);
    reference();
    // How long an uninterrupted run takes here (loaded machines are slower: measure, do not guess).
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_EQ(run(bakeCommand(out)).code, 0);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    fs::remove(out);

    std::mt19937 rng(20061);
    std::uniform_real_distribution<double> when(0.0, 1.1 * seconds);
    int corrupt = 0, resumedFromCheckpoints = 0;
    for (int rep = 0; rep < 10; ++rep) {
        const double delay = when(rng);
        CommandResult k = run("sh -c '" + bakeCommand(out) + " & pid=$!; sleep " + std::to_string(delay) +
                              "; kill -KILL $pid 2>/dev/null; wait $pid; true'");
        // What the kill left: the output complete or absent; checkpoints complete or temporaries.
        if (fs::exists(out)) {
            const std::string why = differenceFromReference(out);
            EXPECT_EQ(why, "") << "after a kill at " << delay << " s the output is " << why;
            corrupt += !why.empty();
        }
        int complete = 0;
        if (fs::exists(work)) {
            for (const auto& e : fs::directory_iterator(work)) {
                const std::string name = e.path().filename().string();
                if (name == "lock" || name.find(".shrefract-tmp.") != std::string::npos) continue;
                try {
                    readShard(e.path().string());
                    ++complete;
                } catch (const std::exception& ex) {
                    ADD_FAILURE() << "after a kill at " << delay << " s: " << ex.what();
                    ++corrupt;
                }
            }
        }
        resumedFromCheckpoints += complete > 0;
        std::printf("[ note ] kill %d at %.2f s: %d complete checkpoints, output %s\n", rep, delay, complete,
                    fs::exists(out) ? "written" : "absent");
        CommandResult r = run(bakeCommand(out, " --resume"));
        ASSERT_EQ(r.code, 0) << "resume after a kill at " << delay << " s: " << r.out;
        const std::string why = differenceFromReference(out);
        EXPECT_EQ(why, "") << "resumed after a kill at " << delay << " s: " << why;
        corrupt += !why.empty();
        EXPECT_EQ(filesOf(out), std::vector<std::string>{fs::path(out).filename().string()})
            << "leftovers after resuming from a kill at " << delay << " s";
        fs::remove(out);
    }
    std::printf("[ note ] 10 kills over %.2f s runs: %d left checkpoints to resume from, %d corrupt or "
                "partial outputs\n", seconds, resumedFromCheckpoints, corrupt);
    EXPECT_EQ(corrupt, 0);
    // The seeded moments must exercise resuming, not only restarting.
    EXPECT_GE(resumedFromCheckpoints, 3);
}

// A full disk (here: a file-size limit, with SIGXFSZ ignored so write() fails with EFBIG) stops
// the final write: a clear error, no output and no temporary, every checkpoint kept. Damage the
// last checkpoints as a power cut might (one cut short, one with a flipped bit): --resume bakes
// those two again and writes the reference's bytes.
TEST(Resume, FullDiskThenDamagedCheckpointsThenResume) {
    const std::string out = tmp("resume_disk.shrefract.exr");
    const std::string work = out + ".work";
    fs::remove_all(work);
    fs::remove(out);
    // 200 KiB per file: enough for a checkpoint (about 40 KB), not for the bake file (~0.4 MB).
    CommandResult full = run("bash -c 'trap \"\" XFSZ; ulimit -f 200; exec " + bakeCommand(out) + "'");
    EXPECT_EQ(full.code, 1) << full.out;  // an I/O failure (README "Exit codes")
    EXPECT_NE(full.out.find(out), std::string::npos) << full.out;
    EXPECT_NE(full.out.find("File too large"), std::string::npos) << full.out;
    EXPECT_FALSE(fs::exists(out));
    std::vector<std::string> left = filesOf(out);
    EXPECT_EQ(left, std::vector<std::string>{fs::path(work).filename().string()});
    for (int i = 0; i < 12; ++i) EXPECT_NO_THROW(readShard(checkpointPath(work, {i, 12})));

    // Without --resume the checkpoints are not touched: an error says what to do.
    CommandResult again = run(bakeCommand(out));
    EXPECT_EQ(again.code, 2) << again.out;
    EXPECT_NE(again.out.find("--resume"), std::string::npos) << again.out;
    EXPECT_NO_THROW(readShard(checkpointPath(work, {11, 12})));

    const std::string cut = checkpointPath(work, {11, 12}), flipped = checkpointPath(work, {10, 12});
    fs::resize_file(cut, fs::file_size(cut) * 2 / 3);
    test::flipByte(flipped, 100, 1);
    CommandResult r = run(kBake + " " + kInput + " -o " + out + kArgs + " --checkpoints 12 --resume");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(differenceFromReference(out), "");
    EXPECT_EQ(filesOf(out), std::vector<std::string>{fs::path(out).filename().string()});
}

// A work folder of a different bake is never taken for this one's.
TEST(Resume, CheckpointsOfAnotherBakeAreRefused) {
    const std::string out = tmp("resume_other.shrefract.exr");
    const std::string work = out + ".work";
    fs::remove_all(work);
    fs::remove(out);
    // Fill the folder with another bake's checkpoints (order 3), stopped by a full disk.
    run("bash -c 'trap \"\" XFSZ; ulimit -f 200; exec " + kBake + " " + kInput + " -o " + out +
        " --rate 1 --grid 8x16 --order 3 --cache \"\" -q --checkpoints 12'");
    ASSERT_TRUE(fs::exists(checkpointPath(work, {0, 12})));
    CommandResult r = run(bakeCommand(out, " --resume"));
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("different bake"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_NO_THROW(readShard(checkpointPath(work, {0, 12})));
    fs::remove_all(work);
}

}  // namespace
}  // namespace shrefract
