#include "common/mesh.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>
#include <unordered_map>

// GCC 12 warns that OpenMesh's VectorT "may be used uninitialized" when its readers copy
// vectors into std::vector (a false positive inside OpenMesh's own templates, reported where
// they inline into this file); keep our build output clean of it.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include "common/error.h"
#include "common/mesh_counts.h"

namespace shrefract {

namespace {

using OMesh = OpenMesh::TriMesh_ArrayKernelT<>;

// A triangle whose doubled area is below this fraction of the squared bbox diagonal is
// degenerate: at that size its normal is rounding noise (float positions carry ~1e-7 relative
// precision, so anything smaller than a sliver of height 1e-10 * diagonal is not a surface).
constexpr double kDegenerateRelativeArea = 1e-10;

std::string lowercase(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

std::string coordinatesString(double x, double y, double z) {
    std::ostringstream os;
    os << "(" << x << ", " << y << ", " << z << ")";
    return os.str();
}

[[noreturn]] void throwNonFinite(const std::string& path, size_t vertex, size_t line, double x,
                                 double y, double z) {
    std::ostringstream os;
    os << "vertex " << vertex;
    if (line > 0) os << " (line " << line << ")";
    os << " has non-finite coordinates " << coordinatesString(x, y, z);
    throw inputError(path, os.str());
}

// Reads up to three numbers with strtod, which (unlike operator>>) accepts "nan" and "inf".
bool parseThree(const std::string& text, size_t start, double v[3]) {
    const char* p = text.c_str() + start;
    for (int i = 0; i < 3; ++i) {
        char* end = nullptr;
        v[i] = std::strtod(p, &end);
        if (end == p) return false;
        p = end;
    }
    return true;
}

// OpenMesh's text readers parse coordinates with operator>>, which fails on "nan" and "inf":
// the vertex is then silently zeroed or dropped and later indices shift. So scan the vertex
// lines of text OBJ, OFF and STL ourselves first, to report the real problem with its line.
void scanTextForNonFinite(const std::string& path, const std::string& ext) {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    size_t lineNo = 0;
    size_t vertex = 0;
    double v[3];
    auto check = [&](size_t start) {
        if (parseThree(line, start, v) &&
            !(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])))
            throwNonFinite(path, vertex, lineNo, v[0], v[1], v[2]);
        ++vertex;
    };
    if (ext == ".obj") {
        while (std::getline(in, line)) {
            ++lineNo;
            size_t s = line.find_first_not_of(" \t");
            if (s != std::string::npos && line.compare(s, 2, "v ") == 0) check(s + 2);
        }
    } else if (ext == ".stl") {
        // Binary STL is told by its size, as OpenMesh does: 80-byte header, uint32 count, then
        // 50 bytes per triangle (normal, three corners, attribute). OpenMesh merges corners
        // through an ordered map, where a NaN compares equal to anything: check them here.
        char header[84] = {};
        in.read(header, 84);
        uint32_t count = 0;
        std::memcpy(&count, header + 80, 4);
        std::error_code ec;
        if (in && std::filesystem::file_size(path, ec) == 84 + 50 * uint64_t(count)) {
            char record[50];
            for (uint32_t t = 0; t < count && in.read(record, 50); ++t) {
                for (int k = 0; k < 3; ++k) {
                    float c[3];
                    std::memcpy(c, record + 12 + 12 * k, 12);
                    if (!(std::isfinite(c[0]) && std::isfinite(c[1]) && std::isfinite(c[2])))
                        throwNonFinite(path, 3 * size_t(t) + k, 0, c[0], c[1], c[2]);
                }
            }
            return;
        }
        if (lowercase(std::string(header, 5)) != "solid") return;  // not STL: OpenMesh decides
        in.clear();
        in.seekg(0);
        while (std::getline(in, line)) {
            ++lineNo;
            size_t s = line.find_first_not_of(" \t");
            if (s != std::string::npos && lowercase(line.substr(s, 6)) == "vertex") check(s + 6);
        }
    } else if (ext == ".off") {
        // Header keyword, then "nv nf ne", then nv vertex lines; '#' starts a comment.
        long vertexCount = -1;
        bool headerSeen = false;
        while (std::getline(in, line)) {
            ++lineNo;
            size_t hash = line.find('#');
            if (hash != std::string::npos) line.resize(hash);
            size_t s = line.find_first_not_of(" \t\r");
            if (s == std::string::npos) continue;
            if (!headerSeen) {
                headerSeen = true;
                std::string key = line.substr(s, line.find_first_of(" \t\r", s) - s);
                if (key.size() >= 3 && key.compare(key.size() - 3, 3, "OFF") == 0) {
                    if (line.find("BINARY") != std::string::npos) return;
                    if (line.find_first_not_of(" \t\r", s + key.size()) == std::string::npos)
                        continue;  // counts on the next line
                    s = line.find_first_not_of(" \t\r", s + key.size());
                }
            }
            if (vertexCount < 0) {
                char* end = nullptr;
                vertexCount = std::strtol(line.c_str() + s, &end, 10);
                if (end == line.c_str() + s) return;  // not OFF as we know it: OpenMesh decides
                continue;
            }
            if (static_cast<long>(vertex) >= vertexCount) return;
            check(s);
        }
    }
}

// OpenMesh reports trouble on omerr()/omlog(), which write to std::cerr/std::clog. We capture
// both while it reads: our caller gets one clear message, and we learn what OpenMesh dropped.
// The stream buffers are process-wide, so concurrent loads are serialized.
std::mutex gStreamCaptureMutex;

class StreamCapture {
public:
    StreamCapture()
        : lock_(gStreamCaptureMutex),
          oldCerr_(std::cerr.rdbuf(buffer_.rdbuf())),
          oldClog_(std::clog.rdbuf(buffer_.rdbuf())) {}
    ~StreamCapture() {
        std::cerr.rdbuf(oldCerr_);
        std::clog.rdbuf(oldClog_);
    }
    std::string text() const { return buffer_.str(); }

private:
    std::lock_guard<std::mutex> lock_;
    std::ostringstream buffer_;
    std::streambuf* oldCerr_;
    std::streambuf* oldClog_;
};

size_t countOccurrences(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
    return n;
}

struct PositionHash {
    size_t operator()(const glm::vec3& p) const {
        uint32_t b[3];
        std::memcpy(b, &p, sizeof b);
        return (size_t(b[0]) * 73856093u) ^ (size_t(b[1]) * 19349663u) ^ (size_t(b[2]) * 83492791u);
    }
};

// Bitwise equality, so that +0 and -0 stay apart exactly as a hash of their bits would.
struct PositionEqual {
    bool operator()(const glm::vec3& a, const glm::vec3& b) const {
        return std::memcmp(&a, &b, sizeof a) == 0;
    }
};

// For each vertex, the first vertex with bitwise the same position. Topology is judged on these
// ids: a ray cannot leak between two triangles that meet at identical coordinates, whether or
// not the file (or OpenMesh, which splits non-manifold faces off) shares the vertex.
std::vector<uint32_t> weldByPosition(const std::vector<glm::vec3>& positions) {
    std::unordered_map<glm::vec3, uint32_t, PositionHash, PositionEqual> first;
    first.reserve(positions.size());
    std::vector<uint32_t> weld(positions.size());
    for (uint32_t i = 0; i < positions.size(); ++i)
        weld[i] = first.emplace(positions[i], i).first->second;
    return weld;
}

glm::dvec3 faceCross(const std::vector<glm::vec3>& p, const glm::uvec3& t) {
    glm::dvec3 a(p[t.x]), b(p[t.y]), c(p[t.z]);
    return glm::cross(b - a, c - a);  // |cross| = twice the area; direction by winding
}

struct Topology {
    size_t borderEdges = 0;
    size_t nonManifoldEdges = 0;
    size_t inconsistentEdges = 0;  // two triangles traverse a shared edge in the same direction
};

Topology analyzeTopology(const std::vector<glm::uvec3>& triangles,
                         const std::vector<uint32_t>& weld) {
    struct EdgeUse {
        uint32_t forward = 0;   // traversed from lower to higher id
        uint32_t backward = 0;  // traversed from higher to lower id
    };
    std::unordered_map<uint64_t, EdgeUse> edges;
    edges.reserve(triangles.size() * 2);
    for (const glm::uvec3& t : triangles) {
        for (int k = 0; k < 3; ++k) {
            uint32_t a = weld[t[k]], b = weld[t[(k + 1) % 3]];
            EdgeUse& use = edges[(uint64_t(std::min(a, b)) << 32) | std::max(a, b)];
            (a < b ? use.forward : use.backward)++;
        }
    }
    Topology topo;
    for (const auto& [key, use] : edges) {
        uint32_t n = use.forward + use.backward;
        if (n == 1)
            ++topo.borderEdges;
        else if (n > 2)
            ++topo.nonManifoldEdges;
        else if (use.forward != 1)
            ++topo.inconsistentEdges;
    }
    return topo;
}

}  // namespace

