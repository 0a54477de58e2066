#include "eval/adaptive.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include <Eigen/Core>

#include "bake/fit.h"
#include "bake/residual.h"
#include "bake/tracer.h"
#include "common/decompress.h"
#include "common/error.h"
#include "common/sh.h"
#include "eval/reference.h"

namespace shrefract {

std::vector<int> adaptiveOrders(const BakeData& bake, double toleranceDeg) {
    const int n = bake.layout.sampleCount();
    // 64 directions spread over the hemisphere (a Fibonacci spiral in z = cos(theta)).
    std::vector<glm::vec3> dirs;
    for (int k = 0; k < 64; ++k) {
        float z = (k + 0.5f) / 64.0f, phi = 2.39996323f * k, s = std::sqrt(1 - z * z);
        dirs.emplace_back(s * std::cos(phi), s * std::sin(phi), z);
    }
    std::vector<int> orders(n, bake.order);
    tbb::parallel_for(0, n, [&](int i) {
        std::vector<glm::vec3> full;
        for (glm::vec3 w : dirs) full.push_back(glm::normalize(glm::vec3(decompressSample(bake, i, w))));
        for (int l = 0; l < bake.order; ++l) {
            double sum = 0;
            for (size_t k = 0; k < dirs.size(); ++k) {
                glm::vec3 e(decompressSample(bake, i, dirs[k], l));
                float len = glm::length(e);
                double c = len > 0 ? std::clamp(double(glm::dot(e / len, full[k])), -1.0, 1.0) : -1.0;
                sum += std::acos(c) * 180.0 / M_PI;
            }
            if (sum / dirs.size() <= toleranceDeg) {
                orders[i] = l;
                break;
            }
        }
    });
    return orders;
}

std::vector<BakeData> perSampleOrderBakes(const BakeData& bake, const Scene& scene,
                                         const std::vector<std::vector<int>>& orders) {
    SHREFRACT_CHECK(bake.basis == Basis::Sh);
    const SurfaceLayout& L = bake.layout;
    const size_t n = size_t(L.sampleCount());
    const int K = bake.coefficientCount();
    const DirectionGrid& grid = bake.grid;
    const int J = grid.count();
    // The bake's own fit, at every order some sample keeps.
    const RecordedFit fit = recordedFit(bake.manifest);
    std::map<int, std::unique_ptr<SampleFit>> fits;
    for (const std::vector<int>& o : orders) {
        SHREFRACT_CHECK(o.size() == n);
        for (const int l : o)
            if (!fits.count(l))
                fits[l] = std::make_unique<SampleFit>(grid, l, fit.fit, fit.weighting, fit.filterWidth, "");
    }
    std::unique_ptr<ResidualFitter> residual;
    if (bake.errorOrder >= 0) {
        residual = std::make_unique<ResidualFitter>(Basis::Sh, grid, bake.order, bake.errorOrder);
        SHREFRACT_CHECK(residual->errorCoefficients() == bake.errorCoefficientCount());
    }
    const int Ke = bake.errorCoefficientCount();

    std::vector<BakeData> out(orders.size(), bake);
    const Tracer tracer(scene, traceOptionsOfBake(bake));
    tbb::parallel_for(size_t(0), n, [&](size_t i) {
        enableFlushToZero();
        // The sample's paths at the grid directions, traced as the bake traced them.
        std::vector<PathResult> paths(J);
        traceSampleGrid(tracer, L, i, grid, true, paths.data());
        Eigen::MatrixXf R(J, 4), C(0, 4), Wt = Eigen::MatrixXf::Zero(4, K), E(std::max(Ke, 1), 1);
        for (int j = 0; j < J; ++j) R.row(j) << paths[j].exit.x, paths[j].exit.y, paths[j].exit.z, paths[j].length;
        for (size_t t = 0; t < out.size(); ++t) {
            // Fitted at its own order, every higher band zero; then the model of what it misses.
            const SampleFit& f = *fits.at(orders[t][i]);
            Wt.setZero();
            f.fit(R, paths.data(), 1, Wt.leftCols(f.coefficients()));
            BakeData& b = out[t];
            for (int k = 0; k < K; ++k)
                for (int c = 0; c < 4; ++c) b.weights[(size_t(k) * n + i) * 4 + c] = Wt(c, k);
            if (!residual) continue;
            residual->fit(R, C, Wt, 1, E);
            for (int k = 0; k < Ke; ++k) b.errors[size_t(k) * n + i] = E(k, 0);
        }
    });
    return out;
}

}  // namespace shrefract
