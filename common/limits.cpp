// The checks of common/limits.h that need no more than the values: kept apart from scene.cpp so
// that the bake-file reader (and the runtime library, which carries it) links no mesh loading.
#include "common/limits.h"

#include <cmath>
#include <sstream>

#include "common/scene.h"

namespace shrefract {

namespace {

std::string numberString(double x) {
    std::ostringstream os;
    os << x;
    return os.str();
}

}  // namespace

std::string mediumProblem(const Medium& m) {
    if (!std::isfinite(m.ior) || m.ior < limits::kMinIor || m.ior > limits::kMaxIor)
        return "'ior' " + numberString(m.ior) + " is not in [" + numberString(limits::kMinIor) +
               ", " + numberString(limits::kMaxIor) + "]";
    for (int c = 0; c < 3; ++c) {
        if (!std::isfinite(m.absorption[c]) || m.absorption[c] < 0.0)
            return "'absorption' has " + numberString(m.absorption[c]) +
                   ": each of the 3 values must be finite and >= 0";
    }
    return {};
}

}  // namespace shrefract