glm::vec3 Mesh::boundsMin() const {
    if (positions.empty()) return glm::vec3(0.0f);
    glm::vec3 m = positions[0];
    for (const glm::vec3& p : positions) m = glm::min(m, p);
    return m;
}

glm::vec3 Mesh::boundsMax() const {
    if (positions.empty()) return glm::vec3(0.0f);
    glm::vec3 m = positions[0];
    for (const glm::vec3& p : positions) m = glm::max(m, p);
    return m;
}

std::string Mesh::checksum() const {
    // FNV-1a 64 over the raw bytes: positions (float x, y, z) then indices (uint32 a, b, c).
    uint64_t h = 14695981039346656037ull;
    auto feed = [&h](const void* data, size_t size) {
        const unsigned char* bytes = static_cast<const unsigned char*>(data);
        for (size_t i = 0; i < size; ++i) {
            h ^= bytes[i];
            h *= 1099511628211ull;
        }
    };
    for (const glm::vec3& p : positions) feed(&p[0], 3 * sizeof(float));
    for (const glm::uvec3& t : triangles) {
        uint32_t idx[3] = {t.x, t.y, t.z};
        feed(idx, sizeof idx);
    }
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
    return hex;
}

Mesh loadMesh(const std::string& path, MeshReport* report) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw inputError(path, "file not found");

    const std::string ext = lowercase(fs::path(path).extension().string());
    if (ext != ".obj" && ext != ".off" && ext != ".ply" && ext != ".stl")
        throw inputError(path, "unsupported extension '" + fs::path(path).extension().string() +
                                   "' (expected .obj, .off, .ply, .stl)");
    if (fs::file_size(path, ec) == 0) throw inputError(path, "file is empty");

    scanTextForNonFinite(path, ext);
    checkMeshCounts(path, ext);  // a file cut short: OpenMesh would take the part it got

    OMesh om;
    om.request_vertex_normals();
    // Texture coordinates: per corner (OBJ `vt`: halfedge texcoords) or per vertex (PLY).
    om.request_halfedge_texcoords2D();
    om.request_vertex_texcoords2D();
    // With status present, OpenMesh's importer marks the faces it had to split off (below).
    om.request_vertex_status();
    om.request_face_status();
    OpenMesh::IO::Options options = OpenMesh::IO::Options::VertexNormal;
    options += OpenMesh::IO::Options::FaceTexCoord;
    options += OpenMesh::IO::Options::VertexTexCoord;
    std::string omMessages;
    bool readOk;
    {
        StreamCapture capture;
        readOk = OpenMesh::IO::read_mesh(om, path, options);
        omMessages = capture.text();
    }
    if (!readOk) throw inputError(path, "could not parse (OpenMesh read failed)");
    const size_t invalidIndexFaces =
        countOccurrences(omMessages, "Face contains invalid vertex index");
    if (invalidIndexFaces > 0)
        throw inputError(path, "could not parse: " + std::to_string(invalidIndexFaces) +
                                   " faces refer to vertices that do not exist");
    // OpenMesh drops faces that repeat a vertex before we see them; they count as degenerate.
    const size_t droppedRepeated = countOccurrences(omMessages, "Face has equal vertices");

    MeshArrays a;
    a.positions.reserve(om.n_vertices());
    for (auto vh : om.vertices()) {
        const auto& p = om.point(vh);
        a.positions.emplace_back(p[0], p[1], p[2]);
    }
    const std::vector<uint32_t> weld = weldByPosition(a.positions);

    // A face OpenMesh cannot connect (complex edge or vertex) is re-added on fresh copies of
    // its vertices. Point it back at the originals so the file's connectivity survives and
    // the edge map sees the non-manifold edge; the copies stay unreferenced.
    std::vector<uint32_t> original(a.positions.size());
    for (auto vh : om.vertices()) {
        uint32_t v = uint32_t(vh.idx());
        original[v] = om.status(vh).fixed_nonmanifold() ? weld[v] : v;
    }
    // Corner texture coordinates: the file's per-corner ones (OBJ), else its per-vertex ones.
    const bool cornerUVs = options.check(OpenMesh::IO::Options::FaceTexCoord);
    const bool vertexUVs = !cornerUVs && options.check(OpenMesh::IO::Options::VertexTexCoord);
    a.triangles.reserve(om.n_faces());
    for (auto fh : om.faces()) {
        glm::uvec3 t;
        glm::vec2 uv[3];
        int k = 0;
        bool copy = false;
        // A face's halfedges in order point at its vertices in fv_range order.
        for (auto heh : om.fh_range(fh)) {
            if (k == 3) break;
            auto vh = om.to_vertex_handle(heh);
            copy |= original[size_t(vh.idx())] != uint32_t(vh.idx());
            const auto& tc = cornerUVs ? om.texcoord2D(heh) : om.texcoord2D(vh);
            uv[k] = glm::vec2(tc[0], tc[1]);
            t[k++] = original[size_t(vh.idx())];
        }
        if (k == 3) {
            a.triangles.push_back(t);
            if (cornerUVs || vertexUVs) a.uvs.insert(a.uvs.end(), uv, uv + 3);
            a.reconnected.push_back(copy);
        }
    }
    a.droppedDegenerate = droppedRepeated;
    // OpenMesh's STL reader sets the vertex-normal option from STL's facet normals; those
    // are per face (and often zero), not vertex normals.
    if (ext != ".stl" && options.check(OpenMesh::IO::Options::VertexNormal)) {
        a.normals.reserve(a.positions.size());
        for (auto vh : om.vertices()) {
            const auto& fn = om.normal(vh);
            a.normals.emplace_back(fn[0], fn[1], fn[2]);
        }
    }
    return finishMesh(path, a, report);
}

