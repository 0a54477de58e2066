// A bake as a glTF 2.0 binary file (docs/format.md "glTF export: SHREFRACT_sh_refraction"): the
// mesh the runtime's direct path draws, the weights (SH or the grid basis's traced exits) as RGBA8
// PNG atlas pages with a scale and offset per coefficient, the error model, and optionally prefiltered environments. Written
// through Debian's tinygltf; read by web/ (the three.js material).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/bakefile.h"
#include "common/latlong.h"

namespace shrefract {

// The largest atlas page, texels per side: what WebGL 2 on phones reliably allows.
constexpr int kMaxGltfTexture = 4096;

// Where coefficient k's tile lies in the weight atlas (docs/format.md): page k / tilesPerPage,
// tile j = k % tilesPerPage at texel ((j % tilesPerRow) * tile[0], (j / tilesPerRow) * tile[1]).
struct AtlasLayout {
    int tile[2] = {1, 1};
    int tilesPerRow = 1, tilesPerPage = 1, pages = 1;
    int coefficients = 1;
    // Page p's size in texels (the last page may hold fewer rows of tiles).
    int pageWidth(int p) const;
    int pageHeight(int p) const;
};
// The atlas for K coefficients of N samples, W samples per tile row, pages at most maxSide
// square: the fewest pages that hold them, the tiles shared evenly among them, each page near
// square. Throws InputError when one tile does not fit.
AtlasLayout atlasLayout(int K, int N, int W, int maxSide = kMaxGltfTexture);

// The 8-bit codes of every coefficient, laid out as RGBA8 pages of the atlas, and the scale and
// offset that decode them (value = scale[4k + c] * code + offset[4k + c]): a u8 bake's own codes,
// a float bake quantized the way writeBake quantizes to u8.
struct WeightAtlas {
    AtlasLayout layout;
    std::vector<std::vector<uint8_t>> pages;  // RGBA8, rows top-down
    std::vector<double> scale, offset;        // [4k + c]
};
WeightAtlas weightAtlas(const BakeData& bake, int maxSide = kMaxGltfTexture);

struct GltfEnvironment {
    std::string name;
    CubeMapImage base;  // level 0; the export prefilters it as the runtime does
};

struct GltfExport {
    const BakeData* bake = nullptr;  // none: a file of environments only
    std::string name;                // the refraction's and the mesh's name
    std::vector<GltfEnvironment> environments;
    int maxTexture = kMaxGltfTexture;  // the weight pages' largest side, texels
};

// The GLB file's bytes. Throws InputError for what a glTF file cannot hold (a chart layout, a
// tile wider than maxTexture) and std::invalid_argument for an empty export.
std::vector<uint8_t> exportGlb(const GltfExport& what);

// The round trip (shrefract-export --into): the glTF scene the bake was made from (.gltf with its
// files, or .glb) as one GLB in which every glass primitive is the sample grid of its part, in its
// node's coordinates (docs/format.md "bakeFromLocal"), keeping its material; every other node,
// mesh, material, texture and image stays as it was (images and buffers moved into the GLB's
// binary chunk, bytes unchanged). Throws InputError when the bake was not made from this scene
// (part count or a mesh checksum differs) or the scene cannot be read.
std::vector<uint8_t> exportInto(const BakeData& bake, const std::string& scenePath,
                                const std::vector<GltfEnvironment>& environments = {},
                                int maxTexture = kMaxGltfTexture);

}  // namespace shrefract
