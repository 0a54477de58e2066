// shrefract-bench-shforms: float32 precision and cost of the generator's two SH evaluation forms
// (expanded polynomial vs associated Legendre recurrence; runtime/src/shadergen.h), run by
// scripts/bench-shforms. For each order and form, on an in-memory octahedron bake with weights
// uniform in [-1, 1]:
//   - error_max / error_median: |GL D_mu - double reference| over samples x 4 eyes x 4 channels
//     (tests/runtime/sh_form_error.h: the reference is sum_k w_k y_k in double at the local view
//     direction the GL pass used);
//   - ms: median GL_TIME_ELAPSED of the decompression stage (Refractor::timings().decompress,
//     stage finished inside its query) over --frames updates after a warm-up, for --timing-orders;
//   - abs_sum_max: the polynomial's cancellation measure, max over the order's functions of
//     ShPolynomial::absSum() (digits lost ~ log10 of it).
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "runtime/src/bake_data.h"
#include "common/cli/cli.h"
#include "common/output.h"
#include "shadergen.h"
#include "sh_form_error.h"
#include "shrefract/context.h"

namespace {

using namespace shrefract;

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
}

double maxAbsSum(int L) {
    double m = 0;
    for (const ShLM& f : shEvenFunctions(L)) m = std::max(m, shPolynomial(f.l, f.m).absSum());
    return m;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Precision and cost of the polynomial and recurrence SH forms in GLSL"};
    std::vector<int> orders, timingOrders = {8, 12, 16};
    for (int L = 2; L <= 20; ++L) orders.push_back(L);
    std::string jsonPath;
    Backend backend = Backend::Egl;
    ShaderPreset preset = ShaderPreset::Modern;
    int rate = 16, timingRate = 48, frames = 9;
    app.add_option("--orders", orders, "orders measured for error")->delimiter(',');
    app.add_option("--timing-orders", timingOrders, "orders also timed")->delimiter(',');
    app.add_option("--rate", rate, "layout rate of the error bake (samples per edge)");
    app.add_option("--timing-rate", timingRate, "layout rate of the timing bake");
    app.add_option("--frames", frames, "timed updates per order and form (median)");
    cli::addEnumOption(app, "--backend", backend, "egl | osmesa");
    cli::addEnumOption(app, "--preset", preset, "shader limits: modern | 2006");
    app.add_option("--json", jsonPath, "write the results here");
    return cli::run(app, "shrefract-bench-shforms", argc, argv, [&] {
        auto context = createHeadlessContext(backend);
        nlohmann::json out;
        out["renderer"] = context->description();
        out["preset"] = nameOf(preset);
        out["recurrence_from_order"] = kRecurrenceFromOrder;
        out["rate"] = rate;
        out["timing_rate"] = timingRate;
        out["frames"] = frames;
        out["weights"] = "uniform [-1, 1]";
        out["results"] = nlohmann::json::array();
        std::printf("%s, preset %s\n", context->description().c_str(), nameOf(preset));
        std::printf("order  coeffs  absSum    form        max err    median err  ms\n");
        for (int L : orders) {
            const bool timed =
                std::find(timingOrders.begin(), timingOrders.end(), L) != timingOrders.end();
            BakeData data = test::uniformWeightBake(L, rate);
            Bake bake = makeBake(data);
            Bake timingBake = timed ? makeBake(test::uniformWeightBake(L, timingRate)) : Bake();
            const double absSum = maxAbsSum(L);
            for (const ShForm shForm : {ShForm::Polynomial, ShForm::Recurrence}) {
                const char* form = nameOf(shForm);
                RefractorOptions o;
                o.preset = preset;
                o.form = shForm;
                o.loader = context->loader();
                nlohmann::json row = {{"order", L},
                                      {"form", form},
                                      {"coefficients", shEvenCount(L)},
                                      {"abs_sum_max", absSum}};
                std::unique_ptr<Refractor> r;
                try {
                    r = Refractor::create(bake, o);
                } catch (const std::invalid_argument& e) {  // the form does not fit the limits
                    row["error"] = e.what();
                    out["results"].push_back(row);
                    std::printf("%5d  %6d  %8.3g  %-10s  %s\n", L, shEvenCount(L), absSum, form,
                                e.what());
                    continue;
                }
                test::FormError e = test::measureFormError(*r, data, test::formErrorEyes());
                row["passes"] = r->passCount();
                row["error_max"] = e.max;
                row["error_median"] = e.median;
                row["values"] = e.values;
                double ms = -1;
                if (timed) {
                    auto t = Refractor::create(timingBake, o);
                    t->update(FrameView::fromEye({0.3f, 0.8f, 3.0f}));  // warm-up: llvmpipe compiles at first draw
                    std::vector<double> v;
                    for (int f = 0; f < frames; ++f) {
                        t->update(FrameView::fromEye({0.3f + 0.01f * f, 0.8f, 3.0f}));
                        v.push_back(t->timings().decompress);
                    }
                    ms = median(v);
                    row["ms"] = ms;
                    row["timing_samples"] = timingBake.sampleCount();
                }
                out["results"].push_back(row);
                std::printf("%5d  %6d  %8.3g  %-10s  %9.3g  %9.3g", L, shEvenCount(L), absSum, form,
                            e.max, e.median);
                if (timed) std::printf("  %7.2f", ms);
                std::printf("\n");
                std::fflush(stdout);
            }
        }
        if (!jsonPath.empty()) writeFile(jsonPath, out.dump(2) + "\n");
        return cli::kOk;
    });
}
