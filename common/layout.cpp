// Addressing in the joining-surfaces layout (declared in common/bakefile.h). The layout itself
// is built by the bake (bake/layout.cpp); these are the lookups everyone shares.
#include "common/bakefile.h"
#include "common/error.h"

namespace shrefract {

glm::ivec2 SurfaceLayout::rhoTexel(int t, int i, int j) const {
    int b = t / 2;
    int bx = (b % blocksPerRow) * blockWidth;
    int by = (b / blocksPerRow) * blockHeight;
    if (t % 2 == 0) return {bx + i, by + j};
    // The partner is rotated 180 degrees so its hypotenuse faces ours across the block.
    return {bx + blockWidth - 1 - i, by + blockHeight - 1 - j};
}

uint32_t SurfaceLayout::sampleAt(int t, int i, int j) const {
    glm::ivec2 p = rhoTexel(t, i, j);
    const RhoTexel& tx = rho[static_cast<size_t>(p.y) * rhoWidth + p.x];
    SHREFRACT_CHECK_EQ(tx.kind, static_cast<uint32_t>(RhoTexel::Sample));
    return tx.a;
}

}  // namespace shrefract
