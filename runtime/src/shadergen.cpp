#include "shadergen.h"

#include "shaders.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "common/sh.h"

namespace shrefract {

ShaderLimits shaderPreset(ShaderPreset preset, int maxTextureUnits) {
    ShaderLimits l;
    l.name = nameOf(preset);
    if (preset == ShaderPreset::Paper2006) {
        l.maxTextureUnits = 16;
        l.maxAluInstructions = 64;
        l.weightArray = false;
        l.vertexTextureFetch = false;
    } else {
        l.maxTextureUnits = maxTextureUnits;
        l.maxAluInstructions = 0;
        l.weightArray = true;
    }
    return l;
}

ShForm resolveShForm(ShForm form, int order) {
    if (form != ShForm::Auto) return form;
    return order >= kRecurrenceFromOrder ? ShForm::Recurrence : ShForm::Polynomial;
}

namespace {

constexpr double kPi = 3.14159265358979323846;

// Normalized associated Legendre recurrence on Q_l^m = Pbar_l^m / s^m (s = sin theta), the
// same coefficients as common/sh.cpp (no Condon-Shortley phase):
//   Q_m^m = prod_{k=1..m} sqrt((2k+1)/(2k)) / sqrt(4 pi),  Q_{m+1}^m = sqrt(2m+3) z Q_m^m,
//   Q_l^m = a_l^m (z Q_{l-1}^m - b_l^m Q_{l-2}^m),
//   a_l^m = sqrt((4l^2-1)/(l^2-m^2)),  b_l^m = sqrt(((l-1)^2-m^2)/(4(l-1)^2-1)).
// y_l^0 = Q_l^0; y_l^{+-m} = sqrt2 Q_l^m Re/Im (x+iy)^m, the sqrt2 folded into Q_m^m (m > 0).
double recA(int l, int m) { return std::sqrt((4.0 * l * l - 1.0) / (double(l) * l - double(m) * m)); }
double recB(int l, int m) {
    return std::sqrt((double(l - 1) * (l - 1) - double(m) * m) / (4.0 * (l - 1) * (l - 1) - 1.0));
}
double recStart(int m) {
    double p = 1.0 / std::sqrt(4.0 * kPi);
    for (int k = 1; k <= m; ++k) p *= std::sqrt((2.0 * k + 1.0) / (2.0 * k));
    return m > 0 ? std::sqrt(2.0) * p : p;
}

// What a recurrence pass computes: the powers (x + iy)^m through maxPower, and column m through
// l = top[m]. add() extends them for y_l^m and returns the ALU spent (cost model in the header).
struct RecurrenceSet {
    int maxPower = 1;          // re_1 = x, im_1 = y are free
    std::map<int, int> top;    // |m| -> largest l computed in that column
    int add(int l, int m) {
        int am = std::abs(m), cost = 0;
        if (am > maxPower) {
            cost += 4 * (am - maxPower);
            maxPower = am;
        }
        auto it = top.find(am);
        int from = it == top.end() ? am : it->second;
        for (int j = from + 1; j <= l; ++j) cost += j == am + 1 ? 1 : 3;
        top[am] = std::max(from, l);
        return cost;
    }
};

struct Mono {
    int a = 0, b = 0, c = 0;
    int degree() const { return a + b + c; }
    bool operator<(const Mono& o) const {
        return std::tie(a, b, c) < std::tie(o.a, o.b, o.c);
    }
};

std::string monoName(const Mono& m) {
    std::string s;
    for (auto [v, e] : {std::pair{'x', m.a}, {'y', m.b}, {'z', m.c}}) {
        if (e == 0) continue;
        s += v;
        if (e > 1) s += std::to_string(e);
    }
    return s;
}

// The monomials a pass computes, in an order where each one's factor comes before it.
struct MonoSet {
    std::vector<Mono> order;
    std::map<Mono, std::pair<Mono, char>> factor;  // m = factor.first * factor.second

