#version 330 core
// The web material's vertex shader (web/src/material.js, docs/web.md): what shade_direct.vert
// does with SHREFRACT_VERTEX_SH, for the glTF mesh of SHREFRACT_sh_refraction (docs/format.md
// "glTF export"), where each vertex names its sample (_SHREFRACT_SAMPLE) and carries its P and N
// in the primitive's own coordinates, which uBakeFromLocal takes to the bake's (identity for a bake
// exported alone; a node's world matrix for a primitive written back into its scene). D is the
// weights evaluated at the sample's local view direction: the SH (loop form, sh_eval.glsl, the
// order a uniform), or with SHREFRACT_GRID_THETA and SHREFRACT_GRID_PHI (a grid-basis bake) the
// bilinear blend of the four traced exits around it (grid_eval.glsl, as the C++ generator's grid
// pass). With SHREFRACT_ERROR_MODEL the bake's predicted error is folded into D's length as
// error_fold.frag does per mu texel. The rasterizer interpolates D barycentrically either way, so
// every pixel gets the C++ direct path's texture-decompressed D (runtime/src/direct_pipeline.cpp).
#include "frame.glsl"
#include "sh_eval.glsl"
#include "resultant.glsl"
#ifdef SHREFRACT_GRID_THETA
#include "grid_eval.glsl"
#endif
in vec3 position;            // the sample's P, the primitive's coordinates
in vec3 normal;              // its unit shading normal, likewise
in float _shrefract_sample;  // which sample (exact in float below 2^24)
uniform mat4 uBakeFromLocal;  // the primitive's coordinates -> the bake's ("object space" below)
uniform mat3 uBakeNormal;     // its inverse transpose
uniform mat4 uModel;          // the bake's space -> world
uniform mat4 uViewProjection;
uniform mat3 uNormalMatrix;
uniform vec3 uEyeObject;
uniform int uOrder;          // SH order used, <= the stored one (0 for a grid)
// The weight atlas: coefficient k is tile k % uTilesPerPage of page k / uTilesPerPage, tiles
// uTileSize texels, uTilesPerRow to a row; sample i is texel (i % width, i / width) of a tile.
uniform ivec2 uTileSize;
uniform int uTilesPerRow;
uniform int uTilesPerPage;
// 8-bit codes read as UNORM: value = texel * scale_k + offset_k, texel (k, 0) and (k, 1) of
// uWeightRange (scale x 255), as the C++ grid pass's uWeightRange (a grid's 512 coefficients
// would overflow a uniform array).
uniform highp sampler2D uWeightRange;
uniform highp sampler2DArray uWeightPages;  // layer p: atlas page p (web/src/material.js)
#ifdef SHREFRACT_ERROR_MODEL
uniform highp sampler2DArray uErrors;  // layer k: e_k per sample, red, laid out as a weight tile
uniform int uErrorOrder;
uniform float uErrorOffset;            // the model is ln(err + offset)
#endif
out vec3 vPosition;
out vec3 vObjectPosition;  // where on the object: a seed that moves with it (jitter shading)
out vec3 vNormal;
out vec4 vD;

// Coefficient k's code at texel s of its tile (s: the sample's texel within a tile), decoded.
vec4 weightAt(int k, ivec3 tile, ivec2 s) {
    vec4 code = texelFetch(uWeightPages, ivec3(tile.xy + s, tile.z), 0);
    return code * texelFetch(uWeightRange, ivec2(k, 0), 0) + texelFetch(uWeightRange, ivec2(k, 1), 0);
}

// Where coefficient k's tile starts: texel (x, y) of page z.
ivec3 tileOf(int k) {
    int page = k / uTilesPerPage, j = k - page * uTilesPerPage;
    return ivec3((j % uTilesPerRow) * uTileSize.x, (j / uTilesPerRow) * uTileSize.y, page);
}

void main() {
    int i = int(_shrefract_sample + 0.5);
    vec3 P = (uBakeFromLocal * vec4(position, 1.0)).xyz;
    vec3 N = normalize(uBakeNormal * normal);
    vec3 w = normalize(toLocalFrame(normalize(uEyeObject - P), N));
    // The even functions are band-major, so one evaluation through the larger order serves both
    // the weights (uOrder) and the error model (uErrorOrder); a grid's uOrder is 0.
    float y[SHREFRACT_SH_MAX_COUNT];
#ifdef SHREFRACT_ERROR_MODEL
    shEvalEven(max(uOrder, uErrorOrder), w, y);
#else
    shEvalEven(uOrder, w, y);
#endif
    ivec2 s = ivec2(i % uTileSize.x, i / uTileSize.x);  // the sample's texel in every tile
    vec4 d = vec4(0.0);
#ifdef SHREFRACT_GRID_THETA
    ivec4 corner;
    vec4 cornerWeight;
    gridCorners(w, corner, cornerWeight);
    for (int c = 0; c < 4; ++c) d += cornerWeight[c] * weightAt(corner[c], tileOf(corner[c]), s);
#else
    // The tiles in order, stepped along the rows and pages rather than divided out per
    // coefficient (integer division is dear where the vertex stage runs on a CPU).
    int count = (uOrder + 1) * (uOrder + 2) / 2;
    ivec3 tile = ivec3(0);
    int column = 0, onPage = 0;
    for (int k = 0; k < SHREFRACT_SH_MAX_COUNT; ++k) {
        if (k >= count) break;
        d += weightAt(k, tile, s) * y[k];
        if (++onPage == uTilesPerPage) {
            tile = ivec3(0, 0, tile.z + 1);
            column = onPage = 0;
        } else if (++column == uTilesPerRow) {
            tile.xy = ivec2(0, tile.y + uTileSize.y);
            column = 0;
        } else {
            tile.x += uTileSize.x;
        }
    }
#endif
#ifdef SHREFRACT_ERROR_MODEL
    int errorCount = (uErrorOrder + 1) * (uErrorOrder + 2) / 2;
    float e = 0.0;
    for (int k = 0; k < SHREFRACT_SH_MAX_COUNT; ++k) {
        if (k >= errorCount) break;
        e += texelFetch(uErrors, ivec3(s, k), 0).r * y[k];
    }
    float err = max(exp(e) - uErrorOffset, 0.0);
    float len = length(d.xyz);
    d.xyz = (len > 1e-10 ? d.xyz / len : vec3(0.0)) * resultantOfSigma(err);
#endif
    vD = d;
    vec4 world = uModel * vec4(P, 1.0);
    vPosition = world.xyz;
    vObjectPosition = P;
    vNormal = uNormalMatrix * N;
    gl_Position = uViewProjection * world;
}
