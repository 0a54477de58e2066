// shrefract-bake as a user meets it: bad input gets a clear error naming
// the file, a non-zero exit and no output file; what is already on disk is kept.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "common/bakefile.h"
#include "support/cli_run.h"
#include "support/files.h"

namespace {

namespace fs = std::filesystem;

using shrefract::test::CommandResult;
using shrefract::test::kTetraOff;
using shrefract::test::run;
using shrefract::test::tmp;
const auto& write = shrefract::test::writeText;

const std::string kBake = SHREFRACT_BAKE_EXE;
// The tetrahedron with UVs: a net (face 0 in the middle, the other three folded out around it),
// then the same with face 3's tip folded back onto face 0 (flipped), all four faces on one
// triangle (overlapping), and a tip outside [0, 1].
#define TETRA_OBJ(TIP) \
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" \
    "vt 0.5 0.35\nvt 0.35 0.6\nvt 0.65 0.6\nvt 0.2 0.35\nvt 0.8 0.35\nvt " TIP "\n" \
    "f 1/1 3/3 2/2\nf 1/1 2/2 4/4\nf 1/1 4/5 3/3\nf 2/2 3/3 4/6\n"
constexpr const char* kTetraUv = TETRA_OBJ("0.5 0.85");
constexpr const char* kTetraUvFlipped = TETRA_OBJ("0.5 0.5");
constexpr const char* kTetraUvOutside = TETRA_OBJ("0.5 1.2");
constexpr const char* kTetraUvOverlap =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0.1 0.1\nvt 0.9 0.1\nvt 0.5 0.9\n"
    "f 1/1 3/2 2/3\nf 1/1 2/2 4/3\nf 1/1 4/2 3/3\nf 2/1 3/2 4/3\n";

// Each case: an input file's content (or none), extra arguments, and a word the message needs.
struct BadCase {
    const char* name;
    const char* file;     // file name under tmp, "" for none written
    const char* content;  // nullptr: do not write
    const char* args;
    const char* expect;   // must appear in the output
};

class BakeRejects : public ::testing::TestWithParam<BadCase> {};

TEST_P(BakeRejects, WithAClearErrorAndNoOutput) {
    const BadCase& c = GetParam();
    std::string in = tmp(std::string(c.name) + "_" + c.file);  // parallel cases: own files
    if (c.content) write(in, c.content);
    std::string out = tmp(std::string("bad_") + c.name + ".shrefract.exr");
    fs::remove(out);
    CommandResult r = run(kBake + " " + in + " -o " + out + " --cache '' -q " + c.args);
    EXPECT_EQ(r.code, 2) << r.out;  // bad input, CLI11's usage errors included (README)
    EXPECT_NE(r.out.find(c.expect), std::string::npos) << "message: " << r.out;
    EXPECT_FALSE(fs::exists(out));
    shrefract::test::expectNoStagedFileLeft(out);
}

INSTANTIATE_TEST_SUITE_P(
    BadInput, BakeRejects,
    ::testing::Values(
        BadCase{"missing", "nope.off", nullptr, "", "nope.off"},
        BadCase{"extension", "mesh.xyz", "hello", "", "mesh.xyz"},
        BadCase{"garbage", "garbage.off", "this is not a mesh\n", "", "garbage.off"},
        BadCase{"empty", "empty.off", "", "", "empty.off"},
        BadCase{"nan", "nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n", "", "nan.off"},
        BadCase{"cut", "cut.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n", "",
                "cut short: the header promises 4 vertices and 4 faces, the file ends after 2 faces"},
        BadCase{"order", "tetra.off", kTetraOff, "--order 99", "order"},
        BadCase{"rate", "tetra.off", kTetraOff, "--rate 0", "rate"},
        BadCase{"grid", "tetra.off", kTetraOff, "--grid 3x5", "grid"},
        BadCase{"gridtext", "tetra.off", kTetraOff, "--grid banana", "grid"},
        BadCase{"ior", "tetra.off", kTetraOff, "--ior 0.5", "ior"},
        BadCase{"precision", "tetra.off", kTetraOff, "--precision f64", "precision"},
        BadCase{"scene", "scene.json", "{\"parts\": [{\"mesh\": \"tetra.off\", \"ior\": -2}]}", "", "scene.json"},
        BadCase{"gltfnoglass", "plain.gltf", "{\"asset\": {\"version\": \"2.0\"}}", "", "plain.gltf: no glass"},
        BadCase{"glbgarbage", "junk.glb", "glTF, but not binary glTF", "", "junk.glb: could not read glTF"},
        BadCase{"layout", "tetra.off", kTetraOff, "--layout spiral", "--layout"},
        BadCase{"chartrate", "tetra.off", kTetraOff, "--layout isolated --rate 2", "--rate is for --layout joining"},
        BadCase{"texels", "tetra.off", kTetraOff, "--layout isolated --texels 0x5", "--texels"},
        BadCase{"texelsjoin", "tetra.off", kTetraOff, "--texels 64", "--texels is for"},
        BadCase{"uvnone", "tetra.off", kTetraOff, "--layout uv", "has no texture coordinates"},
        BadCase{"uvflipped", "tetra.obj", kTetraUvFlipped, "--layout uv", "flipped in UV space"},
        BadCase{"uvoverlap", "tetra.obj", kTetraUvOverlap, "--layout uv", "overlap in UV space"},
        BadCase{"uvoutside", "tetra.obj", kTetraUvOutside, "--layout uv", "outside [0, 1]"},
        // The tetrahedron's smallest model: 4 samples at rate 1, order 1 (3 stored coefficients)
        // in u8, 48 bytes; 0.00004 MB is 40.
        BadCase{"budgetsmall", "tetra.off", kTetraOff, "--budget 0.00004", "order 1, rate 1, u8: 4.8e-05 MB"},
        BadCase{"fitgrid", "tetra.off", kTetraOff, "--order 16 --grid 8x16", "--order 16 stores 153 coefficients, more than the 128 directions"},
        BadCase{"budgettarget", "tetra.off", kTetraOff, "--budget 1 --target-error 5", "--target-error"},
        BadCase{"budgetcharts", "tetra.off", kTetraOff, "--budget 1 --layout isolated", "--budget searches joining layouts only"},
        BadCase{"budgetshard", "tetra.off", kTetraOff, "--budget 1 --shard 0/2", "--budget cannot be combined with --shard"},
        BadCase{"basis", "tetra.off", kTetraOff, "--basis table", "--basis"},
        BadCase{"gridorder", "tetra.off", kTetraOff, "--basis grid --order 8", "--order shapes an SH fit"},
        BadCase{"gridbudget", "tetra.off", kTetraOff, "--basis grid --budget 0.0001", "grid basis 8x16, rate 1, u8"},
        BadCase{"gridsize", "tetra.off", kTetraOff, "--basis grid --grid 32x128", "more than the 2048"}),
    [](const auto& info) { return std::string(info.param.name); });

// The chart layouts bake the test objects and say what they made.
TEST(BakeCli, ChartLayoutsBakeTheirObjects) {
    write(tmp("net_tetra.obj"), kTetraUv);
    const std::string data = SHREFRACT_DATA_DIR;
    const std::pair<std::string, std::string> cases[] = {
        {data + "/scenes/flat_cube.obj --layout isolated", "6 (0 splits"},
        {data + "/scenes/vase.obj --layout uv", "uv layout"},
        {tmp("net_tetra.obj") + " --layout uv", "uv layout"}};
    for (const auto& [args, expect] : cases) {
        const std::string out = tmp("chart.shrefract.exr");
        fs::remove(out);
        CommandResult r = run(kBake + " " + args + " -o " + out + " --samples 2000 --order 1 --grid 4x8 --cache ''");
        EXPECT_EQ(r.code, 0) << r.out;
        EXPECT_NE(r.out.find(expect), std::string::npos) << r.out;
        EXPECT_TRUE(fs::exists(out)) << args;
    }
}

// Say what you do: --samples becomes the smallest rate reaching it, which usually gives more
// samples; the tool says so on stderr with the chosen value (the tetrahedron has 10 unique samples
// at rate 2, 20 at rate 3).
TEST(BakeCli, SamplesRoundingIsReported) {
    write(tmp("round_tetra.off"), kTetraOff);
    const std::string out = tmp("round.shrefract.exr");
    CommandResult r = run(kBake + " " + tmp("round_tetra.off") + " -o " + out +
                          " --samples 12 --order 1 --grid 4x8 --cache '' -q");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("note: --samples 12: rate 3 gives 20 unique samples"), std::string::npos) << r.out;
    r = run(kBake + " " + tmp("round_tetra.off") + " -o " + out + " --samples 10 --order 1 --grid 4x8 --cache '' -q");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(r.out.find("note:"), std::string::npos) << r.out;  // exactly reached: nothing to say
}