    bool has(const Mono& m) const { return m.degree() <= 1 || factor.count(m); }
    // Adds m and what it needs; returns the MULs spent.
    int add(const Mono& m) {
        if (has(m)) return 0;
        const std::pair<Mono, char> preds[] = {{{m.a, m.b, m.c - 1}, 'z'},
                                               {{m.a, m.b - 1, m.c}, 'y'},
                                               {{m.a - 1, m.b, m.c}, 'x'}};
        auto valid = [](const Mono& p) { return p.a >= 0 && p.b >= 0 && p.c >= 0; };
        int cost = 0;
        const std::pair<Mono, char>* pick = nullptr;
        for (const auto& p : preds)
            if (valid(p.first) && has(p.first)) { pick = &p; break; }
        if (!pick) {
            for (const auto& p : preds)
                if (valid(p.first)) { pick = &p; break; }
            cost += add(pick->first);
        }
        factor[m] = *pick;
        order.push_back(m);
        return cost + 1;
    }
};

struct PassPlan {
    std::vector<int> functions;
    MonoSet monos;
    RecurrenceSet rec;
    int alu = 1;  // the output
    int units = 1;  // the local view
};

std::string literal(double v) {
    char b[40];
    std::snprintf(b, sizeof b, "%.9g", v);
    std::string s = b;
    if (s.find_first_of(".en") == std::string::npos) s += ".0";
    return s;
}

// The value of y_k as a GLSL expression over the pass's monomials, coefficients pre-multiplied.
std::string polyExpression(const ShPolynomial& p) {
    std::string e;
    for (size_t i = 0; i < p.terms.size(); ++i) {
        const Monomial& t = p.terms[i];
        double c = static_cast<double>(t.num) * p.scale;
        Mono m{t.a, t.b, t.c};
        std::string factor = m.degree() == 0 ? literal(std::abs(c))
                                              : literal(std::abs(c)) + " * " + monoName(m);
        if (i == 0)
            e += (c < 0 ? "-" : "") + factor;
        else
            e += (c < 0 ? " - " : " + ") + factor;
    }
    return e.empty() ? "0.0" : e;
}

// The generated part of a pass: its header comment, the weight samplers and
//   vec4 shPass(ivec2 p, vec3 w, vec4 s)
// which returns s plus weight(p) x y_k(w) for every function k of the pass. It replaces the
// "#pragma shrefract_generated" line of shaders/decompress.frag.
std::string generatedPass(const DecompressionShaders& s, int index, const PassPlan& plan,
                          const std::vector<ShPolynomial>& polys, DecompressionPass& pass) {
    const bool first = index == 0;
    const ShaderLimits& l = s.limits;
    std::ostringstream o;
    o << "// shrefract SH decompression, pass " << index + 1 << " of " << s.passes.size()
      << ": order " << s.order << ", limits \"" << l.name << "\" (" << l.maxTextureUnits
      << " texture units, "
      << (l.maxAluInstructions > 0 ? std::to_string(l.maxAluInstructions) : "unlimited")
      << " ALU).\n"
      << "// Generated by runtime/src/shadergen.cpp; do not edit. Estimated ALU " << plan.alu
      << ", texture units " << plan.units << ".\n";
    if (s.form == ShForm::Recurrence)
        o << "// Form: associated Legendre recurrence, Q_l^m = Pbar_l^m / sin^m theta, times\n"
          << "// Re/Im (x + iy)^m (no trigonometry, no division; common/sh.cpp shEvalEven).\n";
    pass.samplers.push_back({SamplerBinding::LocalView, -1, "uLocalView"});
    if (!first) pass.samplers.push_back({SamplerBinding::PartialSum, -1, "uPartialSum"});
    if (l.weightArray) {
        o << "uniform sampler2DArray uWeights;  // layer k: weights of y_k (exit x, y, z, length)\n";
        pass.samplers.push_back({SamplerBinding::WeightArray, -1, "uWeights"});
    } else {
        for (int k : plan.functions) {
            std::string name = "uWeight" + std::to_string(k);
            o << "uniform sampler2D " << name << ";  // y_" << polys[k].l << "^" << polys[k].m
              << "\n";
            pass.samplers.push_back({SamplerBinding::Weight, k, name});
        }
    }
    const int K = static_cast<int>(polys.size());
    if (l.unormWeights)
        o << "uniform vec4 uWeightScale[" << K << "];   // 8-bit weights: value = code / 255 * scale + offset\n"
          << "uniform vec4 uWeightOffset[" << K << "];\n";
    o << "\n"
      << "vec4 shPass(ivec2 p, vec3 w, vec4 s) {\n"
      << "    float x = w.x, y = w.y, z = w.z;\n";
    auto fetch = [&](int k) {
        const std::string kk = std::to_string(k);
        const std::string t = l.weightArray ? "texelFetch(uWeights, ivec3(p, " + kk + "), 0)"
                                            : "texelFetch(uWeight" + kk + ", p, 0)";
        return l.unormWeights ? "(" + t + " * uWeightScale[" + kk + "] + uWeightOffset[" + kk + "])" : t;
    };
    if (s.form == ShForm::Recurrence) {
        const RecurrenceSet& r = plan.rec;
        if (!r.top.empty() && r.top.rbegin()->first >= 1)
            o << "    // (x + iy)^m = re_m + i im_m\n    float re1 = x, im1 = y;\n";
        for (int m = 2; m <= r.maxPower; ++m)
            o << "    float re" << m << " = re" << m - 1 << " * x - im" << m - 1 << " * y, im" << m
              << " = re" << m - 1 << " * y + im" << m - 1 << " * x;\n";
        std::map<std::pair<int, int>, int> wanted;  // (l, m) -> k
        for (int k : plan.functions) wanted[{polys[k].l, polys[k].m}] = k;
        for (const auto& [am, topL] : r.top) {
            o << "    // column m = " << am << ": Q_l^" << am << ", l = " << am << ".." << topL
              << (am > 0 ? " (sqrt2 folded in)" : "") << "\n";
            auto q = [am = am](int j) { return "q" + std::to_string(j) + "_" + std::to_string(am); };
            for (int ll = am; ll <= topL; ++ll) {
                o << "    float " << q(ll) << " = ";
                if (ll == am)
                    o << literal(recStart(am)) << ";\n";
                else if (ll == am + 1)
                    o << literal(std::sqrt(2.0 * am + 3.0) * recStart(am)) << " * z;\n";
                else
                    o << literal(recA(ll, am)) << " * (z * " << q(ll - 1) << " - "
                      << literal(recB(ll, am)) << " * " << q(ll - 2) << ");\n";
                for (int sign : {-1, 1}) {
                    if (am == 0 && sign < 0) continue;
                    auto it = wanted.find({ll, sign * am});
                    if (it == wanted.end()) continue;
                    // The scalar product first: one vec4 MAD per function.
                    std::string value = am == 0 ? q(ll)
                                                : "(" + q(ll) + " * " + (sign < 0 ? "im" : "re") +
                                                      std::to_string(am) + ")";
                    o << "    // y_" << ll << "^" << sign * am << "\n"
                      << "    s += " << fetch(it->second) << " * " << value << ";\n";
                }
            }
        }
        o << "    return s;\n}";
        return o.str();
    }
    if (!plan.monos.order.empty()) o << "    // monomials, each computed once for this pass\n";
    for (const Mono& m : plan.monos.order) {
        const auto& f = plan.monos.factor.at(m);
        o << "    float " << monoName(m) << " = " << (f.first.degree() == 0 ? "1.0" : monoName(f.first))
          << " * " << f.second << ";\n";
    }
    for (int k : plan.functions) {
        const ShPolynomial& p = polys[k];
        // The label, then the exact expansion (integer numerators, one scale) it comes from.
        std::string exact = p.ToString();
        o << "    // y_" << p.l << "^" << p.m << "\n"
          << "    //   " << exact.substr(exact.find('=')) << "\n"
          << "    s += " << fetch(k) << " * (" << polyExpression(p) << ");\n";
    }
    o << "    return s;\n}";
    return o.str();
}

// The whole fragment shader of pass `index`: shaders/decompress.frag with the generated part.
std::string fragmentSource(const DecompressionShaders& s, int index, const PassPlan& plan,
                           const std::vector<ShPolynomial>& polys, DecompressionPass& pass) {
    pass.generated = generatedPass(s, index, plan, polys, pass);
    return shaders::withVersion(
        shaders::fill(shaders::source("decompress.frag"), "#pragma shrefract_generated", pass.generated),
        s.limits.version, index == 0 ? "#define SHREFRACT_FIRST_PASS" : "");
}

int functionAlu(const ShPolynomial& p) { return static_cast<int>(p.terms.size()) + 1; }

// ALU that function p adds to `plan` in `form` (and adds what it needs to the plan).
int addFunction(PassPlan& plan, const ShPolynomial& p, ShForm form, bool unorm) {
    if (form == ShForm::Recurrence) return plan.rec.add(p.l, p.m) + (p.m == 0 ? 1 : 2) + unorm;
    int c = functionAlu(p) + unorm;
    for (const Monomial& t : p.terms) c += plan.monos.add({t.a, t.b, t.c});
    return c;
}

DecompressionShaders generateForm(int order, const ShaderLimits& limits, ShForm form) {
    DecompressionShaders out;
    out.order = order;
    out.limits = limits;
    out.form = form;
    std::vector<ShPolynomial> polys;
    for (const ShLM& f : shEvenFunctions(order)) {
        if (form == ShForm::Polynomial) {
            polys.push_back(shPolynomial(f.l, f.m));
        } else {  // only l, m are used: the exact expansion overflows int64 from l ~ 30 on
            ShPolynomial p;
            p.l = f.l;
            p.m = f.m;
            polys.push_back(p);
        }
    }
    const int K = static_cast<int>(polys.size());

    // Standalone cost of each function, for the decreasing order of first-fit decreasing.
    std::vector<int> standalone(K);
    for (int k = 0; k < K; ++k) {
        PassPlan alone;
        standalone[k] = addFunction(alone, polys[k], form, limits.unormWeights);
    }
    std::vector<int> byCost(K);
    std::iota(byCost.begin(), byCost.end(), 0);
    std::stable_sort(byCost.begin(), byCost.end(),
                     [&](int a, int b) { return standalone[a] > standalone[b]; });

    const bool aluLimited = limits.maxAluInstructions > 0;
    std::vector<PassPlan> plans;
    for (int k : byCost) {
        bool placed = false;
        for (size_t pi = 0; pi <= plans.size() && !placed; ++pi) {
            bool fresh = pi == plans.size();
            PassPlan trial = fresh ? PassPlan() : plans[pi];
            if (fresh) trial.units += pi == 0 ? 0 : 1;  // partial sum for every later pass
            if (fresh && limits.weightArray) trial.units += 1;
            if (!limits.weightArray) trial.units += 1;
            trial.alu += addFunction(trial, polys[k], form, limits.unormWeights);
            bool fits = trial.units <= limits.maxTextureUnits &&
                        (!aluLimited || trial.alu <= limits.maxAluInstructions);
            if (!fits) {
                if (fresh) {
                    throw std::invalid_argument(
                        "shader limits \"" + limits.name + "\" too small for y_" +
                        std::to_string(polys[k].l) + "^" + std::to_string(polys[k].m) +
                        " alone (ALU " + std::to_string(trial.alu) + ", units " +
                        std::to_string(trial.units) + ")");
                }
                continue;
            }
            trial.functions.push_back(k);
            if (fresh)
                plans.push_back(std::move(trial));
            else
                plans[pi] = std::move(trial);
            placed = true;
        }
    }
    // Readable output: functions ascending within a pass, monomials by first use kept.
    out.passes.resize(plans.size());
    out.vertex = shaders::withVersion(shaders::source("fullscreen.vert"), limits.version);
    for (size_t i = 0; i < plans.size(); ++i) {
        std::sort(plans[i].functions.begin(), plans[i].functions.end());
        DecompressionPass& pass = out.passes[i];
        pass.functions = plans[i].functions;
        pass.aluCost = plans[i].alu;
        pass.fragment = fragmentSource(out, static_cast<int>(i), plans[i], polys, pass);
    }
    return out;
}

}  // namespace

DecompressionShaders generateDecompression(int order, const ShaderLimits& limits, ShForm form) {
    if (order < 0) throw std::invalid_argument("SH order must be >= 0");
    const ShForm resolved = resolveShForm(form, order);
    if (form == ShForm::Auto && resolved == ShForm::Recurrence) {
        try {
            return generateForm(order, limits, ShForm::Recurrence);
        } catch (const std::invalid_argument&) {
            return generateForm(order, limits, ShForm::Polynomial);  // limits too small for it
        }
    }
    return generateForm(order, limits, resolved);
}

DecompressionShaders generateGridDecompression(int nTheta, int nPhi, const ShaderLimits& limits) {
    if (!limits.weightArray)
        throw std::invalid_argument("the grid basis needs its weights in one texture array (limits \"" +
                                    limits.name + "\" has one texture per coefficient)");
    DecompressionShaders s;
    s.order = 0;
    s.gridTheta = nTheta, s.gridPhi = nPhi;
    s.limits = limits;
    s.form = ShForm::Polynomial;
    s.vertex = shaders::withVersion(shaders::source("fullscreen.vert"), limits.version);
    DecompressionPass pass;
    pass.samplers = {{SamplerBinding::LocalView, -1, "uLocalView"},
                     {SamplerBinding::WeightArray, -1, "uWeights"}};
    std::ostringstream o;
    o << "// shrefract grid-basis decompression: grid " << nTheta << "x" << nPhi
      << ", one pass. Generated by runtime/src/shadergen.cpp; do not edit.\n"
      << "#define SHREFRACT_GRID_THETA " << nTheta << "\n#define SHREFRACT_GRID_PHI " << nPhi << "\n"
      << shaders::source("grid_eval.glsl") << "\n"
      << "uniform sampler2DArray uWeights;  // layer j: the exit at grid direction j (x, y, z, length)\n";
    std::string fetch = "texelFetch(uWeights, ivec3(p, index[c]), 0)";
    if (limits.unormWeights) {
        o << "uniform sampler2D uWeightRange;  // 8-bit weights: value = code / 255 * (k, 0) + (k, 1)\n";
        pass.samplers.push_back({SamplerBinding::WeightRange, -1, "uWeightRange"});
        fetch = "(" + fetch + " * texelFetch(uWeightRange, ivec2(index[c], 0), 0) + "
                "texelFetch(uWeightRange, ivec2(index[c], 1), 0))";
    }
    o << "\n"
      << "vec4 shPass(ivec2 p, vec3 w, vec4 s) {\n"
      << "    ivec4 index;\n    vec4 weight;\n    gridCorners(w, index, weight);\n"
      << "    for (int c = 0; c < 4; ++c) s += weight[c] * " << fetch << ";\n"
      << "    return s;\n}";
    pass.generated = o.str();
    pass.aluCost = 0;
    pass.fragment = shaders::withVersion(
        shaders::fill(shaders::source("decompress.frag"), "#pragma shrefract_generated", pass.generated),
        limits.version, "#define SHREFRACT_FIRST_PASS");
    s.passes.push_back(std::move(pass));
    return s;
}

std::string DecompressionShaders::summary() const {
    std::ostringstream o;
    if (gridTheta > 0) {
        o << "grid " << gridTheta << "x" << gridPhi << ", limits " << limits.name << ": 1 pass";
        return o.str();
    }
    o << "order " << order << ", limits " << limits.name << ": " << passes.size()
      << (passes.size() == 1 ? " pass" : " passes") << " (ALU";
    for (const auto& p : passes) o << ' ' << p.aluCost;
    o << "; units";
    for (const auto& p : passes) o << ' ' << p.samplers.size();
    o << ")";
    if (form == ShForm::Recurrence) o << ", recurrence";
    return o.str();
}

void dumpShaders(const DecompressionShaders& shaders, const std::string& dir) {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw std::runtime_error(dir + ": cannot create directory: " + ec.message());
    auto write = [&](const std::string& name, const std::string& text) {
        std::string path = (fs::path(dir) / name).string();
        std::ofstream f(path, std::ios::binary);
        f << text;
        if (!f) throw std::runtime_error(path + ": cannot write");
    };
    write("decompress.vert", shaders.vertex);
    std::ostringstream list;
    list << shaders.summary() << "\n";
    for (size_t i = 0; i < shaders.passes.size(); ++i) {
        write("decompress_pass" + std::to_string(i + 1) + ".frag", shaders.passes[i].fragment);
        list << "pass " << i + 1 << ": ALU " << shaders.passes[i].aluCost << ", functions";
        for (int k : shaders.passes[i].functions) list << ' ' << k;
        list << "\n";
    }
    write("passes.txt", list.str());
}

}  // namespace shrefract
