// shrefract-subdivide: a mesh in, the same surface uniformly subdivided out (OpenMesh's Loop or
// sqrt(3) subdivider). Makes the Lucy-class mesh of scripts/bench-lucy from bunny00.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "bake/subdivide.h"
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
    CLI11_PARSE(app, argc, argv);
    try {
        const SubdivisionResult r = subdivideMeshFile(input, output, parseSubdivision(scheme), steps);
        std::printf("%s -> %s: %zu vertices, %zu triangles\n", input.c_str(), output.c_str(), r.vertices,
                    r.triangles);
        return 0;
    } catch (const InputError& e) {
        std::fprintf(stderr, "shrefract-subdivide: error: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "shrefract-subdivide: error: %s\n", e.what());
        return 1;
    }
}
