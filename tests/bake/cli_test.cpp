// shrefract-bake and shrefract-eval as a user meets them: bad input gets a clear error naming
// the file, a non-zero exit and no output file; what is already on disk is kept.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

struct CommandResult {
    int code;
    std::string out;  // stdout and stderr together
};

CommandResult run(const std::string& args) {
    fs::create_directories(SHREFRACT_TEST_TMP);
    // One log per test: ctest runs the cases as parallel processes.
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "." + info->name();
    std::replace(name.begin(), name.end(), '/', '_');
    std::string log = std::string(SHREFRACT_TEST_TMP) + "/log_" + name + ".txt";
    int status = std::system((args + " > " + log + " 2>&1").c_str());
    std::ifstream f(log);
    std::stringstream ss;
    ss << f.rdbuf();
    return CommandResult{WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
}

std::string tmp(const std::string& name) { return std::string(SHREFRACT_TEST_TMP) + "/" + name; }

void write(const std::string& path, const std::string& text) {
    fs::create_directories(fs::path(path).parent_path());
    std::ofstream(path) << text;
}

const std::string kBake = SHREFRACT_BAKE_EXE;
const std::string kEval = SHREFRACT_EVAL_EXE;
constexpr const char* kTetra = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

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
    EXPECT_NE(r.code, 0) << r.out;
    EXPECT_NE(r.out.find(c.expect), std::string::npos) << "message: " << r.out;
    EXPECT_FALSE(fs::exists(out));
    for (auto& e : fs::directory_iterator(SHREFRACT_TEST_TMP))
        EXPECT_NE(e.path().string().rfind(out + ".tmp", 0), 0u) << "left behind: " << e.path();
}

INSTANTIATE_TEST_SUITE_P(
    BadInput, BakeRejects,
    ::testing::Values(
        BadCase{"missing", "nope.off", nullptr, "", "nope.off"},
        BadCase{"extension", "mesh.xyz", "hello", "", "mesh.xyz"},
        BadCase{"garbage", "garbage.off", "this is not a mesh\n", "", "garbage.off"},
        BadCase{"empty", "empty.off", "", "", "empty.off"},
        BadCase{"nan", "nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n", "", "nan.off"},
        BadCase{"order", "tetra.off", kTetra, "--order 99", "order"},
        BadCase{"rate", "tetra.off", kTetra, "--rate 0", "rate"},
        BadCase{"grid", "tetra.off", kTetra, "--grid 3x5", "grid"},
        BadCase{"gridtext", "tetra.off", kTetra, "--grid banana", "grid"},
        BadCase{"ior", "tetra.off", kTetra, "--ior 0.5", "ior"},
        BadCase{"precision", "tetra.off", kTetra, "--precision f64", "precision"},
        BadCase{"scene", "scene.json", "{\"parts\": [{\"mesh\": \"tetra.off\", \"ior\": -2}]}", "", "scene.json"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(BakeCli, MissingOutputFolderIsAnErrorBeforeAnyWork) {
    write(tmp("nodir_tetra.off"), kTetra);
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

// A whole small bake, then the evaluation tools on it: the error table, and query answers
// agreeing with the table's decompression at sample positions.
TEST(BakeCli, BakesAndEvaluatesATetrahedron) {
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

namespace {

// Ctrl-C (SIGINT) mid-bake: a clean stop, exit 130, no output file and no temporary left.
TEST(BakeCli, InterruptStopsCleanlyAndWritesNothing) {
    const std::string out = tmp("interrupted.shrefract.exr");
    fs::remove(out);
    // knot1 at rate 3 takes tens of seconds: long enough to interrupt after one.
    const std::string cmd = "sh -c '" + kBake + " " + std::string(SHREFRACT_DATA_DIR) +
                            "/meshes/knot1.off -o " + out +
                            " --rate 3 --cache \"\" & pid=$!; sleep 1; kill -INT $pid; wait $pid; exit $?'";
    CommandResult r = run(cmd);
    EXPECT_EQ(r.code, 130) << r.out;
    EXPECT_NE(r.out.find("cancelled"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(out));
    for (auto& e : fs::directory_iterator(SHREFRACT_TEST_TMP))
        EXPECT_NE(e.path().string().rfind(out + ".tmp", 0), 0u) << "left behind: " << e.path();
}

}  // namespace
