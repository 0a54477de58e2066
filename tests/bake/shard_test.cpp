// Shards and their merge, as a user runs them: `shrefract-bake --shard I/N` on any machine, then
// `shrefract-merge`, against the single-machine bake of the same mesh (docs/bake.md "Shards").
#include <gtest/gtest.h>

#include <unistd.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "bake/shard.h"
#include "common/bakefile.h"
#include "common/error.h"
#include "same_bake.h"
#include "support/cli_run.h"

namespace shrefract {
namespace {

namespace fs = std::filesystem;
using test::CommandResult;
using test::run;
using test::tmp;

const std::string kBake = SHREFRACT_BAKE_EXE;
const std::string kMerge = SHREFRACT_MERGE_EXE;
const std::string kCow = std::string(SHREFRACT_DATA_DIR) + "/meshes/cow.off";
// cow: 2904 samples at rate 1 = 91 batches of 32, so 4 and 7 slices are uneven; a coarse grid
// and a low order keep every bake well under a second.
const std::string kArgs = " --rate 1 --grid 8x16 --cache '' -q --checkpoints 1";
// A case's bake options: kArgs, order 3 unless the case stores the grid basis (which refuses
// --order), and the case's own.
std::string argsWith(const std::string& options) {
    return kArgs + (options.find("--basis grid") == std::string::npos ? " --order 3" : "") + options;
}

void expectSameBake(const std::string& a, const std::string& b) {
    EXPECT_EQ(test::bakeDifference(readBake(a), readBake(b)), "") << a << " and " << b;
}

// Bakes the single-machine reference once per option set and process (never an older build's).
// `options`: extra bake options, e.g. " --precision u8".
std::string reference(const std::string& options) {
    struct RemovedAtExit {
        std::set<std::string> paths;
        ~RemovedAtExit() {
            for (const std::string& p : paths) fs::remove(p);
        }
    };
    static RemovedAtExit made;
    std::string name = options;
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    const std::string out = tmp("shard_ref" + name + "_" + std::to_string(::getpid()) + ".shrefract.exr");
    if (made.paths.insert(out).second) {
        CommandResult r = run(kBake + " " + kCow + " -o " + out + argsWith(options));
        EXPECT_EQ(r.code, 0) << r.out;
    }
    return out;
}

// Shard i of n: the first from the mesh's own folder by a relative path, as a job on another
// machine may find it; the others by the absolute path the reference uses.
std::vector<std::string> bakeShards(const std::string& name, int n, const std::string& extra = "") {
    std::vector<std::string> shards;
    for (int i = 0; i < n; ++i) {
        const std::string s = tmp(name + "_" + std::to_string(i) + "_of_" + std::to_string(n) + ".exr");
        const std::string input = i == 0 ? "cd " + fs::path(kCow).parent_path().string() + " && " + kBake + " cow.off"
                                         : kBake + " " + kCow;
        CommandResult r = run(input + " -o " + s + argsWith(extra) + " --shard " +
                              std::to_string(i) + "/" + std::to_string(n));
        EXPECT_EQ(r.code, 0) << r.out;
        shards.push_back(s);
    }
    return shards;
}

std::string joined(const std::vector<std::string>& v) {
    std::string s;
    for (const std::string& x : v) s += " " + x;
    return s;
}

TEST(Shard, SlicesStartAtBatchBoundariesAndCoverEveryBatchOnce) {
    for (size_t batches : {1, 2, 7, 91, 1000}) {
        for (int n : {1, 2, 3, 4, 7, 13}) {
            size_t next = 0;
            for (int i = 0; i < n; ++i) {
                const auto [b, e] = shardBatches(batches, {i, n});
                EXPECT_EQ(b, next) << batches << " batches, slice " << i << " of " << n;
                EXPECT_LE(e, batches);
                // Even: sizes differ by at most one batch.
                EXPECT_LE(e - b, (batches + n - 1) / size_t(n));
                EXPECT_GE(e - b, batches / size_t(n));
                next = e;
            }
            EXPECT_EQ(next, batches);
        }
    }
}

struct MergeCase {
    const char* name;
    int n;
    const char* options;  // extra bake options, for the shards and the reference alike
};

class MergedShards : public ::testing::TestWithParam<MergeCase> {};

// The merge writes what one machine writes: the same weights bit for bit, the same manifest
// but for the time it took.
TEST_P(MergedShards, EqualTheSingleMachineBake) {
    const MergeCase& c = GetParam();
    const std::string name = std::string("merged_") + c.name;
    const std::vector<std::string> shards = bakeShards(name, c.n, c.options);
    const std::string out = tmp(name + ".shrefract.exr");
    fs::remove(out);
    // In reverse order: the merge orders them by their slice, not by the command line.
    std::vector<std::string> reversed(shards.rbegin(), shards.rend());
    CommandResult r = run(kMerge + " " + out + joined(reversed));
    ASSERT_EQ(r.code, 0) << r.out;
    expectSameBake(out, reference(c.options));
}

// N = 1, 4, 7 (91 batches: uneven slices); 8-bit weights, quantized over the whole bake by the
// merge; the weighted fit, which solves per sample; the scalar tracer; the grid basis.
INSTANTIATE_TEST_SUITE_P(Counts, MergedShards,
                         ::testing::Values(MergeCase{"1", 1, ""}, MergeCase{"4", 4, ""},
                                           MergeCase{"7", 7, ""},
                                           MergeCase{"4_u8", 4, " --precision u8"},
                                           MergeCase{"3_weighted", 3, " --fit weighted"},
                                           MergeCase{"2_scalar", 2, " --tracer scalar"},
                                           MergeCase{"3_grid", 3, " --basis grid"}),
                         [](const auto& info) { return std::string(info.param.name); });

// With --shard N alone, the index comes from SLURM_ARRAY_TASK_ID: the same shard as --shard I/N.
TEST(Shard, SlurmArrayTaskIdGivesTheIndex) {
    const std::string a = tmp("slurm_task_a.exr"), b = tmp("slurm_task_b.exr");
    ASSERT_EQ(run(kBake + " " + kCow + " -o " + a + argsWith("") + " --shard 2/3").code, 0);
    CommandResult r = run("SLURM_ARRAY_TASK_ID=2 " + kBake + " " + kCow + " -o " + b + argsWith("") + " --shard 3");
    ASSERT_EQ(r.code, 0) << r.out;
    const ShardData x = readShard(a), y = readShard(b);
    EXPECT_EQ(x.manifest["shard"], y.manifest["shard"]);
    EXPECT_EQ(x.weights, y.weights);
    r = run("env -u SLURM_ARRAY_TASK_ID " + kBake + " " + kCow + " -o " + b + argsWith("") + " --shard 3");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.out.find("SLURM_ARRAY_TASK_ID"), std::string::npos) << r.out;
}

struct BadShardArgs {
    const char* name;
    const char* args;
    const char* expect;
};

class ShardRejects : public ::testing::TestWithParam<BadShardArgs> {};

TEST_P(ShardRejects, BadSlicesWithAClearError) {
    const std::string out = tmp(std::string("badslice_") + GetParam().name + ".exr");
    fs::remove(out);
    CommandResult r = run("SLURM_ARRAY_TASK_ID=9 " + kBake + " " + kCow + " -o " + out + argsWith("") + " " + GetParam().args);
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find(GetParam().expect), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(out));
}

