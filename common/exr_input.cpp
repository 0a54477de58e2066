#include "common/exr_input.h"

#include <cstdint>
#include <filesystem>
#include <fstream>

#include "common/error.h"

namespace shrefract {

namespace {

constexpr uint32_t kLongNames = 0x400, kMultiPart = 0x1000;

int32_t readInt(const unsigned char* b) {
    return int32_t(uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24);
}

// The size OpenEXR 3.1 reads for a value of a standard fixed-size type, or -1 for others. Its
// typed readers read that many bytes whatever the size field says, so a mismatch would make
// OpenEXR read the rest of the header out of step (and take the bytes it lands on for a size).
int fixedSize(const std::string& type) {
    static const std::pair<const char*, int> sizes[] = {
        {"box2i", 16},  {"box2f", 16},      {"chromaticities", 32}, {"compression", 1},
        {"double", 8},  {"envmap", 1},      {"float", 4},           {"int", 4},
        {"keycode", 28}, {"lineOrder", 1},  {"m33f", 36},           {"m33d", 72},
        {"m44f", 64},   {"m44d", 128},      {"rational", 8},        {"tiledesc", 9},
        {"timecode", 8}, {"v2i", 8},        {"v2f", 8},             {"v2d", 16},
        {"v3i", 12},    {"v3f", 12},        {"v3d", 24},            {"deepImageState", 1}};
    for (const auto& [name, size] : sizes)
        if (type == name) return size;
    return -1;
}

// Whether a value of `type` read the way OpenEXR reads it takes exactly its `size` bytes.
bool valueFits(const std::string& type, const std::string& v, size_t maxName) {
    const int fixed = fixedSize(type);
    if (fixed >= 0) return v.size() == size_t(fixed);
    const auto* b = reinterpret_cast<const unsigned char*>(v.data());
    if (type == "chlist") {  // entries: a name, then type, pLinear + 3 reserved, x and y sampling
        size_t at = 0;
        for (;;) {
            const size_t end = v.find('\0', at);
            if (end == std::string::npos || end - at > maxName) return false;
            if (end == at) return end + 1 == v.size();  // the empty name ends the list
            at = end + 1 + 16;
            if (at > v.size()) return false;
        }
    }
    if (type == "preview") {  // width, height, then 4 bytes a pixel
        if (v.size() < 8) return false;
        const uint64_t w = uint32_t(readInt(b)), h = uint32_t(readInt(b + 4));
        return w * h * 4 + 8 == v.size();
    }
    if (type == "stringvector") {  // (length, bytes) until the size is used up
        size_t at = 0;
        while (at < v.size()) {
            if (at + 4 > v.size()) return false;
            const int32_t n = readInt(b + at);
            if (n < 0 || at + 4 + size_t(n) > v.size()) return false;
            at += 4 + size_t(n);
        }
        return true;
    }
    if (type == "floatvector") return v.size() % 4 == 0;
    return true;  // string, and types OpenEXR keeps opaque: read by their size
}

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
            const std::string type = readName("an attribute type");
            unsigned char b[4];
            if (!in.read(reinterpret_cast<char*>(b), 4)) throw corrupt("the file ends inside a header");
            const int32_t bytes = readInt(b);
            const uint64_t at = uint64_t(in.tellg());
            if (bytes < 0 || at + uint64_t(bytes) > size)
                throw corrupt("header attribute \"" + name + "\" claims " + std::to_string(bytes) +
                              " bytes, the file has " + std::to_string(size - at) + " left");
            std::string value(size_t(bytes), '\0');
            if (!in.read(value.data(), bytes)) throw corrupt("the file ends inside a header");
            if (!valueFits(type, value, maxName))
                throw corrupt("header attribute \"" + name + "\" of type " + type + " does not fill its " +
                              std::to_string(bytes) + " bytes");
        }
    }
    if (flags & kMultiPart) throw corrupt("more than 1024 parts");
}

}  // namespace shrefract
