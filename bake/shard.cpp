#include "bake/shard.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "bake/joining_layout.h"
#include "common/error.h"
#include "common/limits.h"
#include "common/sh.h"

namespace shrefract {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string sliceName(ShardSlice s) { return str("slice ", s.index, " of ", s.count); }

// The identity without what may differ between machines that bake the same thing: the paths
// by which each found the input.
json comparable(json identity) {
    if (!identity.is_object()) return identity;
    identity.erase("input");
    if (identity.contains("media") && identity["media"].is_array())
        for (json& m : identity["media"])
            if (m.is_object()) m.erase("mesh");
    return identity;
}

// The first key in which two identities differ, as "\"grid\" differs ([16,32] here, [32,64]
// there)", or "" when they agree.
std::string difference(const json& here, const json& there) {
    const json a = comparable(here), b = comparable(there);
    if (a == b) return "";
    if (!a.is_object() || !b.is_object()) return "no bake parameters to compare";
    std::set<std::string> keys;
    for (auto it = a.begin(); it != a.end(); ++it) keys.insert(it.key());
    for (auto it = b.begin(); it != b.end(); ++it) keys.insert(it.key());
    for (const std::string& k : keys) {
        const json x = a.value(k, json()), y = b.value(k, json());
        if (x != y) {
            std::string xs = x.dump(), ys = y.dump();
            if (xs.size() > 200) xs = xs.substr(0, 200) + "...";
            if (ys.size() > 200) ys = ys.substr(0, 200) + "...";
            return str("\"", k, "\" differs (", xs, " here, ", ys, " there)");
        }
    }
    return "they differ";
}

ShardSlice sliceOf(const json& manifest) {
    const json& s = manifest["shard"];
    return {s.value("index", -1), s.value("count", -1)};
}

// Scene and options that rebuild the bake `identity` describes (the merge's plan).
BakeOptions optionsOf(const json& id) {
    BakeOptions o;
    o.basis = parseInput<Basis>(id.value("basis", "sh"));
    o.order = id.value("order", -1);
    if (o.order < 0 || o.order > 100) throw InputError(str("SH order ", o.order, " is absurd"));
    o.precision = parseInput<Precision>(id.value("precision", ""));
    o.rate = id.value("rate", 0);
    if (o.rate < 1) throw InputError(str("rate ", o.rate, " is below 1"));
    const json grid = id.value("grid", json::array());
    if (!grid.is_array() || grid.size() != 2) throw InputError("no direction grid");
    o.grid = parseGrid(str(grid[0].get<int>(), "x", grid[1].get<int>()), "grid");
    const RecordedFit fit = recordedFit(id);
    o.fit = fit.fit, o.weighting = fit.weighting, o.filterWidth = fit.filterWidth;
    o.trace.branch = id.value("branch", "") == "transmit" ? Branch::Transmit : Branch::Fresnel;
    o.trace.maxBounces = id.value("maxBounces", 32);
    o.coherent = id.value("tracer", "coherent") == "coherent";
    o.errorOrder = id.value("errorOrder", -1);
    if (o.errorOrder > limits::kMaxErrorOrder)
        throw InputError(str("error model order ", o.errorOrder, " is above ", limits::kMaxErrorOrder));
    o.cacheDir = "";
    return o;
}

Medium mediumOf(const json& id) {
    Medium m;
    const json media = id.value("media", json::array());
    if (!media.is_array() || media.empty() || !media[0].is_object()) return m;
    const json& p = media[0];
    m.name = p.value("name", m.name);
    m.ior = p.value("ior", m.ior);
    const json a = p.value("absorption", json::array());
    if (a.is_array() && a.size() == 3) m.absorption = {a[0].get<double>(), a[1].get<double>(), a[2].get<double>()};
    m.priority = p.value("priority", m.priority);
    return m;
}

// An exclusive lock on a work folder while a bake uses it; released when the process ends,
// however it ends.
class FolderLock {
public:
    explicit FolderLock(const std::string& dir) : path_(dir + "/lock") {
        fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT, 0644);
        if (fd_ < 0) throw inputError(dir, str("cannot create a lock file: ", std::strerror(errno)));
        if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
            ::close(fd_);
            throw inputError(dir, "another bake is using this work folder");
        }
    }
    ~FolderLock() { ::close(fd_); }
    FolderLock(const FolderLock&) = delete;
    FolderLock& operator=(const FolderLock&) = delete;

private:
    std::string path_;
    int fd_ = -1;
};

