#include "common/query.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "common/error.h"

namespace shrefract {

std::vector<Query> parseQueries(const std::string& text, const std::string& name) {
    std::vector<Query> out;
    std::istringstream in(text);
    std::string line;
    int lineNo = 0;
    auto fail = [&](const std::string& what) {
        throw inputError(name, "line " + std::to_string(lineNo) + ": " + what);
    };
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const size_t first = line.find_first_not_of(" \t");
        if (first == std::string::npos || line[first] == '#') continue;
        // A header: the first line, if it does not start with a number (px,py,...).
        if (lineNo == 1) {
            char* end = nullptr;
            std::strtod(line.c_str() + first, &end);
            if (end == line.c_str() + first) continue;
        }
        float v[6];
        const char* p = line.c_str();
        for (int k = 0; k < 6; ++k) {
            while (*p == ' ' || *p == '\t') ++p;
            if (k > 0 && *p == ',') {
                ++p;
                while (*p == ' ' || *p == '\t') ++p;
            }
            char* end = nullptr;
            const double x = std::strtod(p, &end);
            if (end == p)
                fail("expected 6 numbers px,py,pz,wx,wy,wz, found " + std::to_string(k));
            // Finite, and small enough that lengths and dot products stay finite in float.
            if (!std::isfinite(x) || std::fabs(x) > 1e18)
                fail("number " + std::to_string(k + 1) + " is not finite (or beyond 1e18)");
            v[k] = static_cast<float>(x);
            p = end;
        }
        while (*p == ' ' || *p == '\t' || *p == ',') ++p;
        if (size_t(p - line.c_str()) != line.size()) fail("more than 6 values, or text after them");
        Query q;
        q.point = {v[0], v[1], v[2]};
        q.view = {v[3], v[4], v[5]};
        q.line = lineNo;
        if (!(glm::length(q.view) > 1e-6f)) fail("zero view direction");
        out.push_back(q);
    }
    if (out.empty()) throw inputError(name, "no queries (rows px,py,pz,wx,wy,wz)");
    return out;
}

std::vector<Query> readQueries(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw inputError(path, "file not found");
    std::stringstream text;
    text << in.rdbuf();
    return parseQueries(text.str(), path);
}

}  // namespace shrefract
