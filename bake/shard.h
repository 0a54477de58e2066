// A bake at scale (docs/design.md#scale, docs/bake.md "Shards, checkpoints and schedulers"): the
// batches of a bake cut into N deterministic slices. `shrefract-bake --shard I/N` bakes one slice
// into a shard file on any machine; shrefract-merge checks that a set of shards makes one whole
// bake and writes the file a single machine would have written, byte for byte in the weights. A
// long single-machine bake checkpoints the same way, into a work folder, and resumes from it.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "bake/bake.h"

namespace shrefract {

// Slice `index` of `count` (0 <= index < count).
struct ShardSlice {
    int index = 0, count = 1;
};

// "I/N", or "N" alone with the index from `taskId` (SLURM_ARRAY_TASK_ID's value, or null when
// unset). Throws InputError naming --shard on bad text or an index out of range.
ShardSlice parseShard(const std::string& text, const char* taskId);
// Batches [begin, end) of a slice: floor(I * B / N) up to floor((I + 1) * B / N), so that slices
// start at batch boundaries and a sample is always compressed beside the same neighbours.
std::pair<size_t, size_t> shardBatches(size_t batches, ShardSlice slice);

// What every shard of one bake records and the merge compares: the whole bake's manifest
// without its statistics, plus order, precision, rate, sample count, batch size and the
// checksum of the samples the tracing saw (docs/format.md "Shards").
nlohmann::json shardIdentity(const BakePlan& plan);

// Bakes one slice into a shard (manifest: "shard", "bake" = shardIdentity, "stats").
ShardData bakeShard(const BakePlan& plan, ShardSlice slice, const SliceProgress& base = {});

// "" when `shard` is slice `slice` of the bake `identity` (cut into `batches` batches), else why
// it is not.
std::string shardMismatch(const ShardData& shard, const nlohmann::json& identity, ShardSlice slice,
                          size_t batches);

struct MergeOptions {
    // The mesh or scene to rebuild the layout from; empty: the input the shards record. Its
    // checksum must match theirs.
    std::string input;
    std::function<void(const std::string&)> log;  // notes for the user
};

// Checks that the shard files belong together (same bake, same slicing, every slice once, each
// intact) and assembles the bake. Throws InputError naming the file and the problem.
BakeResult mergeShards(const std::vector<std::string>& paths, const MergeOptions& options = {});
// The same with the plan of the bake they must belong to already built (checkpoints).
BakeResult mergeShards(const BakePlan& plan, const std::vector<std::string>& paths);

// Paths per checkpoint when the count is automatic: 2^24, about 10 s of tracing on 2 cores.
constexpr size_t kCheckpointPaths = size_t(1) << 24;

struct CheckpointOptions {
    std::string workDir;  // the checkpoints' folder, made if missing
    int count = 0;        // checkpoints (slices); 0: one per kCheckpointPaths paths; 1: none
    bool resume = false;  // keep the complete, valid checkpoints found in workDir
    std::function<void(const std::string&)> log;  // notes for the user
};

// The number of checkpoints a bake of this plan cuts itself into.
int checkpointCount(const BakePlan& plan, int requested);
// The shard file of checkpoint `slice` in `workDir`.
std::string checkpointPath(const std::string& workDir, ShardSlice slice);

// The whole bake, slice by slice, each slice written to workDir as a shard as soon as it is
// done; then merged from those files. With `resume`, slices whose shard is complete and valid
// are skipped and corrupt ones are baked again. Without it, a work folder that already holds
// checkpoints is an error (nothing on disk is overwritten). A second bake on the same folder is
// refused while the first runs. Throws Cancelled when options().cancel is set: the finished
// checkpoints stay for --resume.
BakeResult bakeWithCheckpoints(const BakePlan& plan, const CheckpointOptions& options);
// Removes the work folder's checkpoints, and the folder (once the bake file is safely written).
void removeCheckpoints(const std::string& workDir);


}  // namespace shrefract