const std::regex kCheckpointName(R"(shard-(\d+)-of-(\d+)\.exr)");

}  // namespace

ShardSlice parseShard(const std::string& text, const char* taskId) {
    const std::regex both(R"(\s*(\d+)\s*/\s*(\d+)\s*)"), countOnly(R"(\s*(\d+)\s*)");
    std::smatch m;
    ShardSlice s;
    try {
        if (std::regex_match(text, m, both)) {
            s.index = std::stoi(m[1]);
            s.count = std::stoi(m[2]);
        } else if (std::regex_match(text, m, countOnly)) {
            s.count = std::stoi(m[1]);
            if (!taskId)
                throw InputError(str("--shard ", text, " gives only the count: the index comes from "
                                     "SLURM_ARRAY_TASK_ID, which is not set (give --shard I/N)"));
            const std::string id = taskId;
            if (!std::regex_match(id, m, countOnly))
                throw InputError(str("SLURM_ARRAY_TASK_ID=\"", id, "\" is not a slice index"));
            s.index = std::stoi(m[1]);
        } else {
            throw InputError(str("--shard \"", text, "\": expected I/N (slice I of N, 0 <= I < N) or N"));
        }
    } catch (const std::out_of_range&) {
        throw InputError(str("--shard \"", text, "\": number out of range"));
    }
    if (s.count < 1 || s.index < 0 || s.index >= s.count)
        throw InputError(str("--shard: slice ", s.index, " of ", s.count,
                             " does not exist (0 <= I < N)"));
    return s;
}

std::pair<size_t, size_t> shardBatches(size_t batches, ShardSlice s) {
    const size_t N = size_t(s.count), I = size_t(s.index);
    return {I * batches / N, (I + 1) * batches / N};
}

json shardIdentity(const BakePlan& plan) {
    json id = plan.manifest(BakeStats{});
    id.erase("stats");
    const BakeOptions& o = plan.options();
    if (o.basis == Basis::Grid) id["basis"] = nameOf(o.basis);  // absent: sh, as before version 4
    id["order"] = o.order;
    id["precision"] = nameOf(o.precision);
    id["rate"] = plan.layout().rate;
    id["sampleCount"] = plan.sampleCount();
    id["batch"] = kBakeBatch;
    id["layoutChecksum"] = plan.layoutChecksum();
    id["errorOrder"] = o.errorOrder < 0 ? -1 : o.errorOrder;
    return id;
}

ShardData bakeShard(const BakePlan& plan, ShardSlice slice, const SliceProgress& base) {
    const auto [b0, b1] = shardBatches(plan.batchCount(), slice);
    SliceResult r = plan.bakeSlice(b0, b1, base);
    ShardData d;
    d.basis = plan.options().basis;
    d.order = plan.options().order;
    d.grid = plan.options().grid;
    d.sampleCount = r.count;
    d.weights = std::move(r.weights);
    d.errorOrder = plan.options().errorOrder < 0 ? -1 : plan.options().errorOrder;
    d.errors = std::move(r.errors);
    d.manifest = {{"shard", {{"index", slice.index}, {"count", slice.count}, {"first", r.first},
                             {"samples", r.count}, {"batches", {b0, b1}}}},
                  {"bake", shardIdentity(plan)},
                  {"stats", r.stats.ToJson()}};
    return d;
}

std::string shardMismatch(const ShardData& shard, const json& identity, ShardSlice slice,
                          size_t batches) {
    const json& m = shard.manifest;
    if (!m.contains("bake") || !m["bake"].is_object()) return "its manifest has no \"bake\"";
    const std::string diff = difference(m["bake"], identity);
    if (!diff.empty()) return "it is a shard of a different bake: " + diff;
    const ShardSlice s = sliceOf(m);
    if (s.index != slice.index || s.count != slice.count)
        return str("it is ", sliceName(s), ", expected ", sliceName(slice));
    const auto [b0, b1] = shardBatches(batches, s);
    const size_t n = identity.value("sampleCount", size_t(0));
    const size_t first = std::min(b0 * kBakeBatch, n), count = std::min(b1 * kBakeBatch, n) - first;
    const int errorOrder = identity.value("errorOrder", -1);
    if (shard.errorOrder != errorOrder || shard.errors.size() != (errorOrder < 0 ? 0 : size_t(shEvenCount(errorOrder))) * shard.sampleCount)
        return str("its error model (order ", shard.errorOrder, ", ", shard.errors.size(),
                   " values) is not the bake's (order ", errorOrder, ")");
    if (m["shard"].value("first", size_t(-1)) != first || shard.sampleCount != count)
        return str("its samples (", m["shard"].value("first", size_t(0)), " + ", shard.sampleCount,
                   ") are not ", sliceName(s), "'s (", first, " + ", count, ")");
    return "";
}

