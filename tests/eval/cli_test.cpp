// shrefract-eval as a user meets it: the error table and point queries on a real bake.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "common/bakefile.h"
#include "common/evalbuffer.h"
#include "eval/image_eval.h"
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
const std::string kEval = SHREFRACT_EVAL_EXE;
const std::string kRender = SHREFRACT_RENDER_EXE;

// Queries `bake` with the rows `csv` (written to NAME.csv): refused with exit 2, the message
// "NAME.csv: WHAT", and no answer file.
void expectQueryRefused(const std::string& bake, const std::string& name, const std::string& csv,
                        const std::string& what) {
    const std::string in = tmp(name + ".csv"), answers = tmp(name + "_a.csv");
    write(in, csv);
    fs::remove(answers);
    CommandResult r = run(kEval + " query " + bake + " --in " + in + " --out " + answers);
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find(in + ": " + what), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(answers));
}

// A whole small bake, then the evaluation tools on it: the error table, and query answers
// agreeing with the table's decompression at sample positions.
TEST(EvalCli, BakesAndEvaluatesATetrahedron) {
    write(tmp("full_tetra.off"), kTetraOff);
    std::string out = tmp("tetra.shrefract.exr");
    fs::remove(out);
    CommandResult b = run(kBake + " " + tmp("full_tetra.off") + " -o " + out + " --rate 2 --grid 8x16 --order 4 --cache ''");
    ASSERT_EQ(b.code, 0) << b.out;
    EXPECT_NE(b.out.find("samples"), std::string::npos);
    EXPECT_TRUE(fs::exists(out));
    CommandResult e = run(kEval + " directions " + out + " --pairs 2000 --json " + tmp("tetra.json"));
    ASSERT_EQ(e.code, 0) << e.out;
    EXPECT_NE(e.out.find("median"), std::string::npos);
    EXPECT_TRUE(fs::exists(tmp("tetra.json")));

    write(tmp("q.csv"), "px,py,pz,wx,wy,wz\n0.2,0.2,0,0,0,-1\n0.1,0,0.1,0,-1,0\n");
    CommandResult q = run(kEval + " query " + out + " --in " + tmp("q.csv") + " --out " + tmp("a.csv"));
    ASSERT_EQ(q.code, 0) << q.out;
    std::ifstream a(tmp("a.csv"));
    std::string header, line;
    std::getline(a, header);
    EXPECT_EQ(header, "ex,ey,ez,len");
    int rows = 0;
    while (std::getline(a, line)) ++rows;
    EXPECT_EQ(rows, 2);

    write(tmp("bad.csv"), "1,2,3\n");
    CommandResult qb = run(kEval + " query " + out + " --in " + tmp("bad.csv") + " --out " + tmp("b.csv"));
    EXPECT_EQ(qb.code, 2);
    EXPECT_NE(qb.out.find("bad.csv"), std::string::npos) << qb.out;
    EXPECT_FALSE(fs::exists(tmp("b.csv")));

    // A point 5 units off the surface, and a direction into the surface, are refused with the
    // line named (the bake knows nothing there); a point within --max-distance is answered.
    expectQueryRefused(out, "off", "px,py,pz,wx,wy,wz\n0.2,0.2,0,0,0,-1\n0.2,0.2,-5,0,0,-1\n",
                       "line 3: point (0.2, 0.2, -5) is 5 from the surface");
    expectQueryRefused(out, "off", "0.2,0.2,0,0,0,-1\n\n0.2,0.2,0,0.1,0,1\n",
                       "line 3: view direction (0.1, 0, 1) points into the surface");
    write(tmp("near.csv"), "0.2,0.2,-0.01,0,0,-1\n");
    CommandResult near = run(kEval + " query " + out + " --in " + tmp("near.csv") + " --out " + tmp("near_a.csv"));
    EXPECT_EQ(near.code, 2) << near.out;  // 0.01 off: beyond 0.001 of the diagonal (1.7e-3)
    near = run(kEval + " query " + out + " --in " + tmp("near.csv") + " --out " + tmp("near_a.csv") +
               " --max-distance 0.02");
    EXPECT_EQ(near.code, 0) << near.out;

    // An --order the bake does not store is refused, not clamped.
    CommandResult o = run(kEval + " directions " + out + " --pairs 10 --order 5");
    EXPECT_EQ(o.code, 2) << o.out;
    EXPECT_NE(o.out.find("--order 5: " + out + " stores orders 0..4"), std::string::npos) << o.out;
}

// A chart bake (its atlas, not the joining grid) refuses the same queries: a point off the surface
// and a view direction into it, with the line named; a point on it is answered.
TEST(EvalCli, ChartBakeQueriesAreRefusedOffTheSurface) {
    write(tmp("chart_tetra.off"), kTetraOff);
    const std::string out = tmp("chart_tetra.shrefract.exr");
    fs::remove(out);
    CommandResult b = run(kBake + " " + tmp("chart_tetra.off") + " -o " + out +
                          " --layout isolated --samples 300 --grid 8x16 --order 4 --cache ''");
    ASSERT_EQ(b.code, 0) << b.out;
    expectQueryRefused(out, "chart_off", "0.2,0.2,-5,0,0,-1\n", "line 1: point (0.2, 0.2, -5) is 5 from the surface");
    expectQueryRefused(out, "chart_off", "0.2,0.2,0,0,0,-1\n0.2,0.2,0,0.1,0,1\n",
                       "line 2: view direction (0.1, 0, 1) points into the surface");
    write(tmp("chart_on.csv"), "0.2,0.2,0,0,0,-1\n");
    fs::remove(tmp("chart_on_a.csv"));
    CommandResult on = run(kEval + " query " + out + " --in " + tmp("chart_on.csv") + " --out " + tmp("chart_on_a.csv"));
    EXPECT_EQ(on.code, 0) << on.out;
    EXPECT_TRUE(fs::exists(tmp("chart_on_a.csv")));
}

