// The atlas (docs/bake.md "Chart layouts", step 5): its size and every chart's place in it. Uv
// charts keep their places and get the least square atlas whose covered texels reach the target;
// isolated charts are turned to their least-area rectangles and shelf-packed, with gutters, at one
// texel density: the least that covers the target, or the largest that fits a given atlas.
#include <numeric>

#include "bake/chart_internal.h"
#include "common/error.h"

namespace shrefract::charts {
namespace {

struct ChartBox {
    glm::dvec2 lo, hi;  // in chart units after rotation
};

// Rotates each chart to its least-area bounding rectangle (an edge of its convex hull lies on the
// rectangle), lying wider than tall, and moves its corner to the origin.
std::vector<ChartBox> orientCharts(Surface& S, int charts) {
    const auto faces = facesByChart(S, charts);
    std::vector<ChartBox> boxes(static_cast<size_t>(charts));
    for (int c = 0; c < charts; ++c) {
        std::vector<glm::dvec2> pts;
        for (uint32_t t : faces[c])
            for (int k = 0; k < 3; ++k) pts.push_back(S.tris[t].uv[k]);
        std::sort(pts.begin(), pts.end(), [](auto a, auto b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
        pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
        std::vector<glm::dvec2> hull;  // monotone chain
        for (int pass = 0; pass < 2; ++pass) {
            const size_t base = hull.size();
            for (size_t i = 0; i < pts.size(); ++i) {
                const glm::dvec2 p = pass == 0 ? pts[i] : pts[pts.size() - 1 - i];
                while (hull.size() >= base + 2 &&
                       cross2(hull.back() - hull[hull.size() - 2], p - hull[hull.size() - 2]) <= 0)
                    hull.pop_back();
                hull.push_back(p);
            }
            hull.pop_back();
        }
        double bestArea = INFINITY;
        glm::dvec2 bestAxis(1, 0);
        for (size_t i = 0; i < hull.size(); ++i) {
            glm::dvec2 e = hull[(i + 1) % hull.size()] - hull[i];
            if (glm::length(e) <= 0) continue;
            e = glm::normalize(e);
            double lo0 = INFINITY, hi0 = -INFINITY, lo1 = INFINITY, hi1 = -INFINITY;
            for (const auto& p : hull) {
                lo0 = std::min(lo0, glm::dot(p, e)), hi0 = std::max(hi0, glm::dot(p, e));
                const double q = cross2(e, p);
                lo1 = std::min(lo1, q), hi1 = std::max(hi1, q);
            }
            if ((hi0 - lo0) * (hi1 - lo1) < bestArea) {
                bestArea = (hi0 - lo0) * (hi1 - lo1);
                bestAxis = (hi0 - lo0) >= (hi1 - lo1) ? e : glm::dvec2(-e.y, e.x);
            }
        }
        // Rotation taking bestAxis to +x keeps the orientation (counter-clockwise stays so).
        ChartBox box{glm::dvec2(INFINITY), glm::dvec2(-INFINITY)};
        for (uint32_t t : faces[c])
            for (int k = 0; k < 3; ++k) {
                const glm::dvec2 p = S.tris[t].uv[k];
                const glm::dvec2 r(glm::dot(p, bestAxis), cross2(bestAxis, p));
                S.tris[t].uv[k] = r;
                box.lo = glm::min(box.lo, r), box.hi = glm::max(box.hi, r);
            }
        for (uint32_t t : faces[c])
            for (int k = 0; k < 3; ++k) S.tris[t].uv[k] -= box.lo;
        box.hi -= box.lo;
        box.lo = glm::dvec2(0.0);
        boxes[c] = box;
    }
    return boxes;
}

// Texel centres covered by the triangles `tris` placed by `place` in a width x height grid, each
// counted once (a centre on an edge inside a chart is covered by both of its triangles).
template <class Place>
size_t countCovered(const Surface& S, const std::vector<std::array<bool, 3>>& open,
                    const std::vector<uint32_t>& tris, Place place, int width, int height) {
    std::vector<char> covered(size_t(width) * height, 0);
    size_t n = 0;
    for (uint32_t t : tris) {
        glm::dvec2 uv[3];
        for (int k = 0; k < 3; ++k) uv[k] = place(S.tris[t].uv[k]);
        forEachCoveredTexel(uv, open[t], width, height, [&](int x, int y, const double*) {
            char& c = covered[size_t(y) * width + x];
            n += !c;
            c = 1;
        });
    }
    return n;
}

// Covered texels of every chart at `scale` texels per chart unit, each at (gutter, gutter) of its
// own box: the count does not depend on where the packer puts the box (whole texels).
size_t coveredAtScale(const Surface& S, const std::vector<std::array<bool, 3>>& open,
                      const std::vector<std::vector<uint32_t>>& faces,
                      const std::vector<ChartBox>& boxes, double scale, int gutter) {
    size_t n = 0;
    for (size_t c = 0; c < faces.size(); ++c) {
        const int w = int(std::ceil(boxes[c].hi.x * scale)) + 2 * gutter + 1;
        const int h = int(std::ceil(boxes[c].hi.y * scale)) + 2 * gutter + 1;
        n += countCovered(S, open, faces[c], [&](glm::dvec2 uv) { return uv * scale + double(gutter); }, w, h);
    }
    return n;
}

struct Packing {
    int width = 0, height = 0;
    std::vector<glm::ivec2> origin;  // per chart, of its box (the chart starts gutter further in)
};

// Shelf packing of the chart boxes at `scale`, rows at most `rowWidth` wide, tallest first.
Packing pack(const std::vector<ChartBox>& boxes, double scale, int gutter, int rowWidth) {
    const int charts = int(boxes.size());
    std::vector<glm::ivec2> size(static_cast<size_t>(charts));
    for (int c = 0; c < charts; ++c)
        size[c] = glm::ivec2(int(std::ceil(boxes[c].hi.x * scale)) + 2 * gutter,
                             int(std::ceil(boxes[c].hi.y * scale)) + 2 * gutter);
    std::vector<int> order(static_cast<size_t>(charts));
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return size[a].y > size[b].y; });
    Packing p;
    p.origin.assign(size_t(charts), glm::ivec2(0));
    int x = 0, y = 0, shelf = 0;
    for (int c : order) {
        if (x > 0 && x + size[c].x > rowWidth) {
            y += shelf;
            x = shelf = 0;
        }
        p.origin[c] = glm::ivec2(x, y);
        x += size[c].x;
        shelf = std::max(shelf, size[c].y);
        p.width = std::max(p.width, x);
    }
    p.height = y + shelf;
    return p;
}

Packing packSquare(const std::vector<ChartBox>& boxes, double scale, int gutter) {
    double area = 0, widest = 0;
    for (const auto& b : boxes) {
        const double w = std::ceil(b.hi.x * scale) + 2 * gutter, h = std::ceil(b.hi.y * scale) + 2 * gutter;
        area += w * h;
        widest = std::max(widest, w);
    }
    return pack(boxes, scale, gutter, int(std::max(widest, std::ceil(std::sqrt(area) * 1.05))));
}

// Isolated charts with --texels: the largest density whose packing fits the atlas, and that
// packing; throws InputError when not even the least density fits.
double densityFillingAtlas(const std::vector<ChartBox>& boxes, double area3, const ChartOptions& opt,
                           int G, Packing* packing) {
    double lo = 0, hi = std::sqrt(double(opt.texels.x) * opt.texels.y / area3);
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        const Packing p = pack(boxes, mid, G, opt.texels.x);
        (p.width <= opt.texels.x && p.height <= opt.texels.y ? lo : hi) = mid;
    }
    const double scale = lo;
    *packing = pack(boxes, scale, G, opt.texels.x);
    if (!(scale > 0) || packing->width > opt.texels.x || packing->height > opt.texels.y)
        throw InputError(str("--texels ", opt.texels.x, "x", opt.texels.y, " cannot hold the ",
                             boxes.size(), " charts with gutters of ", G, " texels"));
    return scale;
}

// Isolated charts with --samples: the least density whose charts cover the target number of
// texels, and a square packing at it.
double densityReachingSamples(const Surface& S, const std::vector<ChartBox>& boxes, double area3,
                              const ChartOptions& opt, int G, Packing* packing) {
    const int charts = int(boxes.size());
    const OutlineEdges open = outlineEdges(S);
    double lo = 0, hi = std::sqrt(double(opt.samples) / area3);
    const auto faces = facesByChart(S, charts);
    while (coveredAtScale(S, open, faces, boxes, hi, G) < opt.samples) hi *= 1.25;
    for (int i = 0; i < 50 && hi - lo > 1e-6 * hi; ++i) {
        const double mid = 0.5 * (lo + hi);
        (coveredAtScale(S, open, faces, boxes, mid, G) >= opt.samples ? hi : lo) = mid;
    }
    *packing = packSquare(boxes, hi, G);
    return hi;
}

}  // namespace

