// The contents of a NAME.shrefract.exr file in memory, and its reader and writer.
// The on-disk layout (one multi-part OpenEXR file) is documented in docs/format.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace shrefract {

// 2: per-part and manifest checksums, the layout kind (docs/format.md "Versions"). Readers take
// version 1 too, unverified.
constexpr int kFormatVersion = 2;

enum class Precision { F32, F16, U8 };
const char* ToString(Precision p);
Precision parsePrecision(const std::string& text);  // "f32" | "f16" | "u8"; throws InputError

// One texel of the rho layout. kind Sample: shows mu sample a. kind Correction: the texel just
// outside a triangle's hypotenuse, value = D[a] + D[b] - D[c] (v11 = v01 + v10 - v00), so that
// hardware bilinear filtering equals barycentric interpolation on the half-cell.
struct RhoTexel {
    enum Kind : uint32_t { Empty = 0, Sample = 1, Correction = 2 };
    uint32_t kind = Empty;
    uint32_t a = 0, b = 0, c = 0;
};

// The joining-surfaces layout (paper §5.3): unique samples O_d packed in mu, every triangle as a
// right triangle of texels in rho, two per block (the second rotated 180 degrees).
struct SurfaceLayout {
    int rate = 1;  // r: grid steps per triangle edge
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

    int sampleCount() const { return static_cast<int>(position.size()); }
    // The texel (x, y) in rho of grid sample (i, j) of triangle t (i + j <= r + 1 reaches the
    // correction texels).
    glm::ivec2 rhoTexel(int t, int i, int j) const;
    // The mu sample at grid position (i, j) of triangle t, i + j <= rate.
    uint32_t sampleAt(int t, int i, int j) const;
};

struct BakeData {
    nlohmann::json manifest;  // everything descriptive: see docs/format.md
    int order = 8;            // L
    Precision precision = Precision::F32;
    SurfaceLayout layout;
    // SH weights, dequantized: weights[(k * sampleCount + i) * 4 + c], k in even order
    // (shEvenIndex), c = exit x, y, z (object space) and path length.
    std::vector<float> weights;
    // For U8 only: per coefficient k and channel c, value = scale * code + offset.
    std::vector<float> u8Scale, u8Offset;  // shEvenCount(order) * 4 each

    int coefficientCount() const;  // shEvenCount(order)

    // Not stored: what readBake noticed that the caller should tell the user (e.g. a version 1
    // file, which carries no checksums).
    std::vector<std::string> warnings;
};

struct ReadOptions {
    // Check every part and the manifest against their checksums (version 2 files). Off: faster,
    // and a corrupt file may load garbage.
    bool verify = true;
};

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
    int order = 8;              // L
    size_t sampleCount = 0;     // samples in this slice
    std::vector<float> weights; // [(k * sampleCount + i) * 4 + c], as BakeData::weights
};

// Writes a shard all or nothing, as writeBake does (uncompressed: float weights hardly compress).
void writeShard(const std::string& path, const ShardData& shard);
// Reads a shard and verifies it against its checksums (the manifest only when `weights` is
// false); throws InputError naming the file: not found, not a shard, corrupt, truncated.
ShardData readShard(const std::string& path, bool weights = true);

}  // namespace shrefract
