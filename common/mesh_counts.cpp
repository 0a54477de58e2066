#include "common/mesh_counts.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "common/error.h"

namespace shrefract {

namespace {

std::string readAll(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

// Splits a line into blank-separated tokens.
std::vector<std::string> tokens(const std::string& line) {
    std::vector<std::string> out;
    std::istringstream ss(line);
    for (std::string t; ss >> t;) out.push_back(t);
    return out;
}

bool isNumber(const std::string& t) {
    if (t.empty()) return false;
    char* end = nullptr;
    std::strtod(t.c_str(), &end);
    return end == t.c_str() + t.size();
}

bool isCount(const std::string& t, uint64_t* v) {
    if (t.empty() || !std::all_of(t.begin(), t.end(), [](unsigned char c) { return std::isdigit(c); }))
        return false;
    if (t.size() > 12) return false;
    *v = std::strtoull(t.c_str(), nullptr, 10);
    return true;
}

// Reads the file line by line, with '#' comments and blank lines dropped (OFF).
class Lines {
public:
    explicit Lines(const std::string& text) : in_(text) {}
    bool next(std::string* line) {
        while (std::getline(in_, *line)) {
            ++number_;
            const size_t hash = line->find('#');
            if (hash != std::string::npos) line->resize(hash);
            if (line->find_first_not_of(" \t\r") != std::string::npos) return true;
        }
        return false;
    }
    size_t number() const { return number_; }
    size_t offset() { return size_t(in_.tellg()); }

private:
    std::istringstream in_;
    size_t number_ = 0;
};

// --- OFF ----------------------------------------------------------------------------------------

void checkOff(const std::string& path, const std::string& text) {
    Lines lines(text);
    std::string line;
    if (!lines.next(&line)) throw inputError(path, "could not parse: no OFF header");
    std::vector<std::string> t = tokens(line);
    const std::string key = t.empty() ? "" : t[0];
    // [ST][C][N]OFF. Anything else is refused here rather than left to OpenMesh, which reads
    // counts from whatever follows and reserves memory for them (found by the fuzzer: an "OFF&"
    // header with a count of -1).
    static const char* const kKeys[] = {"OFF", "COFF", "NOFF", "CNOFF", "STOFF", "STCOFF", "STNOFF",
                                        "STCNOFF"};
    if (std::find(std::begin(kKeys), std::end(kKeys), key) == std::end(kKeys))
        throw inputError(path, "could not parse: '" + key + "' is not an OFF keyword this reader knows "
                               "(OFF, COFF, NOFF, CNOFF, ST...)");
    t.erase(t.begin());
    if (!t.empty() && t[0] == "BINARY") {
        // Counts then data as 32-bit values; refuse only what neither byte order can hold.
        const size_t at = lines.offset();
        if (at == size_t(-1) || text.size() < at + 12)
            throw inputError(path, "cut short: binary OFF without its vertex and face counts");
        uint32_t raw[2];  // as OpenMesh reads them: in the machine's byte order
        std::memcpy(raw, text.data() + at, 8);
        const uint64_t rest = text.size() - at - 12;
        if (uint64_t(raw[0]) * 12 + uint64_t(raw[1]) * 16 > rest)  // xyz; k and 3 indices
            throw inputError(path, "cut short: the binary OFF header promises more vertices and "
                                   "faces than its " + std::to_string(rest) + " bytes of data hold");
        return;
    }
    // OpenMesh reads the counts from the line after the keyword, never from the keyword's own
    // line: counts there leave its counts unread and it reserves for garbage (found by the fuzzer:
    // "OFF 0 0" asked for 4 GB).
    if (!t.empty())
        throw inputError(path, "could not parse: '" + line.substr(0, 40) + "': the vertex and face "
                               "counts must stand on the line after " + key);
    if (!lines.next(&line)) throw inputError(path, "cut short: OFF without its counts");
    t = tokens(line);
    // Exactly the vertex, face and edge counts. OpenMesh reads the three from the stream, not
    // from the line: with two it takes the first coordinate for the edge count and reads every
    // vertex out of step (a cube loaded with bounds up to 3 and one face missing); with more it
    // reads on past them, and the fuzzer's "8 04 63 2 3 3 -1 0" made a face of 2^31 vertices.
    uint64_t nv = 0, nf = 0, ne = 0;
    if (t.size() < 2 || !isCount(t[0], &nv) || !isCount(t[1], &nf))
        throw inputError(path, "could not parse: no vertex and face counts after " + key);
    if (t.size() != 3 || !isCount(t[2], &ne))
        throw inputError(path, "line " + std::to_string(lines.number()) + ": the counts line holds " +
                                   std::to_string(t.size()) + " values, not the vertex, face and edge counts");
    const std::string promise = "the header promises " + std::to_string(nv) + " vertices and " +
                                std::to_string(nf) + " faces";
    // Every value as OpenMesh's stream reads it: a number it would overflow on (and then read no
    // further, for ever: found by the fuzzer) is refused here.
    auto number = [](const std::string& x, double limit) {
        if (!isNumber(x)) return false;
        const double v = std::strtod(x.c_str(), nullptr);
        return !(std::fabs(v) > limit);  // NaN passes: the non-finite scan names it
    };
    for (uint64_t v = 0; v < nv; ++v) {
        if (!lines.next(&line))
            throw inputError(path, "cut short: " + promise + ", the file ends after " +
                                       std::to_string(v) + " vertices");
        t = tokens(line);
        if (t.size() < 3 || t.size() > 12 ||
            !std::all_of(t.begin(), t.end(), [&](const std::string& x) { return number(x, 1e30); }))
            throw inputError(path, "line " + std::to_string(lines.number()) + ": vertex " +
                                       std::to_string(v) + " is not 3 numbers (and its normal, "
                                       "colour or texture coordinates)");
    }
    for (uint64_t f = 0; f < nf; ++f) {
        if (!lines.next(&line))
            throw inputError(path, "cut short: " + promise + ", the file ends after " +
                                       std::to_string(f) + " faces");
        t = tokens(line);
        uint64_t k = 0;
        const std::string where = "line " + std::to_string(lines.number()) + ": face " + std::to_string(f);
        if (t.empty() || !isCount(t[0], &k) || t.size() < k + 1)
            throw inputError(path, where + " is not a count and that many indices");
        for (uint64_t c = 1; c <= k; ++c) {
            uint64_t index = 0;
            if (!isCount(t[c], &index) || index >= nv)
                throw inputError(path, where + " refers to vertex " + t[c] + " of " +
                                           std::to_string(nv));
        }
        // Nothing after the indices. OpenMesh's OFF reader does not read a face colour, even when
        // asked to: it reads on through the stream, and takes the colour as the next face's
        // vertex count (found by the fuzzer: a colour of -12 became a count of 2^32 - 12, and
        // the reader grew a vector to 3 GB). A file with face colours is refused, not misread.
        if (t.size() != k + 1)
            throw inputError(path, where + " has " + std::to_string(t.size() - 1 - k) +
                                       " values after its indices (face colours are not read)");
    }
}

// --- PLY ----------------------------------------------------------------------------------------

struct PlyProperty {
    int size = 0;           // scalar, or the list's item
    int countSize = 0;      // list only: the size of its length
    bool integer = false;   // the scalar or the list's items are integers
};

bool isPlyFloatType(const std::string& type) { return type.find("float") != std::string::npos || type == "double"; }

// An ASCII PLY value as its property's type reads it: an optional sign and digits for integers.
bool isPlyValue(const std::string& t, bool integer) {
    // Decimal syntax only: strtod's "inf", "nan" and hex floats stop a C++ stream too.
    if (!integer) return isNumber(t) && t.find_first_not_of("0123456789+-.eE") == std::string::npos;
    const size_t digits = t[0] == '-' || t[0] == '+' ? 1 : 0;
    return t.size() > digits && t.size() <= 12 &&
           std::all_of(t.begin() + digits, t.end(), [](unsigned char c) { return std::isdigit(c); });
}

struct PlyElement {
    std::string name;
    uint64_t count = 0;
    std::vector<PlyProperty> properties;
};

int plyTypeSize(const std::string& type) {
    static const std::pair<const char*, int> sizes[] = {
        {"char", 1},   {"int8", 1},   {"uchar", 1},   {"uint8", 1},  {"short", 2},
        {"int16", 2},  {"ushort", 2}, {"uint16", 2},  {"int", 4},    {"int32", 4},
        {"uint", 4},   {"uint32", 4}, {"float", 4},   {"float32", 4}, {"double", 8},
        {"float64", 8}};
    for (const auto& [name, size] : sizes)
        if (type == name) return size;
    return 0;
}

uint64_t readUnsigned(const unsigned char* p, int size, bool bigEndian) {
    uint64_t v = 0;
    for (int i = 0; i < size; ++i) v |= uint64_t(p[bigEndian ? size - 1 - i : i]) << (8 * i);
    return v;
}

void checkPly(const std::string& path, const std::string& whole) {
    // OpenMesh's reader skips white space before the magic "ply" (found by the fuzzer: vertical
    // tabs before it let a header past this check, and OpenMesh looped on it): so does this.
    const size_t first = whole.find_first_not_of(" \t\r\n\v\f");
    const std::string text = first == std::string::npos ? std::string() : whole.substr(first);
    std::istringstream in(text);
    std::string line;
    // The magic in any case: OpenMesh takes "PLY" too (found by the fuzzer: an upper-case
    // magic slipped a damaged header past this check, and OpenMesh looped on it).
    auto isMagic = [](const std::string& l) {
        return l.size() >= 3 && std::tolower((unsigned char)l[0]) == 'p' &&
               std::tolower((unsigned char)l[1]) == 'l' && std::tolower((unsigned char)l[2]) == 'y';
    };
    if (!std::getline(in, line) || !isMagic(line)) return;
    std::string format;
    std::vector<PlyElement> elements;
    bool ended = false;
    // The header is checked line by line as the PLY format defines it: OpenMesh's reader trusts
    // it (a property before any element crashed it, found by the fuzzer: tests/fuzz/regressions).
    auto bad = [&](const std::string& why) { return inputError(path, "PLY header: '" + line + "' " + why); };
    while (std::getline(in, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const std::vector<std::string> t = tokens(line);
        if (t.empty()) continue;
        if (t[0] == "end_header") {
            ended = true;
            break;
        }
        if (t[0] == "comment" || t[0] == "obj_info") continue;
        if (t[0] == "format") {
            if (t.size() != 3 || !format.empty() || t[2] != "1.0" ||
                (t[1] != "ascii" && t[1] != "binary_little_endian" && t[1] != "binary_big_endian"))
                throw bad("is not a format this reader knows");
            format = t[1];
        } else if (t[0] == "element") {
            PlyElement e;
            if (t.size() != 3 || !isCount(t[2], &e.count) || e.count > (uint64_t(1) << 31))
                throw bad("is not 'element NAME COUNT'");
            e.name = t[1];
            elements.push_back(e);
        } else if (t[0] == "property") {
            if (elements.empty()) throw bad("comes before any element");
            PlyProperty p;
            if (t.size() == 5 && t[1] == "list") {
                p.countSize = plyTypeSize(t[2]);
                p.size = plyTypeSize(t[3]);
                p.integer = !isPlyFloatType(t[3]);
                if (isPlyFloatType(t[2])) p.countSize = 0;
            } else if (t.size() == 3) {
                p.size = plyTypeSize(t[1]);
                p.integer = !isPlyFloatType(t[1]);
            }
            if (p.size == 0 || (t[1] == "list" && p.countSize == 0))
                throw bad("is not a property of a known type");
            elements.back().properties.push_back(p);
        } else {
            throw bad("is not a PLY header line");
        }
    }
    if (format.empty()) throw inputError(path, "PLY header without a format line");
    if (!ended) throw inputError(path, "cut short: the PLY header has no end_header");
    // Records without properties take no bytes in a binary file, so no file size bounds their
    // count, and OpenMesh reserves memory for all of them (found by the fuzzer: 2^28 vertices
    // without properties asked for 3 GB). They carry nothing, so they are refused in any format.
    for (const PlyElement& e : elements)
        if (e.count > 0 && e.properties.empty())
            throw inputError(path, "PLY header: element " + e.name + " has " + std::to_string(e.count) +
                                       " records but no properties");
    auto promise = [&](const PlyElement& e, uint64_t got) {
        return "cut short: the header promises " + std::to_string(e.count) + " " + e.name +
               " elements, the file ends after " + std::to_string(got);
    };
    if (format == "ascii") {
        for (const PlyElement& e : elements) {
            for (uint64_t r = 0; r < e.count; ++r) {
                std::vector<std::string> t;
                while (t.empty()) {
                    if (!std::getline(in, line)) throw inputError(path, promise(e, r));
                    t = tokens(line);
                }
                size_t at = 0;
                for (const PlyProperty& p : e.properties) {
                    uint64_t n = 1;
                    if (p.countSize > 0 && (at >= t.size() || !isCount(t[at++], &n)))
                        throw inputError(path, e.name + " " + std::to_string(r) +
                                                   ": a list without its length");
                    // Every value a number of its type: OpenMesh's reader stops at the first
                    // that is not and loops on (found by the fuzzer: "3HHH" as a face index
                    // grew a vector to 2 GB).
                    for (size_t v = at; v < at + size_t(n) && v < t.size(); ++v)
                        if (!isPlyValue(t[v], p.integer))
                            throw inputError(path, e.name + " " + std::to_string(r) + ": '" + t[v] +
                                                       "' is not " + (p.integer ? "an integer" : "a number"));
                    at += size_t(n);
                }
                // Exactly those values: OpenMesh reads values, not lines, so one value too many
                // puts every later one out of step (found by the fuzzer: "2 0 3 2" as a face
                // line, then "-4" taken as a list length, grew a vector to 2 GB).
                if (at != t.size())
                    throw inputError(path, e.name + " " + std::to_string(r) + " has " +
                                               std::to_string(t.size()) + " values, its header " +
                                               "says " + std::to_string(at));
            }
        }
        return;
    }
    if (format != "binary_little_endian" && format != "binary_big_endian") return;
    const bool big = format == "binary_big_endian";
    const auto* data = reinterpret_cast<const unsigned char*>(text.data());
    const uint64_t end = text.size();
    uint64_t at = in.tellg() == std::streampos(-1) ? end : uint64_t(in.tellg());
    for (const PlyElement& e : elements) {
        if (e.properties.empty()) continue;  // and so no records
        uint64_t fixed = 0;
        bool lists = false;
        for (const PlyProperty& p : e.properties) {
            lists |= p.countSize > 0;
            fixed += uint64_t(p.countSize > 0 ? p.countSize : p.size);
        }
        if (!lists) {  // fixed-size records: one comparison
            if (e.count > (end - at) / fixed)
                throw inputError(path, promise(e, (end - at) / fixed));
            at += e.count * fixed;
            continue;
        }
        for (uint64_t r = 0; r < e.count; ++r) {
            for (const PlyProperty& p : e.properties) {
                uint64_t n = 1;
                if (p.countSize > 0) {
                    if (at + uint64_t(p.countSize) > end) throw inputError(path, promise(e, r));
                    n = readUnsigned(data + at, p.countSize, big);
                    at += uint64_t(p.countSize);
                }
                if (n > (end - at) / uint64_t(p.size)) throw inputError(path, promise(e, r));
                at += n * uint64_t(p.size);
            }
        }
    }
}

// --- STL ----------------------------------------------------------------------------------------

void checkStl(const std::string& path, const std::string& text) {
    if (text.size() >= 84) {
        uint32_t n = 0;
        std::memcpy(&n, text.data() + 80, 4);
        if (text.size() == 84 + 50 * uint64_t(n)) return;  // binary, exactly its triangles
    }
    const size_t first = text.find_first_not_of(" \t\r\n");
    const bool ascii = first != std::string::npos && lower(text.substr(first, 5)) == "solid";
    if (!ascii) {
        uint32_t n = 0;
        if (text.size() >= 84) std::memcpy(&n, text.data() + 80, 4);
        throw inputError(path, "binary STL cut short or padded: its header promises " +
                                   std::to_string(n) + " triangles (" +
                                   std::to_string(84 + 50 * uint64_t(n)) +
                                   " bytes), the file has " + std::to_string(text.size()));
    }
    std::istringstream in(text);
    std::string line, last;
    uint64_t facets = 0, closed = 0, vertices = 0;
    while (std::getline(in, line)) {
        const std::vector<std::string> t = tokens(line);
        if (t.empty()) continue;
        const std::string key = lower(t[0]);
        last = key;
        if (key == "facet") ++facets;
        if (key == "endfacet") ++closed;
        if (key == "vertex") {
            ++vertices;
            if (t.size() < 4 || !isNumber(t[1]) || !isNumber(t[2]) || !isNumber(t[3]))
                throw inputError(path, "ASCII STL vertex " + std::to_string(vertices - 1) +
                                           " is not 3 numbers");
        }
    }
    if (last != "endsolid" || closed != facets || vertices != 3 * facets)
        throw inputError(path, "cut short: ASCII STL with " + std::to_string(facets) +
                                   " facets, " + std::to_string(closed) + " closed, " +
                                   std::to_string(vertices) + " vertices" +
                                   (last != "endsolid" ? ", no endsolid at its end" : ""));
}

// --- OBJ ----------------------------------------------------------------------------------------

// A face corner: v, v/t, v//n or v/t/n, each a non-zero integer (negative: relative). Writes the
// three indices, 0 where a field is absent.
bool parseObjCorner(const std::string& t, long long index[3]) {
    index[0] = index[1] = index[2] = 0;
    size_t at = 0;
    for (int field = 0; field < 3; ++field) {
        const size_t start = at;
        if (at < t.size() && t[at] == '-') ++at;
        const size_t digits = at;
        while (at < t.size() && std::isdigit(static_cast<unsigned char>(t[at]))) ++at;
        if (at == digits) {
            if (field == 0 || at != start) return false;  // the vertex index is required
        } else if (t.find_first_not_of('0', digits) >= at || at - digits > 12) {
            return false;  // index 0 does not exist in OBJ
        } else {
            index[field] = std::strtoll(t.c_str() + start, nullptr, 10);
        }
        if (at == t.size()) return true;
        if (t[at] != '/' || field == 2) return false;
        ++at;
    }
    return false;
}

void checkObj(const std::string& path, const std::string& text) {
    // Vertices, texture coordinates and normals in the whole file: OpenMesh takes a face before
    // the vertices it names.
    static const char* const kLists[3] = {"v", "vt", "vn"};
    static const char* const kNames[3] = {"vertex", "texture coordinate", "normal"};
    auto list = [](const std::string& key) {
        return int(std::find(std::begin(kLists), std::end(kLists), key) - std::begin(kLists));
    };
    uint64_t total[4] = {0, 0, 0, 0}, seen[4] = {0, 0, 0, 0};  // [3]: every other line
    {
        std::istringstream in(text);
        for (std::string line; std::getline(in, line);)
            if (const std::vector<std::string> t = tokens(line); !t.empty()) ++total[list(t[0])];
    }
    std::istringstream in(text);
    std::string line;
    size_t number = 0;
    auto bad = [&](const std::string& what) {
        return inputError(path, "line " + std::to_string(number) + ": " + what);
    };
    while (std::getline(in, line)) {
        ++number;
        const std::vector<std::string> t = tokens(line);
        if (t.empty()) continue;
        ++seen[list(t[0])];
        const size_t n = t.size() - 1;
        const bool numbers = std::all_of(t.begin() + 1, t.end(), isNumber);
        // OpenMesh's OBJ reader asserts on a face without a readable corner (found by the
        // fuzzer), so vertex and face lines are checked to the letter.
        if (t[0] == "v") {
            if ((n != 3 && n != 4 && n != 6 && n != 7) || !numbers)
                throw bad("a vertex is not 3 numbers (or 4, or with 3 colour values)");
        } else if (t[0] == "vt") {
            if (n < 1 || n > 3 || !numbers) throw bad("a texture coordinate is not 1 to 3 numbers");
        } else if (t[0] == "vn") {
            if (n != 3 || !numbers) throw bad("a normal is not 3 numbers");
        } else if (t[0] == "f") {
            if (t.size() < 4) throw bad("a face of fewer than 3 corners");
            for (size_t c = 1; c < t.size(); ++c) {
                long long index[3];
                if (!parseObjCorner(t[c], index))
                    throw bad("a face corner is not v, v/t, v//n or v/t/n with non-zero indices");
                // Every index names one the file has (a negative one, one before this line).
                // OpenMesh writes the texture coordinate of a corner whose vertex it does not
                // have before it drops the face (found by the fuzzer: "f 2/1 6 5" with one
                // vertex, a heap-buffer-overflow), and takes a texture coordinate or normal
                // index past the file's without a word.
                for (int k = 0; k < 3; ++k) {
                    const uint64_t have = index[k] < 0 ? seen[k] : total[k];
                    if (index[k] != 0 && uint64_t(std::llabs(index[k])) > have)
                        throw bad("face corner " + t[c] + " names " + kNames[k] + " " +
                                  std::to_string(index[k]) + " of " + std::to_string(have));
                }
            }
        }
    }
}

}  // namespace

void checkMeshCounts(const std::string& path, const std::string& ext) {
    const std::string text = readAll(path);
    if (ext == ".off") checkOff(path, text);
    if (ext == ".ply") checkPly(path, text);
    if (ext == ".stl") checkStl(path, text);
    if (ext == ".obj") checkObj(path, text);
}

}  // namespace shrefract
