// The contents of a NAME.shrefract.exr file in memory, and its reader and writer.
// The on-disk layout (one multi-part OpenEXR file) is documented in docs/format.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "common/direction_grid.h"
#include "shrefract/enum_names.h"

namespace shrefract {

// 2: per-part and manifest checksums, the layout kind and the chart layouts; 3: the error model;
// 4: the grid basis (docs/format.md "Versions"). Readers take version 1 too, unverified, as a
// joining layout.
constexpr int kFormatVersion = 4;

// The error model stores ln(angle + kErrorOffset) (radians): the offset keeps the logarithm of an
// exact fit finite, and a prediction at or below it reads as no error at all.
constexpr float kErrorOffset = 0.01f;

// How the surface samples are laid out (manifest "layout.kind"):
//   Joining   paper §5.3: every triangle sampled on a barycentric grid, mu packed, rho with
//             interpolation correction; continuous across every edge.
//   Isolated  paper §5.2: the surface cut into charts (CGAL parameterization) and packed into one
//             atlas with gutters; mu = rho = the atlas, the samples are the covered texel centres.
//   Uv        the same, with the mesh's own texture coordinates as the charts.
enum class LayoutKind { Joining, Isolated, Uv };
template <> struct EnumNames<LayoutKind> {
    static constexpr const char* what = "layout kind";
    static constexpr NamedValue<LayoutKind> table[] = {
        {LayoutKind::Joining, "joining"}, {LayoutKind::Isolated, "isolated"}, {LayoutKind::Uv, "uv"}};
};

// How the weights are stored (docs/format.md): float32, float16, or 8-bit codes with a scale and
// offset per coefficient.
enum class Precision { F32, F16, U8 };
template <> struct EnumNames<Precision> {
    static constexpr const char* what = "weight precision";
    static constexpr NamedValue<Precision> table[] = {
        {Precision::F32, "f32"}, {Precision::F16, "f16"}, {Precision::U8, "u8"}};
};

// What a sample's coefficients are (manifest "basis"; docs/format.md "weights"):
//   Sh    the even real SH through `order` (paper §4.2): D(w) = sum_k weight_k y_k(w).
//   Grid  the traced grid itself, one coefficient per grid direction j: D(w) = sum_j weight_j
//         B_j(w), B_j the grid's bilinear interpolation (DirectionGrid::interpolate), at most four
//         non-zero anywhere. No fit and so no fitting error at the grid directions; more bytes.
enum class Basis { Sh, Grid };
template <> struct EnumNames<Basis> {
    static constexpr const char* what = "basis";
    static constexpr NamedValue<Basis> table[] = {{Basis::Sh, "sh"}, {Basis::Grid, "grid"}};
};
// Coefficients per sample: shEvenCount(order) for Sh, grid.count() for Grid.
int basisCoefficients(Basis basis, int order, const DirectionGrid& grid);

// One texel of the rho layout. kind Sample: shows mu sample a. kind Correction: the texel just
// outside a triangle's hypotenuse, value = D[a] + D[b] - D[c] (v11 = v01 + v10 - v00), so that
// hardware bilinear filtering equals barycentric interpolation on the half-cell.
struct RhoTexel {
    enum Kind : uint32_t { Empty = 0, Sample = 1, Correction = 2 };
    uint32_t kind = Empty;
    uint32_t a = 0, b = 0, c = 0;
};

// A gutter texel of a chart layout whose value is taken across the cut (seam-aware gutter
// filling): sum of weight[k] x D[sample[k]], samples of the chart on the other side of the seam
// around the point that continues the surface there. Unused slots have weight 0.
struct SeamSource {
    uint32_t texel = 0;  // y * atlas width + x
    uint32_t sample[4] = {0, 0, 0, 0};
    float weight[4] = {0, 0, 0, 0};
};

// The charts of an Isolated or Uv layout (paper §5.2): the mesh unfolded into the atlas, vertices
// split along the seams. The atlas is the mu (= rho) layout; texel (x, y) covers
// [x, x + 1] x [y, y + 1] in texel units, uv = texel units / (muWidth, muHeight).
struct ChartAtlas {
    int gutter = 0;      // texels kept free around every chart when it was packed
    int chartCount = 0;
    std::vector<glm::vec3> vertexPosition;  // object space
    std::vector<glm::vec3> vertexNormal;    // unit shading normal
    std::vector<glm::vec2> vertexUV;        // atlas coordinates in [0, 1]
    std::vector<uint32_t> vertexChart;
    std::vector<glm::uvec3> triangles;      // counter-clockwise seen from outside, as the mesh
    std::vector<SeamSource> seam;           // seam-aware gutter texels
    // Not stored (derived from rho on reading): sample i's texel, y * muWidth + x.
    std::vector<uint32_t> sampleTexel;
};

// The surface samples O_d and their layouts. Joining (paper §5.3): unique samples packed in mu,
// every triangle as a right triangle of texels in rho, two per block (the second rotated 180
// degrees). Isolated and Uv (paper §5.2): mu = rho = the chart atlas (`atlas`), sample i at texel
// atlas.sampleTexel[i], rho texel kinds Sample (covered, a = the sample) or Empty.
struct SurfaceLayout {
    LayoutKind kind = LayoutKind::Joining;
    int rate = 1;  // r: grid steps per triangle edge (joining; 0 for chart layouts)
    // mu: sample i sits at texel (i % muWidth, i / muWidth); texels past sampleCount are unused.
    int muWidth = 0, muHeight = 0;
    std::vector<glm::vec3> position;  // per sample, object space
    std::vector<glm::vec3> normal;    // per sample, unit shading normal
    std::vector<uint32_t> part;       // per sample, index of the scene part it lies on