Mesh finishMesh(const std::string& path, const MeshArrays& a, MeshReport* report) {
    Mesh mesh;
    mesh.positions = a.positions;
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
        const glm::vec3& p = mesh.positions[v];
        if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])))
            throwNonFinite(path, v, 0, p[0], p[1], p[2]);
    }
    const std::vector<uint32_t> weld = weldByPosition(mesh.positions);
    const bool withUVs = !a.uvs.empty();
    SHREFRACT_CHECK(!withUVs || a.uvs.size() == 3 * a.triangles.size());
    SHREFRACT_CHECK(a.reconnected.empty() || a.reconnected.size() == a.triangles.size());
    SHREFRACT_CHECK(a.normals.empty() || a.normals.size() == a.positions.size());

    const glm::dvec3 extent = glm::dvec3(mesh.boundsMax()) - glm::dvec3(mesh.boundsMin());
    const double diagonal2 = glm::dot(extent, extent);
    size_t degenerate = a.droppedDegenerate;
    size_t reconnectedKept = 0;
    mesh.triangles.reserve(a.triangles.size());
    for (size_t i = 0; i < a.triangles.size(); ++i) {
        const glm::uvec3& t = a.triangles[i];
        SHREFRACT_CHECK(t.x < mesh.positions.size() && t.y < mesh.positions.size() &&
                        t.z < mesh.positions.size());
        bool repeated = weld[t.x] == weld[t.y] || weld[t.y] == weld[t.z] || weld[t.x] == weld[t.z];
        if (repeated ||
            glm::length(faceCross(mesh.positions, t)) <= kDegenerateRelativeArea * diagonal2) {
            ++degenerate;
            continue;
        }
        mesh.triangles.push_back(t);
        if (withUVs) mesh.uvs.insert(mesh.uvs.end(), &a.uvs[3 * i], &a.uvs[3 * i] + 3);
        if (!a.reconnected.empty()) reconnectedKept += a.reconnected[i];
    }
    if (mesh.triangles.empty()) {
        throw inputError(path, degenerate > 0 ? "no triangles (all " + std::to_string(degenerate) +
                                                    " are degenerate)"
                                              : std::string("no triangles"));
    }

    MeshReport local;
    MeshReport& rep = report ? *report : local;
    rep = MeshReport();
    rep.degenerateTriangles = degenerate;
    auto warn = [&](const std::string& what) { rep.warnings.push_back(path + ": " + what); };
    if (degenerate > 0)
        warn(std::to_string(degenerate) +
             " degenerate triangles (zero area or repeated vertex) "
             "skipped");

    const Topology topo = analyzeTopology(mesh.triangles, weld);
    rep.borderEdges = topo.borderEdges;
    rep.nonManifoldEdges = topo.nonManifoldEdges;
    if (topo.borderEdges > 0)
        warn(std::to_string(topo.borderEdges) + " border edges: paths may leak");
    if (topo.nonManifoldEdges > 0)
        warn(std::to_string(topo.nonManifoldEdges) +
             " non-manifold edges (shared by more than two triangles): paths may leak");
    if (topo.inconsistentEdges > 0)
        warn(std::to_string(topo.inconsistentEdges) +
             " edges whose two triangles wind inconsistently: normals may point inward");
    if (reconnectedKept > 0)
        warn(std::to_string(reconnectedKept) +
             " triangles at non-manifold edges or vertices "
             "(split off by OpenMesh) were reconnected");

    // Outward orientation: a closed mesh wound clockwise (seen from outside) has negative
    // signed volume, sum of det(a, b, c) / 6. Open meshes have no inside to judge by.
    const bool closed = topo.borderEdges == 0 && topo.nonManifoldEdges == 0;
    if (closed) {
        double volume6 = 0.0;
        for (const glm::uvec3& t : mesh.triangles) {
            glm::dvec3 a(mesh.positions[t.x]), b(mesh.positions[t.y]), c(mesh.positions[t.z]);
            volume6 += glm::dot(a, glm::cross(b, c));
        }
        if (volume6 < 0.0) {
            for (glm::uvec3& t : mesh.triangles) std::swap(t.y, t.z);
            for (size_t c = 0; c < mesh.uvs.size(); c += 3) std::swap(mesh.uvs[c + 1], mesh.uvs[c + 2]);
            warn("triangles wound inward (negative volume): flipped so normals point outward");
        }
    }

    // Area-weighted vertex normals: the unnormalized face cross product is 2 * area * n.
    std::vector<glm::dvec3> computed(mesh.positions.size(), glm::dvec3(0.0));
    for (const glm::uvec3& t : mesh.triangles) {
        glm::dvec3 n = faceCross(mesh.positions, t);
        for (int k = 0; k < 3; ++k) computed[t[k]] += n;
    }
    auto computedNormal = [&](size_t v) {
        double len = glm::length(computed[v]);
        // Unreferenced vertices (or cancelling fans) have no normal; any unit vector will do.
        return len > 0.0 ? glm::vec3(computed[v] / len) : glm::vec3(0.0f, 0.0f, 1.0f);
    };

    mesh.normals.resize(mesh.positions.size());
    mesh.normalsFromFile = !a.normals.empty();
    if (mesh.normalsFromFile) {
        size_t fallbacks = 0, disagree = 0, referenced = 0;
        std::vector<bool> fromFile(mesh.positions.size(), false);
        for (size_t v = 0; v < mesh.positions.size(); ++v) {
            glm::dvec3 n(a.normals[v]);
            double len = glm::length(n);
            if (!std::isfinite(len) || len <= 0.0) {
                mesh.normals[v] = computedNormal(v);
                ++fallbacks;
                continue;
            }
            mesh.normals[v] = glm::vec3(n / len);
            fromFile[v] = true;
            if (glm::length(computed[v]) > 0.0) {
                ++referenced;
                disagree += glm::dot(n, computed[v]) < 0.0;
            }
        }
        if (fallbacks > 0)
            warn(std::to_string(fallbacks) +
                 " vertex normals in the file are zero or not finite: computed instead");
        // File normals that mostly oppose the (outward) winding were written for the other
        // orientation; trust the geometry and turn them around.
        if (disagree * 2 > referenced) {
            for (size_t v = 0; v < mesh.normals.size(); ++v)
                if (fromFile[v]) mesh.normals[v] = -mesh.normals[v];
            warn("vertex normals in the file point inward: flipped");
        }
    } else {
        for (size_t v = 0; v < mesh.positions.size(); ++v) mesh.normals[v] = computedNormal(v);
    }
    return mesh;
}

}  // namespace shrefract
