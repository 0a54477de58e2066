// The input of `shrefract-eval query`: rows px,py,pz,wx,wy,wz, an object-space surface point and
// a view direction toward the viewer (docs/evaluation.md).
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace shrefract {

struct Query {
    glm::vec3 point{0.0f};
    glm::vec3 view{0.0f};  // as given, not normalized
    int line = 0;          // in the file, from 1
};

// Parses the CSV text of file `name`: six comma- (or blank-) separated finite numbers per row;
// blank lines, lines starting with '#' and a header on the first line are skipped. Throws
// InputError "NAME: line L: ..." for a short or non-numeric row, a non-finite number, a zero
// view direction, or no rows at all. Numbers beyond 1e18 count as not finite.
std::vector<Query> parseQueries(const std::string& text, const std::string& name);

// Reads and parses file `path` (InputError "file not found" if it cannot be opened).
std::vector<Query> readQueries(const std::string& path);

}  // namespace shrefract
