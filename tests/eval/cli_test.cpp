// shrefract-eval as a user meets it: the error table and point queries on a real bake.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/cli_run.h"

namespace {

namespace fs = std::filesystem;
using shrefract::test::CommandResult;
using shrefract::test::run;
using shrefract::test::tmp;
const auto& write = shrefract::test::writeText;

const std::string kBake = SHREFRACT_BAKE_EXE;
const std::string kEval = SHREFRACT_EVAL_EXE;
constexpr const char* kTetra = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

// A whole small bake, then the evaluation tools on it: the error table, and query answers
// agreeing with the table's decompression at sample positions.
TEST(EvalCli, BakesAndEvaluatesATetrahedron) {
    write(tmp("full_tetra.off"), kTetra);
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
    EXPECT_NE(qb.code, 0);
    EXPECT_NE(qb.out.find("bad.csv"), std::string::npos) << qb.out;
    EXPECT_FALSE(fs::exists(tmp("b.csv")));
}

}  // namespace
