// shrefract-merge: the shards of one bake (shrefract-bake --shard I/N) in, its bake file out,
// the same file a single machine would have written. A thin shell over bake/shard.h; see
// docs/bake.md "Shards, checkpoints and schedulers".
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "bake/shard.h"
#include "common/cli/cli.h"
#include "common/error.h"
#include "common/output.h"

using namespace shrefract;
namespace fs = std::filesystem;

int main(int argc, char** argv) {
    CLI::App app{"shrefract-merge: check that shard files make one whole bake and write its "
                 "NAME.shrefract.exr, identical to a single-machine bake"};
    std::string output, input;
    std::vector<std::string> shards;
    bool quiet = false;
    app.add_option("output", output, "bake file to write, NAME.shrefract.exr")->required();
    app.add_option("shards", shards, "every shard of the bake, in any order")->required();
    app.add_option("--input", input,
                   "mesh or scene to rebuild the layout from (default: the path the shards "
                   "record); its checksum must match theirs");
    app.add_flag("-q,--quiet", quiet, "no notes on stderr");
    const auto t0 = std::chrono::steady_clock::now();
    return cli::run(app, "shrefract-merge", argc, argv, [&] {
        for (const std::string& s : shards)
            if (fs::exists(s) && fs::equivalent(s, output))
                throw inputError(output, "is one of the shards: the output would overwrite it");
        OutputSet outputs;  // checked and staged before the work; see common/output.h
        const std::string staged = outputs.add(output);
        MergeOptions options;
        options.input = input;
        if (!quiet) options.log = [](const std::string& text) { std::fprintf(stderr, "%s\n", text.c_str()); };
        BakeResult res = mergeShards(shards, options);
        writeBake(staged, res.data);
        outputs.commit();
        const BakeStats& s = res.stats;
        std::printf("merged %zu shards -> %s\n", shards.size(), output.c_str());
        std::printf("  samples     %zu, paths %zu, rays %zu\n", s.samples, s.paths, s.rays);
        std::printf("  time        %.1f s wall (the shards: %.1f s of slices)\n",
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                    s.wallSeconds);
        std::printf("  file        %.1f MB\n", fs::file_size(output) / 1e6);
        return int(cli::kOk);
    });
}