    // rho: blocks of blockWidth x blockHeight texels, blocksPerRow per row; triangle t lives in
    // block t / 2; t even is "upright" (texel (x, y) = grid sample (i, j) = (x, y), i + j <= r),
    // t odd is rotated 180 degrees ((x, y) = (blockWidth-1-i, blockHeight-1-j)).
    int rhoWidth = 0, rhoHeight = 0;
    int blockWidth = 0, blockHeight = 0, blocksPerRow = 0;
    int triangleCount = 0;
    std::vector<RhoTexel> rho;  // rhoWidth * rhoHeight, row-major

    // Spatial smoothing (paper §4.3, §5.3.2): sample i's neighbours are
    // neighbourIndex[neighbourOffset[i] .. neighbourOffset[i] + neighbourCount[i]), with weights
    // that sum to 1 including the sample itself (listed first).
    std::vector<uint32_t> neighbourOffset, neighbourCount;
    std::vector<uint32_t> neighbourIndex;
    std::vector<float> neighbourWeight;

    ChartAtlas atlas;  // Isolated and Uv only

    int sampleCount() const { return static_cast<int>(position.size()); }
    bool isChartLayout() const { return kind != LayoutKind::Joining; }
    // The mu texel of sample i: (i % muWidth, i / muWidth) for joining, its atlas texel for charts.
    glm::ivec2 muTexel(int i) const;
    // The texel (x, y) in rho of grid sample (i, j) of triangle t (i + j <= r + 1 reaches the
    // correction texels).
    glm::ivec2 rhoTexel(int t, int i, int j) const;
    // The mu sample at grid position (i, j) of triangle t, i + j <= rate.
    uint32_t sampleAt(int t, int i, int j) const;
};

// One corner of the mesh a renderer draws for a layout, three per triangle. Joining: triangle
// t's grid samples (0, 0), (r, 0), (0, r), uv at their texel centres in rho, id the mu sample.
// Charts: the unfolded mesh, uv in the atlas, id the chart vertex.
struct DrawCorner {
    glm::vec3 position, normal;
    glm::vec2 uv;
    uint32_t id;
};
std::vector<DrawCorner> drawCorners(const SurfaceLayout& layout);
// The joining layout's sample grid as a triangle mesh (the direct path's and the glTF export's):
// every triangle's regular barycentric subdivision at rate r, three sample indices per small
// triangle; both halves of a grid cell keep the triangle's winding (corner 0 -> 1 -> 2).
std::vector<uint32_t> refinedTriangles(const SurfaceLayout& layout);
// The diagonal of the samples' bounding box (object units, at least 1e-6): the unit of jitter
// shading's cell, for the runtime and the glTF export alike.
float samplesDiagonal(const SurfaceLayout& layout);
// The points drawCorners' ids name (joining: the samples; charts: the chart vertices), for data
// given per drawn vertex, such as Wyman's d_N.
void drawPoints(const SurfaceLayout& layout, std::vector<glm::vec3>* positions,
                std::vector<glm::vec3>* normals);

struct BakeData {
    nlohmann::json manifest;  // everything descriptive: see docs/format.md
    Basis basis = Basis::Sh;
    int order = 8;            // L (Sh); 0 for Grid
    DirectionGrid grid;       // the traced directions (manifest "grid"); Grid: the coefficients
    Precision precision = Precision::F32;
    SurfaceLayout layout;
    // Weights, dequantized: weights[(k * sampleCount + i) * 4 + c], k in even order
    // (shEvenIndex) for Sh, the grid direction index j for Grid; c = exit x, y, z (object space)
    // and path length.
    std::vector<float> weights;
    // For U8 only: per coefficient k and channel c, value = scale * code + offset.
    std::vector<float> u8Scale, u8Offset;  // coefficientCount() * 4 each

