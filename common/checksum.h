// XXH3-64 checksums (Debian's libxxhash, used header-only), written as 16 lower-case hex
// digits: what a bake file records for each of its parts and for its manifest (docs/format.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace shrefract {

// Incremental: update() over the bytes in order, then hex(); the same bytes in any split give
// the same result as checksumHex() over them all.
class Checksum {
public:
    Checksum();
    ~Checksum();
    Checksum(Checksum&&) noexcept;
    Checksum& operator=(Checksum&&) noexcept;
    void update(const void* data, size_t bytes);
    uint64_t value() const;
    std::string hex() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

// XXH3-64 (seed 0) of `bytes` bytes, as 16 hex digits.
std::string checksumHex(const void* data, size_t bytes);
inline std::string checksumHex(const std::string& text) { return checksumHex(text.data(), text.size()); }

}  // namespace shrefract