glm::ivec2 scaleUVsToAtlas(Surface& S, const ChartOptions& opt) {
    int W = 0, H = 0;
    const auto open = outlineEdges(S);
    std::vector<uint32_t> all(S.tris.size());
    std::iota(all.begin(), all.end(), 0u);
    auto covered = [&](int w, int h) {
        return countCovered(S, open, all, [&](glm::dvec2 uv) { return uv * glm::dvec2(w, h); }, w, h);
    };
    if (opt.texels.x > 0) {
        W = opt.texels.x, H = opt.texels.y;
    } else {  // the least square atlas whose covered texels reach the target
        int lo = 1, hi = 2;
        while (covered(hi, hi) < opt.samples && hi < 16384) hi *= 2;
        while (lo < hi) {
            const int mid = (lo + hi) / 2;
            if (covered(mid, mid) >= opt.samples) hi = mid;
            else lo = mid + 1;
        }
        W = H = hi;
    }
    for (auto& tr : S.tris)
        for (int k = 0; k < 3; ++k) tr.uv[k] *= glm::dvec2(W, H);
    return {W, H};
}

glm::ivec2 packCharts(Surface& S, const ChartOptions& opt, int G, ChartStats& st) {
    const int charts = chartCount(S);
    const std::vector<ChartBox> boxes = orientCharts(S, charts);
    double area3 = 0;
    for (uint32_t t = 0; t < S.tris.size(); ++t) area3 += S.area3(t);
    Packing packing;
    const double scale = opt.texels.x > 0 ? densityFillingAtlas(boxes, area3, opt, G, &packing)
                                          : densityReachingSamples(S, boxes, area3, opt, G, &packing);
    st.texelsPerObjectUnit = scale;
    for (auto& tr : S.tris)
        for (int k = 0; k < 3; ++k)
            tr.uv[k] = tr.uv[k] * scale + glm::dvec2(packing.origin[size_t(tr.chart)] + G);
    return opt.texels.x > 0 ? opt.texels : glm::ivec2(packing.width, packing.height);
}

}  // namespace shrefract::charts
