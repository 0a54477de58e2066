#include "common/checksum.h"

#include <cstdio>
#include <new>

// Header-only use of Debian's libxxhash-dev: nothing to link, for the bake and for apps that
// link the runtime alike.
#define XXH_INLINE_ALL
#include <xxhash.h>

namespace shrefract {

struct Checksum::State {
    XXH3_state_t s;
};

Checksum::Checksum() : state_(std::make_unique<State>()) { XXH3_64bits_reset(&state_->s); }
Checksum::~Checksum() = default;
Checksum::Checksum(Checksum&&) noexcept = default;
Checksum& Checksum::operator=(Checksum&&) noexcept = default;

void Checksum::update(const void* data, size_t bytes) {
    if (bytes > 0) XXH3_64bits_update(&state_->s, data, bytes);
}

uint64_t Checksum::value() const { return XXH3_64bits_digest(&state_->s); }

static std::string toHex(uint64_t v) {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(v));
    return text;
}

std::string Checksum::hex() const { return toHex(value()); }

std::string checksumHex(const void* data, size_t bytes) { return toHex(XXH3_64bits(data, bytes)); }

}  // namespace shrefract