// adaptive --write-bakes: one readable bake per tolerance, its manifest naming the orders; at a
// tolerance no reconstruction can exceed, every sample keeps band 0 alone. A prefix in a missing
// folder is refused before any work.
TEST(EvalCli, AdaptiveWritesThePerSampleOrderBakes) {
    write(tmp("adaptive_tetra.off"), kTetraOff);
    const std::string bake = tmp("adaptive_tetra.shrefract.exr"), prefix = tmp("adaptive_tetra_po");
    fs::remove(bake);
    CommandResult b = run(kBake + " " + tmp("adaptive_tetra.off") + " -o " + bake +
                          " --rate 2 --grid 8x16 --order 4 --precision f32 --cache ''");
    ASSERT_EQ(b.code, 0) << b.out;
    fs::remove(prefix + "_180.shrefract.exr");
    CommandResult a = run(kEval + " adaptive " + bake + " --tolerances 180 --pairs 200 --write-bakes " + prefix);
    ASSERT_EQ(a.code, 0) << a.out;
    const shrefract::BakeData d = shrefract::readBake(prefix + "_180.shrefract.exr");
    EXPECT_EQ(d.manifest["perSampleOrder"]["meanOrder"].get<double>(), 0.0);
    const size_t n = size_t(d.layout.sampleCount());
    for (size_t k = n * 4; k < d.weights.size(); ++k) ASSERT_EQ(d.weights[k], 0.0f) << "weight " << k;
    CommandResult missing = run(kEval + " adaptive " + bake + " --tolerances 180 --write-bakes " +
                                tmp("no_such_folder/po"));
    EXPECT_EQ(missing.code, 2) << missing.out;
    EXPECT_NE(missing.out.find("no_such_folder"), std::string::npos) << missing.out;
}

// One exit-code table for every tool (README "Exit codes"): 0 for --help and --version (which names
// the project and format versions), 2 for a usage error CLI11 reports (its own codes are 105-109)
// and for bad input, with one "TOOL: error:" line.
TEST(EvalCli, EveryToolSharesTheExitCodes) {
    const std::pair<std::string, std::string> tools[] = {{kBake, "shrefract-bake"},
                                                         {kEval, "shrefract-eval"},
                                                         {kRender, "shrefract-render"}};
    for (const auto& [exe, name] : tools) {
        CommandResult v = run(exe + " --version");
        EXPECT_EQ(v.code, 0) << v.out;
        EXPECT_EQ(v.out.find(name + " "), 0u) << v.out;
        EXPECT_NE(v.out.find("(bake format " + std::to_string(shrefract::kFormatVersion) + ")"), std::string::npos) << v.out;
        EXPECT_EQ(run(exe + " --help").code, 0) << name;
        CommandResult u = run(exe + " --no-such-option");
        EXPECT_EQ(u.code, 2) << name << ": " << u.out;
    }
    CommandResult r = run(kRender + " " + tmp("missing.shrefract.exr") + " --env x.exr --size 8x8");
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("shrefract-render: error: " + tmp("missing.shrefract.exr") + ": file not found"),
              std::string::npos) << r.out;
}

// image --test-png: a reference buffer against a display image; the report has the colour and
// object keys, and the options that need directions are refused with a reason.
TEST(EvalCli, ImageComparesABufferWithADisplayPng) {
    fs::create_directories(tmp(""));
    shrefract::EvalBuffer ref;
    ref.width = 6, ref.height = 4;
    for (int i = 0; i < 24; ++i) {
        ref.color.emplace_back(0.5f, 0.5f, 0.5f, i < 12 ? 1.0f : 0.0f);
        ref.direction.emplace_back(0, 0, i < 12 ? 1 : 0);
    }
    shrefract::writeEvalBuffer(tmp("png_ref.exr"), ref);
    shrefract::Image8 png;
    png.resize(6, 4, 100);
    shrefract::writePng8(tmp("png_test.png"), png);
    CommandResult r = run(kEval + " image --ref " + tmp("png_ref.exr") + " --test-png " + tmp("png_test.png") +
                          " --json " + tmp("png_report.json"));
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("object (reference coverage, 12 pixels): PSNR"), std::string::npos) << r.out;
    std::ifstream report(tmp("png_report.json"));
    const std::string text((std::istreambuf_iterator<char>(report)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("\"objectFlip\""), std::string::npos) << text;
    EXPECT_EQ(text.find("\"angleDeg\""), std::string::npos) << text;
    CommandResult heat = run(kEval + " image --ref " + tmp("png_ref.exr") + " --test-png " + tmp("png_test.png") +
                             " --heatmap " + tmp("png_heat.png"));
    EXPECT_EQ(heat.code, 2) << heat.out;
    EXPECT_NE(heat.out.find("--heatmap and --flip-map need --test"), std::string::npos) << heat.out;
    CommandResult both = run(kEval + " image --ref " + tmp("png_ref.exr") + " --test " + tmp("png_ref.exr") +
                             " --test-png " + tmp("png_test.png"));
    EXPECT_EQ(both.code, 2) << both.out;
    CommandResult none = run(kEval + " image --ref " + tmp("png_ref.exr"));
    EXPECT_EQ(none.code, 2) << none.out;
}

}  // namespace
