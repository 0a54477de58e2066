// shrefract-subdivide: a mesh in, the same surface uniformly subdivided out (OpenMesh's Loop or
// sqrt(3) subdivider). Makes the Lucy-class mesh of scripts/bench-lucy from bunny00.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "bake/subdivide.h"
#include "common/cli/cli.h"
#include "common/error.h"

using namespace shrefract;

int main(int argc, char** argv) {
    CLI::App app{"shrefract-subdivide: uniform Loop or sqrt(3) subdivision of a mesh (OpenMesh)"};
    std::string input, output, scheme = "sqrt3";
    int steps = 1;
    app.add_option("input", input, "mesh (.obj .off .ply .stl)")->required();
    app.add_option("output", output, "subdivided mesh, format by extension")->required();
    app.add_option("--scheme", scheme, "loop (x4 triangles) or sqrt3 (x3 triangles)")
        ->capture_default_str()->check(CLI::IsMember({"loop", "sqrt3"}));
    app.add_option("--steps", steps, "subdivision steps")->capture_default_str()->check(CLI::Range(0, 6));
    return cli::run(app, "shrefract-subdivide", argc, argv, [&] {
        const SubdivisionResult r = subdivideMeshFile(input, output, parseName<Subdivision>(scheme), steps);
        std::printf("%s -> %s: %zu vertices, %zu triangles\n", input.c_str(), output.c_str(), r.vertices,
                    r.triangles);
        return int(cli::kOk);
    });
}
