#include "shaders.h"

#include <map>
#include <stdexcept>

namespace shrefract::shaders {

namespace {
const std::map<std::string, std::string>& table() {
    static const std::map<std::string, std::string> t = [] {
        std::map<std::string, std::string> m;
        for (int i = 0; i < detail::kEmbeddedCount; ++i)
            m.emplace(detail::kEmbedded[i].name, detail::kEmbedded[i].text);
        return m;
    }();
    return t;
}
}  // namespace

const std::string& source(const std::string& name) {
    auto it = table().find(name);
    if (it == table().end()) throw std::invalid_argument("shrefract: no shader named " + name);
    return it->second;
}

std::vector<std::string> names() {
    std::vector<std::string> v;
    for (const auto& [name, text] : table()) v.push_back(name);
    return v;
}

std::string fill(const std::string& text, const std::string& marker, const std::string& replacement) {
    const size_t at = text.find(marker);
    if (at == std::string::npos)
        throw std::invalid_argument("shrefract: shader template has no line \"" + marker + "\"");
    const size_t begin = text.rfind('\n', at) == std::string::npos ? 0 : text.rfind('\n', at) + 1;
    size_t end = text.find('\n', at);
    end = end == std::string::npos ? text.size() : end + 1;
    std::string r = replacement;
    if (!r.empty() && r.back() != '\n') r += '\n';
    return text.substr(0, begin) + r + text.substr(end);
}

std::string withVersion(const std::string& text, const std::string& version,
                        const std::string& defines) {
    if (text.rfind("#version", 0) != 0)
        throw std::invalid_argument("shrefract: shader does not start with #version");
    const size_t eol = text.find('\n');
    std::string d = defines;
    if (!d.empty() && d.back() != '\n') d += '\n';
    return "#version " + version + "\n" + d + text.substr(eol + 1);
}

}  // namespace shrefract::shaders