BakeResult mergeShards(const BakePlan& plan, const std::vector<std::string>& paths) {
    const json identity = shardIdentity(plan);
    const size_t n = plan.sampleCount(), batches = plan.batchCount();
    const int K = basisCoefficients(plan.options().basis, plan.options().order, plan.options().grid);

    // The slices, each once.
    std::map<int, std::string> byIndex;
    int count = -1;
    std::string countFrom;
    for (const std::string& p : paths) try {
        const ShardData s = readShard(p, false);
        const std::string diff = difference(s.manifest.value("bake", json()), identity);
        if (!diff.empty())
            throw inputError(p, "does not belong with " +
                                    (countFrom.empty() ? std::string("the mesh") : countFrom) + ": " + diff);
        const ShardSlice slice = sliceOf(s.manifest);
        if (count < 0) count = slice.count, countFrom = p;
        if (slice.count != count)
            throw inputError(p, str("is ", sliceName(slice), " but ", countFrom, " is a slice of ", count));
        if (slice.index < 0 || slice.index >= slice.count)
            throw inputError(p, str("names ", sliceName(slice), ", which does not exist"));
        auto [it, fresh] = byIndex.emplace(slice.index, p);
        if (!fresh) throw inputError(p, str(sliceName(slice), " is given twice (also ", it->second, ")"));
    } catch (const json::exception& e) {
        throw inputError(p, str("malformed shard manifest: ", e.what()));
    }
    if (count < 0) throw InputError("no shards to merge");
    std::vector<int> missing;
    for (int i = 0; i < count; ++i)
        if (!byIndex.count(i)) missing.push_back(i);
    if (!missing.empty()) {
        std::string list;
        for (size_t k = 0; k < missing.size() && k < 20; ++k) list += (k ? ", " : "") + std::to_string(missing[k]);
        if (missing.size() > 20) list += ", ...";
        throw InputError(str("missing ", missing.size() == 1 ? "slice " : "slices ", list, " of ", count,
                             " (", byIndex.size(), " shards given)"));
    }

    // The weights, slice by slice, each verified as it is read.
    std::vector<float> weights(size_t(K) * n * 4, 0.0f);
    const int Ke = plan.options().errorOrder < 0 ? 0 : shEvenCount(plan.options().errorOrder);
    std::vector<float> errors(size_t(Ke) * n, 0.0f);
    BakeStats stats;
    for (const auto& [index, p] : byIndex) {
        const ShardData s = readShard(p, true);
        const std::string why = shardMismatch(s, identity, {index, count}, batches);
        if (!why.empty()) throw inputError(p, why);
        const size_t first = s.manifest["shard"].value("first", size_t(0));
        for (int k = 0; k < K; ++k)
            std::copy_n(&s.weights[size_t(k) * s.sampleCount * 4], s.sampleCount * 4,
                        &weights[(size_t(k) * n + first) * 4]);
        for (int k = 0; k < Ke; ++k)
            std::copy_n(&s.errors[size_t(k) * s.sampleCount], s.sampleCount, &errors[size_t(k) * n + first]);
        stats += BakeStats::fromJson(s.manifest.value("stats", json::object()));
    }
    BakeResult out;
    stats.samples = n;
    stats.rhoOverhead = rhoOverhead(plan.layout());
    out.stats = stats;
    out.data = plan.data(std::move(weights), std::move(errors), stats);
    return out;
}

BakeResult mergeShards(const std::vector<std::string>& paths, const MergeOptions& options) {
    if (paths.empty()) throw InputError("no shards to merge");
    const ShardData first = readShard(paths.front(), false);
    const json id = first.manifest.value("bake", json());
    if (!id.is_object()) throw inputError(paths.front(), "its manifest has no \"bake\"");
    const std::string input = options.input.empty() ? id.value("input", "") : options.input;
    if (input.empty()) throw inputError(paths.front(), "records no input mesh: give --input");
    BakeOptions o;
    try {
        o = optionsOf(id);
    } catch (const std::exception& e) {
        throw inputError(paths.front(), str("its bake parameters are unreadable: ", e.what()));
    }
    if (options.log) options.log("merge: rebuilding the layout from " + input);
    Scene scene = loadScene(input, mediumOf(id));
    BakePlan plan(scene, o, input);
    const std::string diff = difference(shardIdentity(plan), id);
    if (!diff.empty())
        throw inputError(input, "does not match the bake of the shards (" + paths.front() + "): " + diff);
    return mergeShards(plan, paths);
}