    // The bake's model of its own angular error (docs/format.md "error"): per sample the even SH
    // through errorOrder of ln(angle + kErrorOffset), the angle in radians between the fitted and
    // the traced exit. errors[k * sampleCount + i]; errorOrder < 0 (files before version 3): none.
    int errorOrder = -1;
    std::vector<float> errors;

    int coefficientCount() const;  // basisCoefficients(basis, order, grid)
    // What the tools print for the model: "order 12", or "grid basis 16x32".
    std::string modelName() const;
    int errorCoefficientCount() const;  // shEvenCount(errorOrder), 0 without a model

    // Not stored: what readBake noticed that the caller should tell the user (e.g. a version 1
    // file, which carries no checksums).
    std::vector<std::string> warnings;
};

// The object's medium as the runtime shades it: the manifest's first medium (docs/format.md
// "media"), its "ior" (1.5 when absent) and "absorption" kappa per object-space unit (0 when
// absent).
float frontIor(const BakeData& data);
glm::vec3 frontAbsorption(const BakeData& data);

struct ReadOptions {
    // Check every part and the manifest against their checksums (version 2 files). Off: faster,
    // and a corrupt file may load garbage.
    bool verify = true;
};

// Bytes of one sample's weights, K coefficients of four channels: 16 per coefficient in f32, 8 in
// f16, 4 in u8, in the file's weights part and in the runtime's weight textures alike.
uint64_t weightsTexelBytes(int K, Precision p);

// The weights in memory as a file at `data.precision` holds them, so that a bake drawn straight
// from memory draws as its file does: U8 rounds every weight to its code's value and sets
// u8Scale and u8Offset (the fit writeBake makes, which gives the same again on the rounded
// weights); F16 rounds to half; F32 leaves them. Throws std::invalid_argument on a non-finite
// weight, as writeBake does.
void quantizeWeights(BakeData& data);

// Writes to a temporary file beside `path` and renames it when complete (writeAtomically,
// common/output.h): on any failure nothing is left and an existing file at `path` is untouched;
// a refused target (missing folder, symbolic link, FIFO, device) is an InputError, a failed
// write an IoError with the OS's reason. Quantizes to `data.precision`.
void writeBake(const std::string& path, const BakeData& data);
// Reads and validates; throws InputError naming the file and the problem (missing, not a
// shrefract bake, newer format version than kFormatVersion, a part or the manifest that does not
// match its checksum, inconsistent sizes).
BakeData readBake(const std::string& path, const ReadOptions& options = {});

// A shard (docs/format.md "Shards"): the float32 weights of one slice of a bake's samples and a
// manifest that names the whole bake and the slice. `shrefract-bake --shard` and checkpoints
// write them; shrefract-merge (bake/shard.h) assembles a bake's shards into its bake file.
struct ShardData {
    nlohmann::json manifest;    // must hold a "shard" object; the writer adds the format keys
    Basis basis = Basis::Sh;    // as BakeData's
    int order = 8;              // L
    DirectionGrid grid;         // as BakeData's
    size_t sampleCount = 0;     // samples in this slice
    std::vector<float> weights; // [(k * sampleCount + i) * 4 + c], as BakeData::weights
    int errorOrder = -1;        // the error model, as BakeData's
    std::vector<float> errors;  // [k * sampleCount + i]
};

// Writes a shard all or nothing, as writeBake does (uncompressed: float weights hardly compress).
void writeShard(const std::string& path, const ShardData& shard);
// Reads a shard and verifies it against its checksums (the manifest only when `weights` is
// false); throws InputError naming the file: not found, not a shard, corrupt, truncated.
ShardData readShard(const std::string& path, bool weights = true);

}  // namespace shrefract