// Order 14 from an 8x16 grid: 120 coefficients from 128 directions, rank-deficient (cos 14 phi
// and cos 2 phi agree at 16 azimuths) and, on the tetrahedron's mostly discounted paths, a float
// solve that came out NaN, which the tool reported as an input error. The weighted fit's double
// path (bake/fit.cpp) solves it: the bake succeeds, and the tool's own check that every weight
// is finite (BakePlan::data) passed.
TEST(BakeCli, RankDeficientWeightedFitStillBakes) {
    write(tmp("aliased_tetra.off"), kTetraOff);
    const std::string out = tmp("aliased.shrefract.exr");
    fs::remove(out);
    const CommandResult r = run(kBake + " " + tmp("aliased_tetra.off") + " -o " + out +
                                " --order 14 --grid 8x16 --samples 20 --cache '' -q");
    EXPECT_EQ(r.code, 0) << r.out;
    EXPECT_TRUE(fs::exists(out));
}

// --search-only: the search's choice and the options that bake it, and no bake. Round trip: the
// printed options, given to a bake, make the model the report chose.
TEST(BakeCli, SearchOnlyPrintsTheOptionsThatBakeItsChoice) {
    write(tmp("search_tetra.off"), kTetraOff);
    const std::string report = tmp("search_report.json");
    fs::remove(report);
    CommandResult r = run(kBake + " " + tmp("search_tetra.off") + " --budget 0.002 --search-only --target-report " +
                          report + " --cache '' -q");
    ASSERT_EQ(r.code, 0) << r.out;
    const std::string lead = "bake it with: ";
    const size_t at = r.out.find(lead);
    ASSERT_NE(at, std::string::npos) << r.out;
    const std::string options = r.out.substr(at + lead.size(), r.out.find('\n', at) - at - lead.size());
    std::ifstream f(report);
    ASSERT_TRUE(f) << "no report written";
    const nlohmann::json chosen = nlohmann::json::parse(f)["chosen"];
    EXPECT_LE(chosen["weightMB"].get<double>(), 0.002);

    const std::string out = tmp("search_choice.shrefract.exr");
    fs::remove(out);
    r = run(kBake + " " + tmp("search_tetra.off") + " -o " + out + " " + options + " --cache '' -q");
    ASSERT_EQ(r.code, 0) << options << "\n" << r.out;
    const shrefract::BakeData b = shrefract::readBake(out);
    EXPECT_EQ(shrefract::nameOf(b.basis), chosen["basis"].get<std::string>());
    if (b.basis == shrefract::Basis::Sh) EXPECT_EQ(b.order, chosen["order"].get<int>());
    EXPECT_EQ(b.layout.rate, chosen["rate"].get<int>());
    EXPECT_EQ(b.grid.ToString(), chosen["grid"].get<std::string>());
    EXPECT_EQ(shrefract::nameOf(b.precision), chosen["precision"].get<std::string>());

    // With -o it is refused (CLI11's usage error), and neither file is written.
    fs::remove(report);
    r = run(kBake + " " + tmp("search_tetra.off") + " -o " + tmp("search_no.shrefract.exr") +
            " --budget 0.002 --search-only --target-report " + report + " -q");
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("excludes"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(report));
    EXPECT_FALSE(fs::exists(tmp("search_no.shrefract.exr")));
    // Without it, a bake needs -o.
    r = run(kBake + " " + tmp("search_tetra.off") + " --budget 0.002 -q");
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("-o,--output is required"), std::string::npos) << r.out;
    // And --search-only needs a search.
    r = run(kBake + " " + tmp("search_tetra.off") + " --search-only -q");
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("--search-only needs --target-error or --budget"), std::string::npos) << r.out;
}

