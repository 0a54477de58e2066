#include "common/exr_input.h"

#include <cstdint>
#include <filesystem>
#include <fstream>

#include "common/error.h"

namespace shrefract {

namespace {

constexpr uint32_t kLongNames = 0x400, kMultiPart = 0x1000;

}  // namespace

void checkExrHeaders(const std::string& path) {
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) throw inputError(path, "cannot read: " + ec.message());
    std::ifstream in(path, std::ios::binary);
    if (!in) throw inputError(path, "cannot read");
    auto corrupt = [&](const std::string& what) {
        return inputError(path, "truncated or corrupt: " + what);
    };
    unsigned char head[8];
    if (!in.read(reinterpret_cast<char*>(head), 8) || head[0] != 0x76 || head[1] != 0x2f ||
        head[2] != 0x31 || head[3] != 0x01)
        throw inputError(path, "not an OpenEXR file (no OpenEXR magic number)");
    const uint32_t flags = uint32_t(head[4]) | uint32_t(head[5]) << 8 | uint32_t(head[6]) << 16 |
                           uint32_t(head[7]) << 24;
    const size_t maxName = (flags & kLongNames) ? 255 : 31;
    // A null-terminated name of at most maxName characters; "" at the end of a header.
    auto readName = [&](const char* what) {
        std::string s;
        for (char c; in.get(c);) {
            if (c == '\0') return s;
            if (s.size() == maxName) throw corrupt(std::string(what) + " longer than " +
                                                   std::to_string(maxName) + " characters");
            s += c;
        }
        throw corrupt("the file ends inside a header");
    };
    const int maxParts = (flags & kMultiPart) ? 1024 : 1;
    for (int part = 0; part < maxParts; ++part) {
        for (int attribute = 0;; ++attribute) {
            if (attribute == 4096) throw corrupt("a header of more than 4096 attributes");
            const std::string name = readName("an attribute name");
            if (name.empty()) {
                if (attribute == 0 && part > 0) return;  // the empty header ends a multi-part list
                break;
            }
            readName("an attribute type");
            unsigned char b[4];
            if (!in.read(reinterpret_cast<char*>(b), 4)) throw corrupt("the file ends inside a header");
            const int32_t bytes = int32_t(uint32_t(b[0]) | uint32_t(b[1]) << 8 |
                                          uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24);
            const uint64_t at = uint64_t(in.tellg());
            if (bytes < 0 || at + uint64_t(bytes) > size)
                throw corrupt("header attribute \"" + name + "\" claims " + std::to_string(bytes) +
                              " bytes, the file has " + std::to_string(size - at) + " left");
            in.seekg(bytes, std::ios::cur);
        }
    }
    if (flags & kMultiPart) throw corrupt("more than 1024 parts");
}

}  // namespace shrefract
