// Masks over rendered frames for runtime tests.
#pragma once

#include "shrefract/render.h"

namespace shrefract::test {

// Whether every pixel within `margin` of (x, y) is covered (the direction buffer's w). Tests that
// compare the refracted colour with a closed form keep to such pixels: at the silhouette the
// interpolated normal grazes the view, and Fresnel reflects everything there, even at index 1.
inline bool coveredAround(const RenderedFrame& f, int x, int y, int margin = 2) {
    for (int dy = -margin; dy <= margin; ++dy)
        for (int dx = -margin; dx <= margin; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx < 0 || yy < 0 || xx >= f.width || yy >= f.height) return false;
            if (f.directions[(size_t(yy) * f.width + xx) * 4 + 3] < 0.5f) return false;
        }
    return true;
}

}  // namespace shrefract::test
