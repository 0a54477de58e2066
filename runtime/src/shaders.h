// The GLSL of shaders/, embedded into the library at build time (cmake/EmbedShaders.cmake), with
// its #include lines resolved: what the GPU compiles is exactly these files.
#pragma once

#include <string>
#include <vector>

namespace shrefract::shaders {

// The file shaders/NAME, includes resolved; throws std::invalid_argument for an unknown name.
const std::string& source(const std::string& name);
// Every embedded file's name, sorted.
std::vector<std::string> names();
// `text` with the line that holds `marker` (the whole line) replaced by `replacement`; throws
// std::invalid_argument when the marker is missing. How generated code enters its template.
std::string fill(const std::string& text, const std::string& marker, const std::string& replacement);
// `text` with its #version line set to "#version `version`" followed by `defines`.
std::string withVersion(const std::string& text, const std::string& version,
                        const std::string& defines = "");

namespace detail {
struct Embedded {
    const char* name;
    const char* text;
};
extern const Embedded kEmbedded[];
extern const int kEmbeddedCount;
}  // namespace detail

}  // namespace shrefract::shaders