INSTANTIATE_TEST_SUITE_P(
    Args, ShardRejects,
    ::testing::Values(BadShardArgs{"past", "--shard 4/4", "does not exist"},
                      BadShardArgs{"text", "--shard two/4", "expected I/N"},
                      BadShardArgs{"task", "--shard 4", "does not exist"},
                      BadShardArgs{"target", "--shard 0/2 --target-error 10", "--target-error"}),
    [](const auto& info) { return std::string(info.param.name); });

// Every way a set of shards can fail to make one bake: refused, naming the file and the
// problem, and nothing written.
class MergeRejects : public ::testing::Test {
protected:
    // Baked once per process, by the first test that runs (run() logs under the current test).
    // ctest runs each case as its own process, two at a time: every file a case writes carries
    // its process id, or one case's "precious" is truncated while another reads it.
    void SetUp() override {
        static const std::vector<std::string> four = bakeShards("mr" + pid_, 4),
                                              other = bakeShards("mr_bounces" + pid_, 2, " --max-bounces 16"),
                                              three = bakeShards("mr_three" + pid_, 3);
        four_ = four, other_ = other, three_ = three;
    }
    const std::string pid_ = "_" + std::to_string(::getpid());
    std::vector<std::string> four_, other_, three_;

    // Runs the merge; it must fail with `expect` in its message and leave `precious` intact.
    void expectRefused(const std::string& args, const std::string& expect) {
        const std::string out = tmp("mr_out" + pid_ + ".shrefract.exr");
        test::writeText(out, "precious");
        CommandResult r = run(kMerge + " " + out + " " + args);
        EXPECT_EQ(r.code, 2) << r.out;
        EXPECT_NE(r.out.find(expect), std::string::npos) << "expected \"" << expect << "\" in: " << r.out;
        std::ifstream f(out);
        std::string s;
        f >> s;
        EXPECT_EQ(s, "precious");
        test::expectNoStagedFileLeft(out);
    }
};

