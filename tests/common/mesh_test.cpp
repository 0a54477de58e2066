#include "common/mesh.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "common/error.h"

namespace shrefract {
namespace {

namespace fs = std::filesystem;

std::string dataPath(const std::string& rel) { return std::string(SHREFRACT_DATA_DIR) + "/" + rel; }

// A fresh file under the test temp folder, named after the running test.
std::string tmpPath(const std::string& name) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    fs::path dir = fs::path(SHREFRACT_TEST_TMP) / "mesh" / info->name();
    fs::create_directories(dir);
    return (dir / name).string();
}

std::string writeText(const std::string& name, const std::string& text) {
    std::string path = tmpPath(name);
    std::ofstream(path, std::ios::binary) << text;
    return path;
}

// Expects loadMesh to throw an InputError whose message starts with the path and contains
// `fragment`; returns the message for further checks.
std::string expectInputError(const std::string& path, const std::string& fragment) {
    try {
        loadMesh(path);
    } catch (const InputError& e) {
        std::string what = e.what();
        EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
        EXPECT_NE(what.find(fragment), std::string::npos) << what;
        return what;
    }
    ADD_FAILURE() << "no InputError for " << path;
    return {};
}

// The cube [0,1]^3 with outward winding, as positions and triangles.
const float kCubeV[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                            {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
const unsigned kCubeT[12][3] = {{0, 3, 2}, {0, 2, 1}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                                {2, 3, 7}, {2, 7, 6}, {1, 2, 6}, {1, 6, 5}, {3, 0, 4}, {3, 4, 7}};

std::string cubeOff(size_t skipFaces = 0) {
    std::ostringstream os;
    os << "OFF\n8 " << 12 - skipFaces << " 0\n";
    for (auto& v : kCubeV) os << v[0] << " " << v[1] << " " << v[2] << "\n";
    for (size_t i = skipFaces; i < 12; ++i)
        os << "3 " << kCubeT[i][0] << " " << kCubeT[i][1] << " " << kCubeT[i][2] << "\n";
    return os.str();
}

std::string cubeObj(bool withNormals) {
    std::ostringstream os;
    for (auto& v : kCubeV) os << "v " << v[0] << " " << v[1] << " " << v[2] << "\n";
    if (withNormals) {
        // Corner normals along the diagonal from the centre: what a smooth exporter writes.
        for (auto& v : kCubeV)
            os << "vn " << 2 * v[0] - 1 << " " << 2 * v[1] - 1 << " " << 2 * v[2] - 1 << "\n";
    }
    for (auto& t : kCubeT) {
        os << "f";
        for (unsigned k : t) {
            os << " " << k + 1;
            if (withNormals) os << "//" << k + 1;
        }
        os << "\n";
    }
    return os.str();
}

// Binary little-endian PLY and binary STL, to cover the non-text readers too.
std::string cubePly() {
    std::ostringstream os;
    os << "ply\nformat binary_little_endian 1.0\nelement vertex 8\n"
          "property float x\nproperty float y\nproperty float z\n"
          "element face 12\nproperty list uchar int vertex_indices\nend_header\n";
    for (auto& v : kCubeV) os.write(reinterpret_cast<const char*>(v), 12);
    for (auto& t : kCubeT) {
        unsigned char n = 3;
        os.write(reinterpret_cast<const char*>(&n), 1);
        for (unsigned k : t) {
            int32_t i = int32_t(k);
            os.write(reinterpret_cast<const char*>(&i), 4);
        }
    }
    return os.str();
}

std::string binaryStl(const std::vector<std::array<std::array<float, 3>, 3>>& tris) {
    std::string header(80, ' ');
    header.replace(0, 9, "shrefract");
    std::ostringstream os;
    os << header;
    uint32_t n = uint32_t(tris.size());
    os.write(reinterpret_cast<const char*>(&n), 4);
    for (const auto& t : tris) {
        float normal[3] = {0, 0, 0};
        os.write(reinterpret_cast<const char*>(normal), 12);
        for (const auto& v : t) os.write(reinterpret_cast<const char*>(v.data()), 12);
        uint16_t attr = 0;
        os.write(reinterpret_cast<const char*>(&attr), 2);
    }
    return os.str();
}

std::vector<std::array<std::array<float, 3>, 3>> cubeTriangles() {
    std::vector<std::array<std::array<float, 3>, 3>> tris;
    for (auto& t : kCubeT) {
        std::array<std::array<float, 3>, 3> tri;
        for (int k = 0; k < 3; ++k) tri[k] = {kCubeV[t[k]][0], kCubeV[t[k]][1], kCubeV[t[k]][2]};
        tris.push_back(tri);
    }
    return tris;
}

double signedVolume(const Mesh& m) {
    double v6 = 0;
    for (const auto& t : m.triangles) {
        glm::dvec3 a(m.positions[t.x]), b(m.positions[t.y]), c(m.positions[t.z]);
        v6 += glm::dot(a, glm::cross(b, c));
    }
    return v6 / 6.0;
}

// Each normal is unit length; returns the fraction pointing away from the centroid.
double outwardFraction(const Mesh& m) {
    glm::dvec3 centroid(0.0);
    for (const auto& p : m.positions) centroid += glm::dvec3(p);
    centroid /= double(m.positions.size());
    size_t out = 0;
    for (size_t i = 0; i < m.positions.size(); ++i) {
        EXPECT_NEAR(glm::length(m.normals[i]), 1.0, 1e-5) << "vertex " << i;
        out += glm::dot(glm::dvec3(m.normals[i]), glm::dvec3(m.positions[i]) - centroid) > 0;
    }
    return double(out) / double(m.positions.size());
}

void expectUnitCube(const Mesh& m) {
    EXPECT_EQ(m.triangles.size(), 12u);
    EXPECT_EQ(m.boundsMin(), glm::vec3(0.0f));
    EXPECT_EQ(m.boundsMax(), glm::vec3(1.0f));
    EXPECT_NEAR(signedVolume(m), 1.0, 1e-6);
    EXPECT_EQ(outwardFraction(m), 1.0);
}

struct DataMesh {
    const char* file;
    size_t vertices, triangles;
};

TEST(Mesh, LoadsEveryDataMeshClosedWithExactCounts) {
    const DataMesh meshes[] = {{"sphere.off", 162, 320},
                               {"cow.off", 2904, 5804},
                               {"knot1.off", 3200, 6400},
                               {"bunny00.off", 37706, 75408}};
    for (const DataMesh& d : meshes) {
        SCOPED_TRACE(d.file);
        MeshReport report;
        Mesh m = loadMesh(dataPath(std::string("meshes/") + d.file), &report);
        EXPECT_EQ(m.positions.size(), d.vertices);
        EXPECT_EQ(m.triangles.size(), d.triangles);
        EXPECT_EQ(m.normals.size(), d.vertices);
        EXPECT_FALSE(m.normalsFromFile);
        EXPECT_EQ(report.borderEdges, 0u);
        EXPECT_EQ(report.nonManifoldEdges, 0u);
        EXPECT_EQ(report.degenerateTriangles, 0u);
        EXPECT_TRUE(report.warnings.empty()) << report.warnings.front();
        EXPECT_GT(signedVolume(m), 0.0);
        for (const auto& n : m.normals) ASSERT_NEAR(glm::length(n), 1.0, 1e-5);
    }
}

TEST(Mesh, SphereNormalsPointOutward) {
    Mesh m = loadMesh(dataPath("meshes/sphere.off"));
    EXPECT_EQ(outwardFraction(m), 1.0);
}

TEST(Mesh, IcosphereHasUnitRadiusAndRadialNormals) {
    Mesh m = loadMesh(dataPath("scenes/icosphere.off"));
    EXPECT_EQ(m.triangles.size(), 1280u);
    for (size_t i = 0; i < m.positions.size(); ++i) {
        ASSERT_NEAR(glm::length(m.positions[i]), 1.0, 1e-6);
        // Area-weighted normals of a symmetric fan are close to radial.
        ASSERT_GT(glm::dot(m.normals[i], glm::normalize(m.positions[i])), 0.995f);
    }
}

TEST(Mesh, ChecksumIsStableAndSeesChanges) {
    Mesh a = loadMesh(dataPath("meshes/sphere.off"));
    Mesh b = loadMesh(dataPath("meshes/sphere.off"));
    EXPECT_EQ(a.checksum().size(), 16u);
    EXPECT_EQ(a.checksum(), b.checksum());
    b.positions[5].x += 1e-6f;
    EXPECT_NE(a.checksum(), b.checksum());
    Mesh c = a;
    std::swap(c.triangles[0].y, c.triangles[0].z);
    EXPECT_NE(a.checksum(), c.checksum());
    // FNV-1a 64 of no bytes is its offset basis.
    EXPECT_EQ(Mesh().checksum(), "cbf29ce484222325");
}

TEST(Mesh, OffRoundTrip) { expectUnitCube(loadMesh(writeText("cube.off", cubeOff()))); }

TEST(Mesh, ObjWithoutNormalsComputesThem) {
    Mesh m = loadMesh(writeText("cube.obj", cubeObj(false)));
    expectUnitCube(m);
    EXPECT_FALSE(m.normalsFromFile);
}

TEST(Mesh, ObjWithNormalsUsesThemNormalized) {
    Mesh m = loadMesh(writeText("cube.obj", cubeObj(true)));
    expectUnitCube(m);
    EXPECT_TRUE(m.normalsFromFile);
    // The file's corner normals are (±1, ±1, ±1): normalized, exactly the diagonal.
    for (size_t i = 0; i < m.positions.size(); ++i) {
        glm::vec3 expected = glm::normalize(m.positions[i] * 2.0f - 1.0f);
        EXPECT_NEAR(glm::distance(m.normals[i], expected), 0.0f, 1e-6f) << i;
    }
}

TEST(Mesh, ZeroNormalInFileFallsBackToComputed) {
    std::string obj = cubeObj(true);
    obj.replace(obj.find("vn -1 -1 -1"), 11, "vn 0 0 0");
    MeshReport report;
    Mesh m = loadMesh(writeText("cube.obj", obj), &report);
    EXPECT_TRUE(m.normalsFromFile);
    EXPECT_NEAR(glm::length(m.normals[0]), 1.0f, 1e-6f);
    EXPECT_LT(glm::dot(m.normals[0], glm::vec3(1.0f)), 0.0f);  // corner 0 faces (-1,-1,-1)
    ASSERT_EQ(report.warnings.size(), 1u);
    EXPECT_NE(report.warnings[0].find("1 vertex normals"), std::string::npos);
}

TEST(Mesh, UppercaseExtensionIsAccepted) {
    expectUnitCube(loadMesh(writeText("CUBE.OFF", cubeOff())));
}

TEST(Mesh, BinaryPlyRoundTrip) { expectUnitCube(loadMesh(writeText("cube.ply", cubePly()))); }

TEST(Mesh, BinaryStlRoundTripSharesVertices) {
    MeshReport report;
    Mesh m = loadMesh(writeText("cube.stl", binaryStl(cubeTriangles())), &report);
    expectUnitCube(m);
    EXPECT_EQ(report.borderEdges, 0u);
}

std::string asciiStl() {
    std::ostringstream os;
    os << "solid cube\n";
    for (const auto& t : cubeTriangles()) {
        os << "facet normal 0 0 0\nouter loop\n";
        for (const auto& v : t) os << "vertex " << v[0] << " " << v[1] << " " << v[2] << "\n";
        os << "endloop\nendfacet\n";
    }
    os << "endsolid cube\n";
    return os.str();
}

TEST(Mesh, AsciiStlRoundTrip) { expectUnitCube(loadMesh(writeText("cube.stl", asciiStl()))); }

// A file cut short holds fewer vertices or faces than its header promises: OpenMesh alone took
// the part it got (an open mesh, a warning, exit 0). Every format, cut at every eighth of it.
TEST(Mesh, CutShortFilesAreRefused) {
    std::string ply = cubePly();
    std::string asciiPly = "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\n"
                           "property float y\nproperty float z\nelement face 12\n"
                           "property list uchar int vertex_indices\nend_header\n";
    for (auto& v : kCubeV) asciiPly += std::to_string(v[0]) + " " + std::to_string(v[1]) + " " +
                                       std::to_string(v[2]) + "\n";
    for (auto& t : kCubeT)
        asciiPly += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " +
                    std::to_string(t[2]) + "\n";
    const std::pair<std::string, std::string> files[] = {
        {"cube.off", cubeOff()}, {"cube.ply", ply}, {"ascii.ply", asciiPly},
        {"cube.stl", binaryStl(cubeTriangles())}, {"ascii.stl", asciiStl()}};
    for (const auto& [name, text] : files) {
        expectUnitCube(loadMesh(writeText(name, text)));  // whole: fine
        // Cut where a whole line or record ends as well as in the middle of one.
        for (int eighth = 1; eighth < 8; ++eighth) {
            size_t at = text.size() * size_t(eighth) / 8;
            if (eighth % 2 == 0 && text.rfind('\n', at) != std::string::npos)
                at = text.rfind('\n', at) + 1;
            SCOPED_TRACE(name + " cut at " + std::to_string(at) + " of " + std::to_string(text.size()));
            EXPECT_THROW(loadMesh(writeText("cut_" + name, text.substr(0, at))), InputError);
        }
    }
    const std::string off = cubeOff();
    expectInputError(writeText("short.off", off.substr(0, off.rfind('\n', off.size() - 2) + 1)),
                     "cut short: the header promises 8 vertices and 12 faces, the file ends after 11 faces");
    expectInputError(writeText("short.stl", binaryStl(cubeTriangles()).substr(0, 84 + 50 * 11)),
                     "binary STL cut short or padded: its header promises 12 triangles (684 bytes)");
    expectInputError(writeText("short.ply", ply.substr(0, ply.size() - 13)),
                     "cut short: the header promises 12 face elements, the file ends after 11");
    // Values that are not numbers of their type (found by the fuzzer: OpenMesh's ASCII PLY reader
    // looped on "3HHH" as a face index until it held 2 GB; "inf" stops a C++ stream as well).
    std::string badIndex = asciiPly, badCoordinate = asciiPly;
    badIndex.replace(badIndex.rfind("\n3 ") + 3, 1, "3HHH");
    badCoordinate.replace(badCoordinate.find("end_header\n") + 11, 1, "inf");
    expectInputError(writeText("index.ply", badIndex), "'3HHH' is not an integer");
    expectInputError(writeText("coordinate.ply", badCoordinate), "is not a number");
    // A line holds exactly the values its properties imply. OpenMesh reads values, not lines, so
    // one too many puts every later value out of step (found by the fuzzer: a first face "2 0 3 2",
    // then "-4" read as a list length, grew a vector to 2 GB). A fourth coordinate, or a face
    // list one shorter than its values, is refused.
    const size_t firstVertex = asciiPly.find("end_header\n") + 11;
    std::string extraCoordinate = asciiPly, shortList = asciiPly;
    extraCoordinate.insert(asciiPly.find('\n', firstVertex), " 0.25");
    shortList.replace(asciiPly.find("\n3 ") + 1, 1, "2");
    expectInputError(writeText("coordinates.ply", extraCoordinate), "vertex 0 has 4 values, its header says 3");
    expectInputError(writeText("list.ply", shortList), "face 0 has 4 values, its header says 3");
    // Records without properties take no bytes, so a binary file's size cannot bound their count
    // (found by the fuzzer: OpenMesh reserved 3 GB for 2^28 of them). The cube with one more
    // element of that kind, in either format, is refused.
    const std::string empty = "element extra 268435456\nend_header\n";
    std::string emptyBinary = ply, emptyAscii = asciiPly;
    emptyBinary.replace(emptyBinary.find("end_header\n"), 11, empty);
    emptyAscii.replace(emptyAscii.find("end_header\n"), 11, empty);
    expectInputError(writeText("empty_records.ply", emptyBinary),
                     "element extra has 268435456 records but no properties");
    expectInputError(writeText("empty_records_ascii.ply", emptyAscii),
                     "element extra has 268435456 records but no properties");
    // A face colour: OpenMesh's OFF reader reads it as the next face's vertex count (found by
    // the fuzzer: -12 became 2^32 - 12, and the reader grew a vector to 3 GB).
    std::string colour = off;
    size_t lineEnd = 0;
    for (int line = 0; line < 11; ++line) lineEnd = colour.find('\n', lineEnd) + 1;
    colour.insert(lineEnd - 1, " -12 7 6");  // after the first face's indices (line 11)
    expectInputError(writeText("colour.off", colour), "line 11: face 0 has 3 values after its indices");
    // The counts line holds exactly three counts. OpenMesh reads them from the stream: with two
    // it took the first coordinate for the edge count and loaded a wrong cube; with more it reads
    // on past them, out of step (found by the fuzzer: "8 04 63 2 3 3 -1 0" made a face of 2^31
    // vertices). An edge count that is not a count is refused as well.
    const size_t countsAt = off.find('\n') + 1, countsSize = off.find('\n', countsAt) - countsAt;
    const std::pair<std::string, int> badCounts[] = {{"8 12", 2}, {"8 12 0 3 3 -1 0", 7}, {"8 12 -1", 3}};
    for (const auto& [bad, values] : badCounts) {
        SCOPED_TRACE(bad);
        expectInputError(writeText("counts.off", std::string(off).replace(countsAt, countsSize, bad)),
                         "line 2: the counts line holds " + std::to_string(values) +
                             " values, not the vertex, face and edge counts");
    }
    expectInputError(writeText("short.obj", "v 0 0 0\nv 1 0 0\nv 0 1\n"),
                     "line 3: a vertex is not 3 numbers");
    expectInputError(writeText("corner.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 f 3\n"),
                     "line 4: a face corner is not v, v/t, v//n or v/t/n");
}

// Every OBJ index names what the file has. OpenMesh writes the texture coordinate of a corner
// whose vertex it does not have before it drops the face (found by the fuzzer: a
// heap-buffer-overflow), and a texture coordinate or normal index past the file's loaded without
// a word. A negative index counts back from its line; a face before its vertices is what OpenMesh
// reads, and loads.
TEST(Mesh, ObjIndicesNameWhatTheFileHas) {
    const std::string cube = cubeObj(false);
    const size_t lastFace = cube.rfind("\nf ") + 1;
    const std::string lastLine = cube.substr(lastFace, cube.find('\n', lastFace) - lastFace);
    const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n";
    const std::pair<std::string, std::string> bad[] = {
        {std::string(cube).replace(lastFace, lastLine.size(), "f 1 2 9"), "names vertex 9 of 8"},
        {tri + "f 1/1 2/2 3/4\n", "face corner 3/4 names texture coordinate 4 of 3"},
        {tri + "f 1//1 2//1 3//2\n", "face corner 3//2 names normal 2 of 1"},
        {tri + "f -1 -2 -4\n", "face corner -4 names vertex -4 of 3"},
        {"f -1 -2 -3\n" + tri, "face corner -1 names vertex -1 of 0"},
        {tri + "vt 0.5 x\nf 1 2 3\n", "line 8: a texture coordinate is not 1 to 3 numbers"},
        {tri + "vn 0 1\nf 1 2 3\n", "line 8: a normal is not 3 numbers"},
    };
    for (const auto& [text, fragment] : bad) {
        SCOPED_TRACE(fragment);
        expectInputError(writeText("indices.obj", text), fragment);
    }
    EXPECT_EQ(loadMesh(writeText("forward.obj", "f 1 2 3\n" + tri)).triangles.size(), 1u);
    EXPECT_EQ(loadMesh(writeText("relative.obj", tri + "f -3/-3/-1 -2/-2/-1 -1/-1/-1\n")).triangles.size(), 1u);
}

TEST(Mesh, InwardWoundClosedMeshIsFlipped) {
    MeshReport report;
    Mesh m = loadMesh(dataPath("scenes/inverted_cube.off"), &report);
    EXPECT_NEAR(signedVolume(m), 1.0, 1e-6);
    EXPECT_EQ(outwardFraction(m), 1.0);
    ASSERT_EQ(report.warnings.size(), 1u);
    EXPECT_NE(report.warnings[0].find("flipped"), std::string::npos);
}

// Texture coordinates per triangle corner: OBJ `vt` may differ at one vertex (a UV seam), PLY's
// per-vertex `u v` are copied to every corner; dropped triangles and the inward flip keep every
// corner with its own UV.
TEST(Mesh, TextureCoordinatesFollowTheirCorners) {
    // Two triangles over a square; vertex 0 has two texture coordinates (a seam), and a third,
    // degenerate triangle (repeated vertex) is dropped.
    const std::string obj =
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
        "vt 0.1 0.1\nvt 0.9 0.1\nvt 0.9 0.9\nvt 0.1 0.9\nvt 0.5 0.5\n"
        "f 1/1 2/2 3/3\nf 1/1 1/1 2/2\nf 1/5 3/3 4/4\n";
    Mesh m = loadMesh(writeText("uv.obj", obj));
    ASSERT_EQ(m.triangles.size(), 2u);
    ASSERT_EQ(m.uvs.size(), 6u);
    const glm::vec2 want[6] = {{0.1f, 0.1f}, {0.9f, 0.1f}, {0.9f, 0.9f},
                               {0.5f, 0.5f}, {0.9f, 0.9f}, {0.1f, 0.9f}};
    for (int c = 0; c < 6; ++c) {
        // The corner's vertex decides which UV it has: match by position, not by order.
        const glm::vec3 p = m.positions[m.triangles[c / 3][c % 3]];
        const bool first = c < 3;
        const glm::vec2 expected = p == glm::vec3(0, 0, 0) ? (first ? want[0] : want[3])
                                   : p == glm::vec3(1, 0, 0) ? want[1]
                                   : p == glm::vec3(1, 1, 0) ? want[2]
                                                             : want[5];
        EXPECT_EQ(m.uvs[c], expected) << "corner " << c;
    }
    // PLY vertex u v; the tetrahedron is wound inward, so the loader flips every triangle.
    const std::string ply =
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nproperty float u\nproperty float v\nelement face 4\n"
        "property list uchar int vertex_indices\nend_header\n"
        "0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 1\n0 0 1 0.5 0.5\n"
        "3 0 1 2\n3 0 3 1\n3 0 2 3\n3 1 3 2\n";
    MeshReport report;
    Mesh t = loadMesh(writeText("uv.ply", ply), &report);
    ASSERT_EQ(t.uvs.size(), 12u);
    for (size_t c = 0; c < 12; ++c) {
        const glm::vec3 p = t.positions[t.triangles[c / 3][c % 3]];
        const glm::vec2 expected = p.z == 1.0f ? glm::vec2(0.5f) : glm::vec2(p.x, p.y);
        EXPECT_EQ(t.uvs[c], expected) << "corner " << c;
    }
    EXPECT_GT(signedVolume(t), 0.0);
    // A file without texture coordinates has none.
    EXPECT_TRUE(loadMesh(writeText("nouv.off", cubeOff())).uvs.empty());
}

TEST(Mesh, MissingFile) { expectInputError(tmpPath("nope.off"), "file not found"); }

TEST(Mesh, UnsupportedExtension) {
    expectInputError(writeText("cube.xyz", cubeOff()),
                     "unsupported extension '.xyz' (expected .obj, .off, .ply, .stl)");
}

TEST(Mesh, GarbageIsUnparsable) {
    expectInputError(writeText("junk.off", "hello \x01\x02 world\n"),
                     "could not parse: 'hello' is not an OFF keyword");
    expectInputError(writeText("junk.ply", "hello \x01\x02 world\n"), "could not parse");
}

TEST(Mesh, GarbageObjHasNoTriangles) {
    // OpenMesh's OBJ reader skips lines it does not know and reports success.
    expectInputError(writeText("junk.obj", "hello world\n"), "no triangles");
}

TEST(Mesh, EmptyFile) { expectInputError(writeText("empty.obj", ""), "file is empty"); }

TEST(Mesh, NoFaces) {
    expectInputError(writeText("points.off", "OFF\n1 0 0\n0 0 0\n"), "no triangles");
}

TEST(Mesh, FaceIndexOutOfRangeIsUnparsable) {
    expectInputError(writeText("bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
                     "line 6: face 0 refers to vertex 7 of 3");
}

TEST(Mesh, NanCoordinateInTextOff) {
    std::string off = cubeOff();
    off.replace(off.find("1 1 1\n"), 6, "nan 0 1\n");  // vertex 6
    std::string msg = expectInputError(writeText("nan.off", off),
                                       "vertex 6 (line 9) has non-finite coordinates (nan, 0, 1)");
}

TEST(Mesh, InfCoordinateInTextObj) {
    std::string obj = cubeObj(false);
    obj.replace(obj.find("v 0 1 1\n"), 8, "v 0 -inf 1\n");  // vertex 7, line 8
    expectInputError(writeText("inf.obj", obj),
                     "vertex 7 (line 8) has non-finite coordinates (0, -inf, 1)");
}

TEST(Mesh, NanCoordinateInBinaryStl) {
    auto tris = cubeTriangles();
    tris[3][1][0] = std::numeric_limits<float>::quiet_NaN();
    std::string msg =
        expectInputError(writeText("nan.stl", binaryStl(tris)), "has non-finite coordinates (nan");
    EXPECT_NE(msg.find("vertex "), std::string::npos);
}

TEST(Mesh, DegenerateTrianglesAreSkippedAndCounted) {
    // The cube plus a zero-area triangle (three collinear vertices on an edge) and a triangle
    // that repeats a vertex (which OpenMesh drops itself, and which must still be counted).
    std::string off = cubeOff();
    off.replace(0, 10, "OFF\n9 14 0");
    off.insert(off.find("3 0 3 2"), "0.5 0 0\n");
    off += "3 0 8 1\n3 0 0 1\n";
    MeshReport report;
    std::string path = writeText("degenerate.off", off);
    Mesh m = loadMesh(path, &report);
    EXPECT_EQ(m.triangles.size(), 12u);
    EXPECT_EQ(report.degenerateTriangles, 2u);
    EXPECT_EQ(report.borderEdges, 0u);
    ASSERT_EQ(report.warnings.size(), 1u);
    EXPECT_NE(report.warnings[0].find("2 degenerate triangles"), std::string::npos);
    EXPECT_EQ(report.warnings[0].rfind(path + ": ", 0), 0u);
}

TEST(Mesh, AllDegenerateIsAnError) {
    expectInputError(writeText("flat.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n"),
                     "no triangles (all 1 are degenerate)");
}

TEST(Mesh, OpenMeshCountsBorderEdgesAndKeepsWinding) {
    // A cube missing its -z face (2 triangles): the hole is a square, 4 border edges.
    MeshReport report;
    std::string path = writeText("open.off", cubeOff(2));
    Mesh m = loadMesh(path, &report);
    EXPECT_EQ(m.triangles.size(), 10u);
    EXPECT_EQ(report.borderEdges, 4u);
    EXPECT_EQ(report.nonManifoldEdges, 0u);
    ASSERT_EQ(report.warnings.size(), 1u);
    EXPECT_EQ(report.warnings[0], path + ": 4 border edges: paths may leak");
    EXPECT_EQ(loadMesh(dataPath("scenes/open_cube.off"), &report).triangles.size(), 10u);
    EXPECT_EQ(report.borderEdges, 4u);
}

TEST(Mesh, NonManifoldEdgeIsCountedAndConnectivityKept) {
    // The closed cube plus a fin on edge 0-1: that edge now has three triangles. OpenMesh
    // cannot add the fin and splits it off on copied vertices; the loader reconnects it.
    std::string off = cubeOff();
    off.replace(0, 10, "OFF\n9 13 0");
    off.insert(off.find("3 0 3 2"), "0.5 -1 -1\n");
    off += "3 0 1 8\n";
    MeshReport report;
    Mesh m = loadMesh(writeText("fin.off", off), &report);
    EXPECT_EQ(m.triangles.size(), 13u);
    EXPECT_EQ(report.nonManifoldEdges, 1u);
    EXPECT_EQ(report.borderEdges, 2u);  // the fin's two free edges
    for (const auto& t : m.triangles)
        for (int k = 0; k < 3; ++k) EXPECT_LT(t[k], 9u);  // no OpenMesh vertex copies used
    bool warned = false;
    for (const auto& w : report.warnings)
        warned |= w.find("1 non-manifold edges") != std::string::npos;
    EXPECT_TRUE(warned);
}

TEST(Mesh, UnsharedVerticesAtEqualPositionsCloseTheMesh) {
    // Every triangle on its own three vertices (a "triangle soup"): no edge is shared by index,
    // yet the positions match exactly, so rays cannot leak and no border edge is reported.
    std::ostringstream os;
    os << "OFF\n36 12 0\n";
    for (auto& t : kCubeT)
        for (unsigned k : t)
            os << kCubeV[k][0] << " " << kCubeV[k][1] << " " << kCubeV[k][2] << "\n";
    for (unsigned i = 0; i < 12; ++i)
        os << "3 " << 3 * i << " " << 3 * i + 1 << " " << 3 * i + 2 << "\n";
    MeshReport report;
    Mesh m = loadMesh(writeText("soup.off", os.str()), &report);
    EXPECT_EQ(m.positions.size(), 36u);
    EXPECT_EQ(report.borderEdges, 0u);
    EXPECT_EQ(report.nonManifoldEdges, 0u);
    EXPECT_TRUE(report.warnings.empty());
}

TEST(Mesh, OpenMeshNoiseIsSilenced) {
    ::testing::internal::CaptureStderr();
    EXPECT_THROW(loadMesh(writeText("junk.off", "hello\n")), InputError);
    MeshReport report;
    std::string off = cubeOff();
    off.replace(0, 10, "OFF\n8 13 0");
    off += "3 0 0 1\n";  // OpenMesh: "Face has equal vertices"
    loadMesh(writeText("rep.off", off), &report);
    EXPECT_EQ(report.degenerateTriangles, 1u);
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

}  // namespace
}  // namespace shrefract
