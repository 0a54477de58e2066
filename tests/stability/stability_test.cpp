// Where methods fail, on purpose (docs/design.md#where-methods-fail): each case goes through the
// bake, the evaluation against fresh traces and a GL render, and must finish with finite outputs,
// its trouble reported as shares of affected paths, and errors bounded where the method should
// cope.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "runtime/src/bake_data.h"
#include "bake/bake.h"
#include "eval/directions.h"
#include "common/error.h"
#include "shrefract/context.h"
#include "shrefract/render.h"
#include "shrefract/runtime.h"
#include "test_meshes.h"

namespace shrefract {
namespace {

namespace fs = std::filesystem;
const std::string kData = SHREFRACT_DATA_DIR;
const std::string kTmp = SHREFRACT_TEST_TMP;

struct CaseResult {
    nlohmann::json row;
    nlohmann::json eval;
    BakeData bake;
};

bool allFinite(const std::vector<float>& v) {
    for (float x : v)
        if (!std::isfinite(x)) return false;
    return true;
}

// A tiny lat-long environment: sky gradient and a bright sun, enough to tell pixels apart.
const Environment& environment() {
    static Environment env = [] {
        int w = 64, h = 32;
        std::vector<float> rgb(size_t(w) * h * 3);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                float t = float(y) / h, sun = (std::abs(x - 40) < 2 && std::abs(y - 8) < 2) ? 20.0f : 0.0f;
                float* p = &rgb[(size_t(y) * w + x) * 3];
                p[0] = 0.2f + 0.8f * t + sun, p[1] = 0.4f + 0.5f * t + sun, p[2] = 1.0f - 0.6f * t + sun;
            }
        return Environment::fromLatLong(w, h, rgb);
    }();
    return env;
}

// Bakes, evaluates and renders one case; writes its row for docs/stability.md.
CaseResult runCase(const std::string& name, const std::string& what, const Scene& scene,
                   BakeOptions opt, float zMin = 0.0f, float zMax = 1.0f, int evalOrder = -1) {
    opt.cacheDir = kTmp + "/mcache";
    BakeResult b = bake(scene, opt, "<in memory>");
    const BakeStats& s = b.stats;
    CaseResult r;
    EXPECT_TRUE(allFinite(b.data.weights)) << name << ": non-finite SH weight";
    // Through the file, at the requested precision, as an app would load it.
    fs::create_directories(kTmp);
    std::string path = kTmp + "/" + name + ".shrefract.exr";
    writeBake(path, b.data);
    r.bake = readBake(path);
    EXPECT_TRUE(allFinite(r.bake.weights)) << name;

    r.eval = evaluateDirections(r.bake, scene, 20000, 5, evalOrder, zMin, zMax);
    for (const char* k : {"mean", "median", "p95", "max"})
        EXPECT_TRUE(std::isfinite(r.eval["angleDeg"][k].get<double>())) << name << " " << k;

    // The GL runtime on the same bake: no NaN anywhere, the object covered.
    nlohmann::json render = {{"ran", false}};
    try {
        auto ctx = createHeadlessContext(Backend::Egl, 64, 64);
        RefractorOptions ro;
        ro.loader = ctx->loader();
        auto refractor = Refractor::create(makeBake(r.bake), ro);
        glm::vec3 lo = scene.parts[0].mesh.boundsMin(), hi = scene.parts[0].mesh.boundsMax();
        float radius = 0.5f * glm::length(hi - lo);
        Camera cam = Camera::orbit(30, 20, 3.0f * radius, 0.5f * (lo + hi));
        RenderedFrame f = renderFrame(*refractor, environment(), cam, 64, 64);
        size_t covered = 0;
        for (size_t i = 3; i < f.directions.size(); i += 4) covered += f.directions[i] > 0.5f;
        EXPECT_TRUE(allFinite(f.color)) << name << ": NaN/inf in the rendered colour";
        EXPECT_TRUE(allFinite(f.directions)) << name << ": NaN/inf in the direction buffer";
        EXPECT_GT(covered, 0u) << name << ": object not drawn";
        render = {{"ran", true}, {"finite", allFinite(f.color) && allFinite(f.directions)},
                  {"coverage", double(covered) / (64 * 64)}};
    } catch (const ContextError& e) {
        render = {{"ran", false}, {"why", e.what()}};
    }

    auto share = [&](size_t k) { return double(k) / double(std::max<size_t>(1, s.paths)); };
    r.row = {{"case", name}, {"what", what}, {"samples", s.samples}, {"paths", s.paths},
             {"raysPerPath", double(s.rays) / std::max<size_t>(1, s.paths)},
             {"tir", share(s.tir)}, {"capped", share(s.capped)}, {"softCapped", share(s.softCapped)},
             {"reentered", share(s.reentered)}, {"geometricNormal", share(s.geometricNormal)},
             {"leaked", share(s.leaked)}, {"precision", nameOf(opt.precision)}, {"order", opt.order},
             {"directions", r.eval}, {"render", render}};
    fs::create_directories(kTmp + "/rows");
    std::ofstream(kTmp + "/rows/" + name + ".json") << r.row.dump(2) << "\n";
    return r;
}

BakeOptions small(int order = 8) {
    BakeOptions o;
    o.rate = 1;
    o.order = order;
    return o;
}

double median(const CaseResult& r) { return r.eval["angleDeg"]["median"].get<double>(); }

// The bakes and evaluations are deterministic (fixed seeds, batches independent of threading), so
// each case's median error is a measured number (docs/stability.md); it may grow by at most 30%
// before the test fails. A looser bound (the 45 degrees these tests had) lets a wrong Fresnel or
// filter through.
void expectMedianNear(const CaseResult& r, double measured) {
    EXPECT_LT(median(r), 1.3 * measured) << r.row["case"].get<std::string>() << ": measured "
                                         << measured << " deg when this limit was set";
}

Scene load(const std::string& rel, double ior = 1.5) {
    Medium m;
    m.ior = ior;
    return loadScene(kData + "/" + rel, m);
}

TEST(Stability, DiamondIorTotalInternalReflection) {
    CaseResult glass = runCase("glass_sphere", "IOR 1.5 sphere (1280 triangles), for comparison",
                               load("scenes/icosphere.off"), small());
    CaseResult r = runCase("diamond", "IOR 2.42 sphere: more internal reflection",
                           load("scenes/diamond.json"), small());
    // On a perfect sphere TIR cannot happen (the internal angle equals the refracted one);
    // on the facets it does, and more often at IOR 2.42: measured 7.2% vs 6.6% of paths.
    EXPECT_GT(r.row["tir"].get<double>(), glass.row["tir"].get<double>());
    expectMedianNear(glass, 2.11);
    expectMedianNear(r, 2.32);
}

TEST(Stability, GrazingEntry) {
    CaseResult all = runCase("sphere_all", "sphere, all view directions", load("scenes/icosphere.off"), small());
    CaseResult r = runCase("grazing", "sphere, view directions within 6 deg of the tangent plane",
                           load("scenes/icosphere.off"), small(), 0.0f, 0.1f);
    // Grazing entry is where the method fails: the mapping turns fast there and the mirror
    // across the equator puts a kink in it, which SH of order 8 cannot follow. Measured median
    // 54.7 deg against 2.1 over the whole hemisphere; the test pins that the failure is
    // confined to grazing directions.
    EXPECT_GT(median(r), 5 * median(all));
    expectMedianNear(all, 2.11);
}

TEST(Stability, SphereWhisperingGallery) {
    BakeOptions o = small();
    o.trace.maxBounces = 8;  // a low cap makes the whispering-gallery paths hit it
    CaseResult r = runCase("whispering", "sphere, cap 8: grazing paths circle inside until capped",
                           load("scenes/icosphere.off"), o, 0.0f, 0.05f);
    EXPECT_GT(r.row["softCapped"].get<double>() + r.row["capped"].get<double>(), 0.0);
    expectMedianNear(r, 22.05);
}

TEST(Stability, BeadInShell) {
    CaseResult r = runCase("bead_in_shell", "glass shell (r 1, 0.9) around a bead (r 0.4): depth complexity 6",
                           load("scenes/bead_in_shell.json"), small());
    expectMedianNear(r, 1.77);
}

TEST(Stability, ThinShell) {
    Mesh shell = test::icosphere(3, 1.0f);
    Mesh inner = test::icosphere(3, 0.97f);
    for (auto& t : inner.triangles) std::swap(t[1], t[2]);
    for (auto& n : inner.normals) n = -n;
    test::append(shell, inner);
    CaseResult r = runCase("thin_shell", "sphere shell 3% thick", test::sceneOf(shell), small());
    expectMedianNear(r, 0.28);
}

TEST(Stability, FlatFacesAndFilterAgainstRinging) {
    // A box: the mapping jumps where a path crosses an edge; SH rings (Gibbs). The
    // semi-Gaussian filter trades ringing for blur.
    Scene box = test::sceneOf(test::flatBox({-1, -1, -1}, {1, 1, 1}));
    BakeOptions o = small();
    CaseResult raw = runCase("box_nofilter", "flat-faced box, no SH filter: discontinuities, Gibbs", box, o);
    o.filterWidth = 4;
    CaseResult filtered = runCase("box_filter4", "flat-faced box, semi-Gaussian filter width 4", box, o);
    expectMedianNear(raw, 1.84);
    expectMedianNear(filtered, 1.24);
}

TEST(Stability, CoarseMeshesWithoutShadingNormals) {
    CaseResult sphere = runCase("coarse_sphere", "162-vertex sphere, normals computed (none in file)",
                                load("meshes/sphere.off"), small());
    CaseResult cube = runCase("coarse_cube", "8-vertex cube: corner normals averaged over 3 faces",
                              load("scenes/cube.off"), small());
    EXPECT_GT(cube.row["geometricNormal"].get<double>(), 0.0);  // the fallback is exercised
    expectMedianNear(sphere, 2.73);
    expectMedianNear(cube, 9.44);
}

TEST(Stability, DegenerateAndSliverTriangles) {
    // A tetrahedron whose bottom face is a fan around a point 1e-4 from an edge (two slivers),
    // plus a zero-area triangle that the loader skips.
    fs::create_directories(kTmp);
    std::string path = kTmp + "/sliver.off";
    std::ofstream(path) << "OFF\n5 6 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0.5 0.0001 0\n"
                           "3 0 2 4\n3 2 1 4\n3 1 0 4\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    std::string degenerate = kTmp + "/sliver_degenerate.off";
    std::ofstream(degenerate) << "OFF\n6 7 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0.5 0.0001 0\n2 2 2\n"
                                 "3 0 2 4\n3 2 1 4\n3 1 0 4\n3 0 1 3\n3 0 3 2\n3 1 2 3\n3 5 5 5\n";
    Scene s = loadScene(degenerate);
    EXPECT_GE(s.parts[0].report.degenerateTriangles, 1u);
    expectMedianNear(runCase("sliver", "tetrahedron with two sliver triangles (1e-4 high) and a skipped degenerate one", s, small()), 2.54);
}

TEST(Stability, OpenAndNonManifoldMeshes) {
    CaseResult open = runCase("open_cube", "cube missing a face: paths leak out", load("scenes/open_cube.off"), small());
    EXPECT_GT(open.row["leaked"].get<double>(), 0.0);  // counted, not hidden
    expectMedianNear(open, 5.63);
    fs::create_directories(kTmp);
    std::string fin = kTmp + "/fin.off";
    std::ofstream(fin) << "OFF\n5 5 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0.5 -1 0.5\n"
                          "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n3 0 1 4\n";
    Scene s = loadScene(fin);
    EXPECT_EQ(s.parts[0].report.nonManifoldEdges, 1u);
    expectMedianNear(runCase("nonmanifold", "tetrahedron with a fin on one edge (non-manifold)", s, small()), 1.64);
}

TEST(Stability, VeryLargeAndVerySmallScales) {
    CaseResult unit = runCase("scale_1", "sphere at unit scale", load("scenes/icosphere.off"), small());
    for (double scale : {1e-4, 1e4}) {
        fs::create_directories(kTmp);
        std::string scene = kTmp + "/scaled.json";
        std::ofstream(scene) << "{\"parts\": [{\"mesh\": \"" << kData << "/scenes/icosphere.off\", \"scale\": " << scale
                             << "}]}";
        char name[32];
        std::snprintf(name, sizeof name, "scale_%g", scale);
        CaseResult r = runCase(name, std::string("sphere scaled by ") + (name + 6), loadScene(scene), small());
        // Angles do not care about scale; offsets scale with the scene. Measured equal to the
        // unit-scale medians to 0.01 deg.
        EXPECT_NEAR(median(r), median(unit), 0.1) << name;
        double lenRatio = r.eval["lengthError"]["median"].get<double>() /
                          std::max(1e-12, unit.eval["lengthError"]["median"].get<double>());
        EXPECT_NEAR(lenRatio, scale, 0.05 * scale) << "length errors scale with the object";
    }
}

TEST(Stability, EightBitWeights) {
    Scene s = load("meshes/cow.off");
    CaseResult f32 = runCase("cow_f32", "cow, float32 weights", s, small());
    BakeOptions o = small();
    o.precision = Precision::U8;
    CaseResult u8 = runCase("cow_u8", "cow, 8-bit weights (per-coefficient scale/offset)", s, o);
    // The paper's Figure 5 claim, measured: 8-bit costs little next to SH truncation itself.
    EXPECT_LT(median(u8) - median(f32), 1.0);
    expectMedianNear(f32, 14.14);
}

TEST(Stability, HighOrderInFloat32) {
    CaseResult r = runCase("order16", "sphere at order 16 (153 coefficients), float32 everywhere",
                           load("scenes/icosphere.off"), small(16));
    CaseResult r8 = runCase("order8", "sphere at order 8", load("scenes/icosphere.off"), small(8));
    EXPECT_LT(median(r), median(r8) + 0.5);  // more bands must not make it worse
    expectMedianNear(r, 1.68);
    expectMedianNear(r8, 2.11);
}

}  // namespace
}  // namespace shrefract