TEST_F(MergeRejects, AMissingSlice) {
    expectRefused(four_[0] + " " + four_[1] + " " + four_[3], "missing slice 2 of 4");
}

TEST_F(MergeRejects, ADuplicatedSlice) {
    expectRefused(joined(four_) + " " + four_[1], "slice 1 of 4 is given twice");
}

TEST_F(MergeRejects, ShardsOfAnotherBake) {
    expectRefused(four_[0] + " " + four_[1] + " " + other_[1], "\"maxBounces\" differs");
}

TEST_F(MergeRejects, ShardsOfAnotherSlicing) {
    expectRefused(four_[0] + " " + four_[1] + " " + three_[2] + " " + four_[3], "slice 2 of 3");
}

TEST_F(MergeRejects, ACorruptShard) {
    const std::string bad = tmp("mr_corrupt.exr");
    fs::copy_file(four_[2], bad, fs::copy_options::overwrite_existing);
    test::flipByte(bad, 8, 0x10);  // in the last weight texel of the (uncompressed) part
    expectRefused(four_[0] + " " + four_[1] + " " + bad + " " + four_[3], "mr_corrupt.exr");
    expectRefused(four_[0] + " " + four_[1] + " " + bad + " " + four_[3], "corrupt");
}

TEST_F(MergeRejects, ATruncatedShard) {
    const std::string bad = tmp("mr_truncated.exr");
    fs::copy_file(four_[1], bad, fs::copy_options::overwrite_existing);
    fs::resize_file(bad, fs::file_size(bad) / 2);
    expectRefused(four_[0] + " " + bad + " " + four_[2] + " " + four_[3], "mr_truncated.exr");
}

TEST_F(MergeRejects, ABakeInsteadOfAShard) {
    expectRefused(four_[0] + " " + reference(""), "is a bake, not a shard");
}

TEST_F(MergeRejects, AnotherMesh) {
    expectRefused(joined(four_) + " --input " + std::string(SHREFRACT_DATA_DIR) + "/meshes/knot1.off",
                  "does not match the bake of the shards");
}

TEST_F(MergeRejects, AMissingFile) {
    expectRefused(four_[0] + " " + tmp("no_such_shard.exr"), "no_such_shard.exr: file not found");
}

// A shard is not a bake: the readers that take bakes say what it is.
TEST(Shard, ReadBakeRefusesAShard) {
    const std::vector<std::string> s = bakeShards("notabake", 2);
    try {
        readBake(s[1]);
        FAIL() << "read a shard as a bake";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("is a shard (slice 1 of 2"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace shrefract