int checkpointCount(const BakePlan& plan, int requested) {
    const size_t batches = std::max<size_t>(1, plan.batchCount());
    if (requested > 0) return int(std::min<size_t>(size_t(requested), batches));
    const size_t paths = plan.sampleCount() * size_t(plan.options().grid.count());
    return int(std::clamp<size_t>((paths + kCheckpointPaths - 1) / kCheckpointPaths, 1, batches));
}

std::string checkpointPath(const std::string& workDir, ShardSlice s) {
    char name[64];
    std::snprintf(name, sizeof name, "shard-%05d-of-%05d.exr", s.index, s.count);
    return (fs::path(workDir) / name).string();
}

BakeResult bakeWithCheckpoints(const BakePlan& plan, const CheckpointOptions& options) {
    const std::string& dir = options.workDir;
    const int N = checkpointCount(plan, options.count);
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir)) throw inputError(dir, "cannot create the work folder: " + ec.message());
    FolderLock lock(dir);

    // What the folder holds: checkpoints of this cut, of another, and leftovers of a killed
    // writer (temporaries: whoever wrote them is gone, the lock says so).
    std::vector<std::string> ours(N), foreign;
    for (int i = 0; i < N; ++i) ours[i] = checkpointPath(dir, {i, N});
    for (const auto& e : fs::directory_iterator(dir)) {
        const std::string name = e.path().filename().string();
        std::smatch m;
        if (name.find(".shrefract-tmp.") != std::string::npos) {
            fs::remove(e.path(), ec);
        } else if (std::regex_match(name, m, kCheckpointName) && std::stoi(m[2]) != N) {
            foreign.push_back(e.path().string());
        }
    }
    if (!foreign.empty())
        throw inputError(dir, str("holds checkpoints cut into other slices (", fs::path(foreign[0]).filename().string(),
                                  ", this bake cuts ", N, "): remove the folder, or give the --checkpoints "
                                  "count it was made with"));
    const json identity = shardIdentity(plan);
    std::vector<bool> done(N, false);
    size_t resumedSamples = 0;
    int kept = 0;
    for (int i = 0; i < N; ++i) {
        if (!fs::exists(ours[i])) continue;
        if (!options.resume)
            throw inputError(dir, "holds checkpoints of an earlier bake: pass --resume to continue it, "
                                  "or remove the folder to start over");
        std::string why;
        size_t samples = 0;
        try {
            const ShardData s = readShard(ours[i], true);
            why = shardMismatch(s, identity, {i, N}, plan.batchCount());
            samples = s.sampleCount;
        } catch (const InputError& e) {
            // Cut short by a crash or damaged since: bake it again.
            if (options.log) options.log(str("checkpoint damaged, baking it again: ", e.what()));
            fs::remove(ours[i], ec);
            continue;
        }
        if (!why.empty())
            throw inputError(ours[i], why + ": remove the work folder " + dir + " to start over");
        done[i] = true;
        resumedSamples += samples;
        ++kept;
    }
    if (options.resume && options.log)
        options.log(str("resume: ", kept, " of ", N, " checkpoints complete (", resumedSamples, " of ",
                        plan.sampleCount(), " samples)"));

    SliceProgress progress;
    progress.samplesDone = progress.samplesResumed = resumedSamples;
    for (int i = 0; i < N; ++i) {
        if (done[i]) continue;
        ShardData s = bakeShard(plan, {i, N}, progress);
        const BakeStats st = BakeStats::fromJson(s.manifest["stats"]);
        progress.samplesDone += s.sampleCount;
        progress.rays += st.rays;
        progress.seconds += st.wallSeconds;
        writeShard(ours[i], s);
    }
    return mergeShards(plan, ours);
}

void removeCheckpoints(const std::string& workDir) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(workDir, ec)) {
        const std::string name = e.path().filename().string();
        if (std::regex_match(name, kCheckpointName)) fs::remove(e.path(), ec);
    }
    fs::remove(fs::path(workDir) / "lock", ec);
    fs::remove(workDir, ec);  // only if empty: anything else the user put there stays
}

}  // namespace shrefract
