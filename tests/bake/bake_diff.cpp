// bake_diff A B: exit 0 when two bake files hold the same bake, byte for byte in the weights and
// the same manifest but for its timing field (stats.seconds); else print the first difference
// and exit 1. For the scheduler tests (slurm_test.sh), which compare a merged bake with the
// single-machine one.
#include <cstdio>
#include <exception>

#include "same_bake.h"

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: bake_diff A.shrefract.exr B.shrefract.exr\n");
        return 2;
    }
    try {
        const std::string diff =
            shrefract::test::bakeDifference(shrefract::readBake(argv[1]), shrefract::readBake(argv[2]));
        if (!diff.empty()) {
            std::printf("%s\n", diff.c_str());
            return 1;
        }
        std::printf("same bake: the weights bit for bit, manifests equal but for stats.seconds\n");
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bake_diff: %s\n", e.what());
        return 2;
    }
}