TEST(BakeCli, MissingOutputFolderIsAnErrorBeforeAnyWork) {
    write(tmp("nodir_tetra.off"), kTetraOff);
    CommandResult r = run(kBake + " " + tmp("nodir_tetra.off") + " -o " + tmp("no/such/dir/x.shrefract.exr") + " -q");
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.out.find("does not exist"), std::string::npos) << r.out;
}

TEST(BakeCli, BadInputKeepsAnExistingOutputFile) {
    std::string out = tmp("keep.shrefract.exr");
    write(out, "precious");
    CommandResult r = run(kBake + " " + tmp("nope.off") + " -o " + out + " -q");
    EXPECT_NE(r.code, 0);
    std::ifstream f(out);
    std::string s;
    f >> s;
    EXPECT_EQ(s, "precious");
}

}  // namespace

namespace {

// Ctrl-C (SIGINT) mid-bake: a clean stop, exit 130, no output file and no temporary left; the
// checkpoints finished so far (none after a second) stay for --resume.
TEST(BakeCli, InterruptStopsCleanlyAndWritesNothing) {
    const std::string out = tmp("interrupted.shrefract.exr");
    fs::remove(out);
    fs::remove_all(out + ".work");
    // knot1 at rate 3 takes tens of seconds: long enough to interrupt after one.
    const std::string cmd = "sh -c '" + kBake + " " + std::string(SHREFRACT_DATA_DIR) +
                            "/meshes/knot1.off -o " + out +
                            " --rate 3 --cache \"\" & pid=$!; sleep 1; kill -INT $pid; wait $pid; exit $?'";
    CommandResult r = run(cmd);
    EXPECT_EQ(r.code, 130) << r.out;
    EXPECT_NE(r.out.find("cancelled"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("--resume"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(out));
    fs::remove_all(out + ".work");
    shrefract::test::expectNoStagedFileLeft(out);
}

}  // namespace
